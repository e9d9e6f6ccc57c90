"""Per-body condensation of F* (dolfinx_ext/src/contact_blocks.h).

Bodies share no DOFs, so K is block-diagonal by body and F* = (K⁻¹)_cc is too: flexibility()
finds the bodies of the contact DOFs from K's graph and inverts each body's block of the
Schur complement on its own, on one rank or several ("inverse_entries" asks MUMPS only for
the entries within bodies). Checked on stiffness matrices of 2 and 3 bodies (unit squares/cubes of different
sizes and moduli, assembled separately and joined into one matrix with their rows
interleaved across ranks): the per-body F* against the one-block F* (to 1e-12) and a dense
inverse of K (to 1e-10), exact zeros between bodies, the bodies found, and serial against
`mpirun -n 2`. Run as a script (under mpirun) it writes the F* of each case to the file given.
"""
import sys

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from conftest import on_two_ranks
from test_ext_flexibility import contact_dofs, dense, elasticity, fc, rel

# (dim, n, E) of each body: different sizes and moduli, so no two blocks are alike.
CASES = {
    "2d_two": [(2, 6, 1.0e3), (2, 5, 3.0e3)],
    "2d_three": [(2, 6, 1.0e3), (2, 4, 3.0e3), (2, 5, 2.0e3)],
    "3d_two": [(3, 3, 1.0e3), (3, 2, 2.5e3)],
}


def direct_sum(mats):
    """diag(K_1, ..., K_b) as one MPIAIJ matrix: each rank owns its rows of every body, in
    body order; returns the matrix and, per body, a map from its global rows to the sum's."""
    comm = MPI.COMM_WORLD
    ranges = [np.array(comm.allgather(K.getOwnershipRange())) for K in mats]
    sizes = np.array([r[:, 1] - r[:, 0] for r in ranges])  # body × rank
    rank_start = np.concatenate([[0], np.cumsum(sizes.sum(axis=0))])[:-1]
    body_start = rank_start[None, :] + np.cumsum(sizes, axis=0) - sizes  # body × rank

    def mapper(b):
        def to_sum(rows):
            rows = np.asarray(rows, dtype=np.int64)
            p = np.searchsorted(ranges[b][:, 1], rows, side="right")
            return body_start[b, p] + rows - ranges[b][p, 0]
        return to_sum

    maps = [mapper(b) for b in range(len(mats))]
    n_local, N = int(sizes[:, comm.rank].sum()), int(sizes.sum())
    rows = [(b, i) for b, K in enumerate(mats) for i in range(*K.getOwnershipRange())]
    nnz = np.array([mats[b].getRow(i)[0].size for b, i in rows], dtype=PETSc.IntType)
    A = PETSc.Mat().createAIJ(((n_local, N), (n_local, N)), nnz=(nnz, nnz), comm=comm)
    for b, i in rows:
        cols, vals = mats[b].getRow(i)
        A.setValues(maps[b]([i])[0], maps[b](cols).astype(PETSc.IntType), vals)
    A.assemble()
    return A, maps


def bodies(case, seed=0):
    """The joined stiffness of `case`, its contact DOFs (rank 0, the bodies' top and right
    DOFs in a random interleaved order) and each contact DOF's body (rank 0)."""
    parts = [elasticity(n, dim, E=E) for dim, n, E in CASES[case]]
    A, maps = direct_sum([K for _, _, K, _ in parts])
    dofs, body = [], []
    for b, (_, V, _, tags) in enumerate(parts):
        _, d = contact_dofs(V, tags)
        dofs.append(maps[b](d))
        body.append(np.full(d.size, b))
    dofs, body = np.concatenate(dofs), np.concatenate(body)
    perm = np.random.default_rng(seed).permutation(dofs.size)
    return A, dofs[perm].astype(np.int64), body[perm]


@pytest.mark.parametrize("case", list(CASES))
def test_per_body_equals_one_block(case):
    A, dofs, body = bodies(case)
    F, _, info = fc.flexibility(A, dofs, "schur")
    F1, _, info1 = fc.flexibility(A, dofs, "schur", per_body=False)
    n_bodies = len(CASES[case])
    assert info["n_blocks"] == n_bodies and info1["n_blocks"] == 1
    assert sorted(info["block_sizes"]) == sorted(np.bincount(body).tolist())
    assert rel(F, F1) < 1e-12
    Fd = np.linalg.inv(dense(A))[np.ix_(dofs, dofs)]
    assert rel(F, Fd) < 1e-10
    # exact zeros between bodies: K couples them nowhere
    other = body[:, None] != body[None, :]
    assert np.all(F[other] == 0.0)
    assert np.abs(Fd[other]).max() < 1e-12 * np.abs(Fd).max()


@pytest.mark.parametrize("method", ["inverse_entries", "matmatsolve"])
def test_per_body_other_methods(method):
    A, dofs, body = bodies("2d_three", seed=1)
    F, _, info = fc.flexibility(A, dofs, method)
    F1, _, _ = fc.flexibility(A, dofs, "schur", per_body=False)
    assert info["n_blocks"] == 3
    assert rel(F, F1) < 1e-10
    assert np.all(F[body[:, None] != body[None, :]] == 0.0)


def test_one_body_is_one_block():
    _, V, K, tags = elasticity(6, 2)
    _, dofs = contact_dofs(V, tags)
    F, _, info = fc.flexibility(K, dofs, "schur")
    F1, _, _ = fc.flexibility(K, dofs, "schur", per_body=False)
    assert info["n_blocks"] == 1 and info["block_sizes"] == [dofs.size]
    assert rel(F, F1) < 1e-12


def test_per_body_singular_body_raises():
    """A body with no Dirichlet condition beside a held one: K is singular, and the error
    says so (MUMPS's null pivots find it before the blocks are inverted)."""
    parts = [elasticity(4, 2), elasticity(3, 2, clamped=False)]
    A, maps = direct_sum([K for _, _, K, _ in parts])
    _, d = contact_dofs(parts[0][1], parts[0][3])
    with pytest.raises(RuntimeError, match="stiffness matrix is singular"):
        fc.flexibility(A, maps[0](d).astype(np.int64), "schur")


# ---- serial against two ranks -----------------------------------------------------------
def _write(path):
    out = {}
    for case in CASES:
        A, dofs, body = bodies(case)
        for per_body in (True, False):
            F, _, info = fc.flexibility(A, dofs, "schur", per_body=per_body)
            out[f"{case}_{per_body}"] = F
            out[f"{case}_{per_body}_blocks"] = np.array(info["n_blocks"])
            out[f"{case}_{per_body}_method"] = np.array(info["method"])
    if MPI.COMM_WORLD.rank == 0:
        np.savez(path, **out)


def test_two_ranks_match_serial(tmp_path):
    path = tmp_path / "perbody2.npz"
    on_two_ranks(__file__, path)
    par = np.load(path)
    for case in CASES:
        # The contact DOFs are the same nodes in the same order in either run (each body's
        # sorted by coordinates, then the same permutation), whatever the numbering of K.
        A, dofs, body = bodies(case)
        F, _, _ = fc.flexibility(A, dofs, "schur")
        assert int(par[f"{case}_True_blocks"]) == len(CASES[case])
        assert int(par[f"{case}_False_blocks"]) == 1
        assert str(par[f"{case}_True_method"]) == "schur"
        assert rel(par[f"{case}_True"], par[f"{case}_False"]) < 1e-12
        assert rel(par[f"{case}_True"], F) < 1e-10
        assert np.all(par[f"{case}_True"][body[:, None] != body[None, :]] == 0.0)


if __name__ == "__main__":
    _write(sys.argv[1])
