"""The default chain on rigid-multibody problems (tests/rigid_multibody.py): walls of rigid
bricks, a few hundred contacts, W rank-deficient. Judged by the natural-map residual, by
Siconos' own error measure where Siconos is installed, and by momentum on a wall at rest."""
import numpy as np
import pytest

import crosscheck_problems as cp
import rigid_multibody as rm
from flexcontact import _cpp
from random_problems import _AsCase


@pytest.fixture(scope="module")
def walls():
    return rm.sample(seed=1, count=3)


def test_walls_are_rank_deficient(walls):
    for p in walls:
        assert 100 <= p.m <= 250
        assert np.linalg.matrix_rank(p.W) <= 0.4 * p.unknowns, p.name


def test_chain_solves_them(walls):
    for p in walls:
        r = _cpp.solve(p.dim, p.W, p.q, p.mu)
        assert r.converged, (p.name, r.attempts)
        assert _cpp.natural_map_residual(p.dim, p.W, p.q, p.mu, r.lambda_) <= 1e-10
        try:
            import siconos.numerics  # noqa: F401
        except ImportError:
            continue
        # Siconos' fc3d error on the dimensionless problem: the campaign's 1e-8 mark.
        assert cp.siconos_error(_AsCase(p), r.lambda_) <= 1e-8, p.name


def test_wall_at_rest_carries_its_weight():
    """Gravity only: every brick stays at rest (u = 0 on closed pairs), so the ground's
    normal impulses add up to the wall's weight times the step, to the solver's tolerance."""
    p = rm.make_wall(np.random.default_rng(2), 4, 6, at_rest=True)
    r = _cpp.solve(p.dim, p.W, p.q, p.mu)
    assert r.converged, r.attempts
    lam = np.asarray(r.lambda_).reshape(-1, 3)
    ground = lam[p.on_ground, 0].sum()
    assert ground == pytest.approx(p.weight_N * p.h_s, rel=1e-8)
    # No push, no friction needed: the tangential impulses carry nothing on balance.
    assert abs(lam[p.on_ground, 1].sum()) <= 1e-8 * ground
    u = np.asarray(r.u).reshape(-1, 3)
    assert np.abs(u).max() <= 1e-8 * np.abs(p.q).max()
