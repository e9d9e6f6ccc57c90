"""Detect bodies whose rigid-body motions are not prevented by the Dirichlet conditions.

The condensed method needs F* = (K⁻¹)_cc, so a static problem with a free (or partly free)
body has no answer. Rather than letting the factorization fail with a pivot count, every
body's rigid modes z are tested: z is a null vector of K exactly when the body can move
that way, so the smallest eigenvalue of Zᵀ K Z / Zᵀ Z (relative to the body's stiffness
scale) tells which body, and along which mode.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

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


def check_bodies(K, V, cell_tags, bodies: dict, comm=MPI.COMM_WORLD, rel_tol: float = 1e-9):
    """Raise ValueError naming each body whose rigid modes K does not resist.

    ``bodies`` maps a body name to its cell tag value.
    """
    gdim = V.mesh.geometry.dim
    bs = V.dofmap.index_map_bs
    coords = V.tabulate_dof_coordinates()[:, :gdim]
    diag = K.getDiagonal()
    problems = []
    for name, value in bodies.items():
        blocks = _body_blocks(V, cell_tags, value)
        count = comm.allreduce(blocks.size, op=MPI.SUM)
        if count == 0:
            raise ValueError(f"body '{name}': no cells carry the tag value {value}")
        c_local = coords[blocks].sum(axis=0) if blocks.size else np.zeros(gdim)
        centre = comm.allreduce(c_local, op=MPI.SUM) / count
        X = coords[blocks] - centre
        # Scale rotation modes by the body's size so all modes are O(1) displacements.
        r2 = comm.allreduce(float((X**2).sum()), op=MPI.SUM) / count
        size = max(np.sqrt(r2), 1e-300)
        dofs = (blocks[:, None] * bs + np.arange(gdim)[None, :]).ravel()
        kdiag = comm.allreduce(float(np.max(np.abs(diag.array[dofs]), initial=0.0)), op=MPI.MAX)
        Z, KZ = [], []
        for mode in _modes(X / size, gdim):
            z = K.createVecRight()
            z.array[dofs] = mode.ravel()
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
        for i in free:
            y = Li.T @ vecs[:, i]
            dominant = int(np.argmax(np.abs(y)))
            problems.append(f"body '{name}' (cell tag {value}) can move freely: "
                            f"{_MODE_NAMES[gdim][dominant]} is not prevented by any "
                            f"Dirichlet condition")
    if problems:
        raise ValueError("the stiffness matrix is singular (a static problem needs every "
                         "body held by Dirichlet conditions): " + "; ".join(problems))
