"""Closed-form answers of the verification catalogue (docs/architecture.md §6), SI units.

Every function checks its input and raises ValueError naming the parameter and its value:
a reference computed from a negative load or an impossible Poisson's ratio would otherwise
come out as NaN or as a plausible-looking wrong number.
"""
from __future__ import annotations

import math
import numbers
from .errors import InputError


def _number(name, value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(f"{name}={value!r}: must be a real number")
    x = float(value)
    if not math.isfinite(x):
        raise InputError(f"{name}={value!r}: must be finite")
    return x


def _positive(name, value) -> float:
    x = _number(name, value)
    if x <= 0:
        raise InputError(f"{name}={value!r}: must be > 0")
    return x


def _nonnegative(name, value) -> float:
    x = _number(name, value)
    if x < 0:
        raise InputError(f"{name}={value!r}: must be >= 0")
    return x


def _poisson(name, value) -> float:
    x = _number(name, value)
    if not -1.0 < x <= 0.5:
        raise InputError(f"{name}={value!r}: Poisson's ratio must satisfy -1 < nu <= 0.5")
    return x


def effective_modulus(E1_Pa, nu1, E2_Pa, nu2) -> float:
    """E* = [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]⁻¹ [Pa]."""
    E1, E2 = _positive("E1_Pa", E1_Pa), _positive("E2_Pa", E2_Pa)
    n1, n2 = _poisson("nu1", nu1), _poisson("nu2", nu2)
    return 1.0 / ((1 - n1**2) / E1 + (1 - n2**2) / E2)


def hertz_cylinder(P_N_per_m, R_m, Estar_Pa):
    """Plane-strain cylinder contact: half-width a [m] and peak pressure p0 [Pa]."""
    P = _positive("P_N_per_m", P_N_per_m)
    R, Es = _positive("R_m", R_m), _positive("Estar_Pa", Estar_Pa)
    a = math.sqrt(4 * P * R / (math.pi * Es))
    return a, 2 * P / (math.pi * a)


def hertz_sphere(P_N, R_m, Estar_Pa):
    """Sphere contact: radius a [m] and peak pressure p0 [Pa]."""
    P = _positive("P_N", P_N)
    R, Es = _positive("R_m", R_m), _positive("Estar_Pa", Estar_Pa)
    a = (3 * P * R / (4 * Es)) ** (1 / 3)
    return a, 3 * P / (2 * math.pi * a**2)


def hertz_pressure(x_m, a_m, p0_Pa):
    """p(x) = p0 sqrt(1 − x²/a²) inside the contact, 0 outside [Pa]."""
    x, a = _number("x_m", x_m), _positive("a_m", a_m)
    p0 = _nonnegative("p0_Pa", p0_Pa)
    r = 1 - (x / a) ** 2
    return p0 * math.sqrt(r) if r > 0 else 0.0


def cattaneo_mindlin_stick_halfwidth(a_m, Q, mu, P):
    """c = a sqrt(1 − Q/(μP)) [m] for 0 ≤ Q ≤ μP (Q and P in the same units)."""
    a, mu_, P_ = _positive("a_m", a_m), _positive("mu", mu), _positive("P", P)
    Q_ = _nonnegative("Q", Q)
    if Q_ > mu_ * P_:
        raise InputError(f"Q={Q!r}: exceeds mu*P = {mu_ * P_!r}; past mu*P the contact slides "
                         "and there is no stick zone")
    return a * math.sqrt(1 - Q_ / (mu_ * P_))


def cattaneo_mindlin_shear(x_m, a_m, c_m, mu, p0_Pa):
    """Tangential traction q(x) of Cattaneo–Mindlin partial slip [Pa]."""
    x, a = _number("x_m", x_m), _positive("a_m", a_m)
    c = _nonnegative("c_m", c_m)
    if c > a:
        raise InputError(f"c_m={c_m!r}: the stick zone cannot be wider than a_m = {a_m!r}")
    mu_, p0 = _nonnegative("mu", mu), _nonnegative("p0_Pa", p0_Pa)
    q = mu_ * p0 * math.sqrt(max(0.0, 1 - (x / a) ** 2))
    if abs(x) < c:
        q -= mu_ * p0 * (c / a) * math.sqrt(max(0.0, 1 - (x / c) ** 2))
    return q
