"""Closest-point projection on master facets, rigid analytic targets and the friction
coefficient's accepted types: hand values from geometry (no mesh, no solve)."""
import math

import numpy as np
import pytest

import flexcontact as fc
from flexcontact.problem import _friction_coefficient
from flexcontact.projection import boundary_nodes, closest_points, nodal_normals, facet_normals


def test_segments_inside_and_beyond_the_end():
    X = np.array([[0.0, 0.0], [2.0, 0.0], [3.0, 1.0]])
    facets = np.array([[0, 1], [1, 2]])
    P = np.array([[0.5, 1.0], [-1.0, 0.5], [2.5, 0.5 + 1e-3]])
    f, w, border = closest_points(P, X, facets)
    assert f[0] == 0 and np.allclose(w[0], [0.75, 0.25], atol=1e-15) and not border[0]
    assert f[1] == 0 and np.allclose(w[1], [1.0, 0.0]) and border[1]
    # (2.5, 0.5) lies on the second segment: its midpoint; the weights reproduce the point.
    assert f[2] == 1
    assert np.allclose(w[2] @ X[facets[1]], [2.5 + 5e-4, 0.5 + 5e-4], atol=1e-12)


def test_triangle_interior_and_edge():
    X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    facets = np.array([[0, 1, 2]])
    f, w, border = closest_points(np.array([[0.2, 0.3, 0.5], [2.0, 2.0, 1.0]]), X, facets)
    assert np.allclose(w[0], [0.5, 0.2, 0.3], atol=1e-14) and not border[0]
    # Beyond the hypotenuse: its midpoint (0.5, 0.5, 0).
    assert np.allclose(w[1], [0.0, 0.5, 0.5], atol=1e-14) and border[1]


def _grid(nx, ny, quads):
    """A planar grid of the unit square in the plane x = 0: triangles or quadrilaterals."""
    ys, zs = np.meshgrid(np.linspace(0, 1, nx), np.linspace(0, 1, ny), indexing="ij")
    X = np.stack([np.zeros(ys.size), ys.ravel(), zs.ravel()], axis=1)
    idx = np.arange(ys.size).reshape(nx, ny)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[:-1, 1:].ravel(), idx[1:, 1:].ravel()
    if quads:
        return X, np.stack([a, b, c, d], axis=1)
    return X, np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)])


@pytest.mark.parametrize("surface", ["triangles", "quadrilaterals", "segments"])
def test_many_points_measured_against_near_facets_only_give_the_same_answer(surface,
                                                                            monkeypatch):
    """Above _NEAR_ONLY point × facet combinations only the facets near each point are
    measured (projection._candidates): the facet, the weights and the border flags equal,
    bit for bit, those measured against every facet, ties included (points over the grid's
    nodes and edges, where several facets hold the same closest point)."""
    import flexcontact.projection as projection
    rng = np.random.default_rng(7)
    if surface == "segments":
        t = np.linspace(0.0, 3.0, 800)
        X = np.stack([t, 0.1 * np.sin(t)], axis=1)
        facets = np.stack([np.arange(799), np.arange(1, 800)], axis=1)
        P = np.concatenate([X[rng.integers(0, 800, 200)] + [0.0, 0.01],
                            rng.uniform(-0.5, 3.5, (400, 2))])
    else:
        X, facets = _grid(60, 50, surface == "quadrilaterals")
        P = np.concatenate([X[rng.integers(0, len(X), 300)] + [0.01, 0.0, 0.0],
                            rng.uniform(-0.2, 1.2, (300, 3))])
    assert P.shape[0] * facets.shape[0] > projection._NEAR_ONLY
    near = closest_points(P, X, facets)
    assert projection._candidates(P, X, facets) is not None  # the near path was taken
    monkeypatch.setattr(projection, "_NEAR_ONLY", 10**18)
    everywhere = closest_points(P, X, facets)
    for a, b in zip(near, everywhere):
        assert np.array_equal(a, b)
    # A diverged state (a NaN coordinate) is measured against all facets, as it always was,
    # for the caller's own checks to name; the near path would have nothing to offer it.
    # (On quadrilaterals the bilinear refinement of a NaN point raises either way.)
    if surface == "quadrilaterals":
        return
    P[3] = np.nan
    monkeypatch.setattr(projection, "_NEAR_ONLY", 200_000)
    with_nan = closest_points(P, X, facets)
    monkeypatch.setattr(projection, "_NEAR_ONLY", 10**18)
    for a, b in zip(with_nan, closest_points(P, X, facets)):
        assert np.array_equal(a, b, equal_nan=True)


