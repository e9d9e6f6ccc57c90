"""Surface–surface (mortar) weights of contact rows, integrated exactly over the overlaps:
segments intersected in 2D, triangles clipped against each other in 3D (mortar_rows_3d).

One contact row per slave node j: the weak gap g_j = Σ_i D_ji x_i − Σ_k M_jk x̂_k along the
slave node's normal, with D_ji = ∫ ψ_j N_i and M_jk = ∫ ψ_j N̂_k over the parts of the slave
surface that the master surface covers. ψ_j is the *dual* Lagrange multiplier basis
(Wohlmuth): biorthogonal to the slave shape functions, ∫ ψ_j N_i = δ_ji D_jj, so D is
diagonal and row j, divided by D_jj, is a node-like row: slave node j with weight 1 and the
master nodes k with weights M_jk / D_jj. The multiplier of that row is then the nodal
force of slave node j [N/m in 2D, N in 3D] and its gap is in metres, as for node–node
pairs.

Segmentation (2D). A master segment is projected on the line of a slave segment along the
slave segment's normal; the overlap is an interval [ξ0, ξ1] of the slave parameter ξ ∈ [0, 1].
The projection of a straight segment along a fixed direction is affine, so on the overlap the
master parameter η is affine in ξ and every product N_a N̂_k or ψ_a N̂_k is a quadratic in ξ:
two-point Gauss quadrature on each interval integrates D and M exactly.

Partially covered slave segments (at the end of the master surface) get the dual basis of
their covered part, ψ_a = Σ_b A_ab N_b with A = D_e M_e⁻¹ (D_e = diag ∫ N_a, M_e = ∫ N_a N_b
over the covered part), so biorthogonality holds where the integrals are taken and each row's
master weights sum to 1 (Σ_k N̂_k = 1): a rigid translation makes no gap, and flat coinciding
surfaces give zero initial gap whatever the two meshes. A nearly uncovered segment (M_e
ill-conditioned) uses ψ_a = N_a, with the same row sums.

Why it passes the patch test: with Σ_j ψ_j = 1 on the covered surface, a uniform multiplier
p transmits p ∫ N̂_k to master node k and p ∫ N_j = p × (tributary measure) to slave node j,
the consistent nodal forces of a uniform pressure on either mesh.
"""
from __future__ import annotations

import numpy as np

_GAUSS_2 = np.array([0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)])  # on [0, 1]
_ILL_CONDITIONED = 1e10   # condition number of M_e beyond which ψ_a = N_a is used


def _segment_frames(X, facets, reference):
    """Start point A, tangent t (unit), length L and unit normal n of each segment, the
    normal oriented as ``reference`` (the segments' outward normals)."""
    A, B = X[facets[:, 0]], X[facets[:, 1]]
    e = B - A
    L = np.linalg.norm(e, axis=1)
    t = e / np.maximum(L, 1e-300)[:, None]
    n = np.stack([t[:, 1], -t[:, 0]], axis=1)
    flip = np.einsum("fk,fk->f", n, reference) < 0
    n[flip] *= -1
    return A, B, t, L, n


