"""The mortar integrals of mortar.py on two non-matching meshes of one flat interface.

Exact identities of the dual basis with D and M integrated over the overlaps, for coinciding
flat surfaces (the master covers the slave): Σ_j D_jj = the covered measure; Σ_k M_jk = D_jj
(Σ_k N̂_k = 1); Σ_k M_jk x̂_k = D_jj x_j (∫ ψ_j x = Σ_i x_i ∫ ψ_j N_i, biorthogonality);
D_jj = ∫ N_j (the lumped tributary measure) where the slave is fully covered. They hold to
round-off only if the overlaps are found and integrated exactly, whatever the two meshes.
"""
import numpy as np
import pytest

from flexcontact.mortar import mortar_rows_2d, mortar_rows_3d
from flexcontact.projection import facet_measures

ROUNDOFF = 1e-12


def _sum_rows(D, rows, cols, vals, Xm):
    n = D.size
    row_sum = np.bincount(rows, weights=vals, minlength=n)
    first = np.zeros((n, Xm.shape[1]))
    np.add.at(first, rows, vals[:, None] * Xm[cols])
    return row_sum, first


def _lumped(X, facets):
    nv = facets.shape[1]
    out = np.zeros(X.shape[0])
    np.add.at(out, facets.reshape(-1), np.repeat(facet_measures(X, facets) / nv, nv))
    return out


def _line(xs):
    X = np.column_stack([xs, np.zeros_like(xs)])
    return X, np.column_stack([np.arange(xs.size - 1), np.arange(1, xs.size)])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_segments_2d(seed):
    rng = np.random.default_rng(seed)
    xs = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, 9)]))
    xm = np.sort(np.concatenate([[-0.1, 1.2], rng.uniform(-0.1, 1.2, 6)]))
    Xs, Fs = _line(xs)
    Xm, Fm = _line(xm)
    up = np.tile([0.0, 1.0], (Fm.shape[0], 1))     # master outward normal: +y
    down = np.tile([0.0, -1.0], (Fs.shape[0], 1))   # slave outward normal: −y
    D, rows, cols, vals = mortar_rows_2d(Xs, Fs, down, Xm, Fm, up, cutoff_m=1.0)
    row_sum, first = _sum_rows(D, rows, cols, vals, Xm)
    assert D.sum() == pytest.approx(1.0, rel=ROUNDOFF)
    assert np.allclose(D, _lumped(Xs, Fs), rtol=0, atol=ROUNDOFF)
    assert np.allclose(row_sum, D, rtol=0, atol=ROUNDOFF)
    assert np.allclose(first, D[:, None] * Xs, rtol=0, atol=ROUNDOFF)


def test_segments_2d_partly_covered_rows_sum_to_their_measure():
    # The master covers [0, 0.55] of a slave on [0, 1]: the rows of the partly covered
    # segment use the dual basis of its covered part, so their weights still sum to 1 and
    # reproduce the slave node's position.
    Xs, Fs = _line(np.linspace(0.0, 1.0, 5))
    Xm, Fm = _line(np.array([0.0, 0.3, 0.55]))
    D, rows, cols, vals = mortar_rows_2d(Xs, Fs, np.tile([0.0, -1.0], (4, 1)), Xm, Fm,
                                         np.tile([0.0, 1.0], (2, 1)), cutoff_m=1.0)
    row_sum, first = _sum_rows(D, rows, cols, vals, Xm)
    assert D.sum() == pytest.approx(0.55, rel=ROUNDOFF)
    # Node 3 (x = 0.75) is reached by 0.05 of its left segment: ∫ (x − 0.5)/0.25 = 0.005.
    assert D[3] == pytest.approx(0.05**2 / (2 * 0.25), rel=ROUNDOFF) and D[4] == 0.0
    assert np.allclose(row_sum, D, rtol=0, atol=ROUNDOFF)
    assert np.allclose(first, D[:, None] * Xs, rtol=0, atol=ROUNDOFF)


def test_segments_facing_away_or_far_are_not_paired():
    Xs, Fs = _line(np.linspace(0.0, 1.0, 3))
    Xm, Fm = _line(np.linspace(0.0, 1.0, 4))
    same_side = mortar_rows_2d(Xs, Fs, np.tile([0.0, 1.0], (2, 1)), Xm, Fm,
                               np.tile([0.0, 1.0], (3, 1)), cutoff_m=1.0)
    assert same_side[0].sum() == 0.0
    far = mortar_rows_2d(Xs, Fs, np.tile([0.0, -1.0], (2, 1)), Xm + [0.0, -2.0], Fm,
                         np.tile([0.0, 1.0], (3, 1)), cutoff_m=1.0)
    assert far[0].sum() == 0.0


def _square_triangulation(n, rng, jitter):
    """A triangulated unit square (z = 0): an n × n grid, interior nodes jittered, each cell
    split along a random diagonal."""
    g = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(g, g, indexing="ij")
    P = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    inner = (P[:, 0] > 0) & (P[:, 0] < 1) & (P[:, 1] > 0) & (P[:, 1] < 1)
    P[inner, :2] += rng.uniform(-jitter, jitter, (inner.sum(), 2)) / n
    idx = lambda i, j: i * (n + 1) + j  # noqa: E731
    tris = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i, j + 1), idx(i + 1, j + 1)
            tris += [[a, b, d], [a, d, c]] if rng.uniform() < 0.5 else [[a, b, c], [b, d, c]]
    return P, np.array(tris)


@pytest.mark.parametrize("seed", [0, 1])
def test_triangles_3d(seed):
    rng = np.random.default_rng(seed)
    Xs, Fs = _square_triangulation(5, rng, 0.3)
    Xm, Fm = _square_triangulation(3, rng, 0.3)
    down, up = np.tile([0.0, 0.0, -1.0], (Fs.shape[0], 1)), np.tile([0.0, 0.0, 1.0],
                                                                     (Fm.shape[0], 1))
    D, rows, cols, vals = mortar_rows_3d(Xs, Fs, down, Xm, Fm, up, cutoff_m=1.0)
    row_sum, first = _sum_rows(D, rows, cols, vals, Xm)
    assert D.sum() == pytest.approx(1.0, rel=ROUNDOFF)
    assert np.allclose(D, _lumped(Xs, Fs), rtol=0, atol=ROUNDOFF)
    assert np.allclose(row_sum, D, rtol=0, atol=ROUNDOFF)
    assert np.allclose(first, D[:, None] * Xs, rtol=0, atol=ROUNDOFF)


def test_other_facets_refused_by_name():
    X = np.zeros((5, 3))
    F = np.array([[0, 1, 2, 3, 4]])
    with pytest.raises(ValueError, match="slave facets have 5 vertices"):
        mortar_rows_3d(X, F, np.array([[0, 0, -1.0]]), X, F, np.array([[0, 0, 1.0]]), 1.0)
