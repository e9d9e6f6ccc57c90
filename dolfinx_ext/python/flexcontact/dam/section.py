"""What dam engineers read off a model: base-section resultants, heel and toe stresses, and
peak stresses at a stated distance from a point.

Axes as in :mod:`flexcontact.dam.scenario` (x downstream, vertical last, heel at the
origin). Sign conventions:

* ``force_N``: the force the dam transmits to the foundation through its base (the resultant
  of every load on the dam); ``normal_force_N`` N = −(its vertical component), compression
  positive; ``shear_force_N`` its downstream component.
* moments tip the dam downstream when positive (clockwise in the 2D x–y picture; about +y in
  3D), about the heel or about the base's centre.
* stresses σ (normal to the base, tension positive) by linearisation over the base of width B
  and block width w (w = 1 m in 2D, every value then per metre of dam):

      σ_heel = −N/(B w) + 6 M_c/(w B²),   σ_toe = −N/(B w) − 6 M_c/(w B²)

  with M_c the moment about the base's centre.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .. import compat
from ..errors import InputError


def tipping_moment(arm: np.ndarray, force: np.ndarray) -> np.ndarray:
    """Downstream-tipping moment of forces (rows) at arms (rows) from the moment point."""
    if arm.shape[1] == 2:
        return -(arm[:, 0] * force[:, 1] - arm[:, 1] * force[:, 0])
    return arm[:, 2] * force[:, 0] - arm[:, 0] * force[:, 2]


@dataclass(frozen=True)
class BaseSection:
    """Resultant transmitted through the base: force (N; N/m in 2D) and moment about the
    heel (N·m; N·m/m in 2D), for a base of width ``base_width_m`` and a block of width
    ``width_m`` (1 in 2D)."""

    force_N: tuple
    moment_heel_Nm: float
    base_width_m: float
    width_m: float = 1.0

    @classmethod
    def from_forces(cls, points, forces, base_width_m, width_m=1.0, comm=None):
        """Sum nodal forces (rows of ``forces``) at ``points`` (heel at the origin); with
        ``comm`` the sums run over every rank (each rank passing only what it owns)."""
        points, forces = np.atleast_2d(points), np.atleast_2d(forces)
        f = forces.sum(axis=0)
        m = float(tipping_moment(points, forces).sum()) if len(points) else 0.0
        if comm is not None:
            f = comm.allreduce(f, op=MPI.SUM)
            m = comm.allreduce(m, op=MPI.SUM)
        return cls(tuple(float(x) for x in f), m, float(base_width_m), float(width_m))

    def plus(self, force, point) -> BaseSection:
        """The section with one more load (``force`` at ``point``) on the dam."""
        force = np.asarray(force, dtype=float)
        m = tipping_moment(np.atleast_2d(point), np.atleast_2d(force))[0]
        return BaseSection(tuple(np.asarray(self.force_N) + force), self.moment_heel_Nm + m,
                           self.base_width_m, self.width_m)

    @property
    def normal_force_N(self) -> float:
        return -self.force_N[-1]

    @property
    def shear_force_N(self) -> float:
        return self.force_N[0]

    @property
    def moment_centre_Nm(self) -> float:
        return self.moment_heel_Nm - 0.5 * self.base_width_m * self.normal_force_N

    @property
    def sigma_heel_Pa(self) -> float:
        B, w = self.base_width_m, self.width_m
        return -self.normal_force_N / (B * w) + 6.0 * self.moment_centre_Nm / (w * B * B)

    @property
    def sigma_toe_Pa(self) -> float:
        B, w = self.base_width_m, self.width_m
        return -self.normal_force_N / (B * w) - 6.0 * self.moment_centre_Nm / (w * B * B)

    def as_dict(self) -> dict:
        return {"normal_force_N": self.normal_force_N, "shear_force_N": self.shear_force_N,
                "moment_heel_Nm": self.moment_heel_Nm, "moment_centre_Nm": self.moment_centre_Nm,
                "sigma_heel_Pa": self.sigma_heel_Pa, "sigma_toe_Pa": self.sigma_toe_Pa}


def nodal_forces(V, form, facet_tags=None, tag=None) -> tuple[np.ndarray, np.ndarray]:
    """Assemble the linear ``form`` and return this rank's owned nodal forces (n, gdim) and
    their points (n, gdim), on the nodes of facets tagged ``tag`` (all nodes if None)."""
    return NodalForces(V, facet_tags, tag)(form)


class NodalForces:
    """:func:`nodal_forces` with the nodes and their points found once, for a form assembled
    at every time step. Collective, as is a call."""

    def __init__(self, V, facet_tags=None, tag=None):
        import dolfinx.fem
        msh = V.mesh
        self.V, self.gdim = V, msh.geometry.dim
        n_owned = V.dofmap.index_map.size_local
        if tag is None:
            self.owned = np.arange(n_owned, dtype=np.int32)
        else:
            facets = facet_tags.indices[facet_tags.values == tag]
            blocks = dolfinx.fem.locate_dofs_topological(V, msh.topology.dim - 1, facets)
            self.owned = blocks[blocks < n_owned]
        self.points = V.tabulate_dof_coordinates()[self.owned, :self.gdim]

    def __call__(self, form) -> tuple[np.ndarray, np.ndarray]:
        import dolfinx.fem.petsc
        r = compat.create_petsc_vector(self.V)
        r.zeroEntries()
        dolfinx.fem.petsc.assemble_vector(r, form)
        r.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        values = r.array_r.reshape(-1, self.gdim)[self.owned].copy()
        r.destroy()
        return self.points, values


def nodal_section(V, residual_form, facet_tags, base_tag: int, base_width_m: float,
                  width_m: float = 1.0, nodes: "NodalForces | None" = None) -> BaseSection:
    """Base section from the nodal forces of one side's residual at the base nodes.

    ``residual_form``: compiled linear form L_side(v) − a_side(u_h, v) of the dam's free body
    (loads minus internal forces over the dam's cells only). Its value at a base node is the
    force the dam hands to the foundation there, and elsewhere it vanishes; the sums are
    those of the loads on the dam, exact in statics whatever the mesh. ``nodes``: the base
    nodes as a :class:`NodalForces` of the same V and tag, found once. Collective.
    """
    nodes = nodes or NodalForces(V, facet_tags, base_tag)
    points, values = nodes(residual_form)
    return BaseSection.from_forces(points, values, base_width_m, width_m, comm=V.mesh.comm)


def sample_directions(dim: int, n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly on the circle (2D) or the sphere (3D, Fibonacci)."""
    if dim == 2:
        t = 2.0 * np.pi * np.arange(n) / n
        return np.column_stack([np.cos(t), np.sin(t)])
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5 ** 0.5) * k
    r = np.sqrt(1.0 - z * z)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def peak_at_offset(f, point, offset_m: float, cell_tags=None, tag=None, samples: int = 720):
    """Largest value of the scalar Function ``f`` at distance ``offset_m`` from ``point``.

    Samples the circle (2D) or sphere (3D) of that radius, keeps the points inside the mesh
    (and inside cells tagged ``tag`` if given) and returns ``(value, where)``: the maximum
    and the sample point (3 coordinates), or ``(nan, None)`` if no sample lies in the body.
    Stresses at a re-entrant corner or under a contact edge grow with mesh refinement; at a
    stated distance they converge, which is what a design check can use. Collective. To
    sample the same sphere at every time step, make an :class:`OffsetProbe` once.
    """
    probe = OffsetProbe(f.function_space.mesh, point, offset_m, cell_tags, tag, samples)
    return probe.peak(f)