def overlaps_2d(Xs, slave_facets, slave_ref, Xm, master_facets, master_ref, cutoff_m):
    """The overlapping (slave segment, master segment) couples and their intervals.

    Returns (s, k, xi0, xi1, eta_a, eta_b): indices of the couples, the overlap [xi0, xi1]
    on the slave segment and the affine map η(ξ) = eta_a + eta_b ξ of the master parameter.
    A couple counts when the segments face each other (opposite normals) and the master
    segment's mean distance from the slave line over the overlap is below ``cutoff_m``.
    """
    A, _, t, L, ns = _segment_frames(Xs, slave_facets, slave_ref)
    C, E, _, _, nm = _segment_frames(Xm, master_facets, master_ref)
    # Projections of the master ends on every slave line (ns_f, nm_f).
    def proj(P):
        rel = P[None, :, :] - A[:, None, :]
        return (np.einsum("smk,sk->sm", rel, t) / L[:, None],
                np.einsum("smk,sk->sm", rel, ns))
    xc, hc = proj(C)
    xe, he = proj(E)
    facing = (ns @ nm.T) < 0.0
    span = xe - xc
    lo = np.maximum(0.0, np.minimum(xc, xe))
    hi = np.minimum(1.0, np.maximum(xc, xe))
    usable = facing & (np.abs(span) > 1e-12) & (hi - lo > 1e-12)
    s, k = np.nonzero(usable)
    xc, xe, hc, he, span = xc[s, k], xe[s, k], hc[s, k], he[s, k], span[s, k]
    lo, hi = lo[s, k], hi[s, k]
    eta_b = 1.0 / span
    eta_a = -xc * eta_b
    mid = 0.5 * (lo + hi)
    h_mid = hc + (he - hc) * (eta_a + eta_b * mid)
    near = np.abs(h_mid) <= cutoff_m
    return s[near], k[near], lo[near], hi[near], eta_a[near], eta_b[near]


def mortar_rows_2d(Xs, slave_facets, slave_ref, Xm, master_facets, master_ref, cutoff_m):
    """D (n_slave,) and the couples of M: (rows j, master nodes k, M_jk), dual basis.

    ``Xs``/``Xm`` are the slave/master node coordinates (current configuration), the facets
    rows into them, ``*_ref`` the segments' outward normals (orientation only). M_jk has
    units of length (2D); rows with D_jj = 0 are not covered by the master surface.
    """
    s, k, lo, hi, ea, eb = overlaps_2d(Xs, slave_facets, slave_ref, Xm, master_facets,
                                       master_ref, cutoff_m)
    L = np.linalg.norm(Xs[slave_facets[:, 1]] - Xs[slave_facets[:, 0]], axis=1)
    nfs = slave_facets.shape[0]
    jac = L[s] * (hi - lo)                                    # dx = jac dζ, ζ ∈ [0, 1]
    Me = np.zeros((nfs, 2, 2))
    P = np.zeros((s.size, 2, 2))                              # ∫ N_a N̂_c per couple
    for g in _GAUSS_2:
        xi = lo + (hi - lo) * g
        eta = ea + eb * xi
        N = np.stack([1.0 - xi, xi], axis=1)
        Nh = np.stack([1.0 - eta, eta], axis=1)
        w = 0.5 * jac
        np.add.at(Me, s, w[:, None, None] * N[:, :, None] * N[:, None, :])
        P += w[:, None, None] * N[:, :, None] * Nh[:, None, :]
    De = Me.sum(axis=2)                                        # ∫ N_a over the covered part
    A = _dual_coefficients(Me, De)
    Ms = np.einsum("sab,sbc->sac", A[s], P)                    # ∫ ψ_a N̂_c per couple
    D = np.zeros(Xs.shape[0])
    np.add.at(D, slave_facets.reshape(-1), De.reshape(-1))
    rows = slave_facets[s][:, :, None].repeat(2, axis=2)       # (couples, a, c)
    cols = master_facets[k][:, None, :].repeat(2, axis=1)
    return D, rows.reshape(-1), cols.reshape(-1), Ms.reshape(-1)


def _dual_coefficients(Me, De):
    """A = D_e M_e⁻¹ per slave segment (ψ_a = Σ_b A_ab N_b); the identity where M_e is
    (nearly) singular, i.e. where the master covers (almost) nothing of the segment."""
    A = np.tile(np.eye(2), (Me.shape[0], 1, 1))
    det = Me[:, 0, 0] * Me[:, 1, 1] - Me[:, 0, 1] * Me[:, 1, 0]
    norm2 = np.einsum("sab,sab->s", Me, Me)
    ok = det > norm2 / _ILL_CONDITIONED
    inv = np.stack([np.stack([Me[ok, 1, 1], -Me[ok, 0, 1]], axis=1),
                    np.stack([-Me[ok, 1, 0], Me[ok, 0, 0]], axis=1)], axis=1) / det[ok, None,
                                                                                      None]
    A[ok] = De[ok][:, :, None] * inv
    return A


