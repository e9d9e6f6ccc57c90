"""ResultWriter's XDMF: one Grid per time step holding every field, in double precision.

The file is read back with plain Python (xml.etree and NumPy), and the values compared with
the formulas the fields were interpolated from, evaluated at the written coordinates.
"""
import json
import math
import shutil
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx.fem
import dolfinx.mesh

import flexcontact as fc
from conftest import mpirun, ROOT
from flexcontact import compat
from xdmf_case import TIMES, fields_2d, read, write_2d

REL = 1e-14


def close(a, b):
    scale = max(np.max(np.abs(b)), 1e-300)
    return np.max(np.abs(a - b)) <= REL * scale


def centroids(step):
    return step["x"][step["cells"]].mean(axis=1)


def test_one_grid_per_step_with_all_fields(tmp_path):
    steps = read(write_2d(tmp_path, MPI.COMM_WORLD))
    assert [s["t"] for s in steps] == list(TIMES)
    n_nodes, n_cells = 7 * 7, 2 * 6 * 6
    for s in steps:
        assert s["topology_type"] == "Triangle" and s["cells"].shape == (n_cells, 3)
        assert s["x"].shape == (n_nodes, 3) and s["x"].dtype == np.float64
        assert set(s["attributes"]) == {"cell_tag", "x2", "displacement", "cellx"}
        for name in ("x2", "displacement", "cellx"):
            assert s["attributes"][name][2] == "8", name
    # The mesh is written once: every step points at the same bytes.
    assert len({s["seeks"] for s in steps}) == 1


def test_values_equal_the_fields(tmp_path):
    for s in read(write_2d(tmp_path, MPI.COMM_WORLD)):
        x, y, t = s["x"][:, 0], s["x"][:, 1], s["t"]
        center, kind, _, v = s["attributes"]["x2"]
        assert (center, kind, v.shape) == ("Node", "Scalar", (len(x), 1))
        assert close(v[:, 0], t * x ** 2)
        center, kind, _, u = s["attributes"]["displacement"]
        assert (center, kind, u.shape) == ("Node", "Vector", (len(x), 3))
        assert close(u[:, 0], t * x ** 2) and close(u[:, 1], t * x * y)
        assert np.all(u[:, 2] == 0.0)  # 2D padded to 3 components for Warp By Vector
        c = centroids(s)
        center, kind, _, cx = s["attributes"]["cellx"]
        assert (center, cx.shape) == ("Cell", (len(c), 1))
        assert close(cx[:, 0], c[:, 0] + 2 * c[:, 1])
        center, _, _, tag = s["attributes"]["cell_tag"]
        assert center == "Cell"
        np.testing.assert_array_equal(tag[:, 0] if tag.ndim == 2 else tag,
                                      np.where(c[:, 0] < 0.5, 1, 2))
        # Every triangle counter-clockwise with area 1/72: the node numbers are right.
        p = s["x"][s["cells"]]
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        assert np.allclose(np.abs(area), 1 / 72, rtol=1e-12)


def _nearest(points, targets):
    """Index of the nearest of ``points`` to each target, checked to be within 1e-12."""
    d = np.linalg.norm(points[None, :, :] - targets[:, None, :], axis=2)
    i = d.argmin(axis=1)
    assert np.all(d[np.arange(len(targets)), i] < 1e-12)
    return i


def test_values_are_the_functions_own(tmp_path):
    """Each written value is the Function's value at the DOF sitting at that node / cell."""
    msh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 5, 5)
    fields = fields_2d(msh, 0.7)
    with fc.ResultWriter(tmp_path, "own", msh) as w:
        w.write(fields, 0.7)
    (s,) = read(tmp_path / "own.xdmf")
    for f in fields:
        V = f.function_space
        bs = V.dofmap.index_map_bs
        own = np.asarray(f.x.array).reshape(-1, bs)
        dof_x = V.tabulate_dof_coordinates()[:len(own)]
        center, _, _, v = s["attributes"][f.name]
        where = s["x"] if center == "Node" else centroids(s)
        np.testing.assert_array_equal(v[_nearest(where, dof_x), :bs], own)


