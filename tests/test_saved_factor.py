"""A factor kept on disk (flexcontact.saved_factor, dolfinx_ext/src/saved_factor.cpp and
distributed_schur.cpp): saved by MUMPS in one process, restored in another, the same solves
(and, for a factor with a Schur complement, the same condensations and expansions); files
that are missing, truncated, altered or from another MUMPS are refused by name before MUMPS
reads them. Reference: scipy's sparse LU of the same matrix."""
import json
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from petsc4py import PETSc

from conftest import ROOT
from flexcontact import saved_factor
from flexcontact.errors import FlexcontactError, SavedFileError


def matrix(n=40, shift=-0.3):
    """A symmetric matrix (indefinite for the default shift): a shifted 2D Laplacian on an
    n × n grid with its first row and column replaced by a held DOF (a 1 on the diagonal),
    as a PETSc AIJ."""
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    A = (sp.kron(T, sp.eye(n)) + sp.kron(sp.eye(n), T) + shift * sp.eye(n * n)).tolil()
    A[0, :] = 0
    A[:, 0] = 0
    A[0, 0] = 1.0
    A = A.tocsr()
    A.sort_indices()
    M = PETSc.Mat().createAIJ(A.shape, csr=(A.indptr, A.indices, A.data), comm=PETSc.COMM_SELF)
    M.assemble()
    return A, M


def vec(values):
    v = PETSc.Vec().createSeq(len(values), comm=PETSc.COMM_SELF)
    v.array[:] = values
    return v


def solve(factor, b):
    x = vec(np.zeros(b.size))
    factor.solve(vec(b), x)
    return x.array.copy()


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    A, M = matrix()
    folder = tmp_path_factory.mktemp("factor")
    f = saved_factor.factor_matrix(M)
    entry = saved_factor.save_factor(f, folder, "dam_stage2")
    b = np.random.default_rng(4).standard_normal(A.shape[0])
    (folder / "manifest.json").write_text(json.dumps(entry))
    np.save(folder / "b.npy", b)
    return A, f, folder, entry, b


def test_solve_matches_a_sparse_lu(saved):
    A, f, _, _, b = saved
    x = solve(f, b)
    ref = spla.spsolve(A.tocsc(), b)
    assert np.abs(x - ref).max() <= 1e-11 * np.abs(ref).max()
    assert np.abs(A @ x - b).max() <= 1e-11 * np.abs(b).max()


def test_restored_in_another_process_gives_the_same_solve(saved):
    """The restored factor's solve equals the saving process's bitwise: the same factors,
    the same triangular solves."""
    _, f, folder, _, b = saved
    code = f"""
import json, numpy as np, sys
from pathlib import Path
from petsc4py import PETSc
from flexcontact import saved_factor
folder = Path({str(folder)!r})
entry = json.loads((folder / "manifest.json").read_text())
g = saved_factor.restore_factor(folder, entry)
b = np.load(folder / "b.npy")
x = PETSc.Vec().createSeq(b.size, comm=PETSc.COMM_SELF)
bb = x.duplicate(); bb.array[:] = b
g.solve(bb, x)
np.save(folder / "x_restored.npy", x.array)
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stderr
    x = np.load(folder / "x_restored.npy")
    assert np.array_equal(x, solve(f, b))


def test_bad_files_are_named_before_mumps_reads_them(saved, tmp_path):
    _, _, folder, entry, _ = saved
    name = sorted(entry["files"])[0]
    original = (folder / name).read_bytes()

    def copy_with(data: bytes):
        d = tmp_path / f"case{len(list(tmp_path.iterdir()))}"
        d.mkdir()
        for other in entry["files"]:
            (d / other).write_bytes((folder / other).read_bytes())
        if data is None:
            (d / name).unlink()
        else:
            (d / name).write_bytes(data)
        return d

    cases = [(None, "missing"), (original[: len(original) // 2], "truncated"),
             (original[:-1] + bytes([original[-1] ^ 1]), "altered")]
    for data, words in cases:
        d = copy_with(data)
        with pytest.raises(SavedFileError, match=words) as e:
            saved_factor.restore_factor(d, entry)
        assert name in str(e.value)
        assert isinstance(e.value, FlexcontactError)
    for key, value, words in [("mumps_version", "4.10.0", "MUMPS 4.10.0"),
                              ("format", 99, "format 99")]:
        with pytest.raises(SavedFileError, match=words):
            saved_factor.restore_factor(folder, {**entry, key: value})
    # Nothing was written over the saved files.
    assert (folder / name).read_bytes() == original


def test_a_size_that_does_not_match_is_named(saved):
    _, _, folder, entry, _ = saved
    with pytest.raises(Exception, match="rows"):
        saved_factor._cpp.SavedFactor.restore(str(folder), entry["name"], entry["rows"] + 1)
    f = saved_factor.restore_factor(folder, entry)
    with pytest.raises(ValueError, match="entries"):
        f.solve(vec(np.zeros(3)), vec(np.zeros(3)))


# ---- a factor with a Schur complement (the dam's Ŵ in a model file) ------------------------

SCHUR_DOFS = np.arange(40 * 20, 40 * 20 + 40)  # a grid line across the middle, in its order


@pytest.fixture(scope="module")
def saved_schur(tmp_path_factory):
    A, M = matrix(shift=0.05)  # definite: F* is the Schur complement's Cholesky inverse
    folder = tmp_path_factory.mktemp("schur")
    F, f, _ = saved_factor._cpp.flexibility(M, SCHUR_DOFS, "schur", "auto", False, False)
    F = np.asarray(F)
    entry = saved_factor.save_factor(f, folder, "dam_stage2")
    b = np.random.default_rng(5).standard_normal(A.shape[0])
    u_c = np.random.default_rng(6).standard_normal(SCHUR_DOFS.size)
    (folder / "manifest.json").write_text(json.dumps(entry))
    np.save(folder / "b.npy", b)
    np.save(folder / "u_c.npy", u_c)
    np.save(folder / "F.npy", F)
    return A, f, F, folder, entry, b, u_c


def split_solves(f, b, u_c):
    """The condensation of b, the expansion of u_c after it, and a full solve of b."""
    bc = f.condense(vec(b)).copy()
    x = vec(np.zeros(b.size))
    f.expand(u_c, x)
    return bc, x.array.copy(), solve(f, b)


def test_a_schur_factor_restored_in_another_process_condenses_and_expands_alike(saved_schur):
    """Saved with its Schur complement ("kind": "schur"), restored in a new process from
    MUMPS's files: condense, expand and solve equal the saving process's bitwise, and agree
    with scipy: b̃_c = b_c − A_ci A_ii⁻¹ b_i, x_i = A_ii⁻¹(b_i − A_ic u_c), x = A⁻¹ b
    (1e-11)."""
    A, f, F, folder, entry, b, u_c = saved_schur
    assert entry["kind"] == "schur" and entry["schur_rows"] == SCHUR_DOFS.size
    code = f"""
