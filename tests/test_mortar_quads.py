"""Mortar rows on quadrilateral facets (mortar_3d.py): clipping and integration against
hand-computed overlaps, and the exact identities of the dual basis on parallelogram meshes.

References. (1) A unit-square slave quadrilateral half covered by a master rectangle: the
overlap is the rectangle [0.5, 1] × [0.25, 1], where every N_a N_b and N_a N̂_c is a product
of one-dimensional polynomials, integrated here exactly with numpy.polynomial (no clipping,
no triangle rule); the dual basis A = D_e M_e⁻¹ follows from those. The same couple mapped by
an affine map of the plane, set in a tilted plane of 3D space, has the same shape functions,
so D and M scale by the map's area ratio. (2) A square and the same square turned by 45°:
the overlap is a regular octagon of area 2√2 − 2, shared equally by the four corners
(symmetry). (3) Parallelogram meshes (affine images of graded tensor grids) of one region,
non-matching, and mixed triangle/quadrilateral meshes: Σ_j D_jj = the area, D_jj = ∫ N_j
(a quarter of each parallelogram's area), Σ_k M_jk = D_jj and Σ_k M_jk x̂_k = D_jj x_j —
these hold to round-off only if the overlaps are clipped exactly; on flat quadrilaterals
that are not parallelograms too (they hold at the rule's points). Round-off bound: 1e-12
(measured about 1e-15).
"""
import numpy as np
import pytest
from numpy.polynomial import Polynomial as Poly

from flexcontact.mortar import mortar_rows_3d
from flexcontact.mortar_3d import bilinear_inverse, clip_polygon, full_measures

ROUNDOFF = 1e-12
UP, DOWN = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])


def _dense(D, rows, cols, vals, n_master):
    M = np.zeros((D.size, n_master))
    np.add.at(M, (rows, cols), vals)
    return M


def _hats(lo, hi):
    """The two 1D linear shape functions of the interval [lo, hi]."""
    h = hi - lo
    return [Poly([hi / h, -1.0 / h]), Poly([-lo / h, 1.0 / h])]


def _tensor_reference():
    """Exact D (4,) and M (4, 4) of the unit-square slave and the master rectangle
    [0.5, 1.5] × [0.25, 1.25], overlap [0.5, 1] × [0.25, 1] (tensor corner order)."""
    fx, fy = _hats(0.0, 1.0), _hats(0.0, 1.0)
    gx, gy = _hats(0.5, 1.5), _hats(0.25, 1.25)

    def integral(p, lo, hi):
        q = p.integ()
        return q(hi) - q(lo)
    idx = [(0, 0), (1, 0), (0, 1), (1, 1)]          # tensor order: (x index, y index)
    Me = np.array([[integral(fx[a] * fx[b], 0.5, 1.0) * integral(fy[c] * fy[d], 0.25, 1.0)
                    for b, d in idx] for a, c in idx])
    P = np.array([[integral(fx[a] * gx[b], 0.5, 1.0) * integral(fy[c] * gy[d], 0.25, 1.0)
                   for b, d in idx] for a, c in idx])
    De = Me.sum(axis=1)
    return De, (De[:, None] * np.linalg.inv(Me)) @ P


SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])   # tensor order
QUAD = np.array([[0, 1, 2, 3]])


def test_clip_square_against_turned_square_is_an_octagon():
    c = np.array([0.5, 0.5])
    r = np.array([[np.cos(np.pi / 4), -np.sin(np.pi / 4)], [np.sin(np.pi / 4),
                                                            np.cos(np.pi / 4)]])
    turned = (SQUARE[[0, 1, 3, 2]] - c) @ r.T + c
    poly = clip_polygon(turned, SQUARE[[0, 1, 3, 2]])
    area = 0.5 * abs(np.sum(poly[:, 0] * np.roll(poly[:, 1], -1)
                            - poly[:, 1] * np.roll(poly[:, 0], -1)))
    assert len(poly) == 8
    assert area == pytest.approx(2 * np.sqrt(2) - 2, rel=ROUNDOFF)


def test_bilinear_inverse_of_a_trapezoid():
    Q = np.array([[0.0, 0.0], [2.0, 0.0], [0.5, 1.0], [1.5, 1.0]])
    st = np.array([[0.3, 0.7], [0.9, 0.1], [0.5, 0.5]])
    s, t = st.T
    N = np.column_stack([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t])
    assert np.allclose(bilinear_inverse(N @ Q, Q), st, rtol=0, atol=ROUNDOFF)


