"""Detect bodies whose rigid-body motions are not prevented by the Dirichlet conditions.

The condensed method needs F* = (K⁻¹)_cc, so a static problem with a free (or partly free)
body has no answer. Rather than letting the factorization fail with a pivot count, every
body's rigid modes z are tested: z is a null vector of K exactly when the body can move
that way, so the smallest eigenvalue of Zᵀ K Z / Zᵀ Z (relative to the body's stiffness
scale) tells which body, and along which mode.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from .errors import InputError

_MODE_NAMES = {2: ["translation along x", "translation along y", "rotation about z"],
               3: ["translation along x", "translation along y", "translation along z",
                   "rotation about x", "rotation about y", "rotation about z"]}


def _body_blocks(V, cell_tags, value):
    """Owned DOF blocks of the nodes of the cells with the given tag value."""
    cells = cell_tags.find(value) if hasattr(cell_tags, "find") else \
        cell_tags.indices[cell_tags.values == value]
    n_owned = V.dofmap.index_map.size_local
    blocks = [V.dofmap.cell_dofs(c) for c in cells]
    if not blocks:
        return np.zeros(0, dtype=np.int32)
    b = np.unique(np.concatenate(blocks))
    return b[b < n_owned]


def _modes(X, gdim):
    """Rigid displacement fields at points X (n, gdim): columns of an (n·gdim, k) array."""
    n = X.shape[0]
    c = X.mean(axis=0) if n else np.zeros(gdim)
    Y = X - c
    modes = []
    for i in range(gdim):
        z = np.zeros((n, gdim)); z[:, i] = 1.0; modes.append(z)
    if gdim == 2:
        z = np.zeros((n, 2)); z[:, 0] = -Y[:, 1]; z[:, 1] = Y[:, 0]; modes.append(z)
    else:
        for axis in range(3):
            w = np.zeros(3); w[axis] = 1.0
            modes.append(np.cross(w, Y))
    return modes


def _name_modes(Y: np.ndarray, N: np.ndarray) -> list:
    """One basic rigid mode (translation or rotation) per free motion, each named once.

    Y spans the free motions in mode coordinates, N is the modes' Gram matrix. Greedily: the
    basic mode with the largest share in the free subspace (N-orthogonal projection) is
    named, that direction is removed from the subspace, and so on."""
    w, U = np.linalg.eigh(Y.T @ N @ Y)
    Q = Y @ U / np.sqrt(np.maximum(w, 1e-300))          # N-orthonormal basis of the subspace
    chosen = []
    while Q.shape[1] and len(chosen) < N.shape[0]:
        coords = Q.T @ N                                   # column i: coordinates of P e_i
        share = np.linalg.norm(coords, axis=0) / np.sqrt(np.diag(N))
        share[chosen] = -1.0
        i = int(np.argmax(share))
        chosen.append(i)
        c = coords[:, i] / max(np.linalg.norm(coords[:, i]), 1e-300)
        # The subspace without that direction: an orthonormal basis of c's complement.
        H = np.linalg.svd(np.eye(c.size) - np.outer(c, c))[0][:, :c.size - 1]
        Q = Q @ H
    return sorted(chosen)


@dataclass
class FreeBody:
    """The rigid motions of one body that no Dirichlet condition holds.

    ``dofs`` are the body's owned DOFs (local indices into a PETSc vector of K),
    ``modes`` (len(dofs), r) the free motions there, each an exact null vector of K: the
    free motion nearest each named basic mode (``names``; rotations about the body's
    centroid, scaled by the body's size ``size_m`` so that all are displacements in m).
    """

    name: str
    tag: int
    dofs: np.ndarray
    modes: np.ndarray
    names: list
    size_m: float
    kdiag: float


def _free_body(K, V, cell_tags, name, value, comm, rel_tol):
    """(problem text or None, FreeBody or None) of one body: collective."""
    gdim = V.mesh.geometry.dim
    bs = V.dofmap.index_map_bs
    coords = V.tabulate_dof_coordinates()[:, :gdim]
    diag = K.getDiagonal()
    blocks = _body_blocks(V, cell_tags, value)
    count = comm.allreduce(blocks.size, op=MPI.SUM)
    if count == 0:
        raise InputError(f"body '{name}': no cells carry the tag value {value}")
    c_local = coords[blocks].sum(axis=0) if blocks.size else np.zeros(gdim)
    centre = comm.allreduce(c_local, op=MPI.SUM) / count
    X = coords[blocks] - centre
    # Scale rotation modes by the body's size so all modes are O(1) displacements.
    r2 = comm.allreduce(float((X**2).sum()), op=MPI.SUM) / count
    size = max(np.sqrt(r2), 1e-300)
    dofs = (blocks[:, None] * bs + np.arange(gdim)[None, :]).ravel()
    kdiag = comm.allreduce(float(np.max(np.abs(diag.array[dofs]), initial=0.0)), op=MPI.MAX)
    unstiff = comm.allreduce(int(np.count_nonzero(diag.array[dofs] == 0.0)), op=MPI.SUM)
    diag.destroy()
    if unstiff:
        # A body with no material has no stiffness at all: not a support problem.
        return (f"body '{name}' (cell tag {value}) has no stiffness at "
                f"{unstiff} of its {count * gdim} DOFs: its cells carry no "
                "material in the bilinear form (is cell tag "
                f"{value} missing from the materials?)"), None
    basic = np.column_stack([mode.ravel() for mode in _modes(X / size, gdim)])
    Z, KZ = [], []
    for j in range(basic.shape[1]):
        z = K.createVecRight()
        z.array[dofs] = basic[:, j]
        kz = K.createVecLeft()
        K.mult(z, kz)
        Z.append(z); KZ.append(kz)
    k = len(Z)
    G = np.array([[Z[i].dot(KZ[j]) for j in range(k)] for i in range(k)])
    N = np.array([[Z[i].dot(Z[j]) for j in range(k)] for i in range(k)])
    G = 0.5 * (G + G.T)
    # Generalised eigenproblem G y = θ N y: θ is the modal stiffness per unit DOF.
    Ln = np.linalg.cholesky(N)
    Li = np.linalg.inv(Ln)
    theta, vecs = np.linalg.eigh(Li @ G @ Li.T)
    for v in Z + KZ:
        v.destroy()
    free = [i for i in range(k) if theta[i] <= rel_tol * kdiag]
    if not free:
        return None, None
    Y = Li.T @ vecs[:, free]               # free motions, in mode coordinates
    chosen = _name_modes(Y, N)
    # The free motion nearest each named basic mode: its N-orthogonal projection on span Y.
    P = Y @ np.linalg.solve(Y.T @ N @ Y, Y.T @ N)
    modes = basic @ P[:, chosen]
    names = [_MODE_NAMES[gdim][i] for i in chosen]
    return None, FreeBody(name, int(value), dofs, modes, names, float(size), kdiag)


def free_bodies(K, V, cell_tags, bodies: dict, comm=MPI.COMM_WORLD,
                rel_tol: float = 1e-9) -> list:
    """The bodies with rigid motions no Dirichlet condition holds (FreeBody each).

    Raises ValueError for a body whose cells carry no material. Collective."""
    problems, free = [], []
    for name, value in bodies.items():
        problem, body = _free_body(K, V, cell_tags, name, value, comm, rel_tol)
        if problem:
            problems.append(problem)
        elif body is not None:
            free.append(body)
    if problems:
        raise InputError("the stiffness matrix is singular: " + "; ".join(problems))
    return free


def free_body_text(body: FreeBody) -> str:
    names = body.names
    return (f"body '{body.name}' (cell tag {body.tag}) can move freely: "
            f"{', '.join(names)} {'is' if len(names) == 1 else 'are'} not "
            "prevented by any Dirichlet condition")


def check_bodies(K, V, cell_tags, bodies: dict, comm=MPI.COMM_WORLD, rel_tol: float = 1e-9):
    """Raise ValueError naming each body whose rigid modes K does not resist.

    ``bodies`` maps a body name to its cell tag value.
    """
    problems = []
    for name, value in bodies.items():
        problem, body = _free_body(K, V, cell_tags, name, value, comm, rel_tol)
        if body is not None:
            problem = (free_body_text(body) + " (a static problem needs every body held; "
                       "one held only by contact needs floating=True)")
        if problem:
            problems.append(problem)
    if problems:
        raise InputError("the stiffness matrix is singular: " + "; ".join(problems))
