"""Stage 1: the dam's static state before the impact (a plain linear solve, no contact).

Loads: the self-weight of the dam and of the foundation; the reservoir's hydrostatic pressure
on the upstream face up to the water level and on the reservoir bed; the tailwater's on the
downstream face and the bed below the toe (if ``tailwater_level_m`` > 0). Supports: the
foundation's bottom is clamped; its upstream and downstream ends are on rollers (no normal
displacement), as are, in 3D, its two flanks normal to the dam axis; the dam block's own
flanks are free (open contraction joints).

The log floats (its weight balanced by buoyancy), so it carries no load here; it shares no
node with the dam, and its displacements are held at zero so that K stays regular. Stage 2
starts from this displacement field with the log free.

Uplift (``uplift_factor`` > 0) is water pressure inside the bonded base joint: it pushes the
dam up and the foundation down by equal amounts at the same (shared) nodes, so it leaves the
displacement field unchanged and enters only the base-section statics, where it reduces the
force the concrete transmits. It is added there as its exact resultant.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem

from .. import compat
from ..assembly import assemble_load, assemble_stiffness
from ..boundary import dirichlet
from ..forms import elasticity_form, gravity, hydrostatic_pressure
from ..meshes import dam as dam_mesh
from ..meshes import dam_tags as T
from .section import BaseSection, nodal_section
from .statics import hand_statics, uplift_resultant
from ..errors import SolveError


class DamMesh(NamedTuple):
    msh: Any
    cell_tags: Any
    facet_tags: Any
    info: dict


def build_mesh(scenario, comm=MPI.COMM_WORLD) -> DamMesh:
    """Mesh the scenario (collective); see :mod:`flexcontact.meshes.dam`."""
    return DamMesh(*dam_mesh.build(comm, scenario))


@dataclass
class Stage1Result:
    """The static state: ``u`` (displacement, m) on ``V``, the base section from the dam's
    nodal forces (``section``), the same from the foundation's side (``section_foundation``,
    equal once the solve is exact) and the hand statics (``reference``)."""

    scenario: Any
    mesh: DamMesh
    V: Any
    u: Any
    section: BaseSection
    section_foundation: BaseSection
    reference: BaseSection
    timings_s: dict = field(default_factory=dict)

    @property
    def kind(self) -> str:
        return "plane_strain" if self.scenario.dim == 2 else "3d"

    def materials(self) -> dict:
        s = self.scenario
        return {T.DAM: s.concrete, T.FOUNDATION: s.rock, T.LOG: s.wood}


def _measures(mesh: DamMesh):
    dx = ufl.Measure("dx", domain=mesh.msh, subdomain_data=mesh.cell_tags)
    # Pressure × P1 test function is quadratic on every facet (a node sits at each water
    # line), so degree 2 integrates it exactly.
    ds = ufl.Measure("ds", domain=mesh.msh, subdomain_data=mesh.facet_tags,
                     metadata={"quadrature_degree": 2})
    return dx, ds


def body_loads(s, v, dx, ds) -> dict:
    """L(v) of the loads on each body: {"dam": ..., "foundation": ...} (UFL forms)."""
    g, rho_w, vert = s.gravity_m_s2, s.water_density_kg_m3, s.vertical_axis

    def water(tag, level):
        return hydrostatic_pressure(v, ds(tag), level, rho_w, g, vert)

    dam = gravity(v, s.concrete, dx(T.DAM), g, vert) + water(T.DAM_UPSTREAM, s.water_level_m)
    found = gravity(v, s.rock, dx(T.FOUNDATION), g, vert) + water(T.RESERVOIR_BED,
                                                                  s.water_level_m)
    if s.tailwater_level_m > 0:
        dam += water(T.DAM_DOWNSTREAM, s.tailwater_level_m)
        found += water(T.TAILWATER_BED, s.tailwater_level_m)
    return {"dam": dam, "foundation": found}


def supports(s, V, mesh: DamMesh) -> list:
    """Dirichlet conditions of stage 1 (see the module docstring)."""
    bcs, _ = dirichlet(V, mesh.facet_tags, T.FOUNDATION_BOTTOM)
    bcs += dirichlet(V, mesh.facet_tags, T.FOUNDATION_SIDES, components=[0])[0]
    if s.dim == 3:
        bcs += dirichlet(V, mesh.facet_tags, T.FOUNDATION_FLANKS, components=[1])[0]
    return bcs + [hold_log(V, mesh)]


def hold_log(V, mesh: DamMesh):
    """Zero displacement on every DOF of the log's cells."""
    msh = mesh.msh
    cells = mesh.cell_tags.indices[mesh.cell_tags.values == T.LOG]
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim, tdim)  # DOLFINx 0.9 needs it for cell entities
    dofs = dolfinx.fem.locate_dofs_topological(V, tdim, cells)
    zero = dolfinx.fem.Constant(msh, PETSc.ScalarType((0.0,) * msh.geometry.dim))
    return dolfinx.fem.dirichletbc(zero, dofs, V)


