"""The contact patch test with every pairing, on matching and non-matching interface meshes
(2D plane strain, 3D tetrahedra and 3D hexahedra): demos/patch_test.py and patch_case.py's
two-material cases.

Reference: the exact uniaxial-stress solution, p = δ E / ((H1 + H2)(1 − ν²)) for one material
in plane strain, δ E / (H1 + H2) in 3D (patch_case.exact for two materials), computed here
from the demo's stated inputs and meshes/patch.py's default geometry, never read back from
the demo.

Tolerances. Matching meshes: every pairing is exact up to round-off (measured ≤ 3e-15); the
bound 1e-8 of issue 14 is kept. Non-matching meshes: surface–surface (mortar rows with the
dual basis, integrated exactly over the segment overlaps) transmits a uniform pressure
exactly, and so does 3D with the triangles, or the quadrilaterals (rectangles here),
clipped against each other; issue 14 asks 1e-6 relative (measured 4.5e-14 in 2D, 1.9e-14
on tetrahedra, 1.6e-14 on hexahedra, at the nodes of both sides). Node–surface pairing does
not pass it (measured: nodal pressures 12 % off at slave nodes and 125 % at master nodes in
2D, 25 % and 21 % on tetrahedra, 22 % and 33 % on hexahedra); the test records that the
error is real (above 1 %) so that the default pairing stays the one that passes. 2 ranks against serial: 1e-10
relative (the flexibility comes from another MUMPS path on two ranks).

Runtime: about 8 min on two busy cores (3D and the MPI runs most of it).
"""
import inspect

import numpy as np
import pytest
from mpi4py import MPI

import patch_case
from demo_runner import STEEL, run_demo
from flexcontact.meshes import patch

MATCHING_TOL = 1e-8      # issue 14: matching meshes, every pairing
MORTAR_TOL = 1e-6        # issue 14: non-matching meshes, surface–surface
MPI_TOL = 1e-10
DELTA_M = 1e-5           # the demo's top displacement (its docstring)
PAIRINGS = ("node_to_node", "node_to_surface", "surface_to_surface", "auto")


def _exact_pressure(dim):
    """p [Pa] and the interface measure A (w in 2D, w² in 3D)."""
    defaults = inspect.signature(patch.build).parameters
    H = defaults["lower_height"].default + defaults["upper_height"].default
    w = defaults["width"].default
    if dim == 3:
        return DELTA_M * STEEL["E_Pa"] / H, w * w
    return DELTA_M * STEEL["E_Pa"] / (H * (1 - STEEL["nu"] ** 2)), w


DEMO_MESHES = [(2, "triangle"), (3, "tetrahedron"), (3, "hexahedron")]


def _demo_args(dim, cell):
    """The demo's options and its results subfolder for one mesh kind."""
    if cell == "hexahedron":
        return ("--dim", dim, "--cell", cell), f"{dim}d_{cell}"
    return ("--dim", dim), f"{dim}d"


@pytest.fixture(scope="module", params=DEMO_MESHES, ids=["2d", "3d", "3d-hex"])
def demo(request, tmp_path_factory):
    args, sub = _demo_args(*request.param)
    s, _ = run_demo("patch_test", *args, results=tmp_path_factory.mktemp("patch"),
                    subfolder=sub)
    assert s["cell"] == request.param[1]
    return s


def _runs(s):
    return {(r["matching"], r["pairing"]): r for r in s["runs"]}


def test_demo_inputs(demo):
    assert demo["materials"] == {"lower": STEEL, "upper": STEEL}
    assert demo["delta_m"] == DELTA_M and demo["mu"] == 0.0
    assert set(_runs(demo)) == {(m, p) for m in (True, False) for p in PAIRINGS}


@pytest.mark.parametrize("pairing", PAIRINGS)
def test_matching_meshes_exact_for_every_pairing(demo, pairing):
    p, width = _exact_pressure(demo["dim"])
    r = _runs(demo)[(True, pairing)]
    assert r["p_min"] == pytest.approx(p, rel=MATCHING_TOL, abs=0), r
    assert r["p_max"] == pytest.approx(p, rel=MATCHING_TOL, abs=0), r
    assert abs(r["N"] / (p * width) - 1) <= MATCHING_TOL, r
    assert r["u_error_rel"] <= MATCHING_TOL and r["open"] == 0, r
    if pairing == "auto":
        assert r["pairing_used"] == "node_to_node"


