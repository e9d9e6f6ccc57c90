"""Hand statics of the dam's free body: the loads a dam engineer adds up by hand.

Exact resultants (no mesh) of the self-weight, the reservoir and tailwater pressure on the
faces, and the uplift on the base, as a :class:`~flexcontact.dam.section.BaseSection`; the
finite-element section of :mod:`flexcontact.dam.stage1` must reproduce them.
"""
from __future__ import annotations

import numpy as np

from .section import BaseSection


def polygon_area_centroid(points) -> tuple[float, np.ndarray]:
    """Area (m²) and centroid (m) of a simple polygon given counter-clockwise (shoelace)."""
    p = np.asarray(points, dtype=float)
    q = np.roll(p, -1, axis=0)
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    area = 0.5 * cross.sum()
    centroid = ((p + q) * cross[:, None]).sum(axis=0) / (6.0 * area)
    return float(area), centroid


def water_on_segment(p1, p2, level_m, rho_g):
    """Force (2,) and its point of action for hydrostatic water on the segment p1→p2 of a
    counter-clockwise boundary (water outside), both ends at or below ``level_m``."""
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    t = p2 - p1
    outward = np.array([t[1], -t[0]])  # right of the direction of travel: outside (CCW)
    w1, w2 = rho_g * (level_m - p1[1]), rho_g * (level_m - p2[1])
    force = -outward * 0.5 * (w1 + w2)  # |outward| = segment length
    if w1 + w2 == 0:
        return force, 0.5 * (p1 + p2)
    s = (w1 + 2.0 * w2) / (3.0 * (w1 + w2))  # centroid of the trapezoidal load
    return force, p1 + s * t


def _profile_2d(s):
    from flexcontact.meshes.dam_geometry import profile_points
    return profile_points(s)


def _embed(s, v2):
    """(x, vertical) → the scenario's dimension (y = 0 in 3D, moments do not need it)."""
    v2 = np.asarray(v2, dtype=float)
    return v2 if s.dim == 2 else np.array([v2[0], 0.0, v2[1]])


def hand_statics(s, include_uplift: bool = True) -> BaseSection:
    """The base-section resultant from statics of the dam alone (per metre in 2D)."""
    w = 1.0 if s.dim == 2 else s.dam_width_m
    g, rho_w = s.gravity_m_s2, s.water_density_kg_m3
    pts = _profile_2d(s)
    area, centroid = polygon_area_centroid(pts)
    zero = BaseSection(tuple([0.0] * s.dim), 0.0, s.base_width_m, w)
    out = zero.plus(_embed(s, (0.0, -s.concrete.rho_kg_m3 * g * area * w)), _embed(s, centroid))
    n = len(pts)
    for i in range(n):
        p1, p2 = pts[i], pts[(i + 1) % n]
        upstream = p1[0] == 0.0 and p2[0] == 0.0 and max(p1[1], p2[1]) > 0.0
        level = s.water_level_m if upstream else s.tailwater_level_m
        on_face = i > 0 and max(p1[1], p2[1]) <= level + 1e-12 * s.dam_height_m
        if on_face and level > 0:
            f, at = water_on_segment(p1, p2, level, rho_w * g)
            out = out.plus(_embed(s, f * w), _embed(s, at))
    if include_uplift and s.uplift_factor > 0:
        force, at = uplift_resultant(s)
        out = out.plus(_embed(s, (0.0, force * w)), _embed(s, (at, 0.0)))
    return out


def uplift_resultant(s) -> tuple[float, float]:
    """Uplift on the base per unit width (N/m, upward) and its distance from the heel (m).

    Pressure linear from f ρ_w g h_w at the heel to f ρ_w g h_t at the toe, f the
    ``uplift_factor`` (1: no drains)."""
    B, hw, ht = s.base_width_m, s.water_level_m, s.tailwater_level_m
    k = s.uplift_factor * s.water_density_kg_m3 * s.gravity_m_s2
    force = k * B * (hw + ht) / 2.0
    at = B * (hw + 2.0 * ht) / (3.0 * (hw + ht))
    return force, at
