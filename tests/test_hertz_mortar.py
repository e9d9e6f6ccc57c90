"""Hertz line contact on non-matching meshes with surface–surface (mortar) pairing, either
body as slave: demos/hertz2d_nonmatching.py --pairing surface_to_surface.

Reference: Hertz, a = sqrt(4 P R / (π E*)), p0 = 2 P / (π a), recomputed here from the load P
the demo reached (flexcontact.analytic); a and p0 from the elliptic fit of the nodal
pressures, recomputed here. Issue 14: within 2 % at the finest test mesh (refine 2; measured
a −0.80 %, p0 +0.63 % with the cylinder as slave, a −0.69 %, p0 +0.64 % with the block).
Unlike single-pass node–surface pairs, whose largest nodal pressure is 12 % above p0 on this
mesh (test_node_surface.py), the integrated rows give a smooth profile: the largest nodal
pressure is bounded by 3 % here (measured +0.69 % and +0.88 %).
"""
import numpy as np
import pytest

from demo_runner import A_TARGET, R_HERTZ, STEEL, assert_inputs, run_demo
from flexcontact import analytic
from flexcontact.contact_profile import elliptic_fit

REFINE = 2
ESTAR = analytic.effective_modulus(STEEL["E_Pa"], STEEL["nu"], STEEL["E_Pa"], STEEL["nu"])


@pytest.fixture(scope="module", params=["cylinder", "block"])
def hertz(request, tmp_path_factory):
    slave = request.param
    return slave, run_demo("hertz2d_nonmatching", "--slave", slave, "--refine", REFINE,
                           "--pairing", "surface_to_surface", "--no-plot",
                           results=tmp_path_factory.mktemp("hm"),
                           subfolder=f"{slave}_surface_to_surface")


def test_hertz_surface_to_surface_either_slave(hertz):
    slave, (s, _) = hertz
    assert_inputs(s, {"block": STEEL, "cylinder": STEEL}, R_m=R_HERTZ, a_target_m=A_TARGET,
                  slave=slave, pairing="surface_to_surface")
    a_ref, p0_ref = analytic.hertz_cylinder(s["P"], R_HERTZ, ESTAR)
    x, p = np.array(s["profile"]["x"]), np.array(s["profile"]["pressure"])
    a_fit, p0_fit = elliptic_fit(x, p)
    assert abs(a_fit / a_ref - 1) < 0.02, (a_fit, a_ref)
    assert abs(p0_fit / p0_ref - 1) < 0.02, (p0_fit, p0_ref)
    assert abs(p.max() / p0_ref - 1) < 0.03, (p.max(), p0_ref)
    assert s["factorizations"] == 1
    assert s["pairings"] == len(s["increments"]) + 1
    assert s["max_penetration_rel"] < 1e-6
    assert all(not inc["zone_edge"] for inc in s["increments"])


@pytest.mark.mpi
def test_hertz_surface_to_surface_mpi_equals_serial(hertz, tmp_path):
    slave, (serial, _) = hertz
    if slave != "cylinder":
        pytest.skip("one slave choice suffices for the rank comparison")
    par, _ = run_demo("hertz2d_nonmatching", "--slave", slave, "--refine", REFINE,
                      "--pairing", "surface_to_surface", "--no-plot", results=tmp_path,
                      ranks=2, subfolder=f"{slave}_surface_to_surface")
    for key in ("P", "a", "p0"):
        assert par[key] == pytest.approx(serial[key], rel=1e-10, abs=0), key
    p_s, p_p = np.array(serial["profile"]["pressure"]), np.array(par["profile"]["pressure"])
    assert np.max(np.abs(p_s - p_p)) <= 1e-10 * np.max(np.abs(p_s))
