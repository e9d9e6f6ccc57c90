"""The factored-dam evaluator (dam/reuse.py) on the 3D dam block, against the monolithic
stage 1 + 2.

Two references:

* **identical meshes**: the evaluator's own meshes (the dam block without the log, the
  round log in its own frame, rotated and moved into place) merged node for node into one
  mesh (meshes/merge.py), on which the monolithic stages run. The two methods then solve
  the same discrete problem: every output agrees to 1e-8 (measured at most 4e-12);
* **each one's own mesh** at the 3D default sizes (far 6 m, impact 0.4 m): the two meshes
  differ, and so do their answers, by the discretisation error; again at far 3 m,
  impact 0.3 m, the block of the 1,000-scenario bench; and at the main job's mesh with its
  crushing end.

Serial (COMM_SELF: the evaluator is one process's).
"""
import numpy as np
import pytest
from mpi4py import MPI

from flexcontact.dam import DamScenario
from flexcontact.dam.coupled_step import run_impact, run_steps
from flexcontact.dam.key_numbers import halfspace_tension_Pa
from flexcontact.dam.log_model import rotation
from flexcontact.dam.reuse import ScenarioEvaluator, sweep_time_step_s
from flexcontact.dam.scenario import MAIN_JOB_LOG_MESH_M, MAIN_JOB_MESH, crushed_patch_mesh
from flexcontact.dam.stage1 import DamMesh, solve_stage1
from flexcontact.dam.stage2 import solve_stage2
from flexcontact.meshes.merge import merge
from flexcontact.sweep.monolithic import IMPACT_OFFSET_M, MonolithicEvaluator

COMM = MPI.COMM_SELF
BASE = DamScenario(dim=3, mesh_size_far_m=6.0, mesh_size_impact_m=0.4)
LEVELS = (BASE.water_level_m - 1.0, BASE.water_level_m)
SCENARIOS = [
    BASE,
    # yawed, off-centre, pitched the other way, lower water, a rounded end that crushes
    BASE.replace(log_yaw_deg=12.0, log_across_m=6.0, log_pitch_deg=-4.0,
                 water_level_m=26.0, log_end_shape="rounded", log_end_crushes=True,
                 log_speed_m_s=3.0, friction_mu=0.3),
]
COMPARED = ("impulse_N_s_per_m", "peak_force_N_per_m", "peak_force_filtered_N_per_m",
            "contact_duration_s", "heel_stress_static_Pa", "peak_tensile_stress_Pa",
            "peak_contact_pressure_Pa", "log_momentum_change_N_s_per_m",
            "halfspace_tension_Pa")   # the log's and the dam's force: equal and opposite


@pytest.fixture(scope="module")
def evaluator():
    return ScenarioEvaluator(BASE, sweep_time_step_s(SCENARIOS), LEVELS, COMM)


def monolithic_on_the_same_meshes(evaluator, s) -> dict:
    """The monolithic stages 1 + 2 of ``s`` on the evaluator's dam mesh and its log mesh
    placed by the scenario's rotation and centre, for as many steps as the evaluator's run:
    the outputs under the evaluator's names."""
    log = evaluator.log_model(s)
    R = rotation(s.log_pitch_deg, s.log_yaw_deg, s.dim)
    c = s.log_centre
    dm = evaluator.dam.mesh
    mesh = DamMesh(*merge(COMM, [(dm.msh, dm.cell_tags, dm.facet_tags, None),
                                 (log.msh, log.cell_tags, log.facet_tags,
                                  lambda x: c[None, :] + x @ R.T)]))
    r1 = solve_stage1(s, mesh=mesh, comm=COMM)
    n = run_steps(s, evaluator.dam)
    r2 = solve_stage2(s, r1, dt_s=evaluator.dt, duration_s=n * evaluator.dt)
    m = r2.metrics
    heel = max(r1.section.sigma_heel_Pa, r2.section_extremes()["sigma_heel_max_Pa"])
    return {"impulse_N_s_per_m": m["impulse"], "peak_force_N_per_m": m["peak_force"],
            "peak_force_filtered_N_per_m": m["peak_force_filtered"],
            "contact_duration_s": m["contact_duration_s"],
            "heel_stress_static_Pa": r1.section.sigma_heel_Pa, "heel_stress_impact_Pa": heel,
            "peak_tensile_stress_Pa": r2.peak_tensile_stress_Pa,
            "peak_contact_pressure_Pa": r2.peak_contact_pressure_Pa,
            "log_momentum_change_N_s_per_m": r2.log_momentum_change,
            "halfspace_tension_Pa": halfspace_tension_Pa(
                s, r2.force_at_filtered_peak_N, r2.static_stress_near_impact_Pa, r2.offset_m),
            "steps": r2.timings_s["steps_n"]}


