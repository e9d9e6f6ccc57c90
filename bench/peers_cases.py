"""The shared cases of bench/peers.py: meshes, loads, and one way to measure a, p0 and P.

Every code in the comparison gets the same DOLFINx mesh (GetFEM a copy of its geometry and
topology), the same prescribed approach δ and is measured the same way: nodal normal
contact forces [N or N/m] on the slave nodes, divided by the nodes' tributary lengths or
areas computed here once, give nodal pressures; ``interface.hertz_fit`` gives the contact
half-width (radius) a and the peak pressure p0; P is the total normal force (×4 for the 3D
quarter models).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import ufl
from mpi4py import MPI

from flexcontact import compat, forms
from flexcontact.contact_profile import hertz_fit
from flexcontact.meshes import hertz2d, hertz3d, tags

R_M = 0.05                  # cylinder / sphere radius [m]
A_TARGET_M = 0.1 * R_M      # contact half-width (radius) the load aims at [m]
STEEL = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
MU_FRICTION = 0.3           # friction coefficient of the frictional loadings


@dataclass
class Case:
    """One mesh and its contact set-up.

    kind: "hertz" (two deformable bodies, node–node pairs) or "rigid" (one body against a
    rigid circle in 2D or plane in 3D). The slave nodes carry the pressures.
    """
    name: str
    dim: int
    kind: str
    msh: object
    cells: object
    facets: object
    geo: dict
    slave_tag: int
    quarter: bool
    areas: dict = field(default_factory=dict)

    @property
    def force_scale(self) -> float:
        return 4.0 if self.quarter else 1.0

    def dofs(self) -> int:
        return int(compat.geometry_x(self.msh).shape[0] * self.dim)


def build_case(dim: int, kind: str, refine: int = 0, comm=MPI.COMM_SELF) -> Case:
    """The Hertz mesh of demos/hertz2d.py or demos/hertz3d.py (kind "hertz") or the single
    body of demos/rigid_cylinder.py or demos/sphere_on_plane.py (kind "rigid")."""
    if kind not in ("hertz", "rigid"):
        raise ValueError(f"kind={kind!r}; it must be 'hertz' or 'rigid'")
    two = kind == "hertz"
    if dim == 2:
        mesh = hertz2d.build(comm, R=R_M, a_expected=A_TARGET_M, refine=refine,
                             with_cylinder=two)
        slave = tags.SLAVE if two else tags.MASTER
    elif dim == 3:
        mesh = hertz3d.build(comm, R=R_M, a_expected=A_TARGET_M, h_contact=A_TARGET_M / 6,
                             h_far=0.02, zone_factor=1.6, refine=refine, with_block=two)
        slave = tags.SLAVE
    else:
        raise ValueError(f"dim={dim!r}; it must be 2 or 3")
    case = Case(f"{kind}{dim}d", dim, kind, *mesh, slave_tag=slave, quarter=dim == 3)
    case.areas = tributary_areas(case)
    return case


def target_force(case: Case) -> float:
    """Hertz's load for a = A_TARGET_M [N/m in 2D, N in 3D]."""
    E, nu = STEEL.E_Pa, STEEL.nu
    Estar = E / (1 - nu**2) if case.kind == "rigid" else E / (2 * (1 - nu**2))
    if case.dim == 2:
        return np.pi * Estar * A_TARGET_M**2 / (4 * R_M)
    return 4 * Estar * A_TARGET_M**3 / (3 * R_M)


def node_key(x) -> tuple:
    """A hashable key of a point's coordinates (to nanometres), to match nodes across codes."""
    x = np.zeros(3) + np.pad(np.asarray(x, float).reshape(-1)[:3], (0, max(0, 3 - np.size(x))))
    return tuple(np.round(x * 1e9).astype(np.int64).tolist())


def tributary_areas(case: Case) -> dict:
    """{node key: tributary length [m] (2D) or area [m²] (3D)} of the slave nodes: the
    integral of each P1 hat function over the slave facets."""
    msh = case.msh
    V = compat.scalar_space(msh)
    v = ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=case.facets)
    import dolfinx.fem.petsc
    b = dolfinx.fem.petsc.assemble_vector(dolfinx.fem.form(v * ds(case.slave_tag)))
    x = V.tabulate_dof_coordinates()
    w = b.array_r.copy()
    b.destroy()
    return {node_key(x[i]): float(w[i]) for i in np.flatnonzero(w > 0)}


def measure(case: Case, x, fn) -> dict:
    """a [m], p0 [Pa] and P [N/m or N] from slave-node coordinates x (n, ≥dim) and nodal
    normal forces fn (n,) ≥ 0 [N/m or N]; nodes off the slave surface are ignored."""
    x, fn = np.asarray(x, float), np.asarray(fn, float)
    keep = [i for i in range(len(fn)) if node_key(x[i]) in case.areas]
    x, fn = x[keep], fn[keep]
    area = np.array([case.areas[node_key(xi)] for xi in x])
    p = fn / area
    s = x[:, 0] if case.dim == 2 else np.hypot(x[:, 0], x[:, 1])
    order = np.argsort(s)
    a, p0, _ = hertz_fit(s[order], p[order])
    return {"a_m": a, "p0_Pa": p0, "P": case.force_scale * float(fn.sum()),
            "closed_nodes": int((p > 1e-9 * p.max()).sum())}


def agreement(ref: dict, other: dict) -> dict:
    """Relative differences of a, p0 and P of ``other`` against ``ref`` and whether they
    meet the stated accuracy (a, p0 within 0.5 %, P within 1 %)."""
    d = {k: other[k] / ref[k] - 1 for k in ("a_m", "p0_Pa", "P")}
    ok = abs(d["a_m"]) <= 5e-3 and abs(d["p0_Pa"]) <= 5e-3 and abs(d["P"]) <= 1e-2
    return {"a_rel": d["a_m"], "p0_rel": d["p0_Pa"], "P_rel": d["P"], "within_accuracy": ok}
