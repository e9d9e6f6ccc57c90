"""Surface–surface (mortar) rows in 3D on triangle and quadrilateral facets, the overlaps
clipped exactly in the slave facet's plane (mortar.py explains the rows and the dual basis).

Each master facet is projected on the plane of each slave facet along the slave facet's
normal. Both are convex polygons there, their corners taken around the perimeter (triangle
0, 1, 2; quadrilateral 0, 1, 3, 2, its corners being in the tensor order (0,0), (1,0),
(0,1), (1,1) of surface_nodes). Sutherland–Hodgman clips the master polygon against the
slave one; the overlap is split into triangles from its vertex mean, and ∫ N_a N_b and
∫ N_a N̂_c are summed over those triangles by a triangle rule.

Exactness. Projection along a fixed direction is affine, so the projected master facet
carries the facet's own shape functions, mapped affinely. On triangles every N is affine in
the plane and the products have degree 2: the edge-midpoint rule is exact. A quadrilateral's
shape functions are evaluated through its inverse bilinear map (Newton's method, started
from the parallelogram's answer). On a parallelogram that map is affine, so N is bilinear
in the plane and ψ_a N̂_c (ψ = A N is bilinear too) is a polynomial of degree 4: Radon's
7-point rule, of degree 5, integrates it exactly. On a quadrilateral that is not a
parallelogram the inverse map is not polynomial and each integral is accurate, not exact;
the identities the patch test rests on (Σ_k M_jk = D_jj, Σ_k M_jk x̂_k = D_jj x_j on flat
surfaces, Σ_j D_jj = the covered area) hold at the rule's points and so stay exact. A warped
(non-planar) slave quadrilateral is replaced by its projection on its mean plane, for D and
for the full measures (full_measures) alike.

Memory: the candidate couples (facing, bounding boxes within the cutoff, bounding rectangles
overlapping in the slave plane) are searched in batches, at most a few million slave ×
master tests at a time; only those couples are clipped, one by one.
"""
from __future__ import annotations

import numpy as np

from .projection import facet_normals
from .errors import InputError

ILL_CONDITIONED = 1e10   # condition number of M_e beyond which ψ_a = N_a is used
_BATCH = 4_000_000       # slave × master facet tests per candidate batch
_PERIMETER = {3: [0, 1, 2], 4: [0, 1, 3, 2]}
_NEWTON_STEPS = 30

# Triangle rules in barycentric coordinates; weights are fractions of the triangle's area.
_MIDPOINTS = (np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]]),
              np.full(3, 1.0 / 3.0))


def _radon():
    """Radon's 7-point rule, exact to degree 5."""
    r = np.sqrt(15.0)
    a, b = (6.0 - r) / 21.0, (6.0 + r) / 21.0
    pts = [[1 / 3, 1 / 3, 1 / 3]]
    for t in (a, b):
        pts += [[t, t, 1 - 2 * t], [t, 1 - 2 * t, t], [1 - 2 * t, t, t]]
    w = [9 / 40] + [(155 - r) / 1200] * 3 + [(155 + r) / 1200] * 3
    return np.array(pts), np.array(w)


_RADON = _radon()


def _cross2(a, b):
    """z component of the cross product of plane vectors (..., 2)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _signed_area(poly):
    return 0.5 * float(_cross2(poly, np.roll(poly, -1, axis=0)).sum())


def clip_polygon(subject, clipper):
    """Sutherland–Hodgman: the part of the polygon ``subject`` (k, 2) inside the convex,
    counter-clockwise polygon ``clipper`` (m, 2); an empty (0, 2) array when none is."""
    out = np.asarray(subject, float)
    m = len(clipper)
    for i in range(m):
        if len(out) == 0:
            break
        a, edge = clipper[i], clipper[(i + 1) % m] - clipper[i]
        side = edge[0] * (out[:, 1] - a[1]) - edge[1] * (out[:, 0] - a[0])
        kept = []
        for j in range(len(out)):
            jn = (j + 1) % len(out)
            if side[j] >= 0:
                kept.append(out[j])
            if (side[j] >= 0) != (side[jn] >= 0):
                kept.append(out[j] + (out[jn] - out[j]) * (side[j] / (side[j] - side[jn])))
        out = np.array(kept) if kept else np.zeros((0, 2))
    return out


def bilinear_inverse(P, Q):
    """Reference coordinates (n, 2) ∈ ℝ² of points P (n, 2) in the plane quadrilateral with
    corners Q (4, 2) in tensor order: x(ξ, η) = Σ N_a(ξ, η) Q_a. Exact for parallelograms
    (first step), Newton's method otherwise."""
    a, b, c = Q[0], Q[1] - Q[0], Q[2] - Q[0]
    d = Q[3] - Q[2] - Q[1] + Q[0]
    st = np.linalg.solve(np.column_stack([b, c]), (P - a).T).T
    scale = max(float(np.abs(b).max()), float(np.abs(c).max()), 1e-300)
    if np.abs(d).max() <= 1e-15 * scale:
        return st
    for _ in range(_NEWTON_STEPS):
        s, t = st[:, 0], st[:, 1]
        r = a + np.outer(s, b) + np.outer(t, c) + np.outer(s * t, d) - P
        j11, j12 = b[0] + d[0] * t, c[0] + d[0] * s
        j21, j22 = b[1] + d[1] * t, c[1] + d[1] * s
        det = j11 * j22 - j12 * j21
        step = np.column_stack([j22 * r[:, 0] - j12 * r[:, 1],
                                -j21 * r[:, 0] + j11 * r[:, 1]]) / det[:, None]
        st -= step
        if np.abs(step).max() <= 1e-15:
            break
    return st


