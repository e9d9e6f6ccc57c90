"""The contact patch test (Taylor & Papadopoulos, docs/architecture.md §6) on matching meshes, 2D plane
strain and 3D: uniform pressure through a flat interface must come out uniform.

Two stacked bodies of one footprint (meshes/patch.py), unstructured meshes of different
sizes away from the interface, the interface matching node for node (non-uniform spacing, so
the tributary measures differ from node to node). Bottom on rollers, top pushed down by δ,
symmetry planes x = 0 (y = 0), sides free: the exact solution is uniaxial stress σ = −p in
each body (patch_case.py has the formulas). Cases:

* stick: μ = 0.3, two different materials with equal lateral strain — every pair closed and
  sticking, pressure p, no shear, N = p·A, displacements exact;
* frictionless: μ = 0, steel under aluminium — pressure p, no pair open, each pair's slip
  is the mismatch of the lateral displacements, (c2 − c1)·x.

Tolerances. Displacements are linear in each body, so P1 elements hold the exact field;
the consistent nodal force of a uniform pressure on P1 facets is p times the lumped
tributary measure the library divides by; node–node pairs on matching nodes add no error.
The active-set and Newton solvers are exact once their states settle. So every quantity is
exact up to round-off (measured ≤ 1e-14 relative, see below): the 1e-10 bounds (1e-9 for
the slip, a difference of two nearly equal displacements) leave room for round-off growing
with K's conditioning, not for any discretisation error. The default chain accepts an
answer at the natural-map residual SolverOptions.tolerance; its per-pair error is about
40× that tolerance here (measured: 2–4e-9 at the default 1e-10, 2–5e-12 at 1e-13), so that
test sets 1e-13.

Runtime: about 3 s (the MPI test ~1 s of it).
"""
import json

import numpy as np
import pytest
from mpi4py import MPI

import patch_case
from conftest import on_two_ranks
from flexcontact import compat
from flexcontact.meshes import patch, surface_coordinates as surface_nodes, tags

COMM = MPI.COMM_WORLD
ROUNDOFF = 1e-10       # relative; exact method, measured ≤ 1e-14 (see the module docstring)
SLIP_ROUNDOFF = 1e-9   # relative to the largest exact slip; measured ≤ 1e-14
MPI_ROUNDOFF = 1e-10   # serial vs 2 ranks (MUMPS's Schur complement on one rank or two)
EXACT_CHAINS = [("active_set",), ("newton_ac",)]

_cache = {}


def result(dim, case, increments=1, chain=("active_set",), tolerance=1e-10):
    key = (dim, case, increments, tuple(chain), tolerance)
    if key not in _cache:
        _cache[key] = patch_case.run(dim, case, COMM, increments=increments, chain=chain,
                                     tolerance=tolerance)
    return _cache[key]


# ---- the mesh --------------------------------------------------------------------------
@pytest.fixture(scope="module", params=[2, 3])
def mesh(request):
    dim = request.param
    return (dim, *patch.build(COMM, dim=dim, **patch_case.mesh_sizes(dim)))


def test_mesh_tags_sit_where_the_patch_test_needs_them(mesh):
    dim, msh, cells, facets, info = mesh
    w, H1, H2 = info["width"], info["lower_height"], info["upper_height"]
    v = dim - 1
    where = {tags.FIXED: (v, -H1), tags.LOADED: (v, H2), tags.MASTER: (v, 0.0),
             tags.SLAVE: (v, 0.0), tags.SYMMETRY_X: (0, 0.0)}
    if dim == 3:
        where[tags.SYMMETRY_Y] = (1, 0.0)
    present = set().union(*COMM.allgather(set(np.unique(facets.values).tolist())))
    assert present == set(where)
    for tag, (axis, value) in where.items():
        x = surface_nodes(msh, facets, tag)
        assert len(x) > 0 and np.allclose(x[:, axis], value, rtol=0, atol=1e-12 * w), tag
    cell_tags = set().union(*COMM.allgather(set(np.unique(cells.values).tolist())))
    assert cell_tags == {tags.BASE, tags.UPPER}
    # Symmetry planes cover both bodies.
    xs = surface_nodes(msh, facets, tags.SYMMETRY_X)
    assert xs[:, v].min() == pytest.approx(-H1) and xs[:, v].max() == pytest.approx(H2)


