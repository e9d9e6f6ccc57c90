"""Closest-point projection of points onto a faceted surface (rank 0, NumPy).

The facets are 2D segments, 3D triangles or 3D quadrilaterals (bilinear, corners in the
tensor-product order (0,0), (1,0), (0,1), (1,1) of ``surface_nodes``). For each point the
result is the facet of the closest point, the facet's shape-function weights there (they
sum to 1 and reproduce the point: Σ w_j X_j), and whether the point was clamped to the
facet's border.
"""
from __future__ import annotations

import numpy as np
from .errors import InputError

_CHUNK = 2_000_000  # point × facet combinations per vectorised batch
_NEAR_ONLY = 200_000  # above this many combinations, only the facets near each point


def _segment(P, A, B):
    """Parameter t ∈ [0, 1] and squared distance of P (n, 1, d) to segments A→B (1, f, d)."""
    d = B - A
    L2 = np.maximum(np.einsum("...k,...k->...", d, d), 1e-300)
    t = np.clip(np.einsum("...k,...k->...", P - A, d) / L2, 0.0, 1.0)
    r = P - (A + t[..., None] * d)
    return t, np.einsum("...k,...k->...", r, r)


def _triangle(P, A, B, C):
    """Barycentric weights (n, f, 3) of the closest point on triangles ABC and the squared
    distance (n, f): the plane projection when it falls inside, else the nearest edge."""
    e1, e2 = B - A, C - A
    n = np.cross(e1, e2)
    n2 = np.maximum(np.einsum("...k,...k->...", n, n), 1e-300)
    v = P - A
    # Barycentrics of the plane projection (Cramer's rule with the normal).
    b1 = np.einsum("...k,...k->...", np.cross(v, e2), n) / n2
    b2 = np.einsum("...k,...k->...", np.cross(e1, v), n) / n2
    b0 = 1.0 - b1 - b2
    w = np.stack(np.broadcast_arrays(b0, b1, b2), axis=-1)
    h = np.einsum("...k,...k->...", v, n)
    dist = h * h / n2
    inside = (b0 >= 0) & (b1 >= 0) & (b2 >= 0)
    dist = np.where(inside, dist, np.inf)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        corners = (A, B, C)
        t, d2 = _segment(P, corners[i], corners[j])
        better = d2 < dist
        we = np.zeros(w.shape)
        we[..., i] = 1.0 - t
        we[..., j] = t
        w = np.where(better[..., None], we, w)
        dist = np.minimum(dist, d2)
    return w, dist


def _bilinear_refine(p, Xf, w_tri, steps=12):
    """Bilinear coordinates (ξ, η) ∈ [0, 1]² of the closest point of one quadrilateral to
    p, by projected Gauss–Newton started from the split-triangle answer."""
    # Start: the point Σ w X on the triangles, mapped to (ξ, η) through the corners' (ξ, η).
    ref = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    xi = w_tri @ ref
    for _ in range(steps):
        s, t = xi
        N = np.array([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t])
        dN = np.array([[-(1 - t), (1 - t), -t, t], [-(1 - s), -s, (1 - s), s]])
        r = N @ Xf - p
        J = dN @ Xf                                     # (2, d): tangents
        step = np.linalg.lstsq(J @ J.T, -(J @ r), rcond=None)[0]
        xi = np.clip(xi + step, 0.0, 1.0)
        if np.abs(step).max() < 1e-14:
            break
    s, t = xi
    return np.array([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t])


def _distances(p, corners, d: int, nv: int):
    """Weights (…, nv) of the closest points of points ``p`` on the facets whose corner
    arrays are ``corners`` (broadcast against ``p``), and the squared distances (…)."""
    if d == 2:
        t, dist = _segment(p, corners[0], corners[1])
        return np.stack([1.0 - t, t], axis=-1), dist
    if nv == 3:
        return _triangle(p, *corners)
    # Quadrilateral (0,1,2,3 tensor order) split along the 0–3 diagonal.
    w1, d1 = _triangle(p, corners[0], corners[1], corners[3])
    w2, d2 = _triangle(p, corners[0], corners[3], corners[2])
    first = d1 <= d2
    w = np.zeros(first.shape + (4,))
    w[..., [0, 1, 3]] = np.where(first[..., None], w1, 0.0)
    w[..., [0, 3, 2]] += np.where(first[..., None], 0.0, w2)
    return w, np.minimum(d1, d2)


def _candidates(P, X, facets):
    """Per point, the facets that may hold its closest point, or None when that would not
    cut the work. A facet lies in a ball of radius r_f about its centroid c_f, so it is at
    least |p − c_f| − r_f from p, and the nearest centroid's facet at most |p − c_n| + r_max:
    the facets with |p − c_f| ≤ |p − c_n| + 2 r_max hold every closest point (a superset,
    in ascending facet order, so ties go to the lowest index as over all facets)."""
    from scipy.spatial import cKDTree
    A = X[facets]
    c = A.mean(axis=1)
    r_max = float(np.sqrt(((A - c[:, None, :]) ** 2).sum(axis=2)).max())
    tree = cKDTree(c)
    near, _ = tree.query(P)
    scale = max(float(np.abs(P).max()), float(np.abs(c).max()), 1.0)
    lists = tree.query_ball_point(P, near + 2.0 * r_max + 1e-9 * scale)
    counts = np.array([len(a) for a in lists])
    if counts.sum() * 4 > P.shape[0] * facets.shape[0]:
        return None
    return np.repeat(np.arange(P.shape[0]), counts), np.concatenate(
        [np.sort(np.asarray(a, np.int64)) for a in lists]), counts


