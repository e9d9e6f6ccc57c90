"""Static frictional contact between deformable bodies, loaded in increments.

The flow is one-directional (docs/architecture.md §2), one module per stage: ``assembly`` (K, p),
``pairing`` (node pairs of the contact interfaces), ``condensation`` (one MUMPS
factorization gives F* = (K⁻¹)_cc on the contact DOFs; the kernel object holds B, x0,
W = B F* Bᵀ and solves x = W λ + q per increment), ``postprocess`` (summaries and the
contact fields). u = K⁻¹ (p + Bᵀ λ) comes from the same factor.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Optional, Sequence, Union

import numpy as np

import dolfinx.fem

from . import compat
from ._cpp import ConvergenceError, SolverOptions
from .assembly import assemble_load, assemble_stiffness
from .condensation import Condensation
from .names import FlexibilityMethod, check_chain, check_flexibility_method
from .pairing import pair_interfaces
from .postprocess import (STATE_NAMES, ContactFields, IncrementResult,  # noqa: F401
                          IncrementSummary, record_increment)
from .rigid_modes import check_bodies

# Annotations use DOLFINx 0.9's class names; 0.5 spells them *MetaClass, so never at run time.
if TYPE_CHECKING:
    import ufl
    from dolfinx.fem import DirichletBC
    from dolfinx.mesh import MeshTags


@dataclass
class ContactInterface:
    """Two tagged contact surfaces and their Coulomb friction coefficient.

    ``slave`` is the contact surface (the softer body's, in the seed's words) and ``master``
    the target; the master's outward normal defines the local frame. ``tolerance_m`` is the
    largest tangential offset between paired nodes (default: 1e-6 of the surfaces' extent).
    """

    facet_tags: MeshTags
    slave: int
    master: int
    mu: float
    tolerance_m: Optional[float] = None
    name: str = ""

    def __post_init__(self):
        mu = self.mu
        if not isinstance(mu, (int, float, np.floating)) or not math.isfinite(mu) or mu < 0:
            raise ValueError(f"contact interface {self.label}: friction coefficient mu={mu!r}; "
                             "it must be a finite number ≥ 0")
        if self.slave == self.master:
            raise ValueError(f"contact interface {self.label}: slave and master are the same "
                             f"tag ({self.slave})")

    @property
    def label(self) -> str:
        return self.name or f"slave tag {self.slave} / master tag {self.master}"


class ContactProblem:
    """Static contact of deformable bodies with Coulomb friction, by condensation.

    Parameters
    ----------
    a : UFL bilinear form of linear elasticity (K); must not change between increments.
    L : UFL linear form of the loads (p), or None. Loads change between increments through
        the dolfinx Constants/Functions it contains, set by ``solve``'s ``load`` callback.
    bcs : Dirichlet conditions (values may also change per increment).
    contact : one ContactInterface or a list of them.
    bodies : optional ``(cell_tags, {name: value})``; each body's rigid modes are checked
        so that a singular K is reported with the body's name.
    stress : optional callable u -> UFL scalar (e.g. von Mises) written as a DG0 field.
    solver : kernel SolverOptions (tolerance, max_iterations, chain).
    flexibility : "schur" (MUMPS Schur complement; on several ranks PETSc cannot solve with
        that factor, so MUMPS selected inverse entries are used: "inverse_entries"),
        "inverse_entries", or "matmatsolve" (a multi-right-hand-side solve, the reference).
        Each makes one sparse factorization, which then serves every solve.

    On rank 0, ``contact`` is the kernel's condensed problem and ``B``, ``W``, ``x0``,
    ``frames`` its operators; ``local_problem`` is the last increment's {dim, W, q, mu}.
    """

    def __init__(self, a: ufl.Form, L: Optional[ufl.Form], bcs: Sequence[DirichletBC],
                 contact: Union[ContactInterface, Sequence[ContactInterface]], *,
                 bodies: Optional[tuple[MeshTags, dict[str, int]]] = None,
                 stress: Optional[Callable] = None, solver: Optional[SolverOptions] = None,
                 flexibility: FlexibilityMethod = "schur"):
        check_flexibility_method(flexibility)
        if solver is not None:
            check_chain(solver.chain)
        self.interfaces = list(contact) if isinstance(contact, (list, tuple)) else [contact]
        if not self.interfaces:
            raise ValueError("no contact interface given")
        self.bcs = list(bcs)
        self.a_form = dolfinx.fem.form(a)
        self.L_form = dolfinx.fem.form(L) if L is not None else None
        self.V = a.arguments()[0].ufl_function_space()
        self.msh = self.V.mesh
        self.comm = self.msh.comm  # the mesh's: it may live on a sub-communicator
        self.dim = self.msh.geometry.dim
        self.stress = stress
        self.options = solver if solver is not None else SolverOptions()
        self.flexibility_method = flexibility
        self.timings = {}
        self.increments: list[IncrementResult] = []
        self.local_problem = None  # rank 0: the last increment's {dim, W, q, mu}

        t0 = time.perf_counter()
        self.K = assemble_stiffness(self.a_form, self.bcs)
        self.timings["assemble_K_s"] = time.perf_counter() - t0
        if bodies is not None:
            cell_tags, names = bodies
            check_bodies(self.K, self.V, cell_tags, names, self.comm)
        self.pairs, self.mu, self.m = pair_interfaces(self.V, self.interfaces, self.comm)
        self.condensation = Condensation(self.K, self.bcs, self.pairs, self.mu, self.dim,
                                         self.comm, self.options, self.flexibility_method)
        c = self.condensation
        self.timings.update(c.timings)
        self.factor, self.flex_info, self.n_contact_dofs = c.factor, c.flex_info, c.n_contact_dofs
        self.contact, self.B, self.W, self.x0, self.frames = c.contact, c.B, c.W, c.x0, c.frames
        self.outputs = ContactFields(self.V, self.comm, stress)
        o = self.outputs
        self.u, self.pressure, self.traction, self.status = o.u, o.pressure, o.traction, o.status
        self.von_mises = o.von_mises

    # ---- one increment ---------------------------------------------------------------
    def step(self) -> IncrementResult:
        """Solve one increment with the loads and Dirichlet values as they are set now."""
        t0 = time.perf_counter()
        root = self.comm.rank == 0
        number = len(self.increments) + 1
        p = assemble_load(self.V, self.a_form, self.L_form, self.bcs, self.comm)
        up = self.K.createVecRight()
        self.factor.solve(p, up)
        upc = self.condensation.gather(up)
        out, failure = None, None
        if root:
            try:
                out = self.contact.step(upc)  # the increment's one crossing into the kernel
                q = out["local_q"]
            except ConvergenceError as e:
                failure = (f"increment {number}: {e}", dict(getattr(e, "report", {})))
                q = np.asarray(self.contact.local_q(self.contact.last_q))
            except ValueError as e:
                # e.g. a non-finite u_p: raised on every rank, not left to hang the others
                failure, q = (f"increment {number}: {e}", None), None
            # The increment's local problem u = W λ + q' (slip measured from the last gap),
            # kept for inspection and for cross-checks with other solvers.
            if q is not None:
                self.local_problem = {"dim": self.dim, "W": self.W, "q": q, "mu": self.mu}
        failure = self.comm.bcast(failure, root=0)
        if failure:
            for v in (p, up):
                v.destroy()
            if failure[1] is None:
                raise ValueError(failure[0])
            error = ConvergenceError(failure[0])
            error.report = failure[1]  # what the solvers did, on every rank
            raise error
        r = self.condensation.reaction(out["reaction"] if root else None)
        r.axpy(1.0, p)
        self.factor.solve(r, compat.petsc_vec(self.u))
        self.u.x.scatter_forward()
        for v in (p, up, r):
            v.destroy()
        inc = record_increment(out, number, self.u, self.comm, self.dim,
                               time.perf_counter() - t0)
        self.increments.append(inc)
        self.outputs.write_back(inc, self.pairs)
        return inc

    # ---- driver -------------------------------------------------------------------
    def solve(self, increments: int, load: Optional[Callable[[int, float], None]] = None,
              writer=None, verbose: bool = True) -> list[IncrementSummary]:
        """Run ``increments`` load increments.

        ``load(i, t)`` is called before increment i (1-based), t = i/increments, to set the
        loads and Dirichlet values of that increment (dolfinx Constants). ``writer`` (a
        ResultWriter) receives the fields after each increment. If an increment fails, the
        increments already done stay written and the error is raised; a ConvergenceError
        carries ``report``, a dict of what the solvers did (attempts, residual, iterations).
        """
        if not isinstance(increments, (int, np.integer)) or increments < 1:
            raise ValueError(f"increments={increments!r}; it must be a positive integer")
        out = []
        for i in range(1, increments + 1):
            if load is not None:
                load(i, i / increments)
            inc = self.step()
            out.append(inc.summary)
            if writer is not None:
                writer.write(self, float(i))
            if verbose and self.comm.rank == 0:
                print(inc.summary.line(), flush=True)
        return out

    def fields(self) -> list[dolfinx.fem.Function]:
        """The output Functions (displacement, pressure, traction, status[, von Mises])."""
        return self.outputs.all()
