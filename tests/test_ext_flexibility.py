"""Flexibility F* = (K^-1)_cc from one MUMPS factorization (dolfinx_ext/src/flexibility.cpp).

Checked against a dense inverse of K on small meshes, the Schur and selected-inverse
(MUMPS ICNTL(30)) paths against the multi-right-hand-side path, the returned factor against
a dense solve, singular stiffness and bad input as Python exceptions, and serial against
`mpirun -n 2` (where the default "schur" drives MUMPS directly: tests/test_mpi_schur.py).
Run as a script (under mpirun) it writes F* of every method to the file given.
"""
import sys
from pathlib import Path

import numpy as np

from conftest import on_two_ranks
import pytest
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
import dolfinx.mesh

try:
    import flexcontact._cpp as fc
except ImportError:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "dolfinx_ext" / "python"))
    import flexcontact._cpp as fc
from flexcontact import compat
from flexcontact.surface import surface_nodes

TOP, RIGHT = 3, 5


def elasticity(n, dim, clamped=True, E=1.0e3, nu=0.3):
    """Unit square/cube, P1 elasticity K (bottom clamped unless told), top/right facet tags."""
    comm = MPI.COMM_WORLD
    if dim == 2:
        msh = dolfinx.mesh.create_rectangle(comm, [np.zeros(2), np.ones(2)], [n, n],
                                            dolfinx.mesh.CellType.triangle)
    else:
        msh = dolfinx.mesh.create_box(comm, [np.zeros(3), np.ones(3)], [n, n, n],
                                      dolfinx.mesh.CellType.tetrahedron)
    V = compat.vector_space(msh)
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    a = dolfinx.fem.form(ufl.inner(2 * mu * eps(u) + lmbda * ufl.tr(eps(u)) * ufl.Identity(dim),
                                   eps(v)) * ufl.dx)
    fdim = dim - 1
    bcs = []
    if clamped:
        bottom = dolfinx.mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[1], 0.0))
        dofs = dolfinx.fem.locate_dofs_topological(V, fdim, bottom)
        bcs = [dolfinx.fem.dirichletbc(np.zeros(dim, dtype=PETSc.ScalarType), dofs, V)]
    K = dolfinx.fem.petsc.assemble_matrix(a, bcs=bcs)
    K.assemble()
    msh.topology.create_connectivity(fdim, dim)
    top = dolfinx.mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[1], 1.0))
    right = dolfinx.mesh.locate_entities_boundary(
        msh, fdim, lambda x: np.isclose(x[0], 1.0) & (x[1] < 1.0 - 1e-12))
    idx = np.concatenate([top, right]).astype(np.int32)
    val = np.concatenate([np.full(top.size, TOP), np.full(right.size, RIGHT)]).astype(np.int32)
    order = np.argsort(idx)
    tags = dolfinx.mesh.meshtags(msh, fdim, idx[order], val[order])
    return msh, V, K, tags


def dense(K):
    """K as a dense array on every rank."""
    comm = K.getComm().tompi4py()
    r0, r1 = K.getOwnershipRange()
    loc = np.zeros((r1 - r0, K.getSize()[1]))
    for i in range(r0, r1):
        cols, vals = K.getRow(i)
        loc[i - r0, cols] = vals
    return np.vstack(comm.allgather(loc))


def contact_dofs(V, tags, value=TOP):
    s = surface_nodes(V, tags, value)
    root = V.mesh.comm.rank == 0
    return s, (s["dofs"].reshape(-1).astype(np.int64) if root else np.zeros(0, np.int64))


def rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


METHODS = ["schur", "inverse_entries", "matmatsolve"]


@pytest.mark.parametrize("dim,n", [(2, 6), (3, 3)])
@pytest.mark.parametrize("method", METHODS)
def test_flexibility_equals_dense_inverse_block(dim, n, method):
    msh, V, K, tags = elasticity(n, dim)
    s, dofs = contact_dofs(V, tags)
    F, factor, info = fc.flexibility(K, dofs, method)
    Kd = dense(K)
    Fd = np.linalg.inv(Kd)[np.ix_(dofs, dofs)]
    assert F.shape == (dofs.size, dofs.size)
    assert rel(F, Fd) < 1e-10
    assert np.allclose(F, F.T, rtol=0, atol=1e-14 * np.abs(F).max())
    assert info["method"] == method
    assert info["n_contact_dofs"] == dofs.size == (n + 1) ** (dim - 1) * dim
    assert info["null_pivots"] == 0
    assert info["factorizations"] == 1
    for key in ("factorization_s", "schur_s", "inverse_s"):
        assert info[key] >= 0.0


def test_schur_matches_matmatsolve():
    msh, V, K, tags = elasticity(12, 2)
    _, dofs = contact_dofs(V, tags)
    Fs, _, _ = fc.flexibility(K, dofs, "schur")
    Fm, _, _ = fc.flexibility(K, dofs, "matmatsolve")
    assert rel(Fs, Fm) < 1e-10


