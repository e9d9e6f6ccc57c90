"""Contact surface nodes and write-back (flexcontact.surface, flexcontact.writeback).

Normals of the unit square's / cube's faces, tributary lengths and areas, DOF numbering
against the space's own DOF coordinates, the missing-tag error, write-back round trips, and
serial against `mpirun -n 2`. Run as a script (under mpirun) it writes its results to the
file given.
"""
import sys
from pathlib import Path

import numpy as np

from conftest import on_two_ranks
import pytest
from mpi4py import MPI

import dolfinx
import dolfinx.fem
import dolfinx.mesh

try:
    import flexcontact
except ImportError:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "dolfinx_ext" / "python"))
    import flexcontact
from types import SimpleNamespace
from flexcontact import compat
from flexcontact.surface import surface_nodes
from flexcontact.writeback import set_nodal_values

fc = SimpleNamespace(surface_nodes=surface_nodes, set_nodal_values=set_nodal_values)

TOP, RIGHT = 3, 5


def tagged_box(n, dim):
    """Unit square (triangles) / cube (tetrahedra): top y=1 tagged TOP, right x=1 (below the
    top) RIGHT; vector P1 space."""
    comm = MPI.COMM_WORLD
    if dim == 2:
        msh = dolfinx.mesh.create_rectangle(comm, [np.zeros(2), np.ones(2)], [n, n],
                                            dolfinx.mesh.CellType.triangle)
    else:
        msh = dolfinx.mesh.create_box(comm, [np.zeros(3), np.ones(3)], [n, n, n],
                                      dolfinx.mesh.CellType.tetrahedron)
    fdim = dim - 1
    msh.topology.create_connectivity(fdim, dim)
    top = dolfinx.mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[1], 1.0))
    right = dolfinx.mesh.locate_entities_boundary(
        msh, fdim, lambda x: np.isclose(x[0], 1.0) & (x[1] < 1.0 - 1e-12))
    idx = np.concatenate([top, right]).astype(np.int32)
    val = np.concatenate([np.full(top.size, TOP), np.full(right.size, RIGHT)]).astype(np.int32)
    order = np.argsort(idx)
    tags = dolfinx.mesh.meshtags(msh, fdim, idx[order], val[order])
    V = compat.vector_space(msh)
    return msh, V, tags


def owned_dof_coordinates(V):
    """Global block index -> coordinates, gathered on every rank."""
    im = V.dofmap.index_map
    nl = im.size_local
    g = im.local_to_global(np.arange(nl, dtype=np.int32))
    x = V.tabulate_dof_coordinates()[:nl]
    comm = V.mesh.comm
    return np.concatenate(comm.allgather(g)), np.vstack(comm.allgather(x))


@pytest.mark.parametrize("dim,n", [(2, 8), (3, 4)])
def test_top_face_normals_and_areas(dim, n):
    msh, V, tags = tagged_box(n, dim)
    s = fc.surface_nodes(V, tags, TOP)
    if msh.comm.rank != 0:
        assert s["x"].shape == (0, dim) and s["area"].shape == (0,)
        return
    nn = (n + 1) ** (dim - 1)
    assert s["x"].shape == (nn, dim)
    assert s["dofs"].shape == (nn, dim) and s["dofs"].dtype == np.int64
    assert s["normal"].shape == (nn, dim)
    assert np.allclose(s["x"][:, 1], 1.0)
    # flat face: every normal is the outward +y
    assert np.allclose(s["normal"], np.eye(dim)[1], atol=1e-14)
    # tributary lengths/areas add up to the face's measure
    assert s["area"].sum() == pytest.approx(1.0, rel=1e-13)
    if dim == 2:
        h = 1.0 / n
        expected = np.full(nn, h)
        expected[[0, -1]] = h / 2
        assert np.allclose(s["area"], expected, rtol=1e-13)
    # sorted lexicographically by coordinates
    keys = [tuple(x) for x in s["x"]]
    assert keys == sorted(keys)
    # components of a node are consecutive DOFs
    assert np.all(np.diff(s["dofs"], axis=1) == 1)


