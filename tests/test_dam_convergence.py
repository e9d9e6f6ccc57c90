"""The mesh study's Richardson extrapolation (dam/convergence.py) against quantities with a
known error law, and the report's convergence table."""
import math

import pytest

from flexcontact.dam.convergence import RATIO, SAFETY_FACTOR, richardson
from flexcontact.errors import InputError


@pytest.mark.parametrize("p", [0.7, 1.0, 1.5, 2.0, 2.9])
def test_a_power_law_error_gives_its_order_and_limit(p):
    """f(h) = 10 + 2 hᵖ on h = 1, 1/√2, 1/2: order p and limit 10 to round-off; the default
    mesh's GCI is Fs × its true relative error."""
    f = [10.0 + 2.0 * h ** p for h in (1.0, 1.0 / RATIO, 0.5)]
    c = richardson(f, RATIO)
    assert c.order == pytest.approx(p, rel=1e-10)
    assert c.extrapolated == pytest.approx(10.0, rel=1e-12)
    assert c.gci_default == pytest.approx(SAFETY_FACTOR * 2.0 / 12.0, rel=1e-10)
    assert c.asymptotic and c.note == ""


@pytest.mark.parametrize("f, words", [([1.0, 2.0, 1.5], "oscillating"),
                                      ([10.0, 10.5, 10.5001], "outside \\[0.5, 3\\]"),
                                      ([10.0, 10.001, 10.5], "outside \\[0.5, 3\\]")])
def test_outside_the_asymptotic_range_no_error_is_given(f, words):
    c = richardson(f, RATIO)
    assert not c.asymptotic and c.gci_default is None and c.extrapolated is None
    assert c.note.startswith("not asymptotic") and __import__("re").search(words, c.note)


def test_unchanged_values_are_converged():
    c = richardson([3.0, 3.0, 3.0])
    assert c.asymptotic and c.gci_default == 0.0 and c.extrapolated == 3.0


@pytest.mark.parametrize("args, words", [(([1.0, 2.0], RATIO), "three meshes"),
                                         (([1.0, 2.0, 3.0], 1.0), "ratio=1.0"),
                                         (([1.0, math.nan, 3.0], RATIO), "finite")])
def test_bad_study_input_is_named(args, words):
    with pytest.raises(InputError, match=words):
        richardson(*args)


def test_report_tabulates_the_three_meshes_and_the_estimate():
    from flexcontact.dam.impact_report import _mesh_study
    from flexcontact.dam.key_numbers import CONVERGENCE_QUANTITIES, MESH_STUDY_COLUMNS
    rows = []
    for k, h in enumerate((1.0, 1.0 / RATIO, 0.5)):
        row = {key: 1.0 + 0.1 * h ** 2 for key, _, _ in MESH_STUDY_COLUMNS}
        row.update({key: 2.0 + 0.2 * h for key, _, _ in CONVERGENCE_QUANTITIES})
        row["delta_sigma_toe_Pa"] = [1.0, 2.0, 1.5][k]  # oscillates
        row.update(h_impact_m=0.2 * h, h_far_m=3.0 * h, cells=100 * (k + 1))
        rows.append(row)
    text = "\n".join(_mesh_study(rows))
    assert "### Convergence" in text
    heel = next(line for line in text.splitlines() if line.startswith("| Δσ heel"))
    # f = 2 + 0.2 h: order 1, limit 2 (×1e-6 in MPa), GCI 1.25 × 0.2/2.2 = 11.4 %.
    assert "| 1.00 |" in heel and "11.4 %" in heel
    toe = next(line for line in text.splitlines() if line.startswith("| Δσ toe"))
    assert "not asymptotic" in toe


def test_the_study_can_keep_the_crushed_patch_mesh():
    """contact="kept": far and impact sizes / √2 and / 2, the contact zone's size unchanged;
    "refined" divides it too; another word is refused by name."""
    from flexcontact.dam import DamScenario
    from flexcontact.dam.key_numbers import study_scenarios
    s = DamScenario(dim=3, mesh_size_contact_m=0.0125, contact_zone_m=0.35)
    kept = study_scenarios(s, RATIO, "kept")
    refined = study_scenarios(s, RATIO)
    for k, (a, b) in enumerate(zip(kept, refined)):
        assert a.h_far_m == pytest.approx(s.h_far_m / RATIO ** k, rel=1e-12)
        assert a.h_impact_m == pytest.approx(s.h_impact_m / RATIO ** k, rel=1e-12)
        assert a.h_contact_m == s.h_contact_m
        assert b.h_contact_m == pytest.approx(s.h_contact_m / RATIO ** k, rel=1e-12)
    with pytest.raises(InputError, match="contact='coarse'"):
        study_scenarios(s, RATIO, "coarse")


def test_report_says_when_the_contact_mesh_was_kept():
    from flexcontact.dam.impact_report import _mesh_study
    from flexcontact.dam.key_numbers import CONVERGENCE_QUANTITIES, MESH_STUDY_COLUMNS
    rows = []
    for k, h in enumerate((1.0, 1.0 / RATIO, 0.5)):
        row = {key: 1.0 for key, _, _ in MESH_STUDY_COLUMNS}
        row.update({key: 2.0 + 0.2 * h for key, _, _ in CONVERGENCE_QUANTITIES})
        row.update(h_impact_m=0.4 * h, h_far_m=6.0 * h, h_contact_m=0.0125, cells=100,
                   dofs=300 * (k + 1))
        rows.append(row)
    text = "\n".join(_mesh_study(rows))
    assert "(the crushed patch's, 12.5 mm) are kept" in text
    assert "every element size but the contact zone's divided by 1.41" in text
    assert "| 0.4 | 6 | 12.5 | 100 | 300 |" in text
