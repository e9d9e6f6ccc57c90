"""A small body's iteration matrix held as dense blocks, with the solves of a Schur factor.

For a body of a few hundred to a thousand DOFs (a log of the dam sweep), a sparse direct
solve costs mostly its fixed overhead: a back-substitution of 500 DOFs takes about as long
as one of 5,000. Split on the contact DOFs c and the interior i, A = [[A_ii, A_ic],
[A_ci, A_cc]] (symmetric positive definite):

    T = A_ii⁻¹ A_ic,   S = A_cc − A_ci T,   W = S⁻¹ (the body's flexibility on c),

and the three solves of the stepper (stepper.BodiesStepper) are dense products:

* condense(b): z_i = A_ii⁻¹ b_i is kept, b̃_c = b_c − Tᵀ b_i is returned;
* expand(u_c, x): x_c = u_c, x_i = z_i − T u_c;
* solve(b, x): condense, u_c = W b̃_c, expand.

A dam model's small logs were held this way up to model format 4, and such a model still
loads them (dam/model_file.py); a log built now takes the sparse split factor
(split_factor.SplitFactor), whose set-up and solves cost less (docs/architecture.md §7).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.sparse
from petsc4py import PETSc


def _spd_inverse(A: np.ndarray, what: str) -> np.ndarray:
    """A⁻¹ of a symmetric positive definite A by LAPACK's Cholesky and dpotri (⅓n³ + ⅔n³
    flops; solving against the identity would take 2n³ after the factor)."""
    L, info = scipy.linalg.lapack.dpotrf(A, lower=1, clean=0)
    if info == 0:
        L, info = scipy.linalg.lapack.dpotri(L, lower=1)
    if info != 0:
        raise np.linalg.LinAlgError(
            f"DenseFactor: {what} ({A.shape[0]}×{A.shape[0]}) is not positive definite "
            f"(LAPACK info {info})")
    return np.tril(L) + np.tril(L, -1).T


class DenseFactor:
    """The dense split factor of the symmetric positive definite ``A`` (a serial PETSc
    Mat) on the contact DOFs ``dofs``; see the module docstring. ``W`` is the flexibility on
    ``dofs``, in their order. One factorization (a dense Cholesky of A_ii)."""

    has_condense = True

    def __init__(self, A: PETSc.Mat, dofs):
        ai, aj, av = A.getValuesCSR()
        n = A.getSize()[0]
        D = scipy.sparse.csr_matrix((av, aj, ai), shape=(n, n)).toarray()
        c = np.asarray(dofs, np.int64).reshape(-1)
        interior = np.ones(n, bool)
        interior[c] = False
        i = np.flatnonzero(interior)
        self.n, self.c, self.i = n, c, i
        self.A_ii_inv = _spd_inverse(D[np.ix_(i, i)], "A_ii")
        self.T = self.A_ii_inv @ D[np.ix_(i, c)]
        S = D[np.ix_(c, c)] - D[np.ix_(c, i)] @ self.T
        self.W = _spd_inverse(0.5 * (S + S.T), "the Schur complement on the contact DOFs")
        self._z = None

    def arrays(self, prefix: str) -> dict:
        """The blocks, to be saved (named ``prefix`` + name)."""
        return {f"{prefix}n": np.array([self.n]), f"{prefix}c": self.c,
                f"{prefix}A_ii_inv": self.A_ii_inv, f"{prefix}T": self.T, f"{prefix}W": self.W}

    @classmethod
    def from_arrays(cls, arrays: dict, prefix: str) -> "DenseFactor":
        """The factor of :meth:`arrays` (no factorization)."""
        self = cls.__new__(cls)
        self.n = int(np.asarray(arrays[f"{prefix}n"])[0])
        self.c = np.asarray(arrays[f"{prefix}c"], np.int64)
        interior = np.ones(self.n, bool)
        interior[self.c] = False
        self.i = np.flatnonzero(interior)
        self.A_ii_inv, self.T, self.W = (np.asarray(arrays[f"{prefix}{k}"])
                                         for k in ("A_ii_inv", "T", "W"))
        self._z = None
        return self

    @property
    def n_contact_dofs(self) -> int:
        return int(self.c.size)

    def condense(self, b: PETSc.Vec) -> np.ndarray:
        x = b.array_r
        self._z = self.A_ii_inv @ x[self.i]
        return x[self.c] - self.T.T @ x[self.i]

    def expand(self, u_c, x: PETSc.Vec) -> None:
        if self._z is None:
            raise RuntimeError("DenseFactor.expand without a condense since the last one")
        u_c = np.asarray(u_c, float)
        out = x.array
        out[self.c] = u_c
        out[self.i] = self._z - self.T @ u_c
        self._z = None

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        self.expand(self.W @ self.condense(b), x)

    def destroy(self) -> None:
        self.A_ii_inv = self.T = self.W = None