class OffsetProbe:
    """The samples of :func:`peak_at_offset`, located in the mesh once: finding them builds a
    bounding-box tree of the whole mesh, which costs far more than reading a field there,
    and a linear run's mesh does not move. Collective, as are its methods."""

    def __init__(self, msh, point, offset_m: float, cell_tags=None, tag=None,
                 samples: int = 720):
        self.comm = msh.comm
        self.points, self.found, cells = offset_samples(msh, point, offset_m, cell_tags, tag,
                                                        samples)
        self.cells, self._of_sample = np.unique(cells, return_inverse=True)
        self.cells = self.cells.astype(np.int32)
        self.sample_cells = self.cells[self._of_sample]
        """The cell of each found sample, in the order of :attr:`found`."""

    def peak(self, f):
        """(largest value of the Function ``f`` over the samples, its sample point)."""
        vals = np.zeros(0)
        if len(self.found):
            vals = f.eval(self.points[self.found], self.sample_cells).reshape(-1)
        return self.best(vals)

    def best(self, vals):
        """(largest of ``vals``, one per found sample in order, over every rank; its sample
        point), or (nan, None) if no rank holds a sample."""
        best, where = -np.inf, None
        if len(vals):
            i = int(np.argmax(vals))
            best, where = float(vals[i]), self.points[self.found[i]]
        everyone = ([(best, where)] if self.comm.size == 1
                    else self.comm.allgather((best, where)))
        best, where = max(everyone, key=lambda bw: bw[0])
        return (best, where) if np.isfinite(best) else (float("nan"), None)


def offset_samples(msh, point, offset_m: float, cell_tags=None, tag=None, samples: int = 720):
    """The sample points of :func:`peak_at_offset` (``samples`` on the circle in 2D, four
    times as many on the sphere in 3D, of radius ``offset_m`` around ``point``): all the
    points (n, 3), the indices of those in this rank's cells (tagged ``tag`` if given) and
    their cells."""
    if not offset_m > 0:
        raise InputError(f"offset_m={offset_m!r}: must be > 0")
    gdim = msh.geometry.dim
    pts = np.zeros((samples if gdim == 2 else 4 * samples, 3))
    dirs = sample_directions(gdim, pts.shape[0])
    pts[:, :gdim] = np.asarray(point, dtype=float)[:gdim] + offset_m * dirs
    found, cells = compat.points_in_cells(msh, pts)
    if cell_tags is not None and tag is not None and len(found):
        mark = np.zeros(msh.topology.index_map(msh.topology.dim).size_local
                        + msh.topology.index_map(msh.topology.dim).num_ghosts, dtype=bool)
        mark[cell_tags.indices[cell_tags.values == tag]] = True
        keep = mark[cells]
        found, cells = found[keep], cells[keep]
    return pts, found, cells


def write_section_csv(path, history) -> None:
    """One row per time of ``history`` [(t_s, BaseSection)]: the section's force, moment and
    linearised heel and toe stresses (call on one rank)."""
    import csv
    keys = ("normal_force_N", "shear_force_N", "moment_heel_Nm", "sigma_heel_Pa",
            "sigma_toe_Pa")
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(("t_s",) + keys)
        for t, sec in history:
            d = sec.as_dict()
            w.writerow([repr(float(t))] + [repr(float(d[k])) for k in keys])