def test_bilinear_quadrilateral_weights():
    # A planar, non-parallelogram quadrilateral, corners in tensor order (0,0), (1,0), (0,1),
    # (1,1); a point above x(ξ, η) has the bilinear shape functions at (ξ, η) as weights.
    X = np.array([[0.0, 0, 0], [2, 0, 0], [0, 1, 0], [3, 2, 0]])
    s, t = 0.3, 0.6
    N = np.array([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t])
    P = (N @ X + [0, 0, 0.4])[None]
    f, w, border = closest_points(P, X, np.array([[0, 1, 2, 3]]))
    assert np.allclose(w[0], N, atol=1e-10) and not border[0]


def test_boundary_and_normals_of_a_strip():
    # Two triangles forming the unit square: boundary = all 4 nodes; normals +z.
    X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    facets = np.array([[0, 1, 3], [0, 3, 2]])
    assert boundary_nodes(facets, 3, 4).all()
    fn = facet_normals(X, facets, np.array([[0, 0, 1.0], [0, 0, 1.0]]))
    assert np.allclose(nodal_normals(X, facets, fn), [0, 0, 1])
    # 2D chain of three segments: only the two ends are boundary nodes.
    assert boundary_nodes(np.array([[0, 1], [1, 2], [2, 3]]), 2, 4).tolist() == \
        [True, False, False, True]


def test_rigid_circle_normals_and_offsets():
    c = fc.RigidTarget("circle", point_m=(1.0, 2.0), radius_m=0.5)
    c.displacement_m = np.array([0.0, -1.0])
    n, off = c.normals_and_offsets(np.array([[4.0, 5.0]]))
    assert np.allclose(n, [[0.6, 0.8]]) and off.tolist() == [0.5]
    p = fc.RigidTarget("plane", point_m=(0, 0, 0), normal=(0, 0, 2.0))
    assert np.allclose(p.normal, [0, 0, 1])


@pytest.mark.parametrize("kwargs, word", [
    (dict(kind="cone", point_m=(0, 0)), "kind"),
    (dict(kind="plane", point_m=(0, 0), normal=(0, 0)), "normal"),
    (dict(kind="circle", point_m=(0, 0), radius_m=-1.0), "radius_m"),
    (dict(kind="sphere", point_m=(0, 0), radius_m=1.0), "sphere lives in 3D"),
    (dict(kind="circle", point_m=(0, math.nan), radius_m=1.0), "point_m"),
])
def test_rigid_target_bad_input(kwargs, word):
    with pytest.raises(ValueError, match=word):
        fc.RigidTarget(**kwargs)


@pytest.mark.parametrize("mu", [np.float32(0.25), np.float64(0.25), np.array(0.25),
                                np.int64(0), 0.25, 0])
def test_friction_coefficient_numpy_scalars(mu):
    assert _friction_coefficient(mu, "x") == pytest.approx(float(mu), rel=1e-7)


@pytest.mark.parametrize("mu", [np.array([0.3]), True, "0.3", -0.1, np.array(math.nan),
                                1 + 1j])
def test_friction_coefficient_rejected(mu):
    with pytest.raises(ValueError, match="friction coefficient"):
        _friction_coefficient(mu, "x")
