"""Bodies held only by contact in a static problem (docs/architecture.md §1, the paragraph on a
static body held only by contact), FETI style.

Each such body's free rigid modes R come from its geometry (rigid_modes.py). A few
*fixing DOFs* per body, chosen far from the contact surfaces and so that R restricted to
them is invertible, get identity rows and columns in K: the factor of that regularised K,
applied to vectors zeroed at the fixing DOFs, is a generalized inverse K⁺ of K (the bodies
are coupled only through contact, so one global factorization serves them all). Then

    u = K⁺ (p + Bᵀ λ) + R α,    Rᵀ (p + Bᵀ λ) = 0,

and on the condensed problem the gap is x = W λ + q + G α with G = B R_c and the bodies'
equilibrium is Gᵀ λ = e, e = −Rᵀ p: the kernel solves that bordered problem
(CondensedContact.set_rigid_modes, step(up_c, e)).
"""
from __future__ import annotations

import warnings
from typing import Optional

import numpy as np
from petsc4py import PETSc

from . import compat
from ._cpp import ConvergenceError
from .rigid_modes import FreeBody, free_body_text
from .errors import InputError


class NoEquilibriumError(ConvergenceError):
    """A body held only by contact is loaded in a way no contact force can balance (a push
    past μN, a moment that tips it): the static problem has no solution. The message
    names the body and the mode; ``report`` says what the solver did."""


class FreeModeWarning(UserWarning):
    """A rigid mode of a body held only by contact that no load drives and no contact
    resists (a frictionless block's slide with no tangential load): it takes the
    minimum-norm value, no motion along it."""


class TippingWarning(UserWarning):
    """The contact force resultant of a body held only by contact is at the edge of its
    contact zone: the body is about to tip."""