def closest_points(P: np.ndarray, X: np.ndarray, facets: np.ndarray):
    """Closest points of points P (n, d) on the surface of facets (nf, nv) over nodes X.

    Returns (facet (n,), weights (n, nv), border (n,) bool): the facet holding the closest
    point, its shape-function weights there, and whether some weight is zero (the point
    lies on the facet's border, e.g. beyond the edge of the surface). Many points on many
    facets are measured against the facets near them only (:func:`_candidates`), with the
    same answer as against all.
    """
    P, X, facets = np.asarray(P, float), np.asarray(X, float), np.asarray(facets)
    n, (nf, nv) = P.shape[0], facets.shape
    d = X.shape[1]
    if nf == 0:
        raise InputError("closest_points: the surface has no facets")
    best = np.empty(n, np.int64)
    weights = np.empty((n, nv))
    # A non-finite coordinate (a diverged state) keeps the measure against all facets, and
    # so the same answer as ever, for the caller's own checks to name.
    near = (_candidates(P, X, facets)
            if n * nf > _NEAR_ONLY and np.isfinite(P).all() and np.isfinite(X).all() else None)
    if near is not None:
        point, facet, counts = near
        w, dist = _distances(P[point][:, None, :],
                             [X[facets[facet, j]][:, None, :] for j in range(nv)], d, nv)
        w, dist = w[:, 0], dist[:, 0]
        # The first smallest distance of each point's run, as argmin over all facets.
        first = np.lexsort((np.arange(dist.size), dist, point))
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        pick = first[starts]
        best[:] = facet[pick]
        weights[:] = w[pick]
    else:
        chunk = max(1, _CHUNK // nf)
        corners = [X[facets[:, j]][None] for j in range(nv)]
        for start in range(0, n, chunk):
            w, dist = _distances(P[start:start + chunk, None, :], corners, d, nv)
            k = np.argmin(dist, axis=1)
            rows = np.arange(k.size)
            best[start:start + k.size] = k
            weights[start:start + k.size] = w[rows, k]
    if d == 3 and nv == 4:
        for i in range(n):
            weights[i] = _bilinear_refine(P[i], X[facets[best[i]]], weights[i])
    border = np.any(weights <= 1e-12, axis=1)
    return best, weights, border


def facet_normals(X: np.ndarray, facets: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Unit normals (nf, d) of the facets over nodes X, oriented as ``reference`` (the
    outward normals of the same facets in another configuration)."""
    A = X[facets]
    if X.shape[1] == 2:
        e = A[:, 1] - A[:, 0]
        nrm = np.stack([e[:, 1], -e[:, 0]], axis=1)
    elif facets.shape[1] == 3:
        nrm = np.cross(A[:, 1] - A[:, 0], A[:, 2] - A[:, 0])
    else:
        nrm = np.cross(A[:, 3] - A[:, 0], A[:, 2] - A[:, 1])
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1), 1e-300)[:, None]
    flip = np.einsum("fk,fk->f", nrm, reference) < 0
    nrm[flip] *= -1
    return nrm


def facet_measures(X: np.ndarray, facets: np.ndarray) -> np.ndarray:
    """Length (2D) or area (3D) of each facet."""
    A = X[facets]
    if X.shape[1] == 2:
        return np.linalg.norm(A[:, 1] - A[:, 0], axis=1)
    if facets.shape[1] == 3:
        return 0.5 * np.linalg.norm(np.cross(A[:, 1] - A[:, 0], A[:, 2] - A[:, 0]), axis=1)
    return 0.5 * np.linalg.norm(np.cross(A[:, 3] - A[:, 0], A[:, 2] - A[:, 1]), axis=1)


def nodal_normals(X: np.ndarray, facets: np.ndarray, facet_normal: np.ndarray) -> np.ndarray:
    """Measure-weighted mean of the facet normals around each node, normalised (n, d)."""
    nv = facets.shape[1]
    acc = np.zeros_like(X)
    meas = facet_measures(X, facets)
    np.add.at(acc, facets.reshape(-1), np.repeat(meas[:, None] * facet_normal, nv, axis=0))
    return acc / np.maximum(np.linalg.norm(acc, axis=1), 1e-300)[:, None]


def boundary_nodes(facets: np.ndarray, dim: int, n_nodes: int) -> np.ndarray:
    """Flags (n_nodes,) of the nodes on the boundary of the surface made of ``facets``: in
    2D the segment ends used by one facet, in 3D the ends of edges used by one facet."""
    flags = np.zeros(n_nodes, bool)
    if facets.shape[0] == 0:
        return flags
    if dim == 2:
        ids, counts = np.unique(facets.reshape(-1), return_counts=True)
        flags[ids[counts == 1]] = True
        return flags
    nv = facets.shape[1]
    ring = [(0, 1), (1, 2), (2, 0)] if nv == 3 else [(0, 1), (1, 3), (3, 2), (2, 0)]
    edges = np.sort(np.vstack([facets[:, [i, j]] for i, j in ring]), axis=1)
    uniq, counts = np.unique(edges, axis=0, return_counts=True)
    flags[uniq[counts == 1].reshape(-1)] = True
    return flags
