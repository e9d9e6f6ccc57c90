"""The closed-form references (flexcontact.analytic) against facts that do not use them.

The demo tests measure the method against these formulas, so a wrong formula would pass a
wrong result. Each formula is checked here by something it must satisfy for an independent
reason: the pressure integrates to the load, the shear integrates to the tangential load,
limits, the textbook's other forms. Quadratures are Gauss–Legendre after a substitution
x = a sin θ that makes the square-root integrands smooth, so they are exact to roundoff.
"""
import math

import numpy as np
import pytest

from flexcontact import analytic

E, NU = 200e9, 0.3          # steel [Pa], [-]
R = 0.05                    # radius [m]
P_LINE = 2.5e6              # load per unit length [N/m]
P_POINT = 1.0e5             # load [N]


def gauss(f, lo, hi, n=64):
    """∫ f over [lo, hi] by n-point Gauss–Legendre."""
    t, w = np.polynomial.legendre.leggauss(n)
    x = 0.5 * (hi - lo) * t + 0.5 * (hi + lo)
    return 0.5 * (hi - lo) * sum(wi * f(xi) for xi, wi in zip(x, w))


def integral_over(f, lo, hi, r):
    """∫ f(x) dx over [lo, hi] ⊂ [−r, r] with x = r sin θ (removes sqrt(r² − x²) kinks)."""
    return gauss(lambda th: f(r * math.sin(th)) * r * math.cos(th),
                 math.asin(lo / r), math.asin(hi / r))


# ---- E* --------------------------------------------------------------------------------
def test_effective_modulus_identical_materials():
    assert analytic.effective_modulus(E, NU, E, NU) == pytest.approx(E / (2 * (1 - NU**2)),
                                                                      rel=1e-15)


def test_effective_modulus_rigid_partner_and_symmetry():
    # A partner a million times stiffer leaves the plane-strain modulus of the soft body.
    assert analytic.effective_modulus(E, NU, 1e6 * E, 0.2) == pytest.approx(
        E / (1 - NU**2), rel=2e-6)
    assert analytic.effective_modulus(70e9, 0.33, E, NU) == pytest.approx(
        analytic.effective_modulus(E, NU, 70e9, 0.33), rel=1e-15)


# ---- Hertz, cylinders ------------------------------------------------------------------
def test_hertz_cylinder_pressure_integrates_to_the_load():
    Es = analytic.effective_modulus(E, NU, E, NU)
    a, p0 = analytic.hertz_cylinder(P_LINE, R, Es)
    P = integral_over(lambda x: analytic.hertz_pressure(x, a, p0), -a, a, a)
    assert P == pytest.approx(P_LINE, rel=1e-12)


def test_hertz_cylinder_textbook_forms():
    # Johnson, Contact Mechanics §4.2: p0 = sqrt(P E*/(π R)), a² = 4 P R/(π E*).
    Es = analytic.effective_modulus(E, NU, E, NU)
    a, p0 = analytic.hertz_cylinder(P_LINE, R, Es)
    assert p0 == pytest.approx(math.sqrt(P_LINE * Es / (math.pi * R)), rel=1e-14)
    # a grows like sqrt(P): four times the load, twice the width.
    assert analytic.hertz_cylinder(4 * P_LINE, R, Es)[0] == pytest.approx(2 * a, rel=1e-14)


def test_hertz_pressure_profile():
    a, p0 = 1e-3, 5e8
    assert analytic.hertz_pressure(0.0, a, p0) == p0
    assert analytic.hertz_pressure(0.6 * a, a, p0) == pytest.approx(0.8 * p0, rel=1e-15)
    assert analytic.hertz_pressure(-0.6 * a, a, p0) == pytest.approx(0.8 * p0, rel=1e-15)
    assert analytic.hertz_pressure(a, a, p0) == 0.0
    assert analytic.hertz_pressure(1.5 * a, a, p0) == 0.0


# ---- Hertz, spheres --------------------------------------------------------------------
def test_hertz_sphere_pressure_integrates_to_the_load():
    Es = analytic.effective_modulus(E, NU, E, NU)
    a, p0 = analytic.hertz_sphere(P_POINT, R, Es)
    P = integral_over(lambda r: analytic.hertz_pressure(r, a, p0) * 2 * math.pi * r, 0.0, a, a)
    assert P == pytest.approx(P_POINT, rel=1e-12)


def test_hertz_sphere_textbook_forms():
    # Johnson §4.2: p0 = (6 P E*²/(π³ R²))^(1/3); approach δ = a²/R = (9P²/(16 R E*²))^(1/3).
    Es = analytic.effective_modulus(E, NU, E, NU)
    a, p0 = analytic.hertz_sphere(P_POINT, R, Es)
    assert p0 == pytest.approx((6 * P_POINT * Es**2 / (math.pi**3 * R**2)) ** (1 / 3), rel=1e-14)
    assert a**2 / R == pytest.approx((9 * P_POINT**2 / (16 * R * Es**2)) ** (1 / 3), rel=1e-14)


# ---- Cattaneo–Mindlin ------------------------------------------------------------------
MU = 0.3


def test_cattaneo_mindlin_stick_zone_limits():
    a = 2.5e-3
    assert analytic.cattaneo_mindlin_stick_halfwidth(a, 0.0, MU, P_LINE) == a
    assert analytic.cattaneo_mindlin_stick_halfwidth(a, 1e-9 * MU * P_LINE, MU, P_LINE) == \
        pytest.approx(a, rel=1e-9)
    assert analytic.cattaneo_mindlin_stick_halfwidth(a, MU * P_LINE, MU, P_LINE) == 0.0
    c = analytic.cattaneo_mindlin_stick_halfwidth(a, (1 - 1e-10) * MU * P_LINE, MU, P_LINE)
    assert c == pytest.approx(1e-5 * a, rel=1e-5)
    # Q = 3/4 μP: c = a/2.
    assert analytic.cattaneo_mindlin_stick_halfwidth(a, 0.75 * MU * P_LINE, MU, P_LINE) == \
        pytest.approx(0.5 * a, rel=1e-15)