@pytest.mark.parametrize("k", range(len(SCENARIOS)))
def test_identical_meshes_give_the_monolithic_answer(evaluator, k):
    """Every output within 1e-8 (relative; the heel stress's change relative to itself) of
    the monolithic run on the same meshes, with the dam stepped to the end and with its
    base section convolved after the contact."""
    s = SCENARIOS[k]
    ref = monolithic_on_the_same_meshes(evaluator, s)
    got = evaluator.evaluate(s)
    assert got["steps"] == ref["steps"]
    for key in COMPARED:
        assert got[key] == pytest.approx(ref[key], rel=1e-8), key
    static = ref["heel_stress_static_Pa"]
    change = ref["heel_stress_impact_Pa"] - static
    assert change > 0
    assert abs(got["heel_stress_impact_Pa"] - static - change) <= 1e-8 * change
    assert got["dam_steps_convolved"] > 0  # the dam not stepped after the contact


@pytest.mark.parametrize("k", range(len(SCENARIOS)))
def test_convolved_section_equals_the_stepped_one_in_3d(evaluator, k):
    """The base section's history from the response functions equals the stepped dam's at
    every step (1e-8 of the largest change); the face impulses along x sum to the impulse
    (1e-9)."""
    s = SCENARIOS[k]
    dam, log = evaluator.dam, evaluator.log_model(s)
    static = dam.static_state(s.water_level_m)
    stepped = run_impact(dam, log, s, static, 1.0, "step", histories=True)
    convolved = run_impact(dam, log, s, static, 1.0, "convolve", histories=True)
    for q, ref in stepped["history"].items():
        scale = np.abs(ref).max()
        assert scale > 0
        assert np.abs(convolved["history"][q] - ref).max() <= 1e-8 * scale, q
    assert (convolved["dam_back_substitutions"] + convolved["dam_steps_convolved"]
            == stepped["dam_back_substitutions"])
    assert abs(stepped["face_impulses"][:, 0::3].sum() - stepped["impulse_N_s_per_m"]) \
        <= 1e-9 * stepped["impulse_N_s_per_m"]


@pytest.fixture(scope="module")
def own_meshes(evaluator):
    """The base scenario on each method's own mesh at the 3D default sizes."""
    return evaluator.evaluate(BASE), MonolithicEvaluator(BASE, evaluator.dt).evaluate(BASE)


def heel_change(out: dict) -> float:
    """Δσ_heel: the linearised heel stress during the impact less the static one (Pa)."""
    return out["heel_stress_impact_Pa"] - out["heel_stress_static_Pa"]


def test_each_ones_own_mesh(own_meshes):
    """Impulse within 1 %, filtered peak force within 2 %. Measured: +0.19 %, +0.76 %."""
    got, ref = own_meshes
    assert got["impulse_N_s_per_m"] == pytest.approx(ref["impulse_N_s_per_m"], rel=0.01)
    assert got["peak_force_filtered_N_per_m"] == pytest.approx(
        ref["peak_force_filtered_N_per_m"], rel=0.02)
    assert got["stress_offset_m"] == IMPACT_OFFSET_M


@pytest.mark.xfail(strict=True, reason=(
    "Δσ_heel of the two meshes differs by −6.2 % at far 6 m / impact 0.4 m (+2.3 % at "
    "3 m / 0.3 m; with θ = ½ −8.6 %, −5.1 % at 4 m / 0.4 m and −0.7 % at 3 m / 0.3 m): the "
    "discretisation error of the coarse default far mesh, not the method (identical meshes "
    "agree to 1e-12)"))