# ---- 3D: triangle facets, polygon clipping -------------------------------------------------
# Degree-2 rule on a triangle (the edge midpoints, weights 1/3 of the area): exact for the
# products of two affine functions, which all the integrands are (see mortar_rows_3d).
_MIDPOINTS = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])


def _cross2(a, b):
    """z component of the cross product of two plane vectors (NumPy 2 deprecates np.cross
    of 2-vectors)."""
    return a[0] * b[1] - a[1] * b[0]


def _clip(subject, clipper):
    """Sutherland–Hodgman: the part of the convex polygon ``subject`` (k, 2) inside the
    counter-clockwise triangle ``clipper`` (3, 2)."""
    out = subject
    for i in range(3):
        a, b = clipper[i], clipper[(i + 1) % 3]
        edge = b - a
        side = lambda p: edge[0] * (p[..., 1] - a[1]) - edge[1] * (p[..., 0] - a[0])  # noqa
        if len(out) == 0:
            break
        inp, out = out, []
        s_in = side(inp)
        for j in range(len(inp)):
            p, q = inp[j], inp[(j + 1) % len(inp)]
            sp, sq = s_in[j], s_in[(j + 1) % len(inp)]
            if sp >= 0:
                out.append(p)
            if (sp >= 0) != (sq >= 0):
                out.append(p + (q - p) * (sp / (sp - sq)))
        out = np.array(out) if out else np.zeros((0, 2))
    return out


def _barycentric(P, T):
    """Barycentric coordinates (n, 3) of points P (n, 2) in the triangle T (3, 2)."""
    J = np.column_stack([T[1] - T[0], T[2] - T[0]])
    l12 = np.linalg.solve(J, (P - T[0]).T).T
    return np.column_stack([1.0 - l12.sum(axis=1), l12])


def _couple_3d(Ts, Tm):
    """∫ N_a N_b (3, 3) and ∫ N_a N̂_c (3, 3) over the overlap of the slave triangle Ts and
    the projected master triangle Tm (both (3, 2) in the slave plane, Ts counter-clockwise);
    None when they do not overlap."""
    if _cross2(Tm[1] - Tm[0], Tm[2] - Tm[0]) < 0:
        Tm = Tm[::-1].copy()
        flip = True
    else:
        flip = False
    poly = _clip(Tm, Ts)
    if len(poly) < 3:
        return None
    c = poly.mean(axis=0)
    Mss, Msm = np.zeros((3, 3)), np.zeros((3, 3))
    for i in range(len(poly)):
        tri = np.array([c, poly[i], poly[(i + 1) % len(poly)]])
        area = 0.5 * abs(_cross2(tri[1] - tri[0], tri[2] - tri[0]))
        if area <= 0.0:
            continue
        pts = _MIDPOINTS @ tri
        Ns, Nm = _barycentric(pts, Ts), _barycentric(pts, Tm)
        Mss += (area / 3.0) * Ns.T @ Ns
        Msm += (area / 3.0) * Ns.T @ Nm
    if flip:
        Msm = Msm[:, ::-1]
    return Mss, Msm


