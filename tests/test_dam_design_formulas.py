"""Debris-impact design formulas (dam/design_formulas.py) against hand computations from
their sources."""
import math

import pytest

from flexcontact.dam import design_formulas as dfm

LB_N = 4.4482216152605   # one pound-force in N
FT_M = 0.3048
G_FT_S2 = 9.80665 / FT_M  # standard gravity in ft/s² (32.174)


def test_asce7_in_us_units_as_the_commentary_writes_it():
    # The commentary's recommended debris weight W = 1000 lb, here at 10 ft/s, Δt = 0.03 s,
    # C_O = 0.8, every other coefficient 1: F = π·1000·10·0.8 / (2·32.174·0.03) lb.
    f_lb = math.pi * 1000.0 * 10.0 * 0.8 / (2.0 * G_FT_S2 * 0.03)
    assert abs(f_lb - 13019.0) < 1.0  # by hand: 25132.7 / 1.93044
    f = dfm.asce7_force_N(1000.0 * LB_N, 10.0 * FT_M)
    assert abs(f - f_lb * LB_N) <= 1e-12 * f
    # π/2 × the mean force m v/Δt of the pulse; R_max and the coefficients multiply.
    m = 1000.0 * LB_N / 9.80665
    assert abs(dfm.asce7_force_N(1000.0 * LB_N, 3.0, C_O=1.0) - math.pi / 2 * m * 3.0 / 0.03) \
        <= 1e-12 * m * 3.0 / 0.03 * 2
    assert dfm.asce7_force_N(1.0, 1.0, R_max=1.8) == pytest.approx(1.8 * dfm.asce7_force_N(1.0, 1.0),
                                                                   rel=1e-15)


def test_haehnel_daly_contact_stiffness():
    # 500 kg at 2 m/s on k = 2.4 MN/m: F = 2·√(1.2e9) = 69 282 N.
    assert dfm.contact_stiffness_force_N(500.0, 2.0) == pytest.approx(69282.03, rel=1e-6)
    # Energy: the spring's ½ F²/k equals the log's ½ m v².
    f = dfm.contact_stiffness_force_N(3000.0, 1.5, k_N_m=5e6)
    assert 0.5 * f * f / 5e6 == pytest.approx(0.5 * 3000.0 * 1.5 ** 2, rel=1e-14)


def test_eurocode_bar_is_the_one_dimensional_wave_force():
    # Green wood E = 10 GPa, ρ = 650 kg/m³, Ø 0.8 m at 2 m/s: A √(E ρ) v = 2.5631 MN, for
    # any length (m = ρ A L and k = E A / L).
    E, rho, D, v = 10e9, 650.0, 0.8, 2.0
    A = math.pi * D * D / 4
    expected = A * math.sqrt(E * rho) * v
    assert expected == pytest.approx(2.5631e6, rel=1e-4)
    for L in (5.0, 10.0, 20.0):
        assert dfm.eurocode_bar_force_N(rho * A * L, v, E, A, L) == pytest.approx(expected,
                                                                                  rel=1e-14)


def test_matsutomi_by_hand():
    # D = 0.8 m, L = 10 m, v = 2 m/s, γ = 650·9.80665 N/m³, σ_f = 20 MPa, C_M = 1.7:
    gamma = 650.0 * 9.80665                        # 6374.32 N/m³
    froude = 2.0 / math.sqrt(9.80665 * 0.8)        # 0.71404
    ratio = 20e6 / (gamma * 10.0)                  # 313.76
    by_hand = 1.6 * 1.7 * froude ** 1.2 * ratio ** 0.4 * gamma * 0.64 * 10.0
    assert froude == pytest.approx(0.71404, rel=1e-4)
    assert ratio == pytest.approx(313.76, rel=1e-4)
    assert by_hand == pytest.approx(7.38e5, rel=2e-3)
    assert dfm.matsutomi_force_N(0.8, 10.0, 2.0, gamma) == pytest.approx(by_hand, rel=1e-14)
    # The fit's exponents: F ∝ v^1.2 and σ_f^0.4.
    assert dfm.matsutomi_force_N(0.8, 10.0, 4.0, gamma) / by_hand == pytest.approx(2 ** 1.2)
    assert dfm.matsutomi_force_N(0.8, 10.0, 2.0, gamma, 40e6) / by_hand == pytest.approx(2 ** 0.4)


