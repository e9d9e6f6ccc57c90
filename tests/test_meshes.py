"""Tests of flexcontact.meshes: tags, matching interface nodes, gaps, sizes, MPI."""
import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
import ufl
from mpi4py import MPI

from dolfinx import fem

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
try:
    import flexcontact.meshes as meshes
except ImportError:  # package not built/installed: use the source tree
    sys.path.insert(0, ROOT)
    import meshes

COMM = MPI.COMM_WORLD

# (builder, kwargs) -> serial (cells, nodes, contact nodes per surface). Cell and node counts
# depend on gmsh's unstructured mesher, so they are checked to ±10 %; contact node counts of
# the transfinite 2D interfaces are exact by construction.
CASES = {
    "hertz2d": (meshes.hertz2d.build, {}, (4368, 2318, 51)),
    "block_on_base": (meshes.block_on_base.build, {}, (1122, 632, 21)),
    "block_on_base_3d": (meshes.block_on_base.build_3d, {}, (4820, 1315, 144)),
    "hertz3d": (meshes.hertz3d.build, {}, (17228, 3905, 116)),
}


@pytest.fixture(scope="module", params=list(CASES))
def built(request):
    builder, kwargs, expected = CASES[request.param]
    return (request.param, *builder(COMM, **kwargs), expected)


def _pairs(xs, xm, k):
    """Index of the master node nearest (tangentially) to each slave node."""
    d = np.linalg.norm(xs[:, None, :k] - xm[None, :, :k], axis=2)
    return d.argmin(axis=1), d.min(axis=1)


def _expected_gap(name, xs, info):
    if name == "hertz2d":
        return meshes.hertz2d.gap(xs[:, 0], info["R"])
    if name == "hertz3d":
        return meshes.hertz3d.gap(xs[:, 0], xs[:, 1], info["R"])
    return np.full(len(xs), info["gap"])


def test_tags_exist(built):
    name, msh, ct, ft, info, _ = built
    cell_tags = set().union(*COMM.allgather(set(np.unique(ct.values).tolist())))
    facet_tags = set().union(*COMM.allgather(set(np.unique(ft.values).tolist())))
    assert cell_tags == {meshes.BASE, meshes.UPPER}
    want = {meshes.FIXED, meshes.LOADED, meshes.MASTER, meshes.SLAVE}
    if name == "hertz3d":
        want |= {meshes.SYMMETRY_X, meshes.SYMMETRY_Y}
    assert facet_tags == want
    tdim = msh.topology.dim
    n_cells = msh.topology.index_map(tdim).size_local
    assert COMM.allreduce(len(ct.indices[ct.indices < n_cells])) == \
        msh.topology.index_map(tdim).size_global  # every cell belongs to a body


def test_matching_interface_nodes_and_gap(built):
    name, msh, ct, ft, info, _ = built
    k = msh.topology.dim - 1  # tangential coordinates: x (2D), (x, y) (3D)
    xm = meshes.surface_coordinates(msh, ft, meshes.MASTER)
    xs = meshes.surface_coordinates(msh, ft, meshes.SLAVE)
    assert len(xm) == len(xs) > 0
    j, offset = _pairs(xs, xm, k)
    scale = info.get("R", 0.1)
    assert offset.max() <= 1e-12 * scale
    assert len(np.unique(j)) == len(j)  # one to one
    gap = xs[:, k] - xm[j, k]
    assert np.allclose(gap, _expected_gap(name, xs, info), rtol=0, atol=1e-12 * scale)
    assert np.allclose(xm[:, k], 0.0, atol=1e-15)  # flat master surface at 0


def test_serial_sizes(built):
    name, msh, ct, ft, info, (cells, nodes, contact) = built
    if COMM.size > 1:
        pytest.skip("serial counts")
    tdim = msh.topology.dim
    assert msh.topology.index_map(tdim).size_global == pytest.approx(cells, rel=0.1)
    assert msh.topology.index_map(0).size_global == pytest.approx(nodes, rel=0.1)
    n_contact = len(meshes.surface_coordinates(msh, ft, meshes.MASTER))
    assert n_contact == info["n_contact_nodes"]
    if tdim == 2:
        assert n_contact == contact
    else:
        assert n_contact == pytest.approx(contact, rel=0.1)
    assert msh.topology.index_map(0).size_global * tdim <= 20000  # default: small


