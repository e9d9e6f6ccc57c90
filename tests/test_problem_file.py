"""The local-problem file (docs/solvers.md, "A failing problem as a file"): what solve() was
given comes back bit for bit, and re-running it gives the same report."""
from pathlib import Path

import numpy as np
import pytest

import flexcontact as fc
from flexcontact import _cpp
from random_problems import make_problem

DATA = Path(__file__).resolve().parent / "data"


def _write(path, p, **kw):
    _cpp.write_local_problem(str(path), p.dim, p.W, p.q, p.mu, **kw)


@pytest.mark.parametrize("symmetric", [True, False])
def test_round_trip_is_bitwise(tmp_path, symmetric):
    rng = np.random.default_rng(3)
    p = make_problem(rng, "ill_conditioned", 3, 20, 0)
    W = p.W if symmetric else p.W + 1e-3 * np.triu(p.W, 1)  # a last-bit asymmetry is kept too
    n, m = p.q.size, p.mu.size
    start = rng.standard_normal(n)
    states = rng.integers(1, 4, m).astype(np.int32)
    cap = rng.uniform(1.0, 2.0, m)
    opts = fc.SolverOptions(tolerance=1.2345678901234567e-9, max_iterations=37,
                            chain=["newton_ac", "projection"], work_budget_gflop=0.125)
    path = tmp_path / "p.lp"
    _cpp.write_local_problem(str(path), 3, W, p.q, p.mu, lambda_start=start,
                             states_start=states, options=opts, cap=cap, source="a test\nof two lines")
    back = fc.load_problem(path)
    assert back.dim == 3 and back.pairs == m and back.source == "a test of two lines"
    for a, b in [(back.W, W), (back.q, p.q), (back.mu, p.mu), (back.lambda_start, start),
                 (back.cap, cap), (back.states_start, states)]:
        np.testing.assert_array_equal(a, b)
    assert back.options.tolerance == opts.tolerance
    assert back.options.max_iterations == 37
    assert list(back.options.chain) == ["newton_ac", "projection"]
    assert back.options.work_budget_gflop == 0.125
    # Re-running it is solve() on the same input: the same report, bitwise.
    direct = _cpp.solve(3, W, p.q, p.mu, lambda0=start, states0=states, options=opts, cap=cap)
    again = back.solve()
    np.testing.assert_array_equal(again.lambda_, direct.lambda_)
    assert again.residual == direct.residual and list(again.attempts) == list(direct.attempts)


def test_no_caps_no_start(tmp_path):
    p = make_problem(np.random.default_rng(4), "spd", 2, 7, 0)
    _write(tmp_path / "p.lp", p)
    back = fc.load_problem(tmp_path / "p.lp")
    assert back.cap is None and back.states_start.size == 0
    np.testing.assert_array_equal(back.lambda_start, np.zeros(p.q.size))
    r = back.solve()
    assert r.converged and r.residual <= 1e-10  # the default options came back
    np.testing.assert_array_equal(r.lambda_, _cpp.solve(2, p.W, p.q, p.mu).lambda_)


def test_recorded_problems_of_format_2_are_read():
    """The recorded demo increments (tests/data/README.md): the previous increment's λ and
    states are the start, and the chain answers as the demo did."""
    back = fc.load_problem(DATA / "hertz2d.lp")
    assert back.dim == 2 and back.pairs == 51 and back.states_start.size == 51
    np.testing.assert_array_equal(back.W, back.W.T)
    r = back.solve()
    assert r.converged and r.residual <= back.options.tolerance


def test_bad_files_are_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="no file at"):
        fc.load_problem(tmp_path / "missing.lp")
    p = make_problem(np.random.default_rng(4), "spd", 2, 7, 0)
    _write(tmp_path / "p.lp", p)
    data = (tmp_path / "p.lp").read_bytes()
    (tmp_path / "short.lp").write_bytes(data[:-8])
    with pytest.raises(ValueError, match=r"short\.lp: the binary part is not exactly \d+ float64"):
        fc.load_problem(tmp_path / "short.lp")
    (tmp_path / "other.lp").write_bytes(b"something else\n")
    with pytest.raises(ValueError, match=r"other\.lp: first line 'something else'"):
        fc.load_problem(tmp_path / "other.lp")
    with pytest.raises(ValueError, match=r"q has 14 entries, expected dim·m = 21"):
        _cpp.write_local_problem(str(tmp_path / "x.lp"), 3, p.W, p.q, p.mu)
