"""A factor kept on disk (flexcontact.saved_factor, dolfinx_ext/src/saved_factor.cpp):
saved by MUMPS in one process, restored in another, the same solves; files that are
missing, truncated, altered or from another MUMPS are refused by name before MUMPS reads
them. Reference: scipy's sparse LU of the same matrix."""
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


def matrix(n=40):
    """A symmetric indefinite matrix: a shifted 2D Laplacian on an n × n grid with its first
    row and column replaced by a held DOF (a 1 on the diagonal), as a PETSc AIJ."""
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    A = (sp.kron(T, sp.eye(n)) + sp.kron(sp.eye(n), T) - 0.3 * sp.eye(n * n)).tolil()
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