def test_body_volumes(built):
    """Both bodies have their nominal area/volume: no inverted or missing cells."""
    name, msh, ct, ft, info, _ = built
    dx = ufl.Measure("dx", domain=msh, subdomain_data=ct)
    one = fem.Constant(msh, 1.0)
    vol = {t: COMM.allreduce(fem.assemble_scalar(fem.form(one * dx(t)))) for t in (1, 2)}
    if name == "hertz2d":
        R, W, D = info["R"], info["block_width"], info["block_depth"]
        assert vol[1] == pytest.approx(W * D, rel=1e-12)
        assert vol[2] == pytest.approx(math.pi * R ** 2 / 2, rel=1e-2)  # coarse far arc
    elif name == "block_on_base":
        assert vol[1] == pytest.approx(np.prod(info["base"]), rel=1e-12)
        assert vol[2] == pytest.approx(np.prod(info["block"]), rel=1e-12)
    elif name == "block_on_base_3d":
        assert vol[1] == pytest.approx(np.prod(info["base"]), rel=1e-12)
        assert vol[2] == pytest.approx(np.prod(info["block"]), rel=1e-12)
    else:
        R, Rc, H = info["R"], info["column_radius"], info["column_height"]
        assert vol[1] == pytest.approx(np.prod(info["block"]), rel=1e-12)
        # quarter of ∫_{r<Rc} (H − g(r)) dA, g the sphere; the polygonal rim loses a little
        cap = math.pi * (R * Rc ** 2 - (2 / 3) * (R ** 3 - (R ** 2 - Rc ** 2) ** 1.5))
        assert vol[2] == pytest.approx(0.25 * (math.pi * Rc ** 2 * H - cap), rel=1.5e-2)
    # positive cell orientation everywhere: ∫|det J| = ∫ det J
    detj = ufl.JacobianDeterminant(msh)
    signed = COMM.allreduce(fem.assemble_scalar(fem.form(detj / abs(detj) * ufl.dx)))
    assert signed == pytest.approx(vol[1] + vol[2], rel=1e-12)


def test_hertz3d_symmetry_planes_and_flat_top():
    msh, ct, ft, info = meshes.hertz3d.build(COMM)
    sx = meshes.surface_coordinates(msh, ft, meshes.SYMMETRY_X)
    sy = meshes.surface_coordinates(msh, ft, meshes.SYMMETRY_Y)
    top = meshes.surface_coordinates(msh, ft, meshes.LOADED)
    scale = info["R"]
    assert np.allclose(sx[:, 0], 0.0, atol=1e-12 * scale)
    assert np.allclose(sy[:, 1], 0.0, atol=1e-12 * scale)
    # both bodies touch each symmetry plane
    assert sx[:, 2].min() < 0 < sx[:, 2].max() and sy[:, 2].min() < 0 < sy[:, 2].max()
    assert np.allclose(top[:, 2], info["column_height"], atol=1e-12 * scale)


def test_refine_halves_sizes():
    m0, _, _, i0 = meshes.hertz2d.build(COMM)
    m1, _, ft1, i1 = meshes.hertz2d.build(COMM, refine=1)
    assert i1["h_contact"] == pytest.approx(i0["h_contact"] / 2)
    assert i1["n_contact_nodes"] == 2 * i0["n_contact_nodes"] - 1
    ratio = m1.topology.index_map(2).size_global / m0.topology.index_map(2).size_global
    assert 3.0 < ratio < 5.0


def test_fine_depth_thins_the_mesh_not_the_zone():
    # The fine layer's depth (w/4 by default, 3 h here: 12.5 h against 3 h on a zone of
    # 50 segments a side) changes the cells, not the zone's transfinite contact nodes.
    m0, _, _, i0 = meshes.hertz2d.build(COMM, zone_factor=5.0)
    m1, _, _, i1 = meshes.hertz2d.build(COMM, zone_factor=5.0, fine_depth=3 * i0["h_contact"])
    assert i1["n_contact_nodes"] == i0["n_contact_nodes"] == 101
    assert m1.topology.index_map(2).size_global < 0.5 * m0.topology.index_map(2).size_global


