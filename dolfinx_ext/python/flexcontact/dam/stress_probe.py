"""The largest principal stress at a stated distance from a point, read from a recovered
(nodal-average) stress field rather than from the cell-wise constant one.

With linear elements the stress is constant in each cell. Near a concentrated load it
varies like 1/r² across a cell, and the cell constants scatter about the true field from
cell to cell: the largest of them over a sphere is the worst scatter, and its error is
first order. The volume-weighted average of the cell stresses at each node, interpolated
linearly to the sample points, smooths the scatter out and converges about second order
(Flamant's line load; docs/dam.md, "The peak principal stress near the impact", which also
says what neither reading resolves: in 3D the face's tension near a normal force lies in a
layer thinner than the dam's elements there).
"""
from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.mesh

from .. import compat
from ..forms import lame_fields, stress_3x3
from .section import OffsetProbe

PATCH = 1
"""Tag of the cells whose stresses are averaged, in the probe's own MeshTags."""

_COMPONENTS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


class ProbeSpace:
    """What every probe on one mesh, material map, stress kind and tag shares: the Lamé
    fields, the recovered stress's space and the lumped mass over the whole tag. A dam
    model reads a new probe for each scenario's impact point."""

    def __init__(self, msh, cell_tags, materials: dict, kind: str, tag: int):
        self.lame = lame_fields(msh, cell_tags, materials)
        self.comps = _COMPONENTS if kind == "3d" else _COMPONENTS[:4]
        self.V = compat.vector_space(msh, 1, len(self.comps))
        self.tau = ufl.TestFunction(self.V)
        self.ones = ufl.as_vector([1.0] * len(self.comps))
        self.m = compat.create_petsc_vector(self.V)
        self.full = _assembled(dolfinx.fem.form(
            ufl.inner(self.ones, self.tau)
            * ufl.Measure("dx", domain=msh, subdomain_data=cell_tags)(tag)), self.m)


