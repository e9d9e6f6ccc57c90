"""What the dam report reads off stage 2: the base section during the impact, the log's
small-strain/rotation watch (dam/kinematics.py), the markdown report."""
import math
import warnings

import numpy as np
import pytest
import ufl
from mpi4py import MPI

import dolfinx.fem
import dolfinx.mesh

from flexcontact import compat
from flexcontact.dam import DamScenario
from flexcontact.dam.kinematics import (ROTATION_LIMIT_RAD, STRAIN_LIMIT, LogKinematics,
                                        SmallStrainWarning)
from flexcontact.dam.key_numbers import engineer_numbers
from flexcontact.dam.stage1 import solve_stage1
from flexcontact.dam.stage2 import response_duration_s, solve_stage2

COMM = MPI.COMM_WORLD


# ---- the small-strain/rotation watch on prescribed fields (exact values) -----------------
def body(dim):
    if dim == 2:
        msh = dolfinx.mesh.create_unit_square(COMM, 4, 3)
    else:
        msh = dolfinx.mesh.create_unit_cube(COMM, 2, 2, 2)
    tdim = msh.topology.dim
    n = msh.topology.index_map(tdim).size_local + msh.topology.index_map(tdim).num_ghosts
    cells = np.arange(n, dtype=np.int32)
    tags = dolfinx.mesh.meshtags(msh, tdim, cells, np.full(n, 7, dtype=np.int32))
    u = dolfinx.fem.Function(compat.vector_space(msh))
    return u, tags


def test_rigid_rotation_is_measured_exactly_and_warns_past_the_limit():
    u, tags = body(2)
    theta = 0.05  # u = θ e_z × x: an infinitesimal rotation, no strain
    u.interpolate(lambda x: np.vstack([-theta * x[1], theta * x[0]]))
    watch = LogKinematics(u, tags, 7, name="test log")
    assert abs(watch.volume - 1.0) < 1e-12
    with pytest.warns(SmallStrainWarning, match=r"test log: rigid rotation 0\.05 rad"):
        rot, strain = watch.measure(0.001)
    assert abs(rot - theta) < 1e-12 and strain < 1e-12
    # Once per quantity: the next step above the limit is recorded, not warned again.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        watch.measure(0.002)
    assert watch.max_rotation_rad == pytest.approx(theta, abs=1e-12)


def test_3d_rotation_vector_magnitude_and_uniform_strain():
    u, tags = body(3)
    w = np.array([0.003, -0.004, 0.012])  # |ω| = 0.013 rad, below the limit
    u.interpolate(lambda x: np.vstack([w[1] * x[2] - w[2] * x[1], w[2] * x[0] - w[0] * x[2],
                                       w[0] * x[1] - w[1] * x[0]]))
    watch = LogKinematics(u, tags, 7)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rot, strain = watch.measure(0.0)
    assert abs(rot - 0.013) < 1e-12 and strain < 1e-12
    eps = 1.5 * STRAIN_LIMIT  # uniaxial ε_xx plus a shear ε_yz: principal values ±γ and ε
    u.interpolate(lambda x: np.vstack([eps * x[0], 0.004 * x[2], 0.004 * x[1]]))
    with pytest.warns(SmallStrainWarning, match="largest principal strain 0.015"):
        rot, strain = watch.measure(0.0)
    assert abs(strain - eps) < 1e-12 and rot < 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_a_varying_field_gives_every_cells_largest_strain_and_the_mean_rotation(dim):
    # Against the direct reading: the eigenvalues of sym ∇u on every cell, and the rotation
    # assembled as ∫ skew ∇u dx / volume. A quadratic field varies from cell to cell.
    u, tags = body(dim)
    if dim == 2:
        u.interpolate(lambda x: np.vstack([1e-3 * x[0] ** 2 - 2e-3 * x[1], 3e-3 * x[0] * x[1]]))
    else:
        u.interpolate(lambda x: np.vstack([1e-3 * x[0] * x[2], -2e-3 * x[1] ** 2 + x[0] * 1e-3,
                                           4e-3 * x[0] * x[1] - 1e-3 * x[2]]))
    watch = LogKinematics(u, tags, 7)
    msh = u.function_space.mesh
    tdim = msh.topology.dim
    cells = np.arange(msh.topology.index_map(tdim).size_local, dtype=np.int32)
    point = np.full((1, tdim), 1.0 / (tdim + 1))
    e = compat.eval_expression(dolfinx.fem.Expression(ufl.sym(ufl.grad(u)), point), msh, cells)
    e = np.asarray(e).reshape(len(cells), dim, dim)
    expected = COMM.allreduce(float(np.abs(np.linalg.eigvalsh(e)).max()), op=MPI.MAX)
    g = ufl.grad(u)
    skew = 0.5 * (g - g.T)
    comps = [skew[1, 0]] if dim == 2 else [skew[2, 1], skew[0, 2], skew[1, 0]]
    rot = np.linalg.norm([COMM.allreduce(dolfinx.fem.assemble_scalar(
        dolfinx.fem.form(c * ufl.dx(domain=msh))), op=MPI.SUM) for c in comps])
    assert watch.largest_strain() == pytest.approx(expected, rel=1e-14)
    assert watch.rotation_rad() == pytest.approx(rot, rel=1e-12)


def test_the_limits_are_the_documented_ones():
    # θ²/2 a tenth of green wood's crushing strain along the grain (20 MPa / 10 GPa).
    assert ROTATION_LIMIT_RAD ** 2 / 2 == pytest.approx(0.1 * 20e6 / 10e9)
    assert STRAIN_LIMIT == 0.01