def test_half_covered_square_against_exact_tensor_integrals():
    De, M_ref = _tensor_reference()
    # The overlap [0.5, 1] × [0.25, 1]: D = ∫ N_j there, e.g. D_3 = ∫ x dx ∫ y dy.
    assert De.sum() == pytest.approx(0.5 * 0.75, rel=1e-15)
    assert De[3] == pytest.approx(0.375 * 0.46875, rel=1e-15)
    Xs = np.column_stack([SQUARE, np.zeros(4)])
    Xm = np.column_stack([SQUARE + [0.5, 0.25], np.zeros(4)])
    D, rows, cols, vals = mortar_rows_3d(Xs, QUAD, DOWN[None], Xm, QUAD, UP[None], 1.0)
    M = _dense(D, rows, cols, vals, 4)
    assert np.allclose(D, De, rtol=0, atol=ROUNDOFF)
    assert np.allclose(M, M_ref, rtol=0, atol=ROUNDOFF)
    # Partly covered rows still sum to 1 once divided by D_jj, and reproduce x_j.
    assert np.allclose(M.sum(axis=1), D, rtol=0, atol=ROUNDOFF)
    assert np.allclose(M @ Xm, D[:, None] * Xs, rtol=0, atol=ROUNDOFF)


def test_affine_image_in_a_tilted_plane_scales_the_integrals():
    De, M_ref = _tensor_reference()
    F = np.array([[1.3, 0.4], [-0.2, 0.7]])            # a shear and a stretch of the plane
    axes = np.linalg.qr(np.array([[1.0, 0.2, 0.3], [0.1, 1.0, -0.4], [0.5, 0.3, 1.0]]))[0]
    e1, e2, n = axes.T
    origin = np.array([0.3, -0.2, 0.8])

    def place(P2, height):
        Q = P2 @ F.T
        return origin + Q[:, :1] * e1 + Q[:, 1:] * e2 + height * n
    gap = 1e-3
    Xs, Xm = place(SQUARE, 0.0), place(SQUARE + [0.5, 0.25], gap)
    D, rows, cols, vals = mortar_rows_3d(Xs, QUAD, -n[None], Xm, QUAD, n[None], 1.0)
    M = _dense(D, rows, cols, vals, 4)
    J = abs(np.linalg.det(F))
    assert np.allclose(D, J * De, rtol=0, atol=ROUNDOFF)
    assert np.allclose(M, J * M_ref, rtol=0, atol=ROUNDOFF)
    # The weak gap of each row is the uniform gap: Σ_k M_jk x̂_k − D_jj x_j = D_jj gap n.
    assert np.allclose(M @ Xm - D[:, None] * Xs, gap * D[:, None] * n, rtol=0, atol=ROUNDOFF)


def test_square_against_turned_square():
    c = np.array([0.5, 0.5])
    r = np.array([[np.cos(np.pi / 4), -np.sin(np.pi / 4)], [np.sin(np.pi / 4),
                                                            np.cos(np.pi / 4)]])
    Xs = np.column_stack([SQUARE, np.zeros(4)])
    Xm = np.column_stack([(SQUARE - c) @ r.T + c, np.zeros(4)])
    D, rows, cols, vals = mortar_rows_3d(Xs, QUAD, DOWN[None], Xm, QUAD, UP[None], 1.0)
    M = _dense(D, rows, cols, vals, 4)
    octagon = 2 * np.sqrt(2) - 2
    assert np.allclose(D, octagon / 4, rtol=0, atol=ROUNDOFF)
    assert np.allclose(M.sum(axis=1), D, rtol=0, atol=ROUNDOFF)
    assert np.allclose(M @ Xm, D[:, None] * Xs, rtol=0, atol=ROUNDOFF)


def _grid(xs, ys, F, split=None):
    """Nodes (affine image by F of the tensor grid xs × ys, z = 0) and its facets:
    quadrilaterals in tensor order, or each cell split into two triangles (split='tri')."""
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    P = np.column_stack([X.ravel(), Y.ravel()]) @ F.T
    P = np.column_stack([P, np.zeros(P.shape[0])])
    idx = lambda i, j: i * ys.size + j  # noqa: E731
    cells = []
    for i in range(xs.size - 1):
        for j in range(ys.size - 1):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i, j + 1), idx(i + 1, j + 1)
            cells += [[a, b, d], [a, d, c]] if split == "tri" else [[a, b, c, d]]
    return P, np.array(cells)


def _graded(n, rng):
    return np.concatenate([[0.0], np.sort(rng.uniform(0, 1, n - 1)), [1.0]])


@pytest.mark.parametrize("kinds", [("quad", "quad"), ("tri", "quad"), ("quad", "tri")],
                         ids=["quad-quad", "tri-quad", "quad-tri"])
