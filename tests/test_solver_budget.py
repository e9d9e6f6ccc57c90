"""The chain's budget is work, not time: the same problem gives the bitwise same λ on a quiet
machine and beside CPU hogs (docs/solvers.md, "The work budget").

A wall-clock budget stopped the same problem after 76 Newton steps in one run and 89 in
another. Here a budget of half the work the chain needs cuts it mid-way, where a clock would
cut it at a different iterate as soon as the machine is busier.
"""
import multiprocessing as mp
import os
import time

import numpy as np
import pytest

from flexcontact import _cpp
from random_problems import make_problem


def _hog(stop):
    x = 0.0
    while not stop.is_set():
        for i in range(100_000):
            x += i * 1e-9


@pytest.fixture(scope="module")
def hard():
    """An ill-conditioned 3D problem (150 pairs, condition 1e10) on which the default chain
    needs several attempts, and the work it takes to solve it."""
    p = make_problem(np.random.default_rng(5), "ill_conditioned", 3, 150, 0)
    full = _cpp.solve(p.dim, p.W, p.q, p.mu)
    assert full.converged and len(full.attempts) >= 2, full.attempts
    return p, full


def _solve(p, budget):
    return _cpp.solve(p.dim, p.W, p.q, p.mu,
                      options=_cpp.SolverOptions(work_budget_gflop=budget))


def test_half_the_work_stops_short_and_says_so(hard):
    p, full = hard
    r = _solve(p, 0.5 * full.work_gflop)
    assert not r.converged
    assert 0.5 * full.work_gflop <= r.work_gflop < full.work_gflop
    assert r.residual > full.residual
    assert any("work budget" in a for a in r.attempts), r.attempts


def test_same_answer_beside_cpu_hogs(hard):
    p, full = hard
    budget = 0.5 * full.work_gflop
    quiet = _solve(p, budget)
    stop = mp.Event()
    hogs = [mp.Process(target=_hog, args=(stop,), daemon=True)
            for _ in range(2 * (os.cpu_count() or 1))]
    for h in hogs:
        h.start()
    try:
        time.sleep(0.2)  # let the hogs take the cores
        loaded = _solve(p, budget)
        assert all(h.is_alive() for h in hogs)  # the solve ran beside them to its end
    finally:
        stop.set()
        for h in hogs:
            h.join(timeout=10)
    assert loaded.attempts == quiet.attempts
    assert loaded.work_gflop == quiet.work_gflop
    np.testing.assert_array_equal(loaded.lambda_, quiet.lambda_)
    # Unlimited: still the same converged answer, bitwise, as on the quiet machine.
    np.testing.assert_array_equal(_solve(p, 0.0).lambda_, full.lambda_)
