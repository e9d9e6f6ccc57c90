"""The peers of bench/peers.py solve the same problem as flexcontact (accuracy, not time).

* a penalty contact written by hand in UFL and solved by PETSc SNES against a rigid circle
  (bench/peers_snes.py) and flexcontact's rigid target on the same block mesh and approach:
  a and p0 within 0.5 %, the contact force P within 1 % (the penalty κ = 1e3 E/h leaves a
  penetration that is a small fraction of the approach);
* GetFEM's nodal Alart–Curnier contact (bench/peers_getfem.py) on a copy of the two-body
  Hertz mesh: both codes pair each slave node with the master node below it and solve the
  same discrete problem, so a, p0 and P agree to round-off (1e-8 relative). Skipped where
  python3-getfem is not installed.
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
import peers_flexcontact as pf  # noqa: E402
import peers_getfem as pg  # noqa: E402
import peers_snes as ps  # noqa: E402
from peers_cases import agreement, build_case, measure  # noqa: E402


def test_snes_penalty_agrees_with_rigid_target():
    case = build_case(2, "rigid", refine=0)
    delta = pf.calibrate(case)
    fc = pf.solve(case, delta)
    ref = measure(case, fc["x"], fc["fn"])
    assert ref["closed_nodes"] >= 10, ref
    snes = ps.solve(case, delta)
    d = agreement(ref, measure(case, snes["x"], snes["fn"]))
    assert abs(d["a_rel"]) < 5e-3 and abs(d["p0_rel"]) < 5e-3 and abs(d["P_rel"]) < 1e-2, d


@pytest.mark.skipif(not pg.available(), reason="python3-getfem is not installed")
def test_getfem_frictionless_hertz_equals_flexcontact():
    case = build_case(2, "hertz", refine=0)
    delta = pf.calibrate(case)
    fc = pf.solve(case, delta)
    ref = measure(case, fc["x"], fc["fn"])
    assert ref["closed_nodes"] >= 10, ref
    gf = pg.solve(case, delta)
    d = agreement(ref, measure(case, gf["x"], gf["fn"]))
    for key in ("a_rel", "p0_rel", "P_rel"):
        assert abs(d[key]) < 1e-8, d