# ---- stage 2 long enough for the base to respond -----------------------------------------
@pytest.fixture(scope="module")
def response():
    s = DamScenario()
    stage1 = solve_stage1(s, comm=COMM)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        r = solve_stage2(s, stage1, duration_s=response_duration_s(s))
    return s, stage1, r, [w for w in seen if issubclass(w.category, SmallStrainWarning)]


def test_base_section_before_contact_is_stage_1s(response):
    """The dam is at rest under the stage-1 loads until the log arrives, so the section
    from its displacement is stage 1's (to round-off) up to the contact."""
    s, stage1, r, _ = response
    t_hit = r.metrics["contact_start_s"]
    ref = stage1.section
    before = [sec for t, sec in r.section_history if t <= t_hit]
    assert len(before) > 10
    for sec in before:
        assert abs(sec.sigma_heel_Pa - ref.sigma_heel_Pa) <= 1e-9 * abs(ref.sigma_heel_Pa)
        assert abs(sec.moment_heel_Nm - ref.moment_heel_Nm) <= 1e-9 * abs(ref.moment_heel_Nm)


def test_base_responds_after_the_stress_wave_has_crossed_the_dam(response):
    """The heel stress changes only once the P wave from the impact point has reached the
    base (distance / c_p, c_p² = E(1−ν)/(ρ(1+ν)(1−2ν))): before half that travel time its
    change stays below 1 % of its largest change during the run."""
    s, stage1, r, _ = response
    c = s.concrete
    cp = math.sqrt(c.E_Pa * (1 - c.nu) / (c.rho_kg_m3 * (1 + c.nu) * (1 - 2 * c.nu)))
    travel = r.impact_point_m[-1] / cp
    t_hit = r.metrics["contact_start_s"]
    change = np.array([abs(sec.sigma_heel_Pa - stage1.section.sigma_heel_Pa)
                       for _, sec in r.section_history])
    t = np.array([h[0] for h in r.section_history])
    assert change.max() > 0.1 * abs(stage1.section.sigma_heel_Pa)
    early = change[t <= t_hit + 0.5 * travel]
    assert early.max() <= 0.01 * change.max(), (early.max(), change.max())
    # The impact pushes the dam downstream: the heel's stress rises towards tension.
    ext = r.section_extremes()
    assert ext["sigma_heel_max_Pa"] > stage1.section.sigma_heel_Pa
    assert ext["sigma_heel_max_t_s"] > t_hit + travel


def test_default_log_stays_small_and_numbers_have_their_references(response):
    s, stage1, r, seen = response
    assert not seen, [str(w.message) for w in seen]
    assert 0 < r.log_max_rotation_rad < ROTATION_LIMIT_RAD
    assert 0 < r.log_max_strain < STRAIN_LIMIT
    n = engineer_numbers(s, stage1, r)
    ref = stage1.reference
    assert abs(n["sigma_heel_before_Pa"] - ref.sigma_heel_Pa) <= 1e-6 * abs(ref.sigma_heel_Pa)
    assert abs(n["impulse"] - n["impulse_ref"]) <= 0.01 * n["impulse_ref"]
    assert n["sigma_heel_during_over_tensile_strength"] == pytest.approx(
        n["sigma_heel_during_max_Pa"] / s.concrete_tensile_strength_Pa, rel=1e-15)
    # The state kept for the picture is that of the step of the peak force.
    peak = max(r.problem.records, key=lambda rec: rec.normal_force)
    assert r.peak_time_s == pytest.approx(peak.t_s, rel=1e-12)


def test_a_fast_log_leaves_the_small_strain_range_with_a_warning():
    """At 40 m/s an elastic log's end is compressed to about v/c = 40/3800 ≈ 1 % on average
    and more under its corner: the watch warns, naming the log and the strain. (A crushing
    end stays near σ_c/E = 0.26 %: the crush takes the rest.)"""
    s = DamScenario(log_speed_m_s=40.0, log_gap_m=0.01, log_end_crushes=False)
    stage1 = solve_stage1(s, comm=COMM)
    c = math.sqrt(s.wood.E_Pa / (s.wood.rho_kg_m3 * (1 + s.added_mass_coefficient)))
    assert s.log_speed_m_s / c > STRAIN_LIMIT
    with pytest.warns(SmallStrainWarning, match=r"log: largest principal strain"):
        r = solve_stage2(s, stage1, duration_s=0.003)
    assert r.log_max_strain > STRAIN_LIMIT


def test_a_missing_pvbatch_is_reported_not_raised(tmp_path, monkeypatch):
    import shutil

    from flexcontact.dam import picture
    monkeypatch.setattr(shutil, "which", lambda name: None)
    done, message = picture.render_stress_picture(tmp_path / "none.xdmf", tmp_path / "x.png",
                                                  1.0)
    assert not done and "pvbatch not found" in message
    assert not (tmp_path / "x.png").exists()


def test_dam_period_estimate_by_hand():
    from flexcontact.dam.stage2 import dam_period_estimate_s
    # T₁ = 1.4 H/√E with H = 30 m = 98.425 ft and E = 25 GPa = 3.6259e6 psi: 0.07236 s.
    h_ft, e_psi = 30.0 / 0.3048, 25e9 / 6894.757
    assert h_ft == pytest.approx(98.425, rel=1e-5) and e_psi == pytest.approx(3.6259e6, rel=1e-4)
    assert dam_period_estimate_s(DamScenario()) == pytest.approx(1.4 * h_ft / math.sqrt(e_psi),
                                                                 rel=1e-14)
    assert dam_period_estimate_s(DamScenario()) == pytest.approx(0.07236, rel=1e-3)