def _fixing_rows(body: FreeBody, V, contact_x: np.ndarray, held: np.ndarray, comm) -> np.ndarray:
    """Global indices of r fixing DOFs of the body: far from the contact nodes, off the
    Dirichlet DOFs, with the r × r block of its free modes there well conditioned."""
    gdim = V.mesh.geometry.dim
    bs = V.dofmap.index_map_bs
    start = V.dofmap.index_map.local_range[0] * bs
    coords = V.tabulate_dof_coordinates()[:, :gdim]
    ok = ~held[body.dofs]
    local = (body.dofs[ok] + start, coords[body.dofs[ok] // bs], body.modes[ok])
    gathered = comm.gather(local, root=0)
    rows = None
    if comm.rank == 0:
        g = np.concatenate([a[0] for a in gathered])
        X = np.concatenate([a[1] for a in gathered])
        R = np.concatenate([a[2] for a in gathered])
        # In coordinate order, so that any partition picks the same DOFs.
        order = np.lexsort((g % bs,) + tuple(X.T[::-1]))
        g, X, R = g[order], X[order], R[order]
        # Distance of each DOF's node from the nearest contact node.
        dist = np.full(X.shape[0], np.inf)
        for chunk in np.array_split(np.arange(contact_x.shape[0]), max(1, contact_x.shape[0] // 256)):
            if chunk.size:
                d2 = ((X[:, None, :] - contact_x[None, chunk, :]) ** 2).sum(axis=2)
                dist = np.minimum(dist, np.sqrt(d2.min(axis=1)))
        far = dist >= 0.5 * dist.max() if np.isfinite(dist).any() else np.ones(dist.size, bool)
        far &= dist > 0.0
        cand = np.flatnonzero(far)
        chosen = _pivot_rows(R[cand])
        rows = g[cand[chosen]]
        if len(chosen) < R.shape[1]:
            rows = None
    rows = comm.bcast(rows, root=0)
    if rows is None:
        raise InputError(f"{free_body_text(body)}, and no DOFs of it away from the contact "
                         "surfaces can fix those modes (is the body only a contact surface?)")
    return np.asarray(rows, dtype=np.int64)


def _pivot_rows(R: np.ndarray) -> list:
    """r rows of R (n × r) that make the best conditioned r × r block (greedy, by column-
    pivoted Gram–Schmidt on the rows)."""
    A = R.copy()
    chosen = []
    for _ in range(R.shape[1]):
        norms = np.linalg.norm(A, axis=1)
        i = int(np.argmax(norms))
        if norms[i] <= 1e-8 * max(np.linalg.norm(R, axis=1).max(), 1e-300):
            break
        chosen.append(i)
        v = A[i] / norms[i]
        A -= np.outer(A @ v, v)
    return chosen


class FloatingBodies:
    """The free rigid modes of the bodies held only by contact and their fixing DOFs.

    Parameters
    ----------
    K : assembled stiffness; the fixing DOFs' rows and columns become identity (in place).
    V : the displacement space.
    bodies : the FreeBody of each body held only by contact.
    bcs : the Dirichlet conditions (the modes are zero on the DOFs they hold).
    pairs : the contact pairs (rank 0) and their contact DOFs.
    comm : the mesh's communicator.
    """

    def __init__(self, K: PETSc.Mat, V, bodies: list, bcs, pairs, comm):
        self.comm = comm
        self.bodies = bodies
        self.names = [(b.name, n) for b in bodies for n in b.names]
        marker = K.createVecLeft()
        marker.set(1.0)
        compat.set_bc(marker, list(bcs), scale=0.0)
        held = marker.array == 0.0
        marker.destroy()
        self.R = []
        for b in bodies:
            for j in range(len(b.names)):
                z = K.createVecRight()
                z.zeroEntries()
                z.array[b.dofs] = np.where(held[b.dofs], 0.0, b.modes[:, j])
                self.R.append(z)
        contact_x = comm.bcast(np.asarray(pairs.x)[:pairs.dofs.shape[0] - getattr(pairs, "n_virtual", 0)]
                               if comm.rank == 0 else None, root=0)
        start = V.dofmap.index_map.local_range[0] * V.dofmap.index_map_bs
        end = start + V.dofmap.index_map.size_local * V.dofmap.index_map_bs
        rows = [_fixing_rows(b, V, contact_x, held, comm) for b in bodies]
        self.fixing = np.concatenate(rows) if rows else np.zeros(0, np.int64)
        self._owned = self.fixing[(self.fixing >= start) & (self.fixing < end)]
        self._local = (self._owned - start).astype(np.int32)
        # The identity rows get the bodies' stiffness scale, to keep the factor well scaled.
        scale = max(b.kdiag for b in bodies)
        K.zeroRowsColumns(self._owned.astype(PETSc.IntType), diag=scale)

    @property
    def k(self) -> int:
        return len(self.R)

    def zero_fixed(self, vec: PETSc.Vec) -> None:
        """Zero the fixing DOFs' entries: the regularised factor then applies K⁺."""
        vec.array[self._local] = 0.0

    def loads(self, p: PETSc.Vec) -> np.ndarray:
        """e = −Rᵀ p, the loads along the modes (on every rank). Collective."""
        return np.array([-z.dot(p) for z in self.R])

    def contact_modes(self, condensation) -> Optional[np.ndarray]:
        """R_c (n_c × k) on rank 0 (zero rows for rigid targets' virtual DOFs)."""
        cols = [condensation.gather(z) for z in self.R]
        if self.comm.rank != 0:
            return None
        Rc = np.column_stack(cols) if cols else np.zeros((0, 0))
        nv = condensation.n_virtual_dofs
        return np.vstack([Rc, np.zeros((nv, Rc.shape[1]))]) if nv else Rc

    def check_touched(self, Rc: Optional[np.ndarray]) -> None:
        """Raise, naming the body, if a free body has no contact DOF. Collective."""
        untouched = None
        if self.comm.rank == 0:
            untouched = [f"{free_body_text(b)}, and no contact surface touches it"
                         for b, j in self._columns() if not np.any(Rc[:, j])]
        untouched = self.comm.bcast(untouched, root=0)
        if untouched:
            raise InputError("the stiffness matrix is singular: " + "; ".join(untouched))

    def _columns(self):
        """(body, first column) of each body."""
        j = 0
        for b in self.bodies:
            yield b, j
            j += len(b.names)

    def add_modes(self, u: PETSc.Vec, alpha: np.ndarray) -> None:
        """u += R α."""
        for z, a in zip(self.R, alpha):
            u.axpy(float(a), z)

    def destroy(self) -> None:
        for z in self.R:
            z.destroy()
        self.R = []

    # ---- diagnostics (rank 0) ---------------------------------------------------------
    def warn_undetermined(self, undetermined: np.ndarray, increment: int) -> None:
        """A FreeModeWarning per direction of α that no contact resists."""
        for c in range(undetermined.shape[1]):
            v = np.abs(undetermined[:, c])
            named = [self.names[j] for j in np.flatnonzero(v >= 0.3 * v.max())]
            body = named[0][0]
            modes = ", ".join(n for _, n in named)
            warnings.warn(f"increment {increment}: body '{body}': {modes} is held by no "
                          "contact force and driven by no load; it takes the minimum-norm "
                          "value (no motion along it)", FreeModeWarning, stacklevel=4)

    def no_equilibrium_text(self, G: np.ndarray, e: np.ndarray, lam: np.ndarray,
                            mu: np.ndarray, dim: int, x: np.ndarray) -> Optional[str]:
        """Which body and mode no contact force can balance, from the solver's best
        iterate λ (near its equilibrium Gᵀλ = e; where none exists the Newton system is
        rank deficient and its least-squares steps leave a small imbalance), or None.

        A translation: the load the friction must carry along it (e_j less the normal
        forces' share) beyond what friction can hold, Σ μ λ_n |G_t|. A rotation: the
        normal forces of the body's pairs need tension to balance it, so the body tips."""
        L = lam.reshape(-1, dim)
        lam_n = L[:, 0]
        # Tipping first: the failed iterate of a tipping body pulls on the base at the
        # trailing edge, or has all its normal force at the leading edge; that of a sliding
        # body does neither.
        scale = max(np.abs(lam_n).max(initial=0.0), 1e-300)
        for b, j0 in self._columns():
            cols = G[:, j0:j0 + len(b.names)].reshape(-1, dim, len(b.names))
            mine = np.any(cols != 0, axis=(1, 2))
            rot = [n for n in b.names if n.startswith("rotation")]
            if rot and mine.any() and (lam_n[mine].min() < -1e-2 * scale or
                                       self._resultant_at_edge(b, j0, G, lam_n, x, dim) is not None):
                return (f"body '{b.name}': no static equilibrium: the load along "
                        f"{', '.join(rot)} exceeds what contact can hold: the body tips over "
                        "(its contact force resultant would have to lie beyond the edge of "
                        "its contact zone)")
        for j, (body, mode) in enumerate(self.names):
            Gj = G[:, j].reshape(-1, dim)
            gt = mu * np.linalg.norm(Gj[:, 1:], axis=1)
            if mode.startswith("rotation") or \
                    np.abs(Gj[:, 1:]).max() <= 1e-8 * np.abs(Gj).max():
                continue   # only a translation that friction holds can be pushed past μN
            need = abs(e[j] - Gj[:, 0] @ lam_n)
            # Tension carries no friction: the decision counts compressive pairs only; the
            # message gives μN of the iterate's normal forces.
            hold = float(gt @ np.maximum(lam_n, 0.0))
            if need > hold * (1 + 1e-9) + 1e-12 * abs(e).max():
                return (f"body '{body}': no static equilibrium: the load along {mode} exceeds "
                        f"what contact can hold (Q = {need:.6g}, μN = {float(gt @ lam_n):.6g})")
        return None

    def _resultant_at_edge(self, b, j0: int, G: np.ndarray, lam_n: np.ndarray,
                           x: np.ndarray, dim: int) -> Optional[np.ndarray]:
        """The normal contact force resultant of body b if it lies in the outermost interval
        of its pairs' positions along a principal axis of its contact zone, else None."""
        mine = np.flatnonzero(np.any(
            G[:, j0:j0 + len(b.names)].reshape(-1, dim, len(b.names)) != 0, axis=(1, 2)))
        ln = np.maximum(lam_n[mine], 0.0)
        if mine.size < 3 or ln.sum() <= 0:
            return None
        P = x[mine]
        c = P.mean(axis=0)
        axes = np.linalg.svd(P - c, full_matrices=False)[2][:dim - 1]
        res = (ln @ P) / ln.sum()
        for a in axes:
            s = np.sort((P - c) @ a)
            r = (res - c) @ a
            if r <= 0.5 * (s[0] + s[1]) or r >= 0.5 * (s[-1] + s[-2]):
                return res
        return None

    def tipping(self, G: np.ndarray, lam: np.ndarray, x: np.ndarray, dim: int) -> list:
        """Bodies whose normal contact force resultant lies in the outermost interval of
        their pairs' positions (principal axes of the contact zone)."""
        lam_n = lam.reshape(-1, dim)[:, 0]
        out = []
        for b, j0 in self._columns():
            if not any(n.startswith("rotation") for n in b.names):
                continue
            res = self._resultant_at_edge(b, j0, G, lam_n, x, dim)
            if res is not None:
                out.append(f"body '{b.name}' is about to tip: the contact force resultant "
                           f"is at the edge of its contact zone (at {np.round(res, 12)})")
        return out
