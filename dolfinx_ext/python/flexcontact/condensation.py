"""Condensation on the contact DOFs: F* = (K⁻¹)_cc, the scatter of contact values between
the distributed vectors and rank 0, and the kernel's condensed problem (docs/architecture.md §1).

The method's algebra (B, x0, W = B F* Bᵀ, q = B u_p + x0, the contact solve, r_c = Bᵀ λ and
the totals) lives in the kernel object ``_cpp.CondensedContact`` on rank 0, so that an
increment crosses the binding once.
"""
from __future__ import annotations

import time
from typing import Callable, Optional, Sequence

import numpy as np
from petsc4py import PETSc

from . import _cpp, compat
from .memory import check_dense_memory_collective
from .mpi import raise_on_every_rank
from .pairing import NodePairs, pair_caps


def kernel_pairs(pairs) -> list:
    """The kernel's ContactPairs of NodePairs or SurfacePairs (rank 0)."""
    m = pairs.m
    return _cpp.pairs_from_normals(np.arange(m), pairs.masters, pairs.weights, pairs.normal,
                                   pairs.offset)


class Condensation:
    """F*, its factor and the condensed contact problem of fixed pairs.

    Parameters
    ----------
    K : assembled stiffness (Dirichlet rows are identity rows).
    bcs : the Dirichlet conditions; contact DOFs they hold get no flexibility and no
        contact reaction.
    pairs, mu : the pairs (NodePairs or SurfacePairs) and their friction coefficients
        (rank 0; None elsewhere).
    dim : 2 or 3.
    options : kernel SolverOptions.
    method : how F* is computed (see ``_cpp.flexibility``).
    ordering : the fill-reducing ordering of the factorization (names.Ordering).
    kernel : optional callable ``(dim, F, X, pairs, mu, constrained, options)`` building
        the kernel object instead of ``_cpp.CondensedContact`` (the impact step builds an
        ``_cpp.ImpactContact`` from the F̂ of its iteration matrix this way).

    On rank 0 ``contact`` is the kernel object and ``B``, ``W``, ``x0``, ``frames`` its
    operators as SciPy/NumPy arrays; elsewhere they are None.
    """

    def __init__(self, K: PETSc.Mat, bcs: Sequence, pairs: Optional[NodePairs],
                 mu: np.ndarray, dim: int, comm, options, method: str,
                 kernel: Optional[Callable] = None, ordering: str = "auto"):
        self.comm = comm
        root = comm.rank == 0
        self.pairs = pairs
        self._contact_scatter(K, pairs, dim)
        constrained = self._constrained_mask(K, bcs)

        # Before MUMPS allocates the Schur complement (memory.py).
        check_dense_memory_collective(comm, self.dofs.size + self.n_virtual_dofs if root else None,
                                      pairs.m if root else None, dim)
        self.timings = {}
        t0 = time.perf_counter()
        # The static problem holds F* by body as Cholesky factors, so that W takes the cheaper
        # route per body (docs/architecture.md §7); a caller's own kernel object takes it dense.
        F, self.factor, info = _cpp.flexibility(K, self.dofs, method, ordering,
                                                factors=kernel is None)
        self.timings["flexibility_s"] = time.perf_counter() - t0
        self.flex_info = dict(info)
        self.factorizations = 1
        self.n_contact_dofs = comm.bcast(self.dofs.size if root else None, root=0)

        self.contact = None
        self._cached = None
        if root:
            nv = self.n_virtual_dofs
            if nv and isinstance(F, _cpp.BlockFlexibility):
                F = F.extended(F.rows + nv)
            elif nv:
                F = np.pad(np.asarray(F), ((0, nv), (0, nv)))
            if nv:
                constrained = np.concatenate([constrained, np.ones(nv, bool)])
            t0 = time.perf_counter()
            build = kernel if kernel is not None else _cpp.CondensedContact
            self.contact = build(dim, F, pairs.x, kernel_pairs(pairs), mu, constrained, options)
            caps = pair_caps(pairs)
            if caps is not None:
                self.contact.set_crushing(caps)
            self.timings["delassus_s"] = time.perf_counter() - t0
            self._record_routes()

    def _contact_scatter(self, K: PETSc.Mat, pairs, dim: int) -> None:
        """The contact DOFs (rank 0's list, empty elsewhere), the number of virtual ones
        (rank 0) and the scatter of their values from a distributed vector to rank 0."""
        root = self.comm.rank == 0
        # Rigid targets' reference nodes (last) have no PETSc DOFs: held, zero flexibility.
        n_virtual = getattr(pairs, "n_virtual", 0) if root else 0
        real = pairs.dofs[:pairs.dofs.shape[0] - n_virtual] if root else None
        self.dofs = (real.reshape(-1).astype(np.int64) if root else np.zeros(0, np.int64))
        self.n_virtual_dofs = n_virtual * dim
        is_from = PETSc.IS().createGeneral(self.dofs.astype(PETSc.IntType), comm=self.comm)
        self._seq = PETSc.Vec().createSeq(self.dofs.size, comm=PETSc.COMM_SELF)
        is_to = PETSc.IS().createStride(self.dofs.size, 0, 1, comm=PETSc.COMM_SELF)
        self._scatter = PETSc.Scatter().create(K.createVecLeft(), is_from, self._seq, is_to)
        self._template = K

    collective = False
    """False: the kernel object lives on rank 0 alone (the factor path's is on every rank)."""

    # B, W, x0 and the frames are the kernel object's, read once per pairing and flexibility
    # (the bindings copy them) and forgotten when either changes: never a stale copy.
    def _operator(self, name: str):
        if self.contact is None:
            return None
        if self._cached is None:
            self._cached = {}
        if name not in self._cached:
            self._cached[name] = getattr(self.contact, name)
        return self._cached[name]

    @property
    def B(self):
        """The gap operator B (SciPy sparse; rank 0, None elsewhere)."""
        return self._operator("B")

    @property
    def W(self):
        """W = B F* Bᵀ (rank 0, None elsewhere)."""
        return self._operator("W")

    @property
    def x0(self):
        """The initial gaps, pair-major in the local frames (rank 0, None elsewhere)."""
        return self._operator("x0")

    @property
    def frames(self):
        """(m, d, d) rows n, t₁[, t₂] of each pair (rank 0, None elsewhere)."""
        return self._operator("frames")

    def set_pairs(self, pairs, mu: np.ndarray) -> None:
        """New pairs on the same contact nodes (rank 0): B, x0, W rebuilt from the stored F*,
        no factorization."""
        self.pairs = pairs
        caps = pair_caps(pairs)
        self.contact.set_pairs(kernel_pairs(pairs), mu, np.zeros(0) if caps is None else caps)
        self._cached = None
        self._record_routes()

    def _record_routes(self) -> None:
        """info's account of how W was last formed, per body (rank 0)."""
        routes = getattr(self.contact, "delassus_routes", None)
        if routes is not None:
            self.flex_info["delassus_routes"] = list(routes)
            taken, inverse = self.contact.delassus_flops
            self.flex_info["delassus_flops"] = float(taken)
            self.flex_info["delassus_flops_by_inverse"] = float(inverse)

    def refactor(self, A: PETSc.Mat, method: str, ordering: str, dt_s: float,
                 where: str) -> None:
        """Factor ``A`` on the same contact DOFs and hand the kernel its flexibility
        (``set_flexibility(F, dt_s)``: a new time step of an impact); the factor is replaced
        only once the kernel accepted it. Collective."""
        F, factor, info = _cpp.flexibility(A, self.dofs, method, ordering)
        error = None
        if self.comm.rank == 0:
            try:
                self.contact.set_flexibility(np.asarray(F), float(dt_s))
            except ValueError as e:
                error = f"{where}: {e}"
        raise_on_every_rank(self.comm, error)
        self.factor, self.flex_info = factor, dict(info)
        # The two-solve step's reaction vectors take A's layout: the caller destroys the
        # old matrix.
        self._template = A
        self.factorizations += 1
        self._cached = None

    def contact_values(self, up_c: np.ndarray) -> np.ndarray:
        """The values of all contact DOFs (rank 0): the gathered ``up_c`` of the real ones,
        then the rigid targets' prescribed translations."""
        if not self.n_virtual_dofs:
            return up_c
        return np.concatenate([up_c, self.pairs.virtual_displacement()])

    def _constrained_mask(self, K: PETSc.Mat, bcs: Sequence) -> Optional[np.ndarray]:
        """True for the contact DOFs that a Dirichlet condition fixes (rank 0)."""
        marker = K.createVecLeft()
        marker.set(1.0)
        compat.set_bc(marker, list(bcs), scale=0.0)
        vals = self.gather(marker)
        marker.destroy()
        return vals == 0.0 if vals is not None else None

    def gather(self, vec: PETSc.Vec) -> Optional[np.ndarray]:
        """The contact-DOF values of a distributed vector, node-major, on rank 0."""
        self._scatter.scatter(vec, self._seq, addv=PETSc.InsertMode.INSERT,
                              mode=PETSc.ScatterMode.FORWARD)
        return self._seq.array.copy() if self.comm.rank == 0 else None

    def reaction(self, r_c: Optional[np.ndarray]) -> PETSc.Vec:
        """The contact forces r = Bᵀ λ as a distributed vector (r_c given on rank 0)."""
        r = self._template.createVecLeft()
        r.zeroEntries()
        if self.comm.rank == 0:
            r.setValues(self.dofs.astype(PETSc.IntType), r_c[:self.dofs.size],
                        addv=PETSc.InsertMode.ADD_VALUES)
        r.assemble()
        return r
