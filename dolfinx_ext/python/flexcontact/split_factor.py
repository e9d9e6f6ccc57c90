"""A small body's sparse split factor: the solves of a Schur factor without a sparse direct
solver's fixed cost per call (docs/architecture.md §7, "A small body's sparse split factor").

``_cpp.SplitCholesky`` factors P A Pᵀ = L Lᵀ with the contact rows last (AMD on the
interior): condense is the forward substitution over the interior columns, expand the
backward one with the contact rows given, each two loops over L's entries. At the dam
sweep's 2D dam (1,556 DOFs, 56 contact DOFs) a condensation and an expansion take about
0.5 ms through MUMPS, nearly all of it set-up per call; here they are a few hundredths of a
millisecond. The factorization is simplicial (no dense kernels) and AMD fills more than
MUMPS's METIS ordering, so it is used up to ``SPLIT_LIMIT`` DOFs only: at the 3D sweep's dam
block (5,652 DOFs, 777 contact DOFs; 1.70M factor entries against MUMPS's 1.39M) MUMPS is
already faster, 1.75 against 2.02 ms per condensation and expansion.
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

from . import _cpp
from .errors import InputError

SPLIT_LIMIT = 4000
"""Largest serial body (DOFs) given the sparse split factor instead of MUMPS's Schur factor."""


class SplitFactor:
    """The split factor of the symmetric positive definite serial PETSc Mat ``A`` on the
    contact DOFs ``dofs`` (one factorization); ``W`` is the flexibility on ``dofs``, in
    their order. ``condense``/``expand``/``solve`` take PETSc Vecs, as a Schur factor's."""

    has_condense = True

    def __init__(self, A: PETSc.Mat, dofs):
        if A.getComm().getSize() != 1:
            raise InputError(f"SplitFactor: a matrix on {A.getComm().getSize()} ranks; the "
                             "sparse split factor is serial")
        ai, aj, av = A.getValuesCSR()
        self.c = np.asarray(dofs, np.int64).reshape(-1)
        self._f = _cpp.SplitCholesky(A.getSize()[0], ai, aj, av, self.c.astype(np.int32))
        self.W = np.asarray(self._f.flexibility())

    @classmethod
    def from_arrays(cls, arrays: dict, prefix: str) -> "SplitFactor":
        """The factor of :meth:`arrays` (no factorization; W from L_cc, n_c³ flops)."""
        self = cls.__new__(cls)
        get = lambda k: np.asarray(arrays[f"{prefix}{k}"])  # noqa: E731
        order, n_c = get("order").astype(np.int32), int(get("n_schur")[0])
        self._f = _cpp.SplitCholesky(order, n_c, get("indptr"), get("indices"), get("values"))
        self.c = order[order.size - n_c:].astype(np.int64)  # the contact rows pivot last
        self.W = np.asarray(self._f.flexibility())
        return self

    def arrays(self, prefix: str) -> dict:
        """The pivot order and L, to be saved (named ``prefix`` + name)."""
        parts = self._f.arrays()
        return {f"{prefix}order": np.asarray(parts["order"], np.int32),
                f"{prefix}n_schur": np.array([parts["n_schur"]]),
                f"{prefix}indptr": parts["indptr"], f"{prefix}indices": parts["indices"],
                f"{prefix}values": parts["values"]}

    @staticmethod
    def worth_it(n: int, comm_size: int = 1) -> bool:
        return comm_size == 1 and n <= SPLIT_LIMIT

    @property
    def n(self) -> int:
        return int(self._f.size)

    size = n  # a SavedFactor's name for it

    @property
    def factor_entries(self) -> int:
        return int(self._f.factor_entries)

    @property
    def n_contact_dofs(self) -> int:
        return int(self.c.size)

    def condense(self, b: PETSc.Vec) -> np.ndarray:
        return self._f.condense(b.array_r)

    def expand(self, u_c, x: PETSc.Vec) -> None:
        self._f.expand(np.asarray(u_c, float), x.array)

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        self._f.solve(b.array_r, x.array)

    def destroy(self) -> None:
        self._f = self.W = None
