"""Hydrostatics of the floating log and the water's added masses (SI units).

The log is a circular cylinder of radius R. Floating horizontally, its weight equals the
weight of the water it displaces, so the submerged fraction of its cross-section equals the
density ratio s = ρ_wood / ρ_water. The submerged part of the section is a circular segment
of depth d (the draft):

    A_seg(d) = R² acos((R − d)/R) − (R − d) sqrt(2 R d − d²) = s π R²,

whose left side grows monotonically from 0 (d = 0) to π R² (d = 2R). The log's axis then
sits at ``water level − d + R``; a log of half the water's density floats with its axis on
the water line (d = R).
"""
from __future__ import annotations

import math
from ..errors import InputError


def segment_area_m2(radius_m: float, depth_m: float) -> float:
    """Area (m²) of the circular segment of depth ``depth_m`` (0..2R) cut from a circle."""
    R, d = radius_m, min(max(depth_m, 0.0), 2.0 * radius_m)
    return R * R * math.acos((R - d) / R) - (R - d) * math.sqrt(max(2.0 * R * d - d * d, 0.0))


def floating_draft_m(radius_m: float, density_ratio: float) -> float:
    """Draft d (m) of a horizontal cylinder of radius R floating with ρ_wood/ρ_water = s.

    Solves A_seg(d) = s π R² by bisection to machine precision (A_seg is monotone on
    [0, 2R]). Raises ValueError unless 0 < s < 1 and R > 0.
    """
    if not (radius_m > 0 and math.isfinite(radius_m)):
        raise InputError(f"radius_m={radius_m!r}: must be a finite number > 0")
    if not 0.0 < density_ratio < 1.0:
        raise InputError(f"density_ratio={density_ratio!r}: a floating log needs "
                         f"0 < rho_wood/rho_water < 1")
    target = density_ratio * math.pi * radius_m ** 2
    lo, hi = 0.0, 2.0 * radius_m
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if segment_area_m2(radius_m, mid) < target:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 4e-16 * radius_m:
            break
    return 0.5 * (lo + hi)


def westergaard_added_mass_kg_m2(depth_below_surface_m, water_depth_m: float,
                                 rho_w_kg_m3: float = 1000.0):
    """Westergaard's added mass per unit area of a rigid vertical upstream face (kg/m²).

    m(y) = (7/8) ρ_w sqrt(H_w · (H_w − y)) in terms of the depth below the free surface
    ``H_w − y`` (Westergaard 1933, incompressible water, rigid dam). Zero above the water.
    Works on floats and NumPy arrays alike.
    """
    import numpy as np
    depth = np.clip(np.asarray(depth_below_surface_m, dtype=float), 0.0, None)
    out = 0.875 * rho_w_kg_m3 * np.sqrt(water_depth_m * depth)
    return float(out) if out.ndim == 0 else out