def test_mesh_interface_matches_node_for_node_and_is_unstructured(mesh):
    dim, msh, cells, facets, info = mesh
    xs = surface_nodes(msh, facets, tags.SLAVE)
    xm = surface_nodes(msh, facets, tags.MASTER)
    assert len(xs) == len(xm) == info["n_contact_nodes"]
    order = lambda x: x[np.lexsort(x.T[::-1])]  # noqa: E731
    assert np.array_equal(order(xs), order(xm))  # identical coordinates, bit for bit
    # Separate nodes: each interface position carries one node of each body.
    imap = msh.geometry.index_map()
    on_interface = np.abs(msh.geometry.x[:imap.size_local, dim - 1]) <= 1e-12 * info["width"]
    assert COMM.allreduce(int(on_interface.sum()), op=MPI.SUM) == 2 * len(xs)
    # Different element sizes away from the interface: larger cells in the upper body.
    area = info["area"]
    n_low = COMM.allreduce(int(np.sum(cells.values == tags.BASE)), op=MPI.SUM)
    n_up = COMM.allreduce(int(np.sum(cells.values == tags.UPPER)), op=MPI.SUM)
    mean_low = area * info["lower_height"] / n_low
    mean_up = area * info["upper_height"] / n_up
    assert mean_up / mean_low > 1.3, (mean_low, mean_up)


def test_mesh_rejects_bad_parameters():
    for kwargs, word in [({"dim": 4}, "dim=4"), ({"width": -0.1}, "width=-0.1"),
                         ({"lower_height": 0}, "lower_height=0"),
                         ({"h_upper": float("nan")}, "h_upper=nan"),
                         ({"refine": 1.5}, "refine=1.5"), ({"dim": True}, "dim=True"),
                         ({"matching": "no"}, "matching='no'"),
                         ({"dim": 2, "cell": "hexahedron"}, "cell='hexahedron'"),
                         ({"cell": "prism"}, "cell='prism'")]:
        with pytest.raises(ValueError, match=word):
            patch.build(COMM, **kwargs)


@pytest.mark.parametrize("matching", [True, False], ids=["matching", "nonmatching"])
def test_hexahedral_mesh(matching):
    # cell="hexahedron": hexahedra only; interfaces of (n + 1)² nodes, n = w / h_i, the upper
    # one (n_up + 1)² with n_up = round(1.5 n) when non-matching, graded the other way (no
    # interior node of one side on an interior grid line of the other).
    msh, cells, facets, info = patch.build(COMM, dim=3, cell="hexahedron", matching=matching,
                                           **patch_case.mesh_sizes(3))
    assert compat.cell_type_name(msh) == "hexahedron" and info["cell"] == "hexahedron"
    n = round(info["width"] / info["h_interface"])
    xs = surface_nodes(msh, facets, tags.SLAVE)
    xm = surface_nodes(msh, facets, tags.MASTER)
    assert len(xm) == (n + 1) ** 2
    order = lambda x: x[np.lexsort(x.T[::-1])]  # noqa: E731
    if matching:
        assert np.allclose(order(xs), order(xm), rtol=0, atol=1e-12 * info["width"])
        return
    assert len(xs) == (round(patch.NONMATCHING_RATIO * n) + 1) ** 2
    lines_s, lines_m = np.unique(xs[:, 0]), np.unique(xm[:, 0])
    shared = np.abs(lines_s[1:-1, None] - lines_m[None, 1:-1]) <= 1e-9 * info["width"]
    assert not shared.any()


# ---- (a) stick: different materials, equal lateral strain --------------------------------
@pytest.mark.parametrize("chain", EXACT_CHAINS, ids="-".join)
@pytest.mark.parametrize("increments", [1, 2])
@pytest.mark.parametrize("dim", [2, 3])
def test_stick_patch_is_exact(dim, increments, chain):
    r = result(dim, "stick", increments, chain)
    lower, upper, mu = patch_case.materials(dim, "stick")
    assert r["mu"] == mu > 0
    assert lower.E_Pa != upper.E_Pa and lower.nu != upper.nu  # really two materials
    assert r["area_ratio"] > 1.5, r  # tributary measures differ: uniform p is not trivial
    assert r["stick"] == r["pairs"] and r["slip"] == r["open"] == 0, r
    assert r["pressure_dev_rel"] <= ROUNDOFF, r
    assert r["pressure_function_dev_rel"] <= ROUNDOFF, r  # written-back Function, both sides
    assert r["pressure_function_nodes"] == 2 * r["pairs"]
    assert r["shear_rel"] <= ROUNDOFF, r
    assert r["tangential_force_rel"] <= ROUNDOFF, r
    assert abs(r["N"] / r["N_exact"] - 1) <= ROUNDOFF, r
    assert r["u_error_rel"] <= ROUNDOFF, r
    assert r["slip_error_rel"] <= SLIP_ROUNDOFF, r  # no slip: relative to max |u|
    assert r["max_penetration_rel"] <= ROUNDOFF, r