class RecoveredStressProbe:
    """Peak of the recovered largest principal stress (Pa, tension positive) over the
    samples of an :class:`~flexcontact.dam.section.OffsetProbe` (a circle in 2D, a sphere in
    3D, of radius ``offset_m`` around ``point``, in cells tagged ``tag``).

    The nodal stress is Σ_c |c| σ_c / Σ_c |c| over the cells c tagged ``tag`` around the
    node, so a material interface is not smeared; a constant stress is recovered exactly.
    Only a shell of cells around the sphere counts: it grows until every node of a sample
    cell has all its cells in it (checked against the full lumped mass, so a partition
    boundary cannot cut a node's average short). ``u`` is read at each
    :meth:`peak`; ``kind`` as for the stress forms. ``space``: a :class:`ProbeSpace` built
    for the same mesh, tags, materials, kind and tag, shared between probes. In serial a
    reading is a fixed sparse map of ``u`` (built here); on several ranks the shell is
    assembled at each reading. Collective, as is :meth:`peak`.
    """

    def __init__(self, u, cell_tags, materials: dict, kind: str, point, offset_m: float,
                 tag: int, samples: int = 720, space: "ProbeSpace | None" = None):
        msh = u.function_space.mesh
        if space is None:
            space = ProbeSpace(msh, cell_tags, materials, kind, tag)
        self.offset = OffsetProbe(msh, point, offset_m, cell_tags, tag, samples)
        self.comm = msh.comm
        lame, comps, V, tau, ones = space.lame, space.comps, space.V, space.tau, space.ones
        self._u = u
        self._m = space.m
        self._ncomp = len(comps)
        full = space.full
        needed = np.unique(compat.cell_dofs(V)[self.offset.cells].reshape(-1))
        patch, self._mass = self._patch(msh, cell_tags, tag, np.asarray(point, float),
                                        float(offset_m), ones, tau, full, needed,
                                        V.dofmap.index_map_bs)
        dxp = ufl.Measure("dx", domain=msh, subdomain_data=patch)(PATCH)
        self._comps = comps
        self._linear = (self._operator(u, lame, kind, V, tau, dxp) if self.comm.size == 1
                        else None)
        if self._linear is None:
            self._rec = dolfinx.fem.Function(V)
            self._b = compat.create_petsc_vector(V)
            self._form = _components_form(u, lame, kind, comps, tau, dxp)
        self.patch_cells = int(self.comm.allreduce(
            np.count_nonzero(patch.indices < _owned_cells(msh)), op=MPI.SUM))

    def _operator(self, u, lame, kind, V, tau, dxp):
        """(R, E) in serial: the recovered stress components at the sample cells' nodes are
        R u (the patch's stress form over the lumped mass), and at the samples E R u (their
        linear interpolation). Both are sparse and fixed, so a reading is two small products
        instead of an assembly and a point evaluation (a sweep reads the probe at every
        contact step of every scenario). None on cells other than simplices, whose
        interpolation is not barycentric."""
        import scipy.sparse
        gdim = u.function_space.mesh.geometry.dim
        if compat.cell_dofs(V).shape[1] != gdim + 1:
            return None
        nc = self._ncomp
        found = self.offset.found
        if len(found) == 0:
            return (scipy.sparse.csr_matrix((0, u.x.array.size)),
                    scipy.sparse.csr_matrix((0, 0)))
        A = compat.assemble_matrix(_components_form(ufl.TrialFunction(u.function_space), lame,
                                                    kind, self._comps, tau, dxp), [])
        ai, aj, av = A.getValuesCSR()
        shape = A.getSize()
        A.destroy()
        blocks = compat.cell_dofs(V)[self.offset.sample_cells]            # (k, vertices)
        node_blocks, local = np.unique(blocks, return_inverse=True)
        local = local.reshape(blocks.shape)
        rows = (node_blocks[:, None] * nc + np.arange(nc)).reshape(-1)
        mass = self._mass[rows]
        scale = np.divide(1.0, mass, out=np.zeros_like(mass), where=mass > 0)
        R = scipy.sparse.diags(scale) @ scipy.sparse.csr_matrix((av, aj, ai), shape=shape)[rows]
        # Barycentric coordinates of each sample in its (affine, linear) cell.
        X = V.tabulate_dof_coordinates()[blocks][:, :, :gdim]
        p = self.offset.points[found][:, :gdim]
        edges = (X[:, 1:] - X[:, :1]).transpose(0, 2, 1)
        tail = np.linalg.solve(edges, (p - X[:, 0])[..., None])[..., 0]
        lam = np.column_stack([1.0 - tail.sum(axis=1), tail])
        k, nv = blocks.shape
        E = scipy.sparse.csr_matrix((
            np.repeat(lam, nc, axis=1).reshape(-1),
            ((np.arange(k)[:, None, None] * nc + np.arange(nc)[None, None, :])
             .repeat(nv, axis=1).reshape(-1),
             (local[:, :, None] * nc + np.arange(nc)[None, None, :]).reshape(-1))),
            shape=(k * nc, node_blocks.size * nc))
        return R.tocsr(), E

    def _patch(self, msh, cell_tags, tag, point, offset_m, ones, tau, full, needed, bs):
        """(MeshTags of the shell of cells tagged ``tag`` whose midpoints lie within a
        margin of the sphere, the lumped mass over it): the margin is one sample-cell size
        at first (every call assembles the shell, so a thin one pays), grown by half until
        the lumped mass of every needed node over the shell equals its mass over all of
        ``tag``."""
        tdim = msh.topology.dim
        n_cells = _owned_cells(msh) + msh.topology.index_map(tdim).num_ghosts
        x = compat.geometry_x(msh)
        nodes = compat.geometry_dofmap(msh)[:n_cells]
        mid = x[nodes].mean(axis=1)
        size = 2.0 * np.linalg.norm(x[nodes] - mid[:, None, :], axis=2).max(axis=1)
        tagged = np.zeros(n_cells, dtype=bool)
        tagged[cell_tags.indices[cell_tags.values == tag]] = True
        dist = np.abs(np.linalg.norm(mid[:, :point.size] - point, axis=1) - offset_m)
        own = size[self.offset.cells].max() if len(self.offset.cells) else 0.0
        margin = self.comm.allreduce(float(own), op=MPI.MAX)
        rows = (needed[:, None] * bs + np.arange(bs)).reshape(-1)
        for _ in range(64):
            cells = np.flatnonzero(tagged & (dist <= margin)).astype(np.int32)
            patch = dolfinx.mesh.meshtags(msh, tdim, cells, np.full(cells.size, PATCH, np.int32))
            got = _assembled(dolfinx.fem.form(
                ufl.inner(ones, tau) * ufl.Measure("dx", domain=msh, subdomain_data=patch)(PATCH)),
                self._m)
            short = bool(np.any(got[rows] < full[rows] * (1.0 - 1e-10)))
            if not self.comm.allreduce(short, op=MPI.LOR):
                return patch, got
            margin *= 1.5
        raise RuntimeError("RecoveredStressProbe: the averaging shell never covered the "
                           "sample cells' nodes")  # unreachable: the margin passes the mesh

    def peak(self):
        """(largest recovered principal stress over the samples in Pa, its sample point);
        (nan, None) if no sample lies in the tagged cells."""
        if self._ncomp == 4:
            # In 2D σ_zz is a principal stress and the in-plane pair is in closed form: a
            # sixth of the time of the 3×3 one.
            xx, yy, zz, xy = self._components().T
            return self.offset.best(np.maximum(0.5 * (xx + yy) + np.hypot(0.5 * (xx - yy), xy),
                                               zz))
        t = self._tensors()
        return self.offset.best(largest_principal(t) if len(t) else np.zeros(0))

    def mean(self) -> np.ndarray:
        """The recovered stress tensor (3, 3) in Pa averaged over the samples (nan if none
        lies in the tagged cells): a smooth field's value near the sphere's centre, such as
        the dam's static stress near the impact. A sample found on two ranks (on a shared
        face or in a ghost cell) counts once."""
        k = self.offset.points.shape[0]
        total, count = np.zeros((k, 3, 3)), np.zeros(k)
        total[self.offset.found] = self._tensors()
        count[self.offset.found] = 1.0
        total = self.comm.allreduce(total, op=MPI.SUM)
        count = self.comm.allreduce(count, op=MPI.SUM)
        hit = count > 0
        if not hit.any():
            return np.full((3, 3), np.nan)
        return (total[hit] / count[hit][:, None, None]).mean(axis=0)

    def _tensors(self) -> np.ndarray:
        """The recovered stress (k, 3, 3) at this rank's found samples."""
        c = self._components()   # collective on several ranks, samples here or not
        t = np.zeros((len(c), 3, 3))
        for k, (i, j) in enumerate(self._comps):
            t[:, i, j] = t[:, j, i] = c[:, k]
        return t

    def _components(self) -> np.ndarray:
        """The recovered stress components (k, ncomp) at this rank's found samples
        (collective on several ranks)."""
        if self._linear is not None:
            R, E = self._linear
            return (E @ (R @ self._u.x.array)).reshape(-1, self._ncomp)
        b = _assembled(self._form, self._b)
        with np.errstate(divide="ignore", invalid="ignore"):
            self._rec.x.array[:] = np.where(self._mass > 0, b / self._mass, 0.0)
        found = self.offset.found
        if not len(found):
            return np.zeros((0, self._ncomp))
        c = self._rec.eval(self.offset.points[found], self.offset.sample_cells)
        return np.asarray(c).reshape(len(found), self._ncomp)


