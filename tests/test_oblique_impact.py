"""A disc hitting a block obliquely with friction (demos/oblique_impact.py) against
rigid-body theory, the conservation of momentum, the energy account and two ranks.

Rigid-body theory for a disc (moment of inertia m R²/2): stopping the contact point's slip
takes the tangential impulse m v_t / 3, so the disc slides throughout, with J_t = μ J_n,
when v_t / v_n > 3 μ (1 + e), e its restitution; below, it sticks and J_t < μ J_n. The
demo's cases bracket the threshold for every e in [0, 1]; the references are recomputed
here from μ, v_n and the demo's documented defaults.
"""
import csv

import numpy as np
import pytest

from demo_runner import run_demo

MU, V_N = 0.3, 5.0


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    folder = tmp_path_factory.mktemp("oblique_serial")
    return run_demo("oblique_impact", "--no-plot", results=folder)


def test_cases_bracket_the_rigid_threshold(serial):
    s, _ = serial
    assert (s["mu"], s["speed_m_s"], s["restitution"]) == (MU, V_N, 0.0)
    slide, stick = s["slide"], s["stick"]
    assert slide["v_t_over_v_n"] == pytest.approx(2 * 3 * MU * (1 + 1.0), rel=1e-12)
    assert stick["v_t_over_v_n"] == pytest.approx(0.5 * 3 * MU * (1 + 0.0), rel=1e-12)
    for r in (slide, stick):
        e_eff = r["effective_restitution"]
        assert 0.0 <= e_eff <= 1.0, e_eff
        assert r["contact_episodes"] >= 1


def test_fast_disc_slides_throughout_with_mu_times_the_normal_impulse(serial):
    s, _ = serial
    r = s["slide"]
    assert r["v_t_over_v_n"] >= 2 * 3 * MU * (1 + r["effective_restitution"])
    assert r["stick_steps"] == 0
    assert r["tangential_ratio"] == pytest.approx(MU, rel=0.01)


def test_slow_disc_sticks_and_takes_less_than_mu(serial):
    s, _ = serial
    r = s["stick"]
    assert r["v_t_over_v_n"] <= 0.5 * 3 * MU * (1 + r["effective_restitution"])
    assert r["stick_steps"] > 0
    assert 0.0 < r["tangential_ratio"] <= 0.9 * MU, r["tangential_ratio"]
    # Reported against the rigid disc's sticking impulse m v_t / 3 (no assertion on it: an
    # elastic disc's tangential compliance changes it).
    m = s["mass_kg_m"]
    assert r["tangential_impulse_rigid_stick"] == pytest.approx(m * r["v_t_m_s"] / 3,
                                                                rel=1e-12)


@pytest.mark.parametrize("case", ["slide", "stick"])
def test_impulse_is_the_free_discs_momentum_change(serial, case):
    r = serial[0][case]
    J, dp = np.array(r["impulse"]), np.array(r["momentum_change"])
    scale = np.linalg.norm(dp)
    assert np.linalg.norm(J - dp) <= 0.01 * scale, (J, dp)


@pytest.mark.parametrize("case", ["slide", "stick"])
def test_energy_account_closes_and_every_dissipation_is_positive(serial, case):
    r = serial[0][case]
    e0 = r["energy_before"]
    assert e0 == pytest.approx(0.5 * serial[0]["mass_kg_m"]
                               * (r["v_n_m_s"] ** 2 + r["v_t_m_s"] ** 2), rel=1e-9)
    assert abs(r["energy_balance_error_rel"]) <= 0.01
    tiny = 1e-12 * e0
    for key in ("energy_friction", "energy_contact", "energy_numerical", "energy_damping"):
        assert r[key] >= -tiny, (key, r[key])
    assert r["energy_friction"] > 0.0
    assert r["energy_after"] <= e0 * (1 + 1e-12)
    assert r["pairings"] == r["steps"]   # re-paired before every step but the first
    assert r["factorizations"] == 1


def _forces(folder, case):
    with open(folder / f"{case}_history.csv") as fh:
        return np.array([[float(row[k]) for k in ("normal_force", "force_x", "force_y")]
                         for row in csv.DictReader(fh)])


@pytest.mark.mpi
def test_two_ranks_give_the_serial_answer(serial, tmp_path):
    s, folder = serial
    sp, folder2 = run_demo("oblique_impact", "--no-plot", results=tmp_path, ranks=2)
    assert sp["ranks"] == 2
    for case in ("slide", "stick"):
        f1, f2 = _forces(folder, case), _forces(folder2, case)
        assert f1.shape == f2.shape
        assert np.max(np.abs(f1 - f2)) <= 1e-10 * s[case]["peak_force"]