def mortar_rows_3d(Xs, slave_facets, slave_ref, Xm, master_facets, master_ref, cutoff_m):
    """As mortar_rows_2d, for triangle facets: each master triangle is projected on the
    plane of each slave triangle along the slave triangle's normal, clipped against it
    (both convex), and the clipped polygon split into triangles. In the slave plane N_a and
    the projected master's N̂_k are affine, so the degree-2 midpoint rule is exact."""
    if slave_facets.shape[1] != 3 or master_facets.shape[1] != 3:
        raise ValueError("pairing='surface_to_surface' in 3D needs triangle facets (tetrahedral "
                         "meshes); quadrilateral facets are not supported yet")
    S, Mt = Xs[slave_facets], Xm[master_facets]                 # (nf, 3, 3)
    ns = np.cross(S[:, 1] - S[:, 0], S[:, 2] - S[:, 0])
    ns /= np.linalg.norm(ns, axis=1)[:, None]
    ns[np.einsum("fk,fk->f", ns, slave_ref) < 0] *= -1
    nm = np.cross(Mt[:, 1] - Mt[:, 0], Mt[:, 2] - Mt[:, 0])
    nm /= np.linalg.norm(nm, axis=1)[:, None]
    nm[np.einsum("fk,fk->f", nm, master_ref) < 0] *= -1
    # Candidate couples: facing, and bounding boxes (grown by the cutoff) that meet.
    lo_s, hi_s = S.min(axis=1) - cutoff_m, S.max(axis=1) + cutoff_m
    lo_m, hi_m = Mt.min(axis=1), Mt.max(axis=1)
    s_idx, k_idx = [], []
    chunk = max(1, 4_000_000 // max(Mt.shape[0], 1))   # slave facets per batch
    for a in range(0, S.shape[0], chunk):
        b = min(a + chunk, S.shape[0])
        meet = np.all((lo_m[None] <= hi_s[a:b, None]) & (hi_m[None] >= lo_s[a:b, None]), axis=2)
        si, ki = np.nonzero(meet & ((ns[a:b] @ nm.T) < 0.0))
        s_idx.append(si + a)
        k_idx.append(ki)
    s_idx, k_idx = np.concatenate(s_idx), np.concatenate(k_idx)
    nfs = slave_facets.shape[0]
    Me = np.zeros((nfs, 3, 3))
    couples = []
    for s, k in zip(s_idx, k_idx):
        e1 = S[s, 1] - S[s, 0]
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(ns[s], e1)
        rel_s, rel_m = S[s] - S[s, 0], Mt[k] - S[s, 0]
        if (rel_s[2] @ e2) < 0:
            e2 = -e2                      # a mirrored frame: Ts counter-clockwise
        h = rel_m @ ns[s]
        if np.abs(h).mean() > cutoff_m:
            continue
        Ts = np.column_stack([rel_s @ e1, rel_s @ e2])
        Tm = np.column_stack([rel_m @ e1, rel_m @ e2])
        if abs(_cross2(Tm[1] - Tm[0], Tm[2] - Tm[0])) <= 1e-14 * np.ptp(Ts, axis=0).max()**2:
            continue                      # master triangle seen edge-on
        got = _couple_3d(Ts, Tm)
        if got is None:
            continue
        Me[s] += got[0]
        couples.append((s, k, got[1]))
    De = Me.sum(axis=2)
    A = _dual_coefficients_n(Me, De)
    D = np.zeros(Xs.shape[0])
    np.add.at(D, slave_facets.reshape(-1), De.reshape(-1))
    rows, cols, vals = [], [], []
    for s, k, P in couples:
        Ms = A[s] @ P
        rows.append(np.repeat(slave_facets[s], 3))
        cols.append(np.tile(master_facets[k], 3))
        vals.append(Ms.reshape(-1))
    if not couples:
        return D, np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    return D, np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)


def _dual_coefficients_n(Me, De):
    """A = D_e M_e⁻¹ per slave facet (any size); the identity where M_e is ill-conditioned."""
    n = Me.shape[1]
    A = np.tile(np.eye(n), (Me.shape[0], 1, 1))
    for f in range(Me.shape[0]):
        if De[f].sum() > 0 and np.linalg.cond(Me[f]) < _ILL_CONDITIONED:
            A[f] = De[f][:, None] * np.linalg.inv(Me[f])
    return A