import json, numpy as np
from pathlib import Path
from petsc4py import PETSc
from flexcontact import saved_factor
folder = Path({str(folder)!r})
entry = json.loads((folder / "manifest.json").read_text())
b, u_c = np.load(folder / "b.npy"), np.load(folder / "u_c.npy")
g = saved_factor.restore_factor(folder, entry, {SCHUR_DOFS.tolist()!r}, np.load(folder / "F.npy"))
assert g.has_condense and g.n_schur == u_c.size and g.size == b.size
def v(a):
    x = PETSc.Vec().createSeq(a.size, comm=PETSc.COMM_SELF); x.array[:] = a; return x
bc = g.condense(v(b)).copy()
x = v(np.zeros(b.size)); g.expand(u_c, x)
y = v(np.zeros(b.size)); g.solve(v(b), y)
np.savez(folder / "restored.npz", bc=bc, x=x.array, y=y.array)
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stderr
    got = np.load(folder / "restored.npz")
    bc, x, y = split_solves(f, b, u_c)
    assert np.array_equal(got["bc"], bc)
    assert np.array_equal(got["x"], x)
    assert np.array_equal(got["y"], y)
    c = SCHUR_DOFS
    i = np.setdiff1d(np.arange(A.shape[0]), c)
    Aii = A[i][:, i].tocsc()
    ref_bc = b[c] - A[c][:, i] @ spla.spsolve(Aii, b[i])
    assert np.abs(bc - ref_bc).max() <= 1e-11 * np.abs(ref_bc).max()
    ref_xi = spla.spsolve(Aii, b[i] - A[i][:, c] @ u_c)
    assert np.abs(x[i] - ref_xi).max() <= 1e-11 * np.abs(ref_xi).max()
    assert np.array_equal(x[c], u_c)
    ref = spla.spsolve(A.tocsc(), b)
    assert np.abs(y - ref).max() <= 1e-11 * np.abs(ref).max()


def test_a_schur_factor_needs_its_rows_and_is_refused_when_they_differ(saved_schur):
    _, _, F, folder, entry, _, _ = saved_schur
    with pytest.raises(SavedFileError, match="Schur complement; its rows and flexibility"):
        saved_factor.restore_factor(folder, entry)
    with pytest.raises(SavedFileError, match="saved with 40 Schur rows, 39 are given"):
        saved_factor.restore_factor(folder, entry, SCHUR_DOFS[:-1], F[:-1, :-1])
    cpp = saved_factor._cpp.DistributedSchur
    with pytest.raises(ValueError, match="1600 rows with a Schur complement on 40 of them, "
                                         "not 1601 rows and 40"):
        cpp.restore(str(folder), entry["name"], entry["rows"] + 1, SCHUR_DOFS, F)
    with pytest.raises(ValueError, match="F\\* is 39 x 39 for 40 Schur rows"):
        cpp.restore(str(folder), entry["name"], entry["rows"], SCHUR_DOFS, F[:-1, :-1])
    with pytest.raises(ValueError, match="Schur row 1600 is outside the 1600 rows"):
        cpp.restore(str(folder), entry["name"], entry["rows"], SCHUR_DOFS + 800, F)
    # A plain factor's files hold no Schur complement: named, not a crash.
    A, M = matrix(shift=0.05)
    plain = tmp = folder / "plain"
    tmp.mkdir(exist_ok=True)
    e = saved_factor.save_factor(saved_factor.factor_matrix(M), plain, "k")
    with pytest.raises(ValueError, match="a Schur complement on 0 of them"):
        cpp.restore(str(plain), e["name"], e["rows"], SCHUR_DOFS, F)


