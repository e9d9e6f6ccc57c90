"""Stage 2 of the dam scenario: the floating log hits the dam's upstream face.

Starts from stage 1 (:mod:`flexcontact.dam.stage1`) on the same mesh and function space:

* supports: those of stage 1 on the foundation, without the hold on the log (the log is a
  free body; the Moreau–Jean iteration matrix M + hθC + h²θ²K is regular without one);
* loads: the stage-1 loads (self-weight, water on the faces) kept constant, and the
  initial displacement is stage 1's, so the dam and foundation start in equilibrium and
  stay there until the log arrives. The log gets no load: its weight and buoyancy cancel;
* the log moves at ``log_speed_m_s`` along its axis (``scenario.log_axis``, pointing at
  the dam), as the scenario defines its approach; the water it drags along is added as mass: its density is
  ρ_wood (1 + C_a) with C_a the scenario's ``added_mass_coefficient`` (see scenario.py),
  its stiffness unchanged;
* contact: the log's front end (slave; with the pitched log its lower front corner hits
  first) against the dam's upstream face (master), node–surface with the scenario's μ.
  The pairs are made once from the initial positions and kept (``repair_pairs=False``), as
  the factored-dam evaluator of reuse.py does: over the few milliseconds of contact the log
  slides along the face by far less than an element, and fixed pairs keep the impact
  linear in the log's speed;
* ``westergaard=True``: the reservoir's added mass on the upstream face (Westergaard's
  (7/8) ρ_w sqrt(H_w (H_w − z)) per unit area, acting on the face's normal motion) joins
  the mass matrix (:func:`westergaard_form`); off by default.

* the log's front end crushes at the wood's crushing strength parallel to the grain
  (``log_end_crushes``, docs/crushing.md): where the nodal-average contact pressure reaches
  it, the end crushes irreversibly and the force grows only with the contact area.

Not modelled: water damping and compressibility, the wood's across-grain softness, a crushing
strength that rises with the crush rate.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np
import ufl
from mpi4py import MPI

import dolfinx.fem

from ..boundary import dirichlet
from ..dynamics import ImpactProblem
from ..forms import Material
from ..impact_output import contact_metrics, filter_steps, force_at_filtered_peak
from ..meshes import dam_tags as T
from ..problem import ContactInterface
from .fields import StressFields
from .kinematics import LogKinematics
from .section import NodalForces
from .stress_probe import RecoveredStressProbe
from .stage1 import _measures, body_loads, dam_section, section_form
from ..errors import InputError

MARGIN = 1.5
"""The run lasts approach + MARGIN × the expected contact duration (2L/c of the log)."""


@dataclass
class Stage2Result:
    """The impact run: the ImpactProblem (state at the end, records per step), the contact
    metrics (impulse_contact: Σ normal force × dt, N·s/m in 2D), the log's momentum change
    along x from its nodes, and the peak largest principal stress near the impact point."""

    problem: Any
    metrics: dict
    log_momentum_change: float
    log_mass_effective: float
    log_velocity_before: float
    log_velocity_after: float
    stress_history: list          # (t_s, peak largest principal stress [Pa]) in contact
    impact_point_m: np.ndarray
    offset_m: float
    # largest mean pressure of a step (impulse / h / tributary area) on the log's front
    # nodes: the wood's side, which the crushing law caps
    peak_contact_pressure_Pa: float
    timings_s: dict = field(default_factory=dict)
    section_history: list = field(default_factory=list)  # (t_s, BaseSection) every step
    peak_state: Any = None        # displacement Function at the step of the peak force
    peak_time_s: float = float("nan")
    log_max_rotation_rad: float = 0.0
    log_max_strain: float = 0.0
    force_at_filtered_peak_N: Any = None   # (d,) on the dam, global axes (N/m in 2D)
    static_stress_near_impact_Pa: Any = None   # (3, 3) recovered, mean over the offset's samples

    def section_extremes(self) -> dict:
        """Extremes over the run of the linearised base stresses (Pa, tension positive)
        and of the base-section moment about the heel, with their times."""
        if not self.section_history:
            return {}
        t = np.array([h[0] for h in self.section_history])
        heel = np.array([h[1].sigma_heel_Pa for h in self.section_history])
        toe = np.array([h[1].sigma_toe_Pa for h in self.section_history])
        m = np.array([h[1].moment_heel_Nm for h in self.section_history])
        i, j, k = int(np.argmax(heel)), int(np.argmin(toe)), int(np.argmax(m))
        return {"sigma_heel_max_Pa": float(heel[i]), "sigma_heel_max_t_s": float(t[i]),
                "sigma_toe_min_Pa": float(toe[j]), "sigma_toe_min_t_s": float(t[j]),
                "moment_heel_max_Nm": float(m[k]), "moment_heel_max_t_s": float(t[k])}

    @property
    def peak_tensile_stress_Pa(self) -> float:
        vals = [s for _, s in self.stress_history if np.isfinite(s)]
        return max(vals) if vals else float("nan")


def log_material(s) -> Material:
    """The wood with the added mass of the water: ρ (1 + C_a)."""
    w = s.wood
    return Material(E_Pa=w.E_Pa, nu=w.nu, rho_kg_m3=w.rho_kg_m3 * (1.0 + s.added_mass_coefficient),
                    name="wood+added mass")


def stage2_supports(s, V, mesh) -> list:
    """Stage 1's supports without the hold on the log."""
    bcs, _ = dirichlet(V, mesh.facet_tags, T.FOUNDATION_BOTTOM)
    bcs += dirichlet(V, mesh.facet_tags, T.FOUNDATION_SIDES, components=[0])[0]
    if s.dim == 3:
        bcs += dirichlet(V, mesh.facet_tags, T.FOUNDATION_FLANKS, components=[1])[0]
    return bcs