# ---- (b) frictionless: steel under aluminium, the interface slides ------------------------
@pytest.mark.parametrize("chain", EXACT_CHAINS, ids="-".join)
@pytest.mark.parametrize("increments", [1, 2])
@pytest.mark.parametrize("dim", [2, 3])
def test_frictionless_patch_is_exact(dim, increments, chain):
    r = result(dim, "frictionless", increments, chain)
    assert r["mu"] == 0
    assert r["open"] == 0, r
    # Every pair slips except where the exact slip (c2 − c1)·x vanishes: the pair at x = 0
    # in 2D, the one at x = y = 0 in 3D (its tangential DOFs are held on both sides).
    assert r["slip"] == r["pairs"] - 1 and r["stick"] == 1, r
    assert r["slip_exact_max_m"] > 0
    assert r["slip_error_rel"] <= SLIP_ROUNDOFF, r
    assert r["pressure_dev_rel"] <= ROUNDOFF, r
    assert r["pressure_function_dev_rel"] <= ROUNDOFF, r
    assert abs(r["N"] / r["N_exact"] - 1) <= ROUNDOFF, r
    assert r["shear_rel"] == 0.0  # μ = 0: λ_t is identically zero
    assert r["u_error_rel"] <= ROUNDOFF, r
    assert r["max_penetration_rel"] <= ROUNDOFF, r


# ---- the default solver chain ------------------------------------------------------------
@pytest.mark.parametrize("case", ["stick", "frictionless"])
@pytest.mark.parametrize("dim", [2, 3])
def test_default_chain_is_exact_to_its_tolerance(dim, case):
    # The default chain starts with projection sweeps, which stop at the natural-map
    # residual 1e-13 (per-pair error ~40× that); see the module docstring.
    r = result(dim, case, 1, (), 1e-13)
    assert r["open"] == 0 and r["residual"] <= 1e-13, r
    assert r["pressure_dev_rel"] <= ROUNDOFF, r
    assert abs(r["N"] / r["N_exact"] - 1) <= ROUNDOFF, r
    assert r["u_error_rel"] <= ROUNDOFF, r
    assert r["slip_error_rel"] <= SLIP_ROUNDOFF, r
    assert r["shear_rel_not_held"] <= ROUNDOFF, r


# A pair whose tangential DOFs are held on both sides (on x = 0 here) has a zero row in W:
# its λ_t is not determined by the contact laws, and projection sweeps left it on the cone
# (0.9 % of N reported as friction). The dispatcher reports the admissible value that moves
# nothing, zero, so the reported friction is what the interface transmits.
def test_default_chain_reports_no_shear_on_held_pairs():
    r = result(2, "stick", 1, (), 1e-13)
    assert r["held_shear_components"] == 1
    assert r["shear_rel"] <= ROUNDOFF, r
    assert r["tangential_force_rel"] <= ROUNDOFF, r


# ---- MPI ---------------------------------------------------------------------------------
@pytest.mark.mpi
def test_patch_two_ranks_equal_serial(tmp_path):
    out = tmp_path / "patch.json"
    on_two_ranks(patch_case.__file__, "2,3", "stick,frictionless", "--out", out, timeout=300)
    for par in json.loads(out.read_text()):
        ser = result(par["dim"], par["case"])
        label = f'{par["dim"]}D {par["case"]}'
        assert par["ranks"] == 2 and ser["ranks"] == COMM.size, label
        # The parallel run passes the patch test itself ...
        assert par["pressure_dev_rel"] <= ROUNDOFF, par
        assert par["pressure_function_dev_rel"] <= ROUNDOFF, par  # written back on 2 ranks
        assert par["pressure_function_nodes"] == 2 * par["pairs"], par
        assert par["u_error_rel"] <= ROUNDOFF, par
        # ... and agrees with the serial one, pair by pair (same mesh, sorted by position).
        assert np.array_equal(np.array(par["x"]), np.array(ser["x"])), label
        p_s, p_p = np.array(ser["pressure"]), np.array(par["pressure"])
        assert np.max(np.abs(p_p - p_s)) <= MPI_ROUNDOFF * np.max(np.abs(p_s)), label
        assert par["N"] == pytest.approx(ser["N"], rel=MPI_ROUNDOFF, abs=0), label