@pytest.mark.parametrize("ratio", [0.1, 0.5, 0.9])
def test_cattaneo_mindlin_shear_integrates_to_the_tangential_load(ratio):
    Es = analytic.effective_modulus(E, NU, E, NU)
    a, p0 = analytic.hertz_cylinder(P_LINE, R, Es)
    Q = ratio * MU * P_LINE
    c = analytic.cattaneo_mindlin_stick_halfwidth(a, Q, MU, P_LINE)

    def q(x):
        return analytic.cattaneo_mindlin_shear(x, a, c, MU, p0)

    # Split at ±c, where the shear has kinks; substitute on the square root of each piece.
    total = (integral_over(q, -a, -c, a) + integral_over(q, -c, c, c)
             + integral_over(q, c, a, a))
    assert total == pytest.approx(Q, rel=1e-12)


def test_cattaneo_mindlin_shear_obeys_coulomb():
    Es = analytic.effective_modulus(E, NU, E, NU)
    a, p0 = analytic.hertz_cylinder(P_LINE, R, Es)
    c = analytic.cattaneo_mindlin_stick_halfwidth(a, 0.5 * MU * P_LINE, MU, P_LINE)
    xs = np.linspace(-1.2 * a, 1.2 * a, 241)
    q = np.array([analytic.cattaneo_mindlin_shear(x, a, c, MU, p0) for x in xs])
    p = np.array([analytic.hertz_pressure(x, a, p0) for x in xs])
    # Never outside the cone, positive inside the contact, on the cone in the slip zone.
    assert np.all(q <= MU * p * (1 + 1e-15))
    assert np.all(q[np.abs(xs) < a] > 0)
    slip = (np.abs(xs) >= c) & (np.abs(xs) < a)
    assert slip.sum() > 10
    np.testing.assert_allclose(q[slip], MU * p[slip], rtol=1e-15)
    # Continuous at the edge of the stick zone.
    assert analytic.cattaneo_mindlin_shear(c * (1 - 1e-12), a, c, MU, p0) == pytest.approx(
        MU * analytic.hertz_pressure(c, a, p0), rel=1e-5)


def test_cattaneo_mindlin_shear_at_zero_q_vanishes():
    # Q = 0: c = a, the two terms cancel everywhere.
    a, p0 = 1e-3, 5e8
    for x in (0.0, 0.3 * a, -0.9 * a):
        assert abs(analytic.cattaneo_mindlin_shear(x, a, a, MU, p0)) <= 1e-15 * MU * p0


# ---- bad input -------------------------------------------------------------------------
@pytest.mark.parametrize("call, name", [
    (lambda: analytic.effective_modulus(-E, NU, E, NU), "E1_Pa"),
    (lambda: analytic.effective_modulus(E, NU, 0.0, NU), "E2_Pa"),
    (lambda: analytic.effective_modulus(E, 0.7, E, NU), "nu1"),
    (lambda: analytic.effective_modulus(E, NU, E, -1.0), "nu2"),
    (lambda: analytic.effective_modulus(E, math.nan, E, NU), "nu1"),
    (lambda: analytic.hertz_cylinder(-1.0, R, E), "P_N_per_m"),
    (lambda: analytic.hertz_cylinder(P_LINE, 0.0, E), "R_m"),
    (lambda: analytic.hertz_cylinder(P_LINE, R, math.inf), "Estar_Pa"),
    (lambda: analytic.hertz_sphere(0.0, R, E), "P_N"),
    (lambda: analytic.hertz_sphere(P_POINT, -R, E), "R_m"),
    (lambda: analytic.hertz_sphere(P_POINT, R, "2e11"), "Estar_Pa"),
    (lambda: analytic.hertz_pressure(0.0, 0.0, 1.0), "a_m"),
    (lambda: analytic.hertz_pressure(0.0, 1.0, -1.0), "p0_Pa"),
    (lambda: analytic.hertz_pressure(math.nan, 1.0, 1.0), "x_m"),
    (lambda: analytic.cattaneo_mindlin_stick_halfwidth(1e-3, 1.1 * MU * P_LINE, MU, P_LINE), "Q"),
    (lambda: analytic.cattaneo_mindlin_stick_halfwidth(1e-3, -1.0, MU, P_LINE), "Q"),
    (lambda: analytic.cattaneo_mindlin_stick_halfwidth(1e-3, 1.0, 0.0, P_LINE), "mu"),
    (lambda: analytic.cattaneo_mindlin_stick_halfwidth(1e-3, 1.0, MU, 0.0), "P"),
    (lambda: analytic.cattaneo_mindlin_stick_halfwidth(-1e-3, 1.0, MU, P_LINE), "a_m"),
    (lambda: analytic.cattaneo_mindlin_shear(0.0, 1e-3, 2e-3, MU, 1e8), "c_m"),
    (lambda: analytic.cattaneo_mindlin_shear(0.0, 1e-3, -1e-4, MU, 1e8), "c_m"),
    (lambda: analytic.cattaneo_mindlin_shear(0.0, 1e-3, 5e-4, -MU, 1e8), "mu"),
    (lambda: analytic.cattaneo_mindlin_shear(0.0, 1e-3, 5e-4, MU, -1e8), "p0_Pa"),
])
def test_bad_input_names_the_parameter(call, name):
    with pytest.raises(ValueError, match=rf"^{name}="):
        call()