def shape_functions(P, corners):
    """Shape functions (n, nv) at plane points P (n, 2) of the facet whose corners (nv, 2)
    are in reference order: barycentric (triangle) or bilinear (quadrilateral)."""
    if len(corners) == 3:
        J = np.column_stack([corners[1] - corners[0], corners[2] - corners[0]])
        l12 = np.linalg.solve(J, (P - corners[0]).T).T
        return np.column_stack([1.0 - l12.sum(axis=1), l12])
    s, t = bilinear_inverse(P, corners).T
    return np.column_stack([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t])


def couple_integrals(Ts, Tm, rule=None):
    """∫ N_a N_b (ns, ns) and ∫ N_a N̂_c (ns, nm) over the overlap of the slave facet Ts and
    the projected master facet Tm, both plane corners (nv, 2) in reference order (Ts's
    perimeter counter-clockwise); None when they do not overlap. ``rule``: (barycentric
    points, weights) of the triangle rule, by default the midpoint rule for two triangles
    and Radon's rule otherwise."""
    if rule is None:
        rule = _MIDPOINTS if len(Ts) == len(Tm) == 3 else _RADON
    subject = Tm[_PERIMETER[len(Tm)]]
    extent = float(np.ptp(Ts, axis=0).max())
    if abs(_signed_area(subject)) <= 1e-14 * extent ** 2:
        return None                                    # master facet seen edge-on
    poly = clip_polygon(subject, Ts[_PERIMETER[len(Ts)]])
    if len(poly) < 3:
        return None
    c = poly.mean(axis=0)
    nxt = np.roll(poly, -1, axis=0)
    area = 0.5 * np.abs(_cross2(poly - c, nxt - c))                      # (t,)
    bary, w = rule
    pts = (bary[None, :, 0, None] * c + bary[None, :, 1, None] * poly[:, None]
           + bary[None, :, 2, None] * nxt[:, None]).reshape(-1, 2)       # (t·q, 2)
    wq = (area[:, None] * w[None, :]).reshape(-1)
    if wq.sum() <= 0.0:
        return None
    Ns, Nm = shape_functions(pts, Ts), shape_functions(pts, Tm)
    return Ns.T @ (wq[:, None] * Ns), Ns.T @ (wq[:, None] * Nm)


def slave_frames(S, ns):
    """Per slave facet: its vertex mean c (nf, 3), orthonormal axes E (nf, 2, 3) of its
    plane (normal ns) and its corners in that plane (nf, nv, 2), in reference order; the
    axes are chosen (e2 = ±ns × e1) so that the perimeter runs counter-clockwise."""
    c = S.mean(axis=1)
    e1 = S[:, 1] - S[:, 0]
    e1 -= np.einsum("fk,fk->f", e1, ns)[:, None] * ns
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    E = np.stack([e1, np.cross(ns, e1)], axis=1)
    T = np.einsum("fvk,fik->fvi", S - c[:, None], E)
    ring = T[:, _PERIMETER[S.shape[1]]]
    mirrored = _cross2(ring, np.roll(ring, -1, axis=1)).sum(axis=1) < 0
    E[mirrored, 1] *= -1
    T[mirrored, :, 1] *= -1
    return c, E, T


def full_measures(X, facets, reference):
    """∫ N_j over each whole facet (nf, nv), on the facet's plane as mortar_rows_3d takes
    it: exact for triangles and plane quadrilaterals (2 × 2 Gauss points)."""
    nv = facets.shape[1]
    S = X[facets]
    if nv == 3:
        area = 0.5 * np.linalg.norm(np.cross(S[:, 1] - S[:, 0], S[:, 2] - S[:, 0]), axis=1)
        return np.repeat(area[:, None] / 3.0, 3, axis=1)
    _, _, T = slave_frames(S, facet_normals(X, facets, reference))
    g = np.array([0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)])
    out = np.zeros((facets.shape[0], 4))
    for s in g:
        for t in g:
            N = np.array([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t])
            dxi = (1 - t) * (T[:, 1] - T[:, 0]) + t * (T[:, 3] - T[:, 2])
            deta = (1 - s) * (T[:, 2] - T[:, 0]) + s * (T[:, 3] - T[:, 1])
            out += 0.25 * np.abs(_cross2(dxi, deta))[:, None] * N[None, :]
    return out


