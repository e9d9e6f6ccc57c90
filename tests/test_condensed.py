"""The condensed problem behind one binding call (``_cpp.CondensedContact``) against the
low-level kernel functions, and the report that a failed increment carries on every rank."""
import json
import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conftest import on_two_ranks  # noqa: E402

import flexcontact as fc  # noqa: E402
from flexcontact import _cpp  # noqa: E402


def _random_case(dim, m, seed):
    """m node–node pairs on 2m contact nodes with tilted normals and an SPD F*."""
    rng = np.random.default_rng(seed)
    n_c = 2 * m * dim
    A = rng.standard_normal((n_c, n_c))
    F = A @ A.T / n_c + 0.1 * np.eye(n_c)
    normals = np.tile(np.eye(dim)[-1], (m, 1)) + 0.3 * rng.standard_normal((m, dim))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    X = rng.standard_normal((2 * m, dim))
    X[m:] = X[:m] - 1e-3 * normals  # masters just below their slaves
    return F, X, normals, rng.uniform(0.1, 0.8, m), rng


@pytest.mark.parametrize("dim", [2, 3])
def test_one_call_equals_the_low_level_kernel(dim):
    m = 4
    F, X, normals, mu, rng = _random_case(dim, m, seed=dim)
    held = np.zeros(F.shape[0], bool)
    held[-dim:] = True  # the last master node is held by a Dirichlet condition
    pairs = _cpp.pairs_from_normals(np.arange(m), np.arange(m, 2 * m)[:, None],
                                    np.ones((m, 1)), normals)
    c = _cpp.CondensedContact(dim, F, X, pairs, mu, held)

    # The same algebra through the single-purpose bindings.
    for k, p in enumerate(pairs):
        assert np.allclose(p.frame, _cpp.frame_from_normal(normals[k]), rtol=0, atol=0)
    rows, cols, vals, shape = _cpp.gap_operator(dim, 2 * m, pairs)
    B = np.zeros(shape)
    np.add.at(B, (rows, cols), vals)
    assert np.array_equal(c.B.toarray(), B)
    assert np.allclose(c.x0, _cpp.initial_gap(pairs, X), rtol=0, atol=1e-15)
    Fh = F.copy()
    Fh[held, :] = 0.0
    Fh[:, held] = 0.0
    W = _cpp.delassus(pairs, 2 * m, dim, Fh)
    assert np.allclose(c.W, W, rtol=0, atol=1e-14 * np.abs(W).max())
    solver = _cpp.IncrementalSolver(dim, W, mu)
    solver.set_initial_gap(c.x0)

    frames = c.frames
    prev = c.x0.reshape(m, dim)
    for _ in range(3):
        up = 2e-3 * rng.standard_normal(F.shape[0])
        q = B @ up + c.x0
        assert np.allclose(c.local_q(q), solver.local_q(q), rtol=0, atol=1e-15)
        out = c.step(up)
        rep = solver.step(q)
        lam = np.asarray(rep.lambda_).reshape(m, dim)
        scale = np.abs(lam).max()
        assert np.allclose(out["lambda"], lam, rtol=0, atol=1e-9 * scale)
        gap = np.asarray(solver.gap()).reshape(m, dim)
        assert np.allclose(out["gap"], gap, rtol=0, atol=1e-12)
        assert np.allclose(out["slip"], gap[:, 1:] - prev[:, 1:], rtol=0, atol=1e-12)
        prev = gap
        assert np.array_equal(out["states"], np.asarray(rep.states))
        r_c = B.T @ lam.reshape(-1)
        r_c[held] = 0.0
        assert np.allclose(out["reaction"], r_c, rtol=0, atol=1e-9 * scale)
        t = np.einsum("kij,ki->kj", frames[:, 1:, :], lam[:, 1:])
        assert np.allclose(out["pair_tangential"], t, rtol=0, atol=1e-9 * scale)
        assert np.allclose(out["tangential_force"], t.sum(axis=0), rtol=0, atol=1e-9 * scale)
        assert out["normal_force"] == pytest.approx(lam[:, 0].sum(), rel=1e-9)
        assert out["max_penetration"] == max(0.0, -float(out["gap"][:, 0].min()))
        assert out["report"]["converged"] and out["report"]["solver"] == rep.solver


