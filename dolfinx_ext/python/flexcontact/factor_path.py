"""The condensed contact problem without a dense W: ``ContactProblem(contact_operator="factor")``.

One plain MUMPS factorization of K (no Schur complement, no F*). The local problem is solved
on a working set of pairs (kernel's operator_contact.hpp: solve_working_set): W's columns of
the pairs that come into contact only, computed through that factor by blocks of
right-hand sides and kept across increments, the set grown until no pair outside it
penetrates. Memory is the factor's plus 8·(m·d)·(d·pairs in the set) bytes, capped by
memory.working_set_bytes(); past the cap, an accelerated projected fixed point that needs
only W·x (one back-substitution per iteration, a few hundred) takes over.
bench/large_contact.py measures the crossover; docs/large_contact.md says when to use which.

In parallel every rank holds the kernel object and runs the same deterministic iteration on
replicated contact vectors; each product is a collective MatSolve.
"""
from __future__ import annotations

import time
from typing import Optional, Sequence

import numpy as np
from petsc4py import PETSc

from . import _cpp
from .condensation import Condensation
from .memory import working_set_bytes
from .pairing import pair_caps
from .names import CONTACT_OPERATORS, check_option
from .errors import InputError

def check_contact_operator(value, floating: bool) -> None:
    """A clear error for an unknown contact_operator, or one the options cannot use."""
    check_option(value, CONTACT_OPERATORS, "contact_operator")
    if value == "factor" and floating:
        raise InputError("contact_operator='factor' does not handle bodies held only by "
                         "contact (floating=True); use contact_operator='dense'")


def _pair_arrays(pairs) -> tuple:
    """What the kernel's pairs are made of, picklable (rank 0's pairs to every rank)."""
    return (int(pairs.m), np.asarray(pairs.masters), np.asarray(pairs.weights),
            np.asarray(pairs.normal), np.asarray(pairs.offset))


def _kernel_pairs(arrays: tuple) -> list:
    m, masters, weights, normal, offset = arrays
    return _cpp.pairs_from_normals(np.arange(m), masters, weights, normal, offset)


class FactorCondensation(Condensation):
    """The plain factor of K and the kernel's ``FactorContact`` (on every rank).

    Read as Condensation is: ``contact``, ``factor``, ``flex_info``, ``B``, ``x0``,
    ``frames`` (rank 0), gather/reaction/contact_values; ``W`` is None (never formed). The
    stepper (stepper.py) drives it like the dense one, with every rank in the kernel step.
    """

    def __init__(self, K: PETSc.Mat, bcs: Sequence, pairs, mu: Optional[np.ndarray],
                 dim: int, comm, options, ordering: str = "auto"):
        self.comm = comm
        root = comm.rank == 0
        self.pairs = pairs
        self._contact_scatter(K, pairs, dim)
        # Every rank builds the kernel object: each needs the number of virtual DOFs.
        self.n_virtual_dofs = comm.bcast(self.n_virtual_dofs, root=0)
        constrained = self._constrained_mask(K, bcs)
        if root and self.n_virtual_dofs:
            constrained = np.concatenate([constrained, np.ones(self.n_virtual_dofs, bool)])

        self.timings = {}
        t0 = time.perf_counter()
        # No contact DOFs asked: one plain factorization, no Schur complement. Not "schur":
        # on several ranks that is a DistributedSchur, and the products need PETSc's Mat.
        _, self.factor, info = _cpp.flexibility(K, np.zeros(0, np.int64), "inverse_entries",
                                                ordering)
        self.timings["flexibility_s"] = time.perf_counter() - t0
        self.flex_info = dict(info, method="factor")
        self.factorizations = 1
        self.n_contact_dofs = comm.bcast(self.dofs.size if root else None, root=0)

        # Rank 0's memory for the working set: every rank must take the same branches.
        dofs, x, arrays, mu, constrained, self.working_set_bytes, caps = comm.bcast(
            (self.dofs, np.asarray(pairs.x), _pair_arrays(pairs), np.asarray(mu), constrained,
             working_set_bytes(), pair_caps(pairs)) if root else None, root=0)
        t0 = time.perf_counter()
        self._kernel_dofs = dofs
        self.contact = self._make_contact(dim, K, dofs, x, _kernel_pairs(arrays), mu,
                                          constrained, options)
        if caps is not None:
            self.contact.set_crushing(caps)
        self.timings["delassus_s"] = time.perf_counter() - t0
        self._cached = None

    collective = True
    """Every rank holds the kernel object and runs the same step."""

    def _make_contact(self, dim, K, dofs, x, kpairs, mu, constrained, options):
        return _cpp.FactorContact(dim, self.factor.handle, K.handle, dofs, self.n_virtual_dofs,
                                  x, kpairs, mu, constrained, options, self.working_set_bytes)

    def _operator(self, name: str):
        # W is never formed; B, x0 and the frames are read on rank 0, as on the dense path.
        if name == "W" or self.comm.rank != 0:
            return None
        return super()._operator(name)

    def set_pairs(self, pairs, mu) -> None:
        """New pairs on the same contact nodes (rank 0's pairs and mu). Collective."""
        root = self.comm.rank == 0
        self.pairs = pairs
        arrays, mu, caps = self.comm.bcast(
            (_pair_arrays(pairs), np.asarray(mu), pair_caps(pairs)) if root else None, root=0)
        self.contact.set_pairs(_kernel_pairs(arrays), mu, np.zeros(0) if caps is None else caps)
        self._cached = None