def _candidates(S, ns, frames, Mt, nm, cutoff_m):
    """(slave, master) facet couples that face each other (opposite normals), whose
    bounding boxes (the slave's grown by the cutoff) meet, whose master corners are on
    average within the cutoff of the slave plane, and whose bounding rectangles in that
    plane overlap; in batches of slave facets (the slave × master tests) and of couples."""
    c, E, T = frames
    lo_s, hi_s = S.min(axis=1) - cutoff_m, S.max(axis=1) + cutoff_m
    lo_m, hi_m = Mt.min(axis=1), Mt.max(axis=1)
    t_lo, t_hi = T.min(axis=1), T.max(axis=1)
    tol = 1e-12 * float(np.ptp(T.reshape(-1, 2), axis=0).max(initial=0.0))
    s_idx, k_idx = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    chunk = max(1, _BATCH // max(Mt.shape[0], 1))
    for a in range(0, S.shape[0], chunk):
        b = min(a + chunk, S.shape[0])
        meet = np.all((lo_m[None] <= hi_s[a:b, None]) & (hi_m[None] >= lo_s[a:b, None]), axis=2)
        si, ki = np.nonzero(meet & ((ns[a:b] @ nm.T) < 0.0))
        si += a
        for q in range(0, si.size, _BATCH // 64):
            s, k = si[q:q + _BATCH // 64], ki[q:q + _BATCH // 64]
            rel = Mt[k] - c[s][:, None]                                  # (n, nvm, 3)
            near = np.abs(np.einsum("nvk,nk->nv", rel, ns[s])).mean(axis=1) <= cutoff_m
            P = np.einsum("nvk,nik->nvi", rel, E[s])                     # in the slave plane
            inside = np.all((P.min(axis=1) <= t_hi[s] + tol)
                            & (P.max(axis=1) >= t_lo[s] - tol), axis=1)
            s_idx.append(s[near & inside])
            k_idx.append(k[near & inside])
    return np.concatenate(s_idx), np.concatenate(k_idx)


def mortar_rows_3d(Xs, slave_facets, slave_ref, Xm, master_facets, master_ref, cutoff_m):
    """D (n_slave,) and the couples of M: (rows j, master nodes k, M_jk), dual basis, for
    triangle or quadrilateral facets (each side its own kind). ``Xs``/``Xm`` are the
    slave/master node coordinates (current configuration), the facets rows into them,
    ``*_ref`` the facets' outward normals (orientation only). M_jk is an area [m²]; rows
    with D_jj = 0 are not covered by the master surface. A couple counts when the master
    facet's corners are on average within ``cutoff_m`` of the slave facet's plane."""
    for side, f in (("slave", slave_facets), ("master", master_facets)):
        if f.ndim != 2 or f.shape[1] not in _PERIMETER:
            raise InputError(f"pairing='surface_to_surface' in 3D needs triangle or "
                             f"quadrilateral facets; the {side} facets have "
                             f"{f.shape[-1] if f.ndim == 2 else f.shape} vertices")
    nvs, nvm = slave_facets.shape[1], master_facets.shape[1]
    S, Mt = Xs[slave_facets], Xm[master_facets]                 # (nf, nv, 3)
    ns = facet_normals(Xs, slave_facets, slave_ref)
    nm = facet_normals(Xm, master_facets, master_ref)
    c, E, T = slave_frames(S, ns)
    s_idx, k_idx = _candidates(S, ns, (c, E, T), Mt, nm, cutoff_m)
    Me = np.zeros((S.shape[0], nvs, nvs))
    couples = []
    for s, k in zip(s_idx, k_idx):
        got = couple_integrals(T[s], (Mt[k] - c[s]) @ E[s].T)
        if got is None:
            continue
        Me[s] += got[0]
        couples.append((s, k, got[1]))
    De = Me.sum(axis=2)
    A = dual_coefficients(Me, De)
    D = np.zeros(Xs.shape[0])
    np.add.at(D, slave_facets.reshape(-1), De.reshape(-1))
    if not couples:
        return D, np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    rows = [np.repeat(slave_facets[s], nvm) for s, _, _ in couples]
    cols = [np.tile(master_facets[k], nvs) for _, k, _ in couples]
    vals = [(A[s] @ P).reshape(-1) for s, _, P in couples]
    return D, np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)


def dual_coefficients(Me, De):
    """A = D_e M_e⁻¹ per slave facet (any size), so that ψ_a = Σ_b A_ab N_b is biorthogonal
    to N over the covered part; the identity where M_e is ill-conditioned (the master covers
    almost nothing of the facet). Either way ∫ ψ_a = De_a, so each row's weights sum to 1."""
    n = Me.shape[1]
    A = np.tile(np.eye(n), (Me.shape[0], 1, 1))
    for f in range(Me.shape[0]):
        if De[f].sum() > 0 and np.linalg.cond(Me[f]) < ILL_CONDITIONED:
            A[f] = De[f][:, None] * np.linalg.inv(Me[f])
    return A
