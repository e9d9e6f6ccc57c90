"""The sweep's report reads as a design note (flexcontact.sweep.sweep_report, quantities):
MN and MPa to three significant figures, outputs in words, each stress against the concrete's
tensile strength with its bootstrap band, correlations of the design outputs only — checked
against the analytic outputs of tests/sweep_fakes.py. The table keeps full precision."""
import csv
import math

import numpy as np
import pytest

import sweep_fakes
from flexcontact import sweep
from flexcontact.sweep import stats
from flexcontact.sweep.quantities import quantity, three_figures
from flexcontact.sweep.scenarios import build_scenarios
from test_sweep import fake_config


@pytest.mark.parametrize("value, scale, shown", [
    (1.12857e6, 1e-6, "1.13"), (721109.0, 1e-6, "0.721"), (-46404.2, 1e-6, "-0.0464"),
    (6.24395e6, 1e-6, "6.24"), (12.0, 1.0, "12.0"), (670.865, 1.0, "671"),
    (7.08603e-05, 1e6, "70.9"), (0.0, 1.0, "0"), (1234567.0, 1.0, "1.23e+06"),
    (2.5e-4, 1.0, "2.50e-04"), (float("nan"), 1.0, "—"), (None, 1.0, "—"),
    (float("inf"), 1.0, "—"), ("rounded", 1.0, "rounded"), (32, 1.0, "32")])
def test_three_significant_figures(value, scale, shown):
    assert three_figures(value, scale) == shown


def test_units_follow_the_dimension_and_unknown_columns_their_suffix():
    assert quantity("peak_force_filtered_N_per_m", 2).unit == "MN/m"
    assert quantity("peak_force_filtered_N_per_m", 3).unit == "MN"
    assert quantity("impulse_N_s_per_m", 3).label() == "Impulse (kN·s)"
    assert quantity("heel_stress_impact_Pa").stress
    assert not quantity("heel_stress_static_Pa").stress
    q = quantity("foundation_depth_m")
    assert (q.words, q.unit, q.scale) == ("Foundation depth", "m", 1.0)
    q = quantity("some_new_stress_Pa")
    assert (q.words, q.unit, q.scale) == ("Some new stress", "MPa", 1e-6)


def test_probability_above_and_its_band():
    x = np.arange(10.0)
    a = stats.probability_above(x, 6.5, bootstrap=500, band=0.9, seed=3)
    assert (a["p"], a["above"], a["n"]) == (0.3, 3, 10)
    assert a["lower"] <= a["p"] <= a["upper"] and 0 < a["upper"] - a["lower"] < 1
    assert a == stats.probability_above(x, 6.5, bootstrap=500, band=0.9, seed=3)
    # A limit per value, and NaN values left out.
    b = stats.probability_above([1.0, 5.0, math.nan], [2.0, 4.0, 0.0], 100, 0.9, 0)
    assert (b["p"], b["n"]) == (0.5, 2)
    # Every value above: no uncertainty the resamples can show.
    c = stats.probability_above(x + 10, 6.5, 100, 0.9, 0)
    assert (c["p"], c["lower"], c["upper"]) == (1.0, 1.0, 1.0)