@pytest.mark.parametrize("seed", [0, 1])
def test_parallelogram_meshes_identities(kinds, seed):
    rng = np.random.default_rng(seed)
    F = np.array([[1.0, 0.35], [0.1, 0.8]])
    Xs, Fs = _grid(_graded(6, rng), _graded(5, rng), F, kinds[0])
    Xm, Fm = _grid(_graded(4, rng), _graded(3, rng), F, kinds[1])
    D, rows, cols, vals = mortar_rows_3d(Xs, Fs, np.tile(DOWN, (len(Fs), 1)), Xm, Fm,
                                         np.tile(UP, (len(Fm), 1)), 1.0)
    M = _dense(D, rows, cols, vals, Xm.shape[0])
    area = abs(np.linalg.det(F))
    lumped = np.zeros(Xs.shape[0])
    np.add.at(lumped, Fs.reshape(-1),
              full_measures(Xs, Fs, np.tile(DOWN, (len(Fs), 1))).reshape(-1))
    assert D.sum() == pytest.approx(area, rel=ROUNDOFF)
    assert lumped.sum() == pytest.approx(area, rel=ROUNDOFF)
    assert np.allclose(D, lumped, rtol=0, atol=ROUNDOFF)
    assert np.allclose(M.sum(axis=1), D, rtol=0, atol=ROUNDOFF)
    assert np.allclose(M @ Xm, D[:, None] * Xs, rtol=0, atol=ROUNDOFF)


def test_full_measures_of_a_trapezoid():
    # ∫ N_j over the trapezoid (0,0), (2,0), (0.5,1), (1.5,1): |J| = 2 − t on the unit
    # square, so ∫ N_0 = ∫(1−s) ds ∫(1−t)(2−t) dt = 1/2 · 5/6 = 5/12, ∫ N_2 = 1/2 · 2/3 =
    # 1/3; together the area 3/2.
    X = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.5, 1.0, 0.0], [1.5, 1.0, 0.0]])
    got = full_measures(X, QUAD, DOWN[None])[0]
    assert np.allclose(got, [5 / 12, 5 / 12, 1 / 3, 1 / 3], rtol=0, atol=ROUNDOFF)


def _jittered(X, n, rng, amount=0.25):
    inner = (X[:, 0] > 0) & (X[:, 0] < 1) & (X[:, 1] > 0) & (X[:, 1] < 1)
    X = X.copy()
    X[inner, :2] += rng.uniform(-amount, amount, (inner.sum(), 2)) / n
    return X


def test_distorted_and_warped_quadrilaterals():
    # Flat quadrilaterals that are not parallelograms: the rule is no longer exact for each
    # integral, but the identities are algebraic in the rule (x = Σ N_i x_i and Σ N̂_k = 1
    # at every point, the overlap's area is the sum of its triangles'), so they still hold
    # to round-off. Warped slave facets (out of plane by 2 % of the width): each facet is
    # integrated on its mean plane, so only Σ_k M_jk = D_jj (weights summing to 1) stays
    # exact; the covered area is that of the projections (measured 1.4e-3 off here).
    rng = np.random.default_rng(3)
    Xs, Fs = _grid(np.linspace(0, 1, 7), np.linspace(0, 1, 6), np.eye(2))
    Xm, Fm = _grid(np.linspace(0, 1, 5), np.linspace(0, 1, 4), np.eye(2))
    Xs, Xm = _jittered(Xs, 6, rng), _jittered(Xm, 4, rng)
    down, up = np.tile(DOWN, (len(Fs), 1)), np.tile(UP, (len(Fm), 1))
    D, rows, cols, vals = mortar_rows_3d(Xs, Fs, down, Xm, Fm, up, 1.0)
    M = _dense(D, rows, cols, vals, Xm.shape[0])
    assert D.sum() == pytest.approx(1.0, rel=ROUNDOFF)
    assert np.allclose(M.sum(axis=1), D, rtol=0, atol=ROUNDOFF)
    assert np.allclose(M @ Xm, D[:, None] * Xs, rtol=0, atol=ROUNDOFF)
    warped = Xs.copy()
    warped[:, 2] += 0.02 * np.sin(7 * Xs[:, 0]) * np.cos(5 * Xs[:, 1])
    D, rows, cols, vals = mortar_rows_3d(warped, Fs, down, Xm, Fm, up, 1.0)
    M = _dense(D, rows, cols, vals, Xm.shape[0])
    assert np.all(np.isfinite(M)) and np.all(D > 0)
    assert np.allclose(M.sum(axis=1), D, rtol=0, atol=ROUNDOFF)