@pytest.mark.parametrize("call", [
    lambda: dfm.asce7_force_N(-1.0, 2.0),
    lambda: dfm.contact_stiffness_force_N(500.0, float("nan")),
    lambda: dfm.eurocode_bar_force_N(500.0, 2.0, 0.0, 1.0, 1.0),
    lambda: dfm.matsutomi_force_N(0.8, 10.0, 2.0, 6000.0, C_M=-1.0)])
def test_bad_input_names_the_parameter(call):
    with pytest.raises(ValueError, match="must be a finite number > 0"):
        call()


def test_comparison_demo_in_2d(tmp_path):
    """The comparison script on one 2D run: its formula columns are the module's, the
    computed peak per metre stays below the elastic wave bound of the plane-strain slab
    (thickness D, modulus E/(1−ν²), density with the added mass) hitting a rigid wall, and
    each crushing end's (flat and rounded) below the elastic one and below σ_c D."""
    import csv

    from demo_runner import run_demo
    from flexcontact.dam import DamScenario
    summary, folder = run_demo("dam_design_formulas", "--dim", "2", "--speeds", "2",
                               "--lengths", "10", "--no-plot", results=tmp_path)
    with open(folder / "comparison.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 1 and (folder / "comparison.md").is_file()
    row = {k: float(v) for k, v in rows[0].items() if not k.startswith("contact_ended")}
    s = DamScenario(log_speed_m_s=2.0)
    w = s.wood
    expected = dfm.all_formulas_N(s.log_mass_kg(), 2.0, s.log_diameter_m, 10.0, w.E_Pa,
                                  w.rho_kg_m3, s.wood_crushing_strength_Pa)
    for key, value in expected.items():
        assert row[key] == pytest.approx(value, rel=1e-12), key
    D = s.log_diameter_m
    slab_bound = D * math.sqrt(w.E_Pa / (1 - w.nu ** 2) * w.rho_kg_m3
                               * (1 + s.added_mass_coefficient)) * 2.0
    per_metre = row["computed_N"] / D
    assert 0 < per_metre <= slab_bound, (per_metre, slab_bound)
    assert rows[0]["contact_ended"] == "True"
    # Each crushing end (flat, rounded): below the elastic end, and no more per metre than
    # the whole end crushing at once, σ_c D (the normal force of pairs all at their caps).
    for end in ("flat", "rounded"):
        crushing = row[f"computed_crushing_{end}_N"] / D
        assert 0 < crushing < per_metre, end
        assert crushing <= s.wood_crushing_strength_Pa * D, (end, crushing)
        assert row[f"crush_depth_{end}_m"] > 0, end
        assert rows[0][f"contact_ended_crushing_{end}"] == "True", end


def test_the_main_reports_comparison_is_each_formula_and_its_stiffness():
    """comparison(): each formula at the scenario's log and speed; k_eff = F²/(m v²), the
    model's with the added mass and a formula's with the log's own mass, so that Haehnel &
    Daly's is their 2.4 MN/m and the elastic bar's EA/L, exactly; the 2D force scaled by
    the log's diameter."""
    from flexcontact.dam import DamScenario
    for dim in (2, 3):
        s = DamScenario(dim=dim)
        m = s.log_mass_kg()
        c = dfm.comparison(s.as_dict(), m, 1.0e6)
        v = s.log_speed_m_s
        assert c["formulas_N"] == dfm.all_formulas_N(m, v, s.log_diameter_m, s.log_length_m,
                                                     s.wood.E_Pa, s.wood.rho_kg_m3,
                                                     s.wood_crushing_strength_Pa)
        width = s.log_diameter_m if dim == 2 else 1.0
        assert c["model_N"] == 1.0e6 * width
        m_eff = m * (1 + s.added_mass_coefficient)
        assert c["k_eff_N_m"]["model"] == pytest.approx((1e6 * width) ** 2 / (m_eff * v * v),
                                                        rel=1e-14)
        assert c["k_eff_N_m"]["haehnel_daly"] == pytest.approx(dfm.HAEHNEL_DALY_STIFFNESS_N_M,
                                                               rel=1e-14)
        area = math.pi * s.log_diameter_m ** 2 / 4
        assert c["k_eff_N_m"]["eurocode_bar"] == pytest.approx(
            s.wood.E_Pa * area / s.log_length_m, rel=1e-14)