# ---- several right-hand sides at once (scenarios stepped side by side) ----------------------

def columns(n, k, seed):
    return np.asfortranarray(np.random.default_rng(seed).standard_normal((n, k)))


def test_several_right_hand_sides_in_one_call_equal_the_single_solves(saved):
    """solve_many reads the factor once for k columns; each column is the single solve's and
    scipy's to 1e-11 and leaves a residual below 1e-11 of B's. (MUMPS takes its blocked
    kernels for several columns: the sums are ordered differently, so not bitwise, and on
    this indefinite matrix the two differ by 1.2e-13 of the solution: round-off times its
    condition.)"""
    A, f, _, _, _ = saved
    B = columns(A.shape[0], 3, 7)
    X = f.solve_many(B)
    assert X.shape == B.shape
    assert np.abs(A @ X - B).max() <= 1e-11 * np.abs(B).max()
    for j in range(B.shape[1]):
        one = solve(f, B[:, j])
        assert np.abs(X[:, j] - one).max() <= 1e-11 * np.abs(one).max()
        ref = spla.spsolve(A.tocsc(), B[:, j])
        assert np.abs(X[:, j] - ref).max() <= 1e-11 * np.abs(ref).max()
    assert np.array_equal(f.solve_many(B[:, :1]).ravel(), solve(f, B[:, 0]))
    with pytest.raises(ValueError, match="B has 3 rows and 2 columns; the factor has 1600 rows"):
        f.solve_many(np.zeros((3, 2)))


def test_a_schur_factor_condenses_and_expands_several_right_hand_sides_at_once(saved_schur):
    """condense_many / expand_many: each column equals the single condense / expand to
    round-off and scipy's b̃_c = b_c − A_ci A_ii⁻¹ b_i and x_i = A_ii⁻¹(b_i − A_ic u_c) to
    1e-11; the Schur rows of x are U_c's columns exactly."""
    A, f, _, _, _, _, _ = saved_schur
    c = SCHUR_DOFS
    i = np.setdiff1d(np.arange(A.shape[0]), c)
    Aii = A[i][:, i].tocsc()
    B, U = columns(A.shape[0], 4, 8), columns(c.size, 4, 9)
    Bc = f.condense_many(B)
    X = f.expand_many(U)
    assert Bc.shape == (c.size, 4) and X.shape == B.shape
    for j in range(4):
        bc, x, _ = split_solves(f, B[:, j], U[:, j])
        assert np.abs(Bc[:, j] - bc).max() <= 1e-13 * np.abs(bc).max()
        assert np.abs(X[:, j] - x).max() <= 1e-13 * np.abs(x).max()
        ref_bc = B[c, j] - A[c][:, i] @ spla.spsolve(Aii, B[i, j])
        assert np.abs(Bc[:, j] - ref_bc).max() <= 1e-11 * np.abs(ref_bc).max()
        ref_xi = spla.spsolve(Aii, B[i, j] - A[i][:, c] @ U[:, j])
        assert np.abs(X[i, j] - ref_xi).max() <= 1e-11 * np.abs(ref_xi).max()
        assert np.array_equal(X[c, j], U[:, j])


def test_several_right_hand_sides_are_expanded_as_they_were_condensed(saved_schur):
    """One expansion per condensation, of the same kind and count: misuse is named, and
    the factor still serves single solves afterwards."""
    A, f, _, _, _, b, u_c = saved_schur
    n, n_c = A.shape[0], SCHUR_DOFS.size
    with pytest.raises(RuntimeError, match="expand_many: no condense_many"):
        f.expand_many(np.zeros((n_c, 2)))
    f.condense_many(columns(n, 2, 10))
    with pytest.raises(RuntimeError, match="the last condensation was condense_many"):
        f.expand(u_c, vec(np.zeros(n)))
    with pytest.raises(ValueError, match="U_c is 40 × 3; the last condense_many needs 40 × 2"):
        f.expand_many(np.zeros((n_c, 3)))
    f.expand_many(np.zeros((n_c, 2)))
    with pytest.raises(RuntimeError, match="expand_many: no condense_many"):
        f.expand_many(np.zeros((n_c, 2)))
    f.condense(vec(b))
    with pytest.raises(RuntimeError, match="expand_many: no condense_many"):
        f.expand_many(np.zeros((n_c, 1)))
    f.expand(u_c, vec(np.zeros(n)))
    with pytest.raises(ValueError, match="B has 5 rows and 1 columns; K has 1600 rows"):
        f.condense_many(np.zeros((5, 1)))
    ref = spla.spsolve(A.tocsc(), b)
    assert np.abs(solve(f, b) - ref).max() <= 1e-11 * np.abs(ref).max()