class FactorImpactCondensation(FactorCondensation):
    """The factor path of ImpactProblem (``contact_operator="factor"``): one plain
    factorization of Ŵ = M + hθC + h²θ²K and the kernel's ``FactorImpact`` on every rank.

    Each time step's index set fetches W_eff's columns of its pairs not held yet (one block
    of back-substitutions) and keeps them; its local problem is the dense path's (the same
    chain on W_eff restricted to the index set), so the answers agree to rounding. A step
    costs two solves while an impulse acts (v_free, then v⁺), one otherwise."""

    def __init__(self, W_hat: PETSc.Mat, bcs: Sequence, pairs, mu: Optional[np.ndarray],
                 dim: int, comm, options, *, restitution: float, dt_s: float, theta: float,
                 ordering: str = "auto"):
        self._scheme = (float(restitution), float(dt_s), float(theta))
        super().__init__(W_hat, bcs, pairs, mu, dim, comm, options, ordering=ordering)

    def _make_contact(self, dim, K, dofs, x, kpairs, mu, constrained, options):
        if not self.working_set_bytes > 0:
            raise InputError("contact_operator='factor': no memory allowed for W_eff's "
                             "columns (FLEXCONTACT_WORKING_SET_GB = 0); the impact factor "
                             "path needs the index set's columns")
        e, dt, theta = self._scheme
        return _cpp.FactorImpact(dim, self.factor.handle, K.handle, dofs, self.n_virtual_dofs,
                                 x, kpairs, mu, e, dt, theta, constrained, options,
                                 self.working_set_bytes)

    def refactor(self, A: PETSc.Mat, method: str, ordering: str, dt_s: float,
                 where: str) -> None:
        """The new time step's Ŵ factored (one plain factorization) and handed to every
        rank's kernel object, whose held columns are dropped. Collective."""
        _, factor, info = _cpp.flexibility(A, np.zeros(0, np.int64), "inverse_entries",
                                           ordering)
        self.contact.set_flexibility(factor.handle, A.handle, self._kernel_dofs,
                                     self.n_virtual_dofs, float(dt_s))
        self.factor, self.flex_info = factor, dict(info, method="factor")
        # The reaction's vectors take A's layout: the old Ŵ is destroyed by the caller.
        self._template = A
        self.factorizations += 1
        self._cached = None
