"""Parameter checks with messages that name the parameter and its value."""

import math
import numbers
from flexcontact.errors import InputError


def positive(name: str, value, unit: str = "m") -> float:
    """``value`` as float if it is a finite number > 0, else ValueError."""
    if not (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and math.isfinite(value) and value > 0):
        raise InputError(f"{name}={value!r}: must be a finite number > 0 ({unit})")
    return float(value)


def refine_level(value) -> int:
    """``refine`` as int if it is an integer >= 0, else ValueError."""
    if not (isinstance(value, numbers.Integral) and not isinstance(value, bool) and value >= 0):
        raise InputError(f"refine={value!r}: must be an integer >= 0")
    return int(value)


def less(name: str, value: float, bound_name: str, bound: float):
    """ValueError unless value < bound."""
    if not value < bound:
        raise InputError(f"{name}={value!r} must be < {bound_name}={bound!r}")


def hertz_zone(R, a_expected, zone_factor):
    """Checked (R, a, w) of a Hertz geometry [m]: radius R, the expected contact half-width
    a (default R/10, must be < R) and the candidate zone half-width w = zone_factor·a."""
    R = positive("R", R)
    a = positive("a_expected", R / 10 if a_expected is None else a_expected)
    if a >= R:
        raise InputError(f"a_expected={a!r} must be < R={R!r} (Hertz needs a << R)")
    zone_factor = positive("zone_factor", zone_factor, "dimensionless")
    if zone_factor < 1:
        raise InputError(f"zone_factor={zone_factor!r} must be >= 1 (the zone must contain a)")
    return R, a, zone_factor * a