def test_3d_vector_and_hexahedra(tmp_path):
    for cell, kind, n_vert, volume in (
            (dolfinx.mesh.CellType.tetrahedron, "Tetrahedron", 4, 1 / 6 / 27),
            (dolfinx.mesh.CellType.hexahedron, "Hexahedron", 8, 1 / 27)):
        msh = dolfinx.mesh.create_unit_cube(MPI.COMM_WORLD, 3, 3, 3, cell)
        u = dolfinx.fem.Function(compat.vector_space(msh), name="displacement")
        u.interpolate(lambda x: np.vstack([x[0] ** 2, x[1] * x[2], -x[2]]))
        with fc.ResultWriter(tmp_path, kind, msh) as w:
            w.write(u, 2.0)
        (s,) = read(tmp_path / f"{kind}.xdmf")
        assert s["topology_type"] == kind and s["cells"].shape[1] == n_vert
        x = s["x"]
        v = s["attributes"]["displacement"][3]
        assert close(v, np.column_stack([x[:, 0] ** 2, x[:, 1] * x[:, 2], -x[:, 2]]))
        p = x[s["cells"]]
        if kind == "Hexahedron":
            # XDMF order: bottom face counter-clockwise seen from above, then the top face.
            base = p[:, :4]
            edges = np.roll(base, -1, axis=1) - base
            assert np.allclose(np.linalg.norm(edges, axis=2), 1 / 3, rtol=1e-12)
            assert np.allclose(p[:, 4:] - p[:, :4], [0, 0, 1 / 3], atol=1e-14)
        else:
            vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                            p[:, 3] - p[:, 0]) / 6
            assert np.allclose(np.abs(vol), volume, rtol=1e-12)


def test_quadrilaterals_in_xdmf_order(tmp_path):
    msh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 4, 4,
                                          dolfinx.mesh.CellType.quadrilateral)
    with fc.ResultWriter(tmp_path, "q", msh) as w:
        w.write(fields_2d(msh, 1.0), 1.0)
    (s,) = read(tmp_path / "q.xdmf")
    p = s["x"][s["cells"]][:, :, :2]
    shoelace = 0.5 * np.sum(p[:, :, 0] * np.roll(p[:, :, 1], -1, axis=1)
                            - np.roll(p[:, :, 0], -1, axis=1) * p[:, :, 1], axis=1)
    # Vertices in turn round the cell: area ±1/16; DOLFINx's own order crosses itself (0).
    assert np.allclose(np.abs(shoelace), 1 / 16, rtol=1e-12)
    c = centroids(s)
    assert close(s["attributes"]["cellx"][3][:, 0], c[:, 0] + 2 * c[:, 1])


def test_file_readable_after_a_failure_mid_run(tmp_path):
    msh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    with pytest.raises(RuntimeError, match="increment 3 failed"):
        with fc.ResultWriter(tmp_path, "run", msh) as w:
            for i, t in enumerate(TIMES, start=1):
                if i == 3:
                    raise RuntimeError("increment 3 failed")
                w.write(fields_2d(msh, t), t)
    steps = read(tmp_path / "run.xdmf")
    assert [s["t"] for s in steps] == list(TIMES[:2])
    assert close(steps[1]["attributes"]["x2"][3][:, 0], TIMES[1] * steps[1]["x"][:, 0] ** 2)
    assert not list(tmp_path.glob("*.tmp"))


@pytest.mark.parametrize("bad, match", [
    (("Lagrange", 2), "'bad' is neither continuous degree 1"),
    (("DG", 1), "'bad' is neither continuous degree 1"),
])
def test_unsupported_field_is_named_and_keeps_steps(tmp_path, bad, match):
    msh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    f = dolfinx.fem.Function(compat.scalar_space(msh, *bad), name="bad")
    with fc.ResultWriter(tmp_path, "run", msh) as w:
        w.write(fields_2d(msh, 1.0), 1.0)
        with pytest.raises(ValueError, match=match):
            w.write(fields_2d(msh, 2.0) + [f], 2.0)
        w.write(fields_2d(msh, 3.0), 3.0)   # the writer goes on after a refused step
    assert [s["t"] for s in read(tmp_path / "run.xdmf")] == [1.0, 3.0]