@pytest.mark.parametrize("pairing", ["surface_to_surface", "auto"])
def test_nonmatching_surface_to_surface_passes(demo, pairing):
    p, width = _exact_pressure(demo["dim"])
    r = _runs(demo)[(False, pairing)]
    assert r["pairing_used"] == "surface_to_surface"
    assert r["slave_nodes"] != r["master_nodes"]          # really non-matching
    for key in ("p_min", "p_max"):
        assert r[key] == pytest.approx(p, rel=MORTAR_TOL, abs=0), r
    assert abs(r["N"] / (p * width) - 1) <= MORTAR_TOL, r
    assert r["u_error_rel"] <= MORTAR_TOL and r["open"] == 0, r
    assert r["factorizations"] == 1


def test_nonmatching_node_to_node_refused_and_node_to_surface_fails(demo):
    p, _ = _exact_pressure(demo["dim"])
    runs = _runs(demo)
    assert "no matching" in runs[(False, "node_to_node")]["refused"] or \
        "matching interface nodes" in runs[(False, "node_to_node")]["refused"]
    r = runs[(False, "node_to_surface")]
    assert max(abs(r["p_min"] / p - 1), abs(r["p_max"] / p - 1)) > 1e-2, r


@pytest.mark.parametrize("case", ["stick", "frictionless"])
@pytest.mark.parametrize("dim, cell", DEMO_MESHES, ids=["2d", "3d", "3d-hex"])
def test_two_materials_nonmatching_surface_to_surface(dim, cell, case):
    # Friction that sticks, and free sliding (steel under aluminium, slip (c2 − c1)·x): the
    # mortar rows carry both exactly on non-matching meshes.
    r = patch_case.run(dim, case, MPI.COMM_WORLD, pairing="surface_to_surface",
                       matching=False, cell=cell)
    assert r["pressure_dev_rel"] <= MORTAR_TOL, r
    assert r["pressure_function_dev_rel"] <= MORTAR_TOL, r
    assert r["N_error_rel"] <= MORTAR_TOL and r["u_error_rel"] <= MORTAR_TOL, r
    assert r["slip_error_rel"] <= MORTAR_TOL and r["open"] == 0, r
    if case == "stick":
        assert r["stick"] == r["pairs"] and r["shear_rel_not_held"] <= MORTAR_TOL, r


@pytest.mark.mpi
def test_demo_two_ranks_equal_serial(demo, tmp_path):
    args, sub = _demo_args(demo["dim"], demo["cell"])
    par, _ = run_demo("patch_test", *args, results=tmp_path, ranks=2, subfolder=sub)
    assert par["ranks"] == 2
    ser = _runs(demo)
    for key, r in _runs(par).items():
        s = ser[key]
        if "refused" in s:
            assert "refused" in r
            continue
        assert np.array_equal(np.array(r["x"]), np.array(s["x"])), key
        ps, pp = np.array(s["p_slave"]), np.array(r["p_slave"])
        assert np.max(np.abs(pp - ps)) <= MPI_TOL * np.max(np.abs(ps)), key
        assert r["N"] == pytest.approx(s["N"], rel=MPI_TOL, abs=0), key


# ---- the patch test by pressure: the upper block held only by contact -----------------
# `--load pressure` presses the top with the exact p instead of moving it by δ; the upper
# block's vertical motion is then held by contact alone (floating=True). The exact field is
# the same, so are the bounds.

@pytest.fixture(scope="module", params=[2, 3], ids=["2d", "3d"])
def demo_pressure(request, tmp_path_factory):
    dim = request.param
    s, _ = run_demo("patch_test", "--dim", dim, "--load", "pressure",
                    results=tmp_path_factory.mktemp("patch_pressure"),
                    subfolder=f"{dim}d_pressure")
    return s


@pytest.mark.parametrize("pairing", PAIRINGS)
def test_pressure_load_matching_meshes_exact_for_every_pairing(demo_pressure, pairing):
    assert demo_pressure["load"] == "pressure"
    p, width = _exact_pressure(demo_pressure["dim"])
    r = _runs(demo_pressure)[(True, pairing)]
    assert r["p_min"] == pytest.approx(p, rel=MATCHING_TOL, abs=0), r
    assert r["p_max"] == pytest.approx(p, rel=MATCHING_TOL, abs=0), r
    assert abs(r["N"] / (p * width) - 1) <= MATCHING_TOL, r
    assert r["u_error_rel"] <= MATCHING_TOL and r["open"] == 0, r


def test_pressure_load_nonmatching_surface_to_surface_passes(demo_pressure):
    p, width = _exact_pressure(demo_pressure["dim"])
    r = _runs(demo_pressure)[(False, "surface_to_surface")]
    assert r["slave_nodes"] != r["master_nodes"]
    for key in ("p_min", "p_max"):
        assert r[key] == pytest.approx(p, rel=MORTAR_TOL, abs=0), r
    assert abs(r["N"] / (p * width) - 1) <= MORTAR_TOL, r
    assert r["u_error_rel"] <= MORTAR_TOL and r["open"] == 0, r
