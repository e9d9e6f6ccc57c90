"""Checks of a :class:`~flexcontact.dam.scenario.DamScenario`, run by its constructor.

Every error is a ValueError naming the parameter and its value, raised before any mesh is
built or anything computed.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from ..forms import Material
from ..errors import InputError

_POSITIVE = ("dam_height_m", "crest_width_m", "downstream_slope", "dam_width_m",
             "foundation_depth_m", "foundation_upstream_m", "foundation_downstream_m",
             "water_level_m", "log_length_m", "log_diameter_m", "wood_E_across_grain_Pa",
             "wood_crushing_strength_Pa", "concrete_tensile_strength_Pa",
             "water_density_kg_m3", "gravity_m_s2", "impact_zone_m", "contact_zone_m")
_NON_NEGATIVE = ("tailwater_level_m", "log_gap_m", "log_speed_m_s", "friction_mu",
                 "added_mass_coefficient")


def _real(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


def _fail(name, value, why):
    raise InputError(f"{name}={value!r}: {why}")


def check_scenario(s) -> None:
    """Raise ValueError for the first bad parameter of scenario ``s``."""
    _check_types(s)
    _check_profile(s)
    _check_water(s)
    _check_log(s)


def _check_types(s):
    if s.dim not in (2, 3) or isinstance(s.dim, bool):
        _fail("dim", s.dim, "must be 2 (plane-strain section) or 3 (dam block)")
    for name in _POSITIVE:
        v = getattr(s, name)
        if not (_real(v) and v > 0):
            _fail(name, v, "must be a finite number > 0")
    for name in _NON_NEGATIVE:
        v = getattr(s, name)
        if not (_real(v) and v >= 0):
            why = {"log_gap_m": "the log would overlap the dam's upstream face (need >= 0)",
                   "log_speed_m_s": "the log's speed must be >= 0 m/s (it moves towards the "
                                    "dam; the direction is its axis)"}.get(name, "must be >= 0")
            _fail(name, v, why)
    for name in ("mesh_size_far_m", "mesh_size_impact_m", "mesh_size_log_m",
                 "mesh_size_contact_m", "contact_layer_m", "log_end_chamfer_m",
                 "log_end_radius_m"):
        v = getattr(s, name)
        if v is not None and not (_real(v) and v > 0):
            _fail(name, v, "must be None (default) or a finite number > 0")
    if not (isinstance(s.refine, numbers.Integral) and not isinstance(s.refine, bool)
            and s.refine >= 0):
        _fail("refine", s.refine, "must be an integer >= 0")
    for name in ("westergaard", "log_end_crushes"):
        if not isinstance(getattr(s, name), bool):
            _fail(name, getattr(s, name), "must be True or False")
    for name in ("concrete", "rock", "wood"):
        if not isinstance(getattr(s, name), Material):
            _fail(name, getattr(s, name), "must be a flexcontact.forms.Material")
    if not (_real(s.time_scheme_theta) and 0.5 <= s.time_scheme_theta <= 1.0):
        _fail("time_scheme_theta", s.time_scheme_theta,
              "must be in [0.5, 1] (½: no numerical damping; 1: backward Euler)")
    if not (_real(s.uplift_factor) and 0.0 <= s.uplift_factor <= 1.0):
        _fail("uplift_factor", s.uplift_factor, "must be in [0, 1] (1: full uplift, no drains)")


def _check_profile(s):
    B = s.base_width_m
    if s.crest_width_m >= B:
        _fail("crest_width_m", s.crest_width_m,
              f"must be < the base width downstream_slope·dam_height_m = {B!r} m")


def _check_water(s):
    H = s.dam_height_m
    if s.water_level_m > H:
        _fail("water_level_m", s.water_level_m,
              f"the water is above the crest (dam_height_m={H!r}): the dam is overtopped, "
              f"which this model does not cover")
    if s.tailwater_level_m >= s.water_level_m:
        _fail("tailwater_level_m", s.tailwater_level_m,
              f"must be below the reservoir level water_level_m={s.water_level_m!r}")


def _check_log(s):
    for name in ("log_pitch_deg", "log_yaw_deg"):
        v = getattr(s, name)
        if not (_real(v) and -90.0 < v < 90.0):
            _fail(name, v, "must be strictly between -90 and 90 degrees (the log's front end "
                           "faces the dam)")
    if s.dim == 2 and s.log_yaw_deg != 0:
        _fail("log_yaw_deg", s.log_yaw_deg, "a yaw angle needs the 3D variant (dim=3)")
    if s.log_across_m is not None:
        if s.dim == 2:
            _fail("log_across_m", s.log_across_m, "a place across the block needs the 3D "
                                                  "variant (dim=3); None in 2D")
        if not (_real(s.log_across_m) and s.log_radius_m <= s.log_across_m
                <= s.dam_width_m - s.log_radius_m):
            _fail("log_across_m", s.log_across_m,
                  f"the log's centre must be within the block, at least its radius "
                  f"{s.log_radius_m:.4g} m from both joints (0 to dam_width_m="
                  f"{s.dam_width_m!r})")
    s.log_end.check(s.log_diameter_m)
    rho, rho_w = s.wood.rho_kg_m3, s.water_density_kg_m3
    if not 0 < rho < rho_w:
        _fail("wood.rho_kg_m3", rho, f"the log must be lighter than water "
                                      f"(water_density_kg_m3={rho_w!r}) to float, and > 0")
    if s.log_diameter_m >= s.log_length_m:
        _fail("log_diameter_m", s.log_diameter_m,
              f"must be < log_length_m={s.log_length_m!r} (a log, not a disc)")
    low = s.log_lowest_elevation_m
    if low <= 0:
        _fail("water_level_m", s.water_level_m,
              f"too shallow for the log: its lowest point would be at {low:.4g} m, at or "
              f"below the reservoir bed (0 m)")
    front = s.log_front_point
    if not 0 < front[-1] < s.dam_height_m:
        _fail("log_pitch_deg", s.log_pitch_deg,
              f"the log's front point would be at elevation {front[-1]:.4g} m, not on the "
              f"upstream face (0 to dam_height_m={s.dam_height_m!r})")
    if s.dim == 3 and not 0 < front[1] < s.dam_width_m:
        _fail("log_yaw_deg", s.log_yaw_deg,
              f"the log's front point would be at y = {front[1]:.4g} m, outside the block "
              f"(0 to dam_width_m={s.dam_width_m!r})")
    back = s.log_centre[0] - s._log_reach(np.eye(s.dim)[0])
    if back <= -s.foundation_upstream_m:
        _fail("foundation_upstream_m", s.foundation_upstream_m,
              f"the log reaches x = {back:.4g} m, beyond the reservoir bed modelled")