def _components_form(u, lame, kind: str, comps, tau, dx):
    """∫ σ(u)_ij τ_k dx over the components (i, j) = comps[k]: linear in τ, and bilinear
    when ``u`` is a trial function."""
    s = stress_3x3(u, lame, kind)
    return dolfinx.fem.form(ufl.inner(ufl.as_vector([s[i, j] for i, j in comps]), tau) * dx)


def largest_principal(t: np.ndarray) -> np.ndarray:
    """The largest eigenvalue of each symmetric 3×3 matrix of ``t`` (k, 3, 3), in closed
    form (the trigonometric solution of the characteristic cubic): a tenth of the time of
    LAPACK's eigenvalues, which a 3D probe took at 2,880 samples per reading. Where the two
    largest nearly coincide, the arccos loses half the digits, so those few take LAPACK's."""
    a00, a11, a22 = t[:, 0, 0], t[:, 1, 1], t[:, 2, 2]
    a01, a02, a12 = t[:, 0, 1], t[:, 0, 2], t[:, 1, 2]
    q = (a00 + a11 + a22) / 3.0
    b00, b11, b22 = a00 - q, a11 - q, a22 - q
    p = np.sqrt((b00 * b00 + b11 * b11 + b22 * b22
                 + 2.0 * (a01 * a01 + a02 * a02 + a12 * a12)) / 6.0)
    det = (b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02)
           + a02 * (a01 * a12 - b11 * a02))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.clip(np.where(p > 0, det / (2.0 * p ** 3), 0.0), -1.0, 1.0)
    lam = q + 2.0 * p * np.cos(np.arccos(r) / 3.0)
    near = r < -1.0 + 1e-6
    if near.any():
        lam[near] = np.linalg.eigvalsh(t[near])[:, -1]
    return lam


def _assembled(form, vec) -> np.ndarray:
    """The linear ``form`` assembled into ``vec``, ghosts summed and updated: a copy of the
    local array."""
    with vec.localForm() as loc:
        loc.set(0.0)
    dolfinx.fem.petsc.assemble_vector(vec, form)
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    with vec.localForm() as loc:
        return loc.array.copy()


def _owned_cells(msh) -> int:
    return msh.topology.index_map(msh.topology.dim).size_local