def default_time_step_s(s, steps_in_contact: int = 40) -> float:
    """dt = 2L_x/c of the log (its first wave round trip along x) / ``steps_in_contact``."""
    c = math.sqrt(s.wood.E_Pa / (s.wood.rho_kg_m3 * (1.0 + s.added_mass_coefficient)))
    extent = s.log_length_m * abs(s.log_axis[0]) + s.log_diameter_m * math.sqrt(
        max(1.0 - s.log_axis[0] ** 2, 0.0))
    return 2.0 * extent / c / steps_in_contact


def sweep_time_step_s(scenarios) -> float:
    """One time step (s) for every scenario: the smallest of stage 2's default steps
    (the log's first wave round trip along x over 40 steps), so that the most demanding
    scenario (the shortest log round trip) is resolved as a single run would resolve it.
    The speed does not enter: an elastic impact lasts 2L/c whatever the speed."""
    steps = [default_time_step_s(s) for s in scenarios]
    if not steps:
        raise InputError("scenarios: empty; give at least one scenario to choose dt_s from")
    return min(steps)


FILTER_FRACTION = 0.1
"""The peak-force filter's window as a fraction of the log's wave round trip 2L/c
(impact_output.contact_metrics): long enough to average out a discrete wave front's
overshoot, short enough to keep the plateau of the exact pulse."""


def force_filter_window_s(s) -> float:
    """The filter window of the peak force: FILTER_FRACTION × 2L/c of the log along its axis
    (c with the added mass, as the log moves it)."""
    c_log = math.sqrt(s.wood.E_Pa / (s.wood.rho_kg_m3 * (1.0 + s.added_mass_coefficient)))
    return FILTER_FRACTION * 2.0 * s.log_length_m / c_log


def log_crushing_strength_Pa(s) -> Optional[float]:
    """σ_c of the log's front end on the log/dam interface: the wood's crushing strength
    parallel to the grain, or None for an elastic end (``log_end_crushes=False``)."""
    return s.wood_crushing_strength_Pa if s.log_end_crushes else None


def make_problem(s, stage1, dt_s: float, contact_operator: str = "dense") -> ImpactProblem:
    """The ImpactProblem of stage 2 (collective). ``contact_operator``: "dense", or "factor"
    for contact zones whose dense F̂ would not fit (docs/impact.md, "The factor path"; the
    same answer to rounding)."""
    mesh, V = stage1.mesh, stage1.V
    dx, ds = _measures(mesh)
    v = ufl.TestFunction(V)
    loads = body_loads(s, v, dx, ds)
    materials = {T.DAM: s.concrete, T.FOUNDATION: s.rock, T.LOG: log_material(s)}
    contact = ContactInterface(mesh.facet_tags, slave=T.LOG_FRONT, master=T.DAM_UPSTREAM,
                               mu=s.friction_mu, name="log/dam", pairing="node_to_surface",
                               crushing_strength_Pa=log_crushing_strength_Pa(s))
    speed = s.log_speed_m_s * np.asarray(s.log_axis, dtype=float)
    return ImpactProblem(
        V, mesh.cell_tags, {"dam": T.DAM, "foundation": T.FOUNDATION, "log": T.LOG},
        materials, stage2_supports(s, V, mesh), contact, dt_s=dt_s, kind=stage1.kind,
        theta=s.time_scheme_theta,
        initial_velocity={"log": tuple(speed)}, loads=loads["dam"] + loads["foundation"],
        initial_displacement=stage1.u, repair_pairs=False,
        added_mass=westergaard_form(s, mesh) if s.westergaard else None,
        contact_operator=contact_operator)