def test_heel_stress_change_on_each_ones_own_mesh(own_meshes):
    """Δσ_heel = σ_heel during the impact − σ_heel static within 5 %."""
    got, ref = own_meshes
    assert heel_change(got) == pytest.approx(heel_change(ref), rel=0.05)


FINE = DamScenario(dim=3, mesh_size_far_m=3.0, mesh_size_impact_m=0.3)
"""The dam block of bench/sweep_1000_3d_3m.toml, where 1,000 scenarios take under 30 min."""


@pytest.fixture(scope="module")
def own_meshes_fine():
    """The base scenario on each method's own mesh at far 3 m, impact 0.3 m."""
    dt = sweep_time_step_s([FINE])
    fine = ScenarioEvaluator(FINE, dt, (FINE.water_level_m - 1.0, FINE.water_level_m), COMM)
    return fine.evaluate(FINE), MonolithicEvaluator(FINE, dt).evaluate(FINE)


def test_each_ones_own_mesh_at_3m_03m(own_meshes_fine):
    """At the resolution the 1,000-scenario bench runs (docs/dam.md, "Sweeps"): impulse
    within 1 %, filtered peak force within 2 %, Δσ_heel and the half-space tension within
    5 %. Measured: +0.23 %, −0.41 %, +2.26 %, −0.27 % (with θ = ½: +0.15 %, −0.30 %,
    −0.72 %, −0.78 %)."""
    within_the_targets(*own_meshes_fine)


def within_the_targets(got: dict, ref: dict) -> None:
    """Impulse within 1 %, filtered peak force within 2 %, Δσ_heel (an increase) and the
    half-space tension within 5 % of the monolithic run's."""
    assert got["impulse_N_s_per_m"] == pytest.approx(ref["impulse_N_s_per_m"], rel=0.01)
    assert got["peak_force_filtered_N_per_m"] == pytest.approx(
        ref["peak_force_filtered_N_per_m"], rel=0.02)
    assert heel_change(ref) > 0
    assert heel_change(got) == pytest.approx(heel_change(ref), rel=0.05)
    assert got["halfspace_tension_Pa"] == pytest.approx(ref["halfspace_tension_Pa"], rel=0.05)


_H_CONTACT, _ZONE, _LAYER = crushed_patch_mesh(3, "rounded")
MAIN_JOB = DamScenario(dim=3, mesh_size_far_m=MAIN_JOB_MESH[3][0],
                       mesh_size_impact_m=MAIN_JOB_MESH[3][1],
                       mesh_size_log_m=MAIN_JOB_LOG_MESH_M[3], mesh_size_contact_m=_H_CONTACT,
                       contact_zone_m=_ZONE, contact_layer_m=_LAYER, log_end_crushes=True,
                       log_end_shape="rounded")
"""The main job's block, mesh and crushing rounded end (demos/dam_debris.py)."""


@pytest.fixture(scope="module")
def own_meshes_main_job():
    """The main job's scenario on each method's own mesh: the monolithic mesh with the log
    in place, and the factored dam's block and log in its own frame, both refined where the
    end crushes."""
    dt = sweep_time_step_s([MAIN_JOB])
    ev = ScenarioEvaluator(MAIN_JOB, dt, (MAIN_JOB.water_level_m,) * 2, COMM)
    return ev.evaluate(MAIN_JOB), MonolithicEvaluator(MAIN_JOB, dt).evaluate(MAIN_JOB)


def test_each_ones_own_mesh_at_the_main_jobs_mesh(own_meshes_main_job):
    """The crushing rounded end at the main job's mesh: impulse within 1 %, filtered peak
    force within 2 %, Δσ_heel and the half-space tension within 5 %. Measured: −0.13 %,
    −0.23 %, +2.20 %, −0.05 % (with the flat end and the log at 0.2 m +0.10 %, −0.34 %,
    +3.36 %, −0.24 %)."""
    within_the_targets(*own_meshes_main_job)