def test_new_flexibility_and_new_pairs():
    F, X, normals, mu, rng = _random_case(3, 3, seed=9)
    pairs = _cpp.pairs_from_normals(np.arange(3), np.arange(3, 6)[:, None],
                                    np.ones((3, 1)), normals)
    c = _cpp.CondensedContact(3, F, X, pairs, mu)
    W = c.W
    c.step(2e-3 * rng.standard_normal(F.shape[0]))
    q = c.last_q
    before = c.local_q(q)
    c.set_flexibility(2.0 * F)  # e.g. another time step: history kept
    assert np.allclose(c.W, 2.0 * W, rtol=0, atol=1e-14 * np.abs(W).max())
    assert np.array_equal(c.local_q(q), before)
    c.set_pairs(c.contact_pairs, 0.5 * mu)  # re-paired: slip measured from the current gap
    assert np.allclose(c.local_q(q), before, rtol=0, atol=1e-15)
    assert np.array_equal(c.mu, 0.5 * mu)


def test_bad_arguments_name_what_is_wrong():
    F, X, normals, mu, _ = _random_case(2, 2, seed=5)
    pairs = _cpp.pairs_from_normals(np.arange(2), np.arange(2, 4)[:, None],
                                    np.ones((2, 1)), normals)
    with pytest.raises(ValueError, match="F\\* is 7x7, expected 8x8"):
        _cpp.CondensedContact(2, F[:7, :7], X, pairs, mu)
    with pytest.raises(ValueError, match="mu has 1 entries but there are 2 pairs"):
        _cpp.CondensedContact(2, F, X, pairs, mu[:1])
    c = _cpp.CondensedContact(2, F, X, pairs, mu)
    with pytest.raises(ValueError, match="up_c has 3 entries"):
        c.step(np.zeros(3))


# ---- a failed increment's report, serial and on two ranks ---------------------------------
def _failed_increment_report():
    """Report of a ContactProblem increment that cannot converge, as seen by this rank."""
    import ufl
    from flexcontact import compat, forms
    from flexcontact.meshes import block_on_base, tags

    msh, cells, facets, geo = block_on_base.build(MPI.COMM_WORLD)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, (ux, uy) = fc.dirichlet(V, facets, tags.LOADED)
    opts = fc.SolverOptions(tolerance=1e-14, max_iterations=1, chain=["projection"])
    problem = fc.ContactProblem(a, None, fixed + top,
                                fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.3),
                                solver=opts)
    uy.value = -1e-6
    with pytest.raises(fc.ConvergenceError) as info:
        problem.solve(1, verbose=False)
    assert problem.increments == []
    return str(info.value), info.value.report


def _check_report(message, report):
    assert message.startswith("increment 1: ")
    assert report["converged"] is False
    assert report["solver"] == "projection"
    assert report["iterations"] == 50
    assert report["residual"] > 1e-14
    assert len(report["attempts"]) == 1 and report["attempts"][0].startswith("projection")


def test_failed_increment_carries_the_report():
    _check_report(*_failed_increment_report())


@pytest.mark.mpi
def test_failed_increment_carries_the_report_on_every_rank(tmp_path):
    on_two_ranks(__file__, tmp_path, timeout=300)
    for rank in range(2):
        _check_report(*json.loads((tmp_path / f"report{rank}.json").read_text()))


if __name__ == "__main__":
    message, report = _failed_increment_report()
    Path(sys.argv[1], f"report{MPI.COMM_WORLD.rank}.json").write_text(
        json.dumps([message, report]))