WESTERGAARD_QUADRATURE_DEGREE = 12
"""The added mass varies as sqrt(depth): smooth on every facet but the one ending at the
water line (a face node sits there), where the high degree keeps the error of the
√-endpoint behaviour small (tests/test_dam_impact.py measures the total)."""


def westergaard_form(s, mesh):
    """Westergaard's added mass of the reservoir on the upstream face, as a bilinear form
    (u, v) -> ∫ m(z) u_x v_x ds over the face below the water, m(z) = (7/8) ρ_w
    sqrt(H_w (H_w − z)) kg/m² (floating.westergaard_added_mass_kg_m2): the water moving with
    the face along its normal x, for a rigid dam and incompressible water (Westergaard
    1933). Its total is (7/12) ρ_w H_w² per metre of face."""
    x = ufl.SpatialCoordinate(mesh.msh)
    depth = ufl.max_value(s.water_level_m - x[s.vertical_axis], 0.0)
    m = 0.875 * s.water_density_kg_m3 * ufl.sqrt(s.water_level_m * depth)
    ds = ufl.Measure("ds", domain=mesh.msh, subdomain_data=mesh.facet_tags,
                     metadata={"quadrature_degree": WESTERGAARD_QUADRATURE_DEGREE})
    return lambda u, v: m * u[0] * v[0] * ds(T.DAM_UPSTREAM)


def solve_stage2(scenario, stage1, dt_s: Optional[float] = None,
                 duration_s: Optional[float] = None, offset_m: float = 1.0,
                 writer=None, write_every: int = 5, stress_every: int = 1,
                 contact_operator: str = "dense") -> Stage2Result:
    """Run the impact from ``stage1`` (a Stage1Result of the same scenario). Collective.

    ``dt_s``: time step (default :func:`default_time_step_s`); ``duration_s``: simulated
    time (default: the approach gap / (speed · x) plus MARGIN × 2L/c of the log);
    ``offset_m``: the distance from the first-contact point on the face at which the
    largest principal stress in the dam (recovered, see :class:`RecoveredStressProbe`) is
    sampled every ``stress_every`` steps in contact; ``writer``: a ResultWriter receiving
    the ImpactProblem's fields every ``write_every`` steps; ``contact_operator``: as for
    :func:`make_problem`.

    Besides the contact metrics the result holds, for every step, the base section from
    the dam's displacement (``section_history``), the log's largest rigid rotation and
    strain (a :class:`~flexcontact.dam.kinematics.SmallStrainWarning` when they leave the
    small range) and the displacement at the step of the peak force (``peak_state``). The
    default duration ends before the base responds; :func:`response_duration_s` covers it.
    """
    s = scenario
    if duration_s is not None and not (math.isfinite(duration_s) and duration_s > 0):
        raise InputError(f"duration_s={duration_s!r}: must be a finite number > 0 s")
    t0 = time.perf_counter()
    dt = dt_s if dt_s is not None else default_time_step_s(s)
    problem = make_problem(s, stage1, dt, contact_operator)
    t_setup = time.perf_counter() - t0
    if duration_s is None:
        duration_s = approach_time_s(s) + MARGIN * problem.expected_contact_s
    impact = np.zeros(s.dim)
    impact[-1] = s.log_front_point[-1]
    if s.dim == 3:
        impact[1] = s.log_front_point[1]
    cells = stage1.mesh.cell_tags
    materials = {T.DAM: s.concrete, T.FOUNDATION: s.rock, T.LOG: s.wood}
    history, p_peak = [], 0.0
    watch = _Watch(s, stage1, problem)

    fields = StressFields(stage1.V, problem.u, cells, materials, stage1.kind)
    stresses = fields.update
    probe = RecoveredStressProbe(problem.u, cells, materials, stage1.kind, impact, offset_m,
                                 T.DAM)

    static_stress = probe.mean()   # the run starts from the static state
    n = int(round(duration_s / dt))
    if writer is not None:
        writer.write(problem.fields() + stresses(), 0.0)
    for i in range(n):
        rec = problem.step()
        watch.after_step(rec)
        if writer is not None and (i + 1) % write_every == 0:
            writer.write(problem.fields() + stresses(), problem.t)
        if rec.active > 0 and (i % stress_every == 0):
            peak, _ = probe.peak()
            history.append((problem.t, peak))
            p_peak = max(p_peak, problem.peak_contact_pressure_Pa(slave_only=True))
    metrics = contact_metrics(problem.records, dt, filter_window_s=force_filter_window_s(s))
    force_peak = -force_at_filtered_peak(   # the log is the slave: the dam takes the opposite
        [r.normal_force for r in problem.records], [r.slave_force for r in problem.records],
        filter_steps(force_filter_window_s(s), dt))
    m_eff, v0, v1 = _log_momentum(problem)
    return Stage2Result(problem, metrics, m_eff * (v1 - v0), m_eff, v0, v1, history, impact,
                        offset_m, p_peak, {"setup": t_setup, "steps": time.perf_counter() - t0 - t_setup,
                                   "dt_s": dt, "duration_s": duration_s, "steps_n": n},
                        watch.sections, watch.peak_u, watch.peak_t,
                        watch.log.max_rotation_rad, watch.log.max_strain, force_peak,
                        static_stress)