def test_bad_input_named(tmp_path):
    msh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    other = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, msh.topology.dim)
    facets = dolfinx.mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[0], 0))
    ftags = dolfinx.mesh.meshtags(msh, fdim, facets, np.ones_like(facets))
    ftags.name = "walls"
    with pytest.raises(ValueError, match=r"tags 'walls' are of dimension 1"):
        fc.ResultWriter(tmp_path, "tags", msh, tags=(ftags,))
    with fc.ResultWriter(tmp_path, "run", msh) as w:
        with pytest.raises(ValueError, match=r"time t = nan"):
            w.write(fields_2d(msh, 1.0), math.nan)
        with pytest.raises(ValueError, match=r"'x2' lives on another mesh"):
            w.write(fields_2d(other, 1.0), 1.0)
        s = fields_2d(msh, 1.0)
        with pytest.raises(ValueError, match=r"two fields are named 'x2'"):
            w.write([s[0], s[0]], 1.0)
    assert read(tmp_path / "run.xdmf") == []
    ET.parse(tmp_path / "run.xdmf")


@pytest.mark.mpi
def test_two_ranks_write_the_serial_file(tmp_path):
    script = ROOT / "tests" / "xdmf_case.py"
    for n in (1, 2):
        mpirun(n, script, tmp_path / f"np{n}", cwd=ROOT / "tests")
    a, b = tmp_path / "np1", tmp_path / "np2"
    # Same XML, so the same arrays at the same offsets; the mesh and the tags to the bit.
    # The fields to 1e-14: DOLFINx interpolates at points it pushes forward from the
    # reference cell, whose rounding follows each rank's local vertex order (1 ulp seen).
    assert (a / "case.xdmf").read_text() == (b / "case.xdmf").read_text()
    for s1, s2 in zip(read(a / "case.xdmf"), read(b / "case.xdmf"), strict=True):
        np.testing.assert_array_equal(s1["x"], s2["x"])
        np.testing.assert_array_equal(s1["cells"], s2["cells"])
        for name, (_, _, _, v1) in s1["attributes"].items():
            v2 = s2["attributes"][name][3]
            if name == "cell_tag":
                np.testing.assert_array_equal(v1, v2)
            else:
                assert close(v2, v1), name


@pytest.mark.skipif(shutil.which("pvbatch") is None,
                    reason="ParaView's pvbatch not installed (Debian package paraview)")
def test_paraview_warps_and_colours_one_dataset(tmp_path):
    path = write_2d(tmp_path, MPI.COMM_WORLD)
    proc = subprocess.run(["pvbatch", str(ROOT / "tests" / "paraview_check.py"), str(path),
                           "displacement", "cellx"], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    seen = json.loads(proc.stdout.strip().splitlines()[-1])
    last = read(path)[-1]
    # One dataset (no multiblock to extract and merge), every field double precision.
    assert seen["class"] == "vtkUnstructuredGrid" and seen["times"] == list(TIMES)
    assert (seen["points"], seen["cells"]) == (len(last["x"]), len(last["cells"]))
    kinds = {name: (assoc, cls) for name, assoc, cls, _ in seen["arrays"]}
    for name, assoc in (("x2", "POINTS"), ("displacement", "POINTS"), ("cellx", "CELLS")):
        assert kinds[name][0] == assoc, (name, kinds[name])
        assert kinds[name][1] in ("vtkTypeFloat64Array", "vtkDoubleArray"), (name, kinds[name])
    assert seen["point_type"] in ("vtkTypeFloat64Array", "vtkDoubleArray")
    # Warp By Vector moved every node by its written displacement.
    moved = last["x"] + last["attributes"]["displacement"][3]
    bounds = np.column_stack([moved.min(axis=0), moved.max(axis=0)]).ravel()
    np.testing.assert_allclose(seen["warped_bounds"], bounds, rtol=0, atol=1e-14 * 2.5)
    cx = last["attributes"]["cellx"][3]
    np.testing.assert_allclose(seen["field_range"], [cx.min(), cx.max()], rtol=1e-15)