PRINCIPAL_STRESS_MISS = {
    "own_meshes": "+6.2 % at far 6 m / impact 0.4 m (r/h = 2.5; +5.9 % with θ = ½, where the "
                  "cell-wise reading gave −3.8 %)",
    "own_meshes_fine": "−10.0 % at far 3 m / impact 0.3 m (r/h = 3.3; −10.7 % with θ = ½)",
    "own_meshes_main_job": "−11.0 % at the main job's mesh, far 3 m / impact 0.2 m, crushing "
                           "rounded end (r/h = 5; 94.1 against 105.7 kPa, while the half-space "
                           "values agree to 0.05 %; with the flat end −36.7 %)",
}
"""How far the recovered peak principal stress 1 m from the contact differs between the two
meshes: neither resolves the face's tension layer there (docs/dam.md, 'The peak principal
stress near the impact')."""


@pytest.mark.parametrize("meshes", [
    pytest.param(k, marks=pytest.mark.xfail(strict=True, reason=f"the two meshes differ by {v}"))
    for k, v in PRINCIPAL_STRESS_MISS.items()])
def test_peak_principal_stress_on_each_ones_own_mesh(meshes, request):
    """Within 5 %."""
    got, ref = request.getfixturevalue(meshes)
    assert got["peak_tensile_stress_Pa"] == pytest.approx(ref["peak_tensile_stress_Pa"],
                                                          rel=0.05)


def test_a_log_beyond_the_face_patch_is_named(evaluator):
    """A log whose front end leaves the condensed patch across the block is refused before
    computing, naming the parameter."""
    lo, hi = evaluator.dam.patch_y_m
    s = BASE.replace(log_across_m=min(hi + 1.0, BASE.dam_width_m - BASE.log_radius_m))
    with pytest.raises(ValueError, match="log_yaw_deg=.*face patch"):
        evaluator.evaluate(s)


@pytest.mark.parametrize("bad, name", [(dict(log_across_m=0.1), "log_across_m=0.1"),
                                       (dict(log_across_m=float("nan")), "log_across_m=nan")])
def test_bad_place_across_the_block(bad, name):
    with pytest.raises(ValueError, match=name):
        BASE.replace(**bad)


def test_a_place_across_is_3d_only():
    with pytest.raises(ValueError, match="log_across_m=5.0"):
        DamScenario(log_across_m=5.0)


def test_a_saved_models_face_compliance_and_response_functions_take_several_solves_at_once():
    """The block as a model file prepares it: (K⁻¹)_ii of the face nodes from K's saved
    factor 128 right-hand sides a solve, equal to one-by-one solves of it (1e-12); the
    response functions from a plain factor of Ŵ (counted "dam_response"), N's and M's
    side by side, equal to the adjoint recursion made with the Schur factor's whole solves
    (1e-12 of the largest, measured 5e-15)."""
    from flexcontact.dam.dam_model import DamModel
    from flexcontact.dam.response import TABULATED
    dam = DamModel(BASE, sweep_time_step_s([BASE]), LEVELS, COMM, saveable=True)
    c = dam.face_compliance(0)
    e, x = dam.new_vector(), dam.new_vector()
    for j in (0, c.size // 2, c.size - 1):
        i = dam.face_dofs[0::3][j]
        e.zeroEntries()
        e.array[i] = 1.0
        dam._solve1(e, x, "check")
        assert c[j] == pytest.approx(x.array_r[i], rel=1e-12)
    G = dam.responses()
    G.ensure(40)
    assert dam.counts()["factorizations"]["dam_response"] == 1
    h, theta = dam.dt, dam.theta
    for q in TABULATED:
        a, b = dam.new_vector(), dam.new_vector()
        a.array[:] = dam.section_gradients[q]
        rhs, z, Kz = dam.new_vector(), dam.new_vector(), dam.new_vector()
        ref = []
        for _ in range(40):
            rhs.array[:] = h * theta * a.array_r + b.array_r
            dam.factor.solve(rhs, z)
            ref.append(z.array_r[dam.face_dofs].copy())
            dam.K.mult(z, Kz)
            a_old = a.array_r.copy()
            a.array[:] = a_old - h * Kz.array_r
            b.array[:] = h * a_old + b.array_r - h * h * theta * Kz.array_r
        ref = np.array(ref)
        assert np.abs(G.G[q][:40] - ref).max() <= 1e-12 * np.abs(ref).max(), q
    assert dam.response_factor() is not dam.factor    # the Schur factor stays the steps'