@pytest.mark.parametrize("dim,n", [(2, 12), (3, 4)])
def test_inverse_entries_matches_matmatsolve(dim, n):
    msh, V, K, tags = elasticity(n, dim)
    _, dofs = contact_dofs(V, tags)
    Fi, _, info = fc.flexibility(K, dofs, "inverse_entries")
    Fm, _, _ = fc.flexibility(K, dofs, "matmatsolve")
    assert rel(Fi, Fm) < 1e-10
    assert info["method"] == "inverse_entries" and info["factorizations"] == 1


@pytest.mark.parametrize("method, seed, tol", [("schur", 1, 1e-12), ("inverse_entries", 2, 1e-10)])
def test_contact_dof_order_is_kept(method, seed, tol):
    msh, V, K, tags = elasticity(5, 2)
    _, dofs = contact_dofs(V, tags)
    perm = np.random.default_rng(seed).permutation(dofs.size)
    F, _, _ = fc.flexibility(K, dofs, "schur")
    Fp, _, _ = fc.flexibility(K, dofs[perm], method)
    assert rel(Fp, F[np.ix_(perm, perm)]) < tol


@pytest.mark.parametrize("method", METHODS)
def test_factor_solves_with_K(method):
    """The returned factor (the Schur-enabled one, or the one that computed inverse entries)
    still gives x = K^-1 b exactly, solve after solve."""
    msh, V, K, tags = elasticity(6, 2)
    _, dofs = contact_dofs(V, tags)
    _, factor, _ = fc.flexibility(K, dofs, method)
    Kd = dense(K)
    for seed in (0, 1):
        b = K.createVecLeft()
        b.setArray(np.random.default_rng(seed).standard_normal(b.getLocalSize()))
        x = K.createVecRight()
        factor.solve(b, x)
        x_ref = np.linalg.solve(Kd, b.getArray())
        assert rel(x.getArray(), x_ref) < 1e-10


@pytest.mark.parametrize("method", METHODS)
def test_singular_stiffness_raises(method):
    msh, V, K, tags = elasticity(4, 2, clamped=False)
    _, dofs = contact_dofs(V, tags)
    with pytest.raises(RuntimeError, match="stiffness matrix is singular"):
        fc.flexibility(K, dofs, method)
    assert issubclass(fc.SingularStiffnessError, RuntimeError)


def test_bad_arguments_raise_value_error():
    msh, V, K, tags = elasticity(3, 2)
    with pytest.raises(ValueError, match="unknown flexibility method"):
        fc.flexibility(K, np.array([0], np.int64), "lu")
    with pytest.raises(ValueError, match="out of range"):
        fc.flexibility(K, np.array([K.getSize()[0]], np.int64))
    with pytest.raises(ValueError, match="listed twice"):
        fc.flexibility(K, np.array([1, 1], np.int64))


def test_petsc_error_becomes_exception():
    A = PETSc.Mat().createAIJ([4, 4], comm=MPI.COMM_WORLD)
    A.setUp()  # never assembled
    with pytest.raises(RuntimeError, match="unassembled"):
        fc.flexibility(A, np.array([0], np.int64))


# ---- serial against two ranks -----------------------------------------------------------
def _write_flexibility(path):
    """Under mpirun: F* (both methods) and contact node coordinates on rank 0."""
    comm = MPI.COMM_WORLD
    out = {}
    for dim, n in [(2, 6), (3, 3)]:
        msh, V, K, tags = elasticity(n, dim)
        s, dofs = contact_dofs(V, tags)
        for method in METHODS:
            F, factor, info = fc.flexibility(K, dofs, method)
            out[f"{method}_{dim}"] = F
            # One sparse factorization always, on one rank or two.
            out[f"{method}_{dim}_factorizations"] = np.array(info["factorizations"])
            out[f"{method}_{dim}_used"] = np.array(info["method"])
            # the returned factor solves with K in parallel too
            b = K.createVecLeft()
            b.set(1.0)
            x, r = K.createVecRight(), K.createVecLeft()
            factor.solve(b, x)
            K.mult(x, r)
            r.axpy(-1.0, b)
            out[f"{method}_{dim}_residual"] = np.array(r.norm() / b.norm())
        out[f"x_{dim}"] = s["x"]
    if comm.rank == 0:
        np.savez(path, **out)


def test_two_ranks_match_serial(tmp_path):
    path = tmp_path / "flex2.npz"
    on_two_ranks(__file__, path)
    par = np.load(path)
    for dim, n in [(2, 6), (3, 3)]:
        msh, V, K, tags = elasticity(n, dim)
        s, dofs = contact_dofs(V, tags)
        # Nodes come sorted by coordinates, so the orders agree whatever the partition.
        assert np.array_equal(par[f"x_{dim}"], s["x"])
        for method in METHODS:
            F, _, _ = fc.flexibility(K, dofs, method)
            assert rel(par[f"{method}_{dim}"], F) < 1e-10
            assert float(par[f"{method}_{dim}_residual"]) < 1e-10
            assert int(par[f"{method}_{dim}_factorizations"]) == 1
        assert str(par[f"schur_{dim}_used"]) == "schur"
        assert rel(par[f"inverse_entries_{dim}"], par[f"matmatsolve_{dim}"]) < 1e-10


if __name__ == "__main__":
    _write_flexibility(sys.argv[1])
