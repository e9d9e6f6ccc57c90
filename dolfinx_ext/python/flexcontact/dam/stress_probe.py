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


class RecoveredStressProbe:
    """Peak of the recovered largest principal stress (Pa, tension positive) over the
    samples of an :class:`~flexcontact.dam.section.OffsetProbe` (a circle in 2D, a sphere in
    3D, of radius ``offset_m`` around ``point``, in cells tagged ``tag``).

    The nodal stress is Σ_c |c| σ_c / Σ_c |c| over the cells c tagged ``tag`` around the
    node, so a material interface is not smeared; a constant stress is recovered exactly.
    Only a shell of cells around the sphere is assembled at each call: the shell grows until
    every node of a sample cell has all its cells in it (checked against the full lumped
    mass, so a partition boundary cannot cut a node's average short). ``u`` is read at each
    :meth:`peak`; ``kind`` as for the stress forms. Collective, as is :meth:`peak`.
    """

    def __init__(self, u, cell_tags, materials: dict, kind: str, point, offset_m: float,
                 tag: int, samples: int = 720):
        msh = u.function_space.mesh
        self.offset = OffsetProbe(msh, point, offset_m, cell_tags, tag, samples)
        self.comm = msh.comm
        s = stress_3x3(u, lame_fields(msh, cell_tags, materials), kind)
        comps = _COMPONENTS if kind == "3d" else _COMPONENTS[:4]
        V = compat.vector_space(msh, 1, len(comps))
        tau = ufl.TestFunction(V)
        ones = ufl.as_vector([1.0] * len(comps))
        self._rec = dolfinx.fem.Function(V)
        self._b = compat.create_petsc_vector(V)
        self._m = compat.create_petsc_vector(V)
        self._ncomp = len(comps)
        full = self._assemble(dolfinx.fem.form(
            ufl.inner(ones, tau) * ufl.Measure("dx", domain=msh, subdomain_data=cell_tags)(tag)),
            self._m)
        needed = np.unique(compat.cell_dofs(V)[self.offset.cells].reshape(-1))
        patch, self._mass = self._patch(msh, cell_tags, tag, np.asarray(point, float),
                                        float(offset_m), ones, tau, full, needed,
                                        V.dofmap.index_map_bs)
        dxp = ufl.Measure("dx", domain=msh, subdomain_data=patch)(PATCH)
        self._form = dolfinx.fem.form(
            ufl.inner(ufl.as_vector([s[i, j] for i, j in comps]), tau) * dxp)
        self._comps = comps
        self.patch_cells = int(self.comm.allreduce(
            np.count_nonzero(patch.indices < _owned_cells(msh)), op=MPI.SUM))

    def _assemble(self, form, vec) -> np.ndarray:
        with vec.localForm() as loc:
            loc.set(0.0)
        dolfinx.fem.petsc.assemble_vector(vec, form)
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with vec.localForm() as loc:
            return loc.array.copy()

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
            got = self._assemble(dolfinx.fem.form(
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
        t = self._tensors()
        return self.offset.best(np.linalg.eigvalsh(t)[:, -1] if len(t) else np.zeros(0))

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
        b = self._assemble(self._form, self._b)
        with np.errstate(divide="ignore", invalid="ignore"):
            self._rec.x.array[:] = np.where(self._mass > 0, b / self._mass, 0.0)
        found = self.offset.found
        t = np.zeros((len(found), 3, 3))
        if len(found):
            c = self._rec.eval(self.offset.points[found], self.offset.sample_cells)
            c = np.asarray(c).reshape(len(found), self._ncomp)
            for k, (i, j) in enumerate(self._comps):
                t[:, i, j] = t[:, j, i] = c[:, k]
        return t


def _owned_cells(msh) -> int:
    return msh.topology.index_map(msh.topology.dim).size_local
