"""Surface–surface (mortar) weights of contact rows, integrated exactly over the overlaps:
segments intersected in 2D, triangle and quadrilateral facets clipped against each other in
3D (mortar_3d.py, re-exported here as mortar_rows_3d).

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

from .mortar_3d import ILL_CONDITIONED as _ILL_CONDITIONED
from .mortar_3d import mortar_rows_3d  # noqa: F401  (the 3D rows, one import for both)

_GAUSS_2 = np.array([0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)])  # on [0, 1]


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
