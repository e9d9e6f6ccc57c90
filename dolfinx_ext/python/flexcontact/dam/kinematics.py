"""Is the log still in the small-strain, small-rotation range of linear elasticity?

The model's kinematics are linear: a rigid rotation θ of the log is represented by the
displacement u = θ × x, which stretches every fibre by sec θ − 1 ≈ θ²/2 instead of leaving
it unstrained, and the linear strain ε = sym ∇u misses the quadratic part ½ ∇uᵀ∇u of the
Green–Lagrange strain. Both errors are quadratic, so they stay negligible while:

* the log's rigid rotation θ ≤ :data:`ROTATION_LIMIT_RAD` = 0.02 rad (1.15°): the spurious
  stretch θ²/2 = 2·10⁻⁴ is a tenth of the strain at which green wood starts to crush along
  the grain (about 20 MPa / 10 GPa = 2·10⁻³), so it cannot mimic a real stress;
* the log's largest principal strain |ε| ≤ :data:`STRAIN_LIMIT` = 0.01: the neglected
  ½ |∇u|² is then at most 0.5 % of the strain itself. (Wood crushes far below 1 %; that is
  a material limit, reported separately as the contact pressure against the crushing
  strength.)

:class:`LogKinematics` measures both on the log's cells for the current displacement: θ as
the log's mean infinitesimal rotation (the mean of skew ∇u, exact for P1 as ∇u is constant
per cell) and ε as the largest |eigenvalue| of sym ∇u over its cells (3×3 in 3D, in-plane
in plane strain, where ε_zz = 0).
"""
from __future__ import annotations

import warnings

import numpy as np
import ufl
from mpi4py import MPI

import dolfinx.fem

from .. import compat

ROTATION_LIMIT_RAD = 0.02
"""Largest rigid rotation of the log for the linear kinematics (see the module docstring)."""
STRAIN_LIMIT = 0.01
"""Largest principal strain of the log for the linear kinematics."""


class SmallStrainWarning(UserWarning):
    """The log's rotation or strain left the small range of the linear model."""


class LogKinematics:
    """Measures the rigid rotation (rad) and largest principal strain of the cells tagged
    ``tag`` for the displacement Function ``u`` (read at each :meth:`measure`)."""

    def __init__(self, u, cell_tags, tag: int, name: str = "log"):
        msh = u.function_space.mesh
        self.u, self.name, self.comm = u, name, msh.comm
        self.dim = msh.geometry.dim
        dx = ufl.Measure("dx", domain=msh, subdomain_data=cell_tags)(tag)
        n_owned = msh.topology.index_map(msh.topology.dim).size_local
        cells = cell_tags.indices[cell_tags.values == tag]
        self._cells = cells[cells < n_owned].astype(np.int32)
        # ∇u of P1 is constant per cell: one evaluation per cell gives both the rotation
        # (its skew part times the cell's volume) and the strain (its symmetric part).
        point = np.full((1, msh.topology.dim), 1.0 / (msh.topology.dim + 1))
        self._grad = dolfinx.fem.Expression(ufl.grad(u), point)
        self._msh = msh
        V0 = compat.scalar_space(msh, "DG", 0)
        volumes = compat.assemble_vector_array(dolfinx.fem.form(ufl.TestFunction(V0) * dx))
        self._cell_volume = volumes[compat.cell_dofs(V0)[self._cells, 0]]
        self.volume = self.comm.allreduce(float(self._cell_volume.sum()), op=MPI.SUM)
        self.max_rotation_rad = 0.0
        self.max_strain = 0.0

    def gradients(self) -> np.ndarray:
        """∇u on this rank's owned cells of the body, (cells, dim, dim)."""
        if not len(self._cells):
            return np.zeros((0, self.dim, self.dim))
        g = compat.eval_expression(self._grad, self._msh, self._cells)
        return np.asarray(g).reshape(len(self._cells), self.dim, self.dim)

    def rotation_rad(self, g: np.ndarray | None = None) -> float:
        """Magnitude of the mean infinitesimal rotation of the body (rad), from the
        gradients ``g`` of :meth:`gradients` if given. Collective."""
        g = self.gradients() if g is None else g
        skew = 0.5 * (g - np.transpose(g, (0, 2, 1)))
        # The rotation vector's components (2D: the one about z).
        comps = (skew[:, [1], [0]] if self.dim == 2
                 else np.column_stack([skew[:, 2, 1], skew[:, 0, 2], skew[:, 1, 0]]))
        local = self._cell_volume @ comps
        return float(np.linalg.norm(self.comm.allreduce(local, op=MPI.SUM))) / self.volume

    def largest_strain(self, g: np.ndarray | None = None) -> float:
        """Largest |principal strain| over the body's cells, from the gradients ``g`` of
        :meth:`gradients` if given. Collective.

        A symmetric tensor's largest |eigenvalue| lies between its Frobenius norm / √dim
        and its Frobenius norm, so only the cells whose norm reaches the largest norm / √dim
        can hold the largest one: the eigenvalues are computed on those alone."""
        g = self.gradients() if g is None else g
        best = 0.0
        if len(g):
            e = 0.5 * (g + np.transpose(g, (0, 2, 1)))
            frob = np.sqrt(np.einsum("cij,cij->c", e, e))
            # A relative margin keeps a cell whose rounded norm sits at the bound.
            bound = frob.max() / np.sqrt(self.dim) * (1.0 - 1e-12)
            best = float(np.abs(np.linalg.eigvalsh(e[frob >= bound])).max())
        return self.comm.allreduce(best, op=MPI.MAX)

    def measure(self, t_s: float) -> tuple[float, float]:
        """Measure now, keep the maxima and warn (once per quantity) when a limit is passed.
        Returns (rotation in rad, largest principal strain). Collective."""
        g = self.gradients()
        rot, strain = self.rotation_rad(g), self.largest_strain(g)
        if rot > ROTATION_LIMIT_RAD >= self.max_rotation_rad:
            warnings.warn(
                f"{self.name}: rigid rotation {rot:.4g} rad at t = {t_s:.6g} s exceeds the "
                f"small-rotation limit {ROTATION_LIMIT_RAD} rad of the linear model "
                f"(spurious stretch θ²/2 = {rot ** 2 / 2:.3g})", SmallStrainWarning,
                stacklevel=2)
        if strain > STRAIN_LIMIT >= self.max_strain:
            warnings.warn(
                f"{self.name}: largest principal strain {strain:.4g} at t = {t_s:.6g} s "
                f"exceeds the small-strain limit {STRAIN_LIMIT} of the linear model",
                SmallStrainWarning, stacklevel=2)
        self.max_rotation_rad = max(self.max_rotation_rad, rot)
        self.max_strain = max(self.max_strain, strain)
        return rot, strain