def linear_solve(K, p, u) -> None:
    """u = K⁻¹ p by MUMPS's LU (PETSc KSP preonly)."""
    ksp = PETSc.KSP().create(K.getComm())
    ksp.setOperators(K)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    x = compat.petsc_vec(u)
    ksp.solve(p, x)
    reason = ksp.getConvergedReason()
    ksp.destroy()
    if reason < 0:
        raise SolveError(f"stage 1: the MUMPS solve failed (KSP reason {reason})")
    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)


def solve_stage1(scenario, mesh: DamMesh = None, comm=MPI.COMM_WORLD) -> Stage1Result:
    """Solve the static state of ``scenario`` (meshing it unless ``mesh`` is given)."""
    s = scenario
    t0 = time.perf_counter()
    mesh = mesh or build_mesh(s, comm)
    t_mesh = time.perf_counter() - t0
    kind = "plane_strain" if s.dim == 2 else "3d"
    V = compat.vector_space(mesh.msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx, ds = _measures(mesh)
    materials = {T.DAM: s.concrete, T.FOUNDATION: s.rock, T.LOG: s.wood}
    a = dolfinx.fem.form(elasticity_form(u, v, materials, dx, kind, cell_tags=mesh.cell_tags))
    loads = body_loads(s, v, dx, ds)
    L = dolfinx.fem.form(loads["dam"] + loads["foundation"])
    bcs = supports(s, V, mesh)
    K = assemble_stiffness(a, bcs)
    p = assemble_load(V, a, L, bcs, mesh.msh.comm)
    uh = dolfinx.fem.Function(V, name="displacement_m")
    t1 = time.perf_counter()
    linear_solve(K, p, uh)
    t_solve = time.perf_counter() - t1
    K.destroy()
    p.destroy()
    sections = _sections(s, V, uh, loads, dx, kind, mesh)
    return Stage1Result(s, mesh, V, uh, *sections, hand_statics(s),
                        {"mesh": t_mesh, "solve": t_solve, "total": time.perf_counter() - t0})


def _sections(s, V, uh, loads, dx, kind, mesh):
    """Base section from the dam's residual and (sign reversed) from the foundation's, each
    with the uplift resultant added (it does not enter the FE loads, see above)."""
    v = ufl.TestFunction(V)
    r_found = elasticity_form(uh, v, s.rock, dx(T.FOUNDATION), kind) - loads["foundation"]
    return [dam_section(s, V, section_form(s, V, uh, loads, dx, kind), mesh),
            dam_section(s, V, dolfinx.fem.form(r_found), mesh)]


def section_form(s, V, u, loads, dx, kind):
    """The compiled residual L_dam(v) − a_dam(u, v) of the dam's cells: at the base nodes,
    the forces the dam hands to the foundation for the displacement ``u`` (a Function on
    V, read when the form is assembled, so one compiled form serves every time step)."""
    v = ufl.TestFunction(V)
    return dolfinx.fem.form(loads["dam"] - elasticity_form(u, v, s.concrete, dx(T.DAM), kind))


def dam_section(s, V, residual_form, mesh: DamMesh, nodes=None) -> BaseSection:
    """The base section from a compiled residual (:func:`section_form`), the uplift
    resultant added; ``nodes``: the base's section.NodalForces, found once for a form
    assembled at every step. Collective."""
    w = 1.0 if s.dim == 2 else s.dam_width_m
    sec = nodal_section(V, residual_form, mesh.facet_tags, T.DAM_BASE, s.base_width_m, w,
                        nodes)
    if s.uplift_factor > 0:
        force, at = uplift_resultant(s)
        up = np.zeros(s.dim)
        up[-1] = force * w
        point = np.zeros(s.dim)
        point[0] = at
        sec = sec.plus(up, point)
    return sec


def upstream_water_resultant(result: Stage1Result) -> tuple[float, float]:
    """The finite-element reservoir load on the upstream face: its downstream force (N/m in
    2D, N in 3D) and the height above the base where it acts (m), from the assembled nodal
    loads. Collective."""
    from .section import nodal_forces, tipping_moment
    s, V = result.scenario, result.V
    v = ufl.TestFunction(V)
    _, ds = _measures(result.mesh)
    L = hydrostatic_pressure(v, ds(T.DAM_UPSTREAM), s.water_level_m, s.water_density_kg_m3,
                             s.gravity_m_s2, s.vertical_axis)
    points, forces = nodal_forces(V, dolfinx.fem.form(L))
    comm = V.mesh.comm
    force = comm.allreduce(float(forces[:, 0].sum()), op=MPI.SUM)
    moment = comm.allreduce(float(tipping_moment(points, forces).sum()), op=MPI.SUM)
    return force, moment / force
