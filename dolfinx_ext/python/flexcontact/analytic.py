"""Closed-form answers of the verification catalogue (DESIGN.md §5), SI units."""
from __future__ import annotations

import math


def effective_modulus(E1_Pa, nu1, E2_Pa, nu2) -> float:
    """E* = [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]⁻¹ [Pa]."""
    return 1.0 / ((1 - nu1**2) / E1_Pa + (1 - nu2**2) / E2_Pa)


def hertz_cylinder(P_N_per_m, R_m, Estar_Pa):
    """Plane-strain cylinder contact: half-width a [m] and peak pressure p0 [Pa]."""
    a = math.sqrt(4 * P_N_per_m * R_m / (math.pi * Estar_Pa))
    return a, 2 * P_N_per_m / (math.pi * a)


def hertz_sphere(P_N, R_m, Estar_Pa):
    """Sphere contact: radius a [m] and peak pressure p0 [Pa]."""
    a = (3 * P_N * R_m / (4 * Estar_Pa)) ** (1 / 3)
    return a, 3 * P_N / (2 * math.pi * a**2)


def hertz_pressure(x_m, a_m, p0_Pa):
    """p(x) = p0 sqrt(1 − x²/a²) inside the contact, 0 outside [Pa]."""
    r = 1 - (x_m / a_m) ** 2
    return p0_Pa * math.sqrt(r) if r > 0 else 0.0


def cattaneo_mindlin_stick_halfwidth(a_m, Q, mu, P):
    """c = a sqrt(1 − Q/(μP)) [m] for 0 ≤ Q < μP."""
    return a_m * math.sqrt(1 - Q / (mu * P))


def cattaneo_mindlin_shear(x_m, a_m, c_m, mu, p0_Pa):
    """Tangential traction q(x) of Cattaneo–Mindlin partial slip [Pa]."""
    q = mu * p0_Pa * math.sqrt(max(0.0, 1 - (x_m / a_m) ** 2))
    if abs(x_m) < c_m:
        q -= mu * p0_Pa * (c_m / a_m) * math.sqrt(max(0.0, 1 - (x_m / c_m) ** 2))
    return q