def test_report_reads_as_a_design_note(tmp_path):
    n = 40
    cfg = sweep.from_dict(fake_config(n=n, seed=5, output={"plots": True}))
    summary = sweep.run(cfg, out=tmp_path / "out")
    _, points, _ = build_scenarios(cfg)
    expected = [sweep_fakes.expected_outputs(p["log_speed_m_s"], p["friction_mu"],
                                             p["log_length_m"], p["wood_density_kg_m3"], 27.0)
                for p in points]
    report = (tmp_path / "out" / "report.md").read_text()

    # The stress near the impact is 10⁶ v μ Pa: P[X > f_t] is the share of v μ above 2.5.
    ft = 2.5e6
    sigma = np.array([e["peak_tensile_stress_Pa"] for e in expected])
    assert 0 < (sigma > ft).sum() < n
    a = summary["exceedance"]["peak_tensile_stress_Pa"]["above_tensile_strength"]
    assert a["p"] == (sigma > ft).sum() / n and a["above"] == (sigma > ft).sum()
    assert a["lower"] <= a["p"] <= a["upper"]
    assert summary["exceedance"]["peak_tensile_stress_Pa"]["tensile_strength_Pa"] == ft
    assert "f_t = 2.50 MPa" in report
    assert (f"Peak principal stress near the impact: P[X > f_t | impact] = "
            f"{three_figures(a['p'])} (90 % bootstrap band {three_figures(a['lower'])}–"
            f"{three_figures(a['upper'])}; {a['above']} of {n} scenarios)") in report
    # The heel stress never reaches f_t here; a force is not a stress.
    assert summary["exceedance"]["heel_stress_impact_Pa"]["above_tensile_strength"]["p"] == 0
    assert "above_tensile_strength" not in summary["exceedance"]["peak_force_N_per_m"]

    # Worst cases in MN/m and MPa, three figures, with the inputs in words.
    force = np.array([e["peak_force_N_per_m"] for e in expected])
    assert f"| Peak impact force, raw | {three_figures(force.max(), 1e-6)} MN/m |" in report
    assert f"| Peak principal stress near the impact | {three_figures(sigma.max(), 1e-6)} MPa" \
        in report
    assert "| Log speed (m/s) |" in report and "Wood density (kg/m³)" in report
    assert "e+0" not in report and "nan" not in report.lower()
    # Correlations of the design outputs only: no bookkeeping row.
    assert set(summary["spearman"]) == {"peak_force_N_per_m", "impulse_N_s_per_m",
                                        "heel_stress_impact_Pa", "peak_tensile_stress_Pa"}
    drivers = report.split("## What drives the design outputs")[1].split("##")[0]
    assert "Steps" not in drivers and "steps" not in drivers
    table = [line.split(" | ") for line in drivers.splitlines() if line.startswith("|")]
    speed = table[0].index("Log speed")
    row = next(r for r in table if r[0] == "| Peak impact force, raw")
    assert row[speed] == "+1.00"  # the force is 10⁶ × speed: ρ = 1
    # Each output defined in words.
    assert "linearised over the section" in report
    assert (tmp_path / "out" / "exceedance_peak_tensile_stress_Pa.png").exists()

    # The table keeps full precision.
    with open(tmp_path / "out" / "results.csv") as f:
        rows = list(csv.DictReader(f))
    by_id = {int(r["id"]): r for r in rows}
    i = int(np.argmax(sigma))
    assert float(by_id[i]["peak_tensile_stress_Pa"]) == sigma[i]


def test_a_swept_tensile_strength_is_compared_per_scenario(tmp_path):
    raw = fake_config(n=30, seed=2)
    raw["parameters"]["concrete_tensile_strength_Pa"] = {"distribution": "uniform",
                                                         "lo": 1.5e6, "hi": 3.0e6}
    cfg = sweep.from_dict(raw)
    summary = sweep.run(cfg, out=tmp_path / "out")
    _, points, _ = build_scenarios(cfg)
    above = [1e6 * p["log_speed_m_s"] * p["friction_mu"] > p["concrete_tensile_strength_Pa"]
             for p in points]
    c = summary["exceedance"]["peak_tensile_stress_Pa"]
    assert c["above_tensile_strength"]["p"] == sum(above) / len(points)
    assert c["tensile_strength_Pa"] is None
    assert "f_t is swept" in (tmp_path / "out" / "report.md").read_text()


def _crushing_summary(forces, dim=3, crushes=True):
    return {"dim": dim, "base": {"log_end_crushes": crushes, "wood_crushing_strength_Pa": 26.1e6},
            "mesh": {"h_far_m": 6.0, "h_impact_m": 0.4, "h_log_m": 0.2, "h_contact_m": 0.05,
                     "contact_zone_m": 0.35, "contact_layer_m": 0.05},
            "exceedance": {"peak_force_filtered_N_per_m": {"x": sorted(forces)}}}


def test_a_crushing_ends_force_steps_are_stated_where_scenarios_tie():
    """Three of five scenarios with one peak force to the last digit: the report says why
    (σ_c·h² = 26.1 MPa × (50 mm)² = 0.06525 MN) and counts the ties (2 beyond the first)."""
    from flexcontact.sweep.sweep_report import _mesh
    tied = _mesh(_crushing_summary([3.27e5, 3.27e5, 3.27e5, 4.1e5, 6.0e5]))
    assert ("where only a few of them crush, the force comes in steps of about σ_c·h² = "
            "0.0653 MN, and 2 of the 5 scenarios share their filtered peak force") in tied
    assert "end's 50.0 mm elements" in tied
    one = _mesh(_crushing_summary([3.27e5, 3.27e5, 4.1e5]))
    assert "1 of the 3 scenarios shares its filtered peak force with another" in one
    for quiet in (_crushing_summary([3.27e5, 4.1e5, 6.0e5]),           # no tie
                  _crushing_summary([3.27e5, 3.27e5], crushes=False),  # elastic end
                  _crushing_summary([3.27e5, 3.27e5], dim=2)):         # a section
        assert "σ_c·h²" not in _mesh(quiet)