@pytest.mark.parametrize("builder, kwargs, word", [
    (meshes.hertz2d.build, dict(a_expected=0.06), "a_expected=0.06"),
    (meshes.hertz2d.build, dict(fine_depth=-1.0), "fine_depth=-1.0"),
    (meshes.hertz2d.build, dict(refine=-1), "refine=-1"),
    (meshes.hertz2d.build, dict(R=0.0), "R=0.0"),
    (meshes.hertz2d.build, dict(zone_factor=15.0), "zone half-width"),
    (meshes.hertz3d.build, dict(a_expected=0.05), "a_expected=0.05"),
    (meshes.hertz3d.build, dict(column_radius=0.01), "zone radius"),
    (meshes.hertz3d.build, dict(refine=1.5), "refine=1.5"),
    (meshes.block_on_base.build, dict(block=(0.5, 0.05)), "block width 0.5"),
    (meshes.block_on_base.build, dict(gap=-0.001), "gap=-0.001"),
    (meshes.block_on_base.build_3d, dict(h=0.0), "h=0.0"),
])
def test_invalid_parameters(builder, kwargs, word):
    with pytest.raises(ValueError) as err:
        builder(COMM, **kwargs)
    assert word in str(err.value)


def test_block_on_base_with_gap():
    msh, ct, ft, info = meshes.block_on_base.build_3d(COMM, gap=1e-3, h=0.02, h_far=0.05)
    xm = meshes.surface_coordinates(msh, ft, meshes.MASTER)
    xs = meshes.surface_coordinates(msh, ft, meshes.SLAVE)
    j, offset = _pairs(xs, xm, 2)
    assert len(xm) == len(xs) and offset.max() < 1e-14
    assert np.allclose(xs[:, 2] - xm[j, 2], 1e-3, atol=1e-15)


_MPI_SCRIPT = r"""
import json, sys
sys.path.insert(0, {root!r})
from mpi4py import MPI
import numpy as np
try:
    import flexcontact.meshes as meshes
except ImportError:
    import meshes
comm = MPI.COMM_WORLD
out = {{}}
for name, build in [("hertz2d", meshes.hertz2d.build),
                    ("block_on_base", meshes.block_on_base.build),
                    ("block_on_base_3d", meshes.block_on_base.build_3d),
                    ("hertz3d", meshes.hertz3d.build)]:
    msh, ct, ft, info = build(comm)
    tdim = msh.topology.dim
    k = tdim - 1
    xm = meshes.surface_coordinates(msh, ft, meshes.MASTER)
    xs = meshes.surface_coordinates(msh, ft, meshes.SLAVE)
    d = np.linalg.norm(xs[:, None, :k] - xm[None, :, :k], axis=2).min(axis=1)
    owned = msh.topology.index_map(tdim).size_local
    out[name] = dict(cells=msh.topology.index_map(tdim).size_global,
                     nodes=msh.topology.index_map(0).size_global,
                     master=len(xm), slave=len(xs), offset=float(d.max()),
                     distributed=comm.allreduce(int(owned > 0)))
if comm.rank == 0:
    print("RESULT" + json.dumps(out))
"""


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_builders_under_mpirun_2(tmp_path):
    if COMM.size > 1:
        pytest.skip("spawns its own MPI job")
    script = tmp_path / "mpi_meshes.py"
    script.write_text(_MPI_SCRIPT.format(root=ROOT))
    cmd = ["mpirun", "-n", "2", "--oversubscribe"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    run = subprocess.run(cmd + [sys.executable, str(script)], capture_output=True, text=True,
                         timeout=300, env=env)
    assert run.returncode == 0, run.stderr[-3000:]
    line = [ln for ln in run.stdout.splitlines() if ln.startswith("RESULT")][0]
    par = json.loads(line[len("RESULT"):])
    for name, (builder, kwargs, _) in CASES.items():
        msh, ct, ft, info = builder(COMM, **kwargs)
        tdim = msh.topology.dim
        assert par[name]["cells"] == msh.topology.index_map(tdim).size_global, name
        assert par[name]["nodes"] == msh.topology.index_map(0).size_global, name
        n = len(meshes.surface_coordinates(msh, ft, meshes.MASTER))
        assert par[name]["master"] == par[name]["slave"] == n, name
        assert par[name]["offset"] <= 1e-12 * info.get("R", 0.1), name
        assert par[name]["distributed"] == 2, name  # both ranks own cells