class _Watch:
    """What stage 2 follows at every step besides the contact records: the base section
    from the dam's displacement, the log's rotation and strain (warning when they leave
    the small range, see kinematics.py) and the displacement at the peak contact force."""

    def __init__(self, s, stage1, problem):
        dx, ds = _measures(stage1.mesh)
        v = ufl.TestFunction(stage1.V)
        self.s, self.V, self.mesh, self.problem = s, stage1.V, stage1.mesh, problem
        self.form = section_form(s, stage1.V, problem.u, body_loads(s, v, dx, ds),
                                 dx, stage1.kind)
        self.base = NodalForces(stage1.V, stage1.mesh.facet_tags, T.DAM_BASE)
        self.sections = [(0.0, dam_section(s, stage1.V, self.form, stage1.mesh, self.base))]
        self.log = LogKinematics(problem.u, stage1.mesh.cell_tags, T.LOG)
        self.peak_u = dolfinx.fem.Function(stage1.V, name="displacement_m")
        self.peak_u.x.array[:] = problem.u.x.array
        self.peak_force, self.peak_t = -1.0, float("nan")

    def after_step(self, rec) -> None:
        t = self.problem.t
        self.sections.append((t, dam_section(self.s, self.V, self.form, self.mesh, self.base)))
        self.log.measure(t)
        if rec.normal_force > self.peak_force:
            self.peak_force, self.peak_t = rec.normal_force, t
            self.peak_u.x.array[:] = self.problem.u.x.array


def dam_period_estimate_s(s) -> float:
    """Fundamental period of the dam on rigid ground, T₁ = 1.4 H/√E in feet and psi
    (Fenves & Chopra's simplified analysis of concrete gravity dams), i.e.
    T₁ ≈ 381 H/√E with H in m and E in Pa. With ``westergaard`` the water's added mass
    lengthens it by sqrt(1 + m_water / m_dam) (the whole of each mass moving with the mode:
    an upper bound on the lengthening, which is what a long enough run needs). Only used to
    choose how long to simulate."""
    from .statics import polygon_area_centroid
    feet_per_m, pa_per_psi = 1.0 / 0.3048, 6894.757
    T = 1.4 * s.dam_height_m * feet_per_m / math.sqrt(s.concrete.E_Pa / pa_per_psi)
    if s.westergaard:
        area, _ = polygon_area_centroid(s.dam_outline())
        m_water = 7.0 / 12.0 * s.water_density_kg_m3 * s.water_level_m ** 2
        T *= math.sqrt(1.0 + m_water / (s.concrete.rho_kg_m3 * area))
    return T


def response_duration_s(s) -> float:
    """A run long enough to see the dam's base respond: the approach, the contact (2L/c of
    the log) and half the dam's first period after it, when the base moment from the
    impulse peaks (the stress wave needs H/c ≈ 10 ms just to reach the base)."""
    contact = default_time_step_s(s, steps_in_contact=1)
    return approach_time_s(s) + contact + 0.5 * dam_period_estimate_s(s)


def approach_time_s(s) -> float:
    """Time for the log to cross the gap to the face: gap / (its velocity's x component)."""
    return s.log_gap_m / (s.log_speed_m_s * float(s.log_axis[0]))


def _log_momentum(problem) -> tuple[float, float, float]:
    """The log's mass (Σ M over its x DOFs, with the added mass) and its mean x velocity
    (along the face's normal)
    before and after, from the momenta of its nodes (M v summed over the log's x DOFs)."""
    log = next(b for b in problem.bodies if b.name == "log")
    ones = problem.K.createVecLeft()
    ones.zeroEntries()
    ones.array[log.dofs[0]] = 1.0
    Mo = problem.K.createVecLeft()
    problem.M.mult(ones, Mo)
    m_eff = problem.comm.allreduce(float(Mo.array_r[log.dofs[0]].sum()), op=MPI.SUM)
    for o in (ones, Mo):
        o.destroy()
    p0 = problem.momentum0["log"][0]
    p1 = problem.records[-1].momentum["log"][0] if problem.records else p0
    return m_eff, p0 / m_eff, p1 / m_eff