@pytest.mark.parametrize("dim,n", [(2, 6), (3, 3)])
def test_dofs_match_coordinates(dim, n):
    msh, V, tags = tagged_box(n, dim)
    s = fc.surface_nodes(V, tags, RIGHT)
    g, x = owned_dof_coordinates(V)
    if msh.comm.rank == 0:
        bs = V.dofmap.index_map_bs
        lut = dict(zip(g.tolist(), x[:, :dim]))
        for dofs, xs in zip(s["dofs"], s["x"]):
            assert np.allclose(lut[int(dofs[0]) // bs], xs, atol=1e-14)
        assert np.allclose(s["normal"], np.eye(dim)[0], atol=1e-14)
        # the right face without its top row of cells
        assert s["area"].sum() == pytest.approx(1.0 - 1.0 / n, rel=1e-13)


def test_missing_tag_names_present_values():
    msh, V, tags = tagged_box(3, 2)
    with pytest.raises(ValueError, match=r"value 42 .*\[3, 5\]"):
        fc.surface_nodes(V, tags, 42)


def test_wrong_objects_are_named():
    msh, V, tags = tagged_box(3, 2)
    with pytest.raises(TypeError, match="FunctionSpace"):
        fc.surface_nodes(msh, tags, TOP)
    cells = dolfinx.mesh.meshtags(msh, 2, np.arange(2, dtype=np.int32),
                                  np.ones(2, dtype=np.int32))
    with pytest.raises(ValueError, match="facet tags"):
        fc.surface_nodes(V, cells, 1)


def _writeback_errors(msh, V, tags):
    """Write 10x, 100y into the top nodes of a vector Function and x into a scalar one;
    return the max errors on this rank (owned and ghost entries), and untouched entries."""
    s = fc.surface_nodes(V, tags, RIGHT)
    root = msh.comm.rank == 0
    dim = msh.topology.dim
    scale = np.array([10.0, 100.0, 1000.0][:dim])
    u = dolfinx.fem.Function(V)
    u.x.array[:] = -7.0
    fc.set_nodal_values(u, s["dofs"] if root else np.zeros((0, dim), np.int64),
                        s["x"] * scale if root else np.zeros((0, dim)))
    xd = V.tabulate_dof_coordinates()[:, :dim]
    on = np.isclose(xd[:, 0], 1.0) & (xd[:, 1] < 1.0 - 1e-12)
    arr = u.x.array.reshape(-1, dim)
    err_v = np.abs(arr[on] - xd[on] * scale).max(initial=0.0)
    untouched = np.abs(arr[~on] + 7.0).max(initial=0.0)

    Q = compat.scalar_space(msh, "Lagrange", 1)
    p = dolfinx.fem.Function(Q)
    blocks = s["dofs"][:, 0] // dim if root else np.zeros(0, np.int64)
    fc.set_nodal_values(p, blocks, s["x"][:, 1] if root else np.zeros(0))
    xq = Q.tabulate_dof_coordinates()
    onq = np.isclose(xq[:, 0], 1.0) & (xq[:, 1] < 1.0 - 1e-12)
    err_s = np.abs(p.x.array[onq] - xq[onq, 1]).max(initial=0.0)
    untouched = max(untouched, np.abs(p.x.array[~onq]).max(initial=0.0))
    return err_v, err_s, untouched, int(on.sum())


@pytest.mark.parametrize("dim,n", [(2, 6), (3, 3)])
def test_writeback_round_trip(dim, n):
    msh, V, tags = tagged_box(n, dim)
    err_v, err_s, untouched, _ = _writeback_errors(msh, V, tags)
    assert err_v < 1e-12 and err_s < 1e-14 and untouched == 0.0
    with pytest.raises(ValueError, match="out of range"):
        fc.set_nodal_values(dolfinx.fem.Function(V), np.array([10**9], np.int64),
                            np.array([1.0]))
    with pytest.raises(ValueError, match="values"):
        fc.set_nodal_values(dolfinx.fem.Function(V), np.array([0, 1], np.int64),
                            np.array([1.0]))


# ---- serial against two ranks -----------------------------------------------------------
def _write_surface(path):
    comm = MPI.COMM_WORLD
    out = {}
    for dim, n in [(2, 6), (3, 3)]:
        msh, V, tags = tagged_box(n, dim)
        for value in (TOP, RIGHT):
            s = fc.surface_nodes(V, tags, value)
            for k in ("x", "normal", "area"):
                out[f"{k}_{dim}_{value}"] = s[k]
        err = comm.allreduce(max(_writeback_errors(msh, V, tags)[:3]), op=MPI.MAX)
        out[f"writeback_{dim}"] = np.array(err)
    if comm.rank == 0:
        np.savez(path, **out)


def test_two_ranks_match_serial(tmp_path):
    path = tmp_path / "surface2.npz"
    on_two_ranks(__file__, path)
    par = np.load(path)
    for dim, n in [(2, 6), (3, 3)]:
        msh, V, tags = tagged_box(n, dim)
        for value in (TOP, RIGHT):
            s = fc.surface_nodes(V, tags, value)
            for k in ("x", "normal", "area"):
                assert np.allclose(par[f"{k}_{dim}_{value}"], s[k], rtol=1e-13, atol=1e-15)
        assert float(par[f"writeback_{dim}"]) < 1e-12


if __name__ == "__main__":
    _write_surface(sys.argv[1])
