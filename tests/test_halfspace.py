"""The closed-form half-space stresses behind the report's tension near the impact
(flexcontact.dam.halfspace): Boussinesq's and Cerruti's fields must be in equilibrium, free
of traction on the surface, balance the force over a hemisphere, and be the stress of the
displacement Green's tensor (Landau & Lifshitz, Theory of Elasticity, §8)."""
import numpy as np
import pytest

from flexcontact.dam.halfspace import (face_frame, hemisphere_points, peak_tension_Pa,
                                       point_force_stress)

NU = 0.2
FORCES = [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.3, -0.7, 1.1)]
RNG = np.random.default_rng(7)
POINTS = np.column_stack([RNG.uniform(-1, 1, 12), RNG.uniform(-1, 1, 12),
                          RNG.uniform(0.05, 1, 12)])


def _displacement(p, force, nu, G=1.0):
    """u (k, 3) of a force (Q_x, Q_y, P) at the origin of the half-space z ≥ 0: the Green's
    tensor of Landau & Lifshitz, written independently of the stresses under test."""
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    R = np.linalg.norm(p, axis=1)
    c = 1.0 / (4.0 * np.pi * G)
    s = 2.0 * R * (nu * R + z) + z ** 2
    g = np.zeros((p.shape[0], 3, 3))
    g[:, 0, 0] = (2 * (1 - nu) * R + z) / (R * (R + z)) + s * x ** 2 / (R ** 3 * (R + z) ** 2)
    g[:, 1, 1] = (2 * (1 - nu) * R + z) / (R * (R + z)) + s * y ** 2 / (R ** 3 * (R + z) ** 2)
    g[:, 0, 1] = g[:, 1, 0] = s * x * y / (R ** 3 * (R + z) ** 2)
    g[:, 0, 2] = x * z / R ** 3 - (1 - 2 * nu) * x / (R * (R + z))
    g[:, 1, 2] = y * z / R ** 3 - (1 - 2 * nu) * y / (R * (R + z))
    g[:, 2, 0] = x * z / R ** 3 + (1 - 2 * nu) * x / (R * (R + z))
    g[:, 2, 1] = y * z / R ** 3 + (1 - 2 * nu) * y / (R * (R + z))
    g[:, 2, 2] = 2 * (1 - nu) / R + z ** 2 / R ** 3
    return c * g @ np.asarray(force, float)


@pytest.mark.parametrize("force", FORCES)
def test_the_stress_is_the_greens_tensors_and_in_equilibrium(force):
    step = 1e-6
    grad = np.stack([(_displacement(POINTS + step * np.eye(3)[j], force, NU)
                      - _displacement(POINTS - step * np.eye(3)[j], force, NU)) / (2 * step)
                     for j in range(3)], axis=2)          # (k, i, j) = ∂u_i/∂x_j
    eps = 0.5 * (grad + grad.transpose(0, 2, 1))
    G = 1.0
    lam = 2 * G * NU / (1 - 2 * NU)
    hooke = 2 * G * eps + lam * np.trace(eps, axis1=1, axis2=2)[:, None, None] * np.eye(3)
    sig = point_force_stress(POINTS, force, NU)
    scale = np.abs(sig).max()
    assert np.abs(sig - hooke).max() <= 1e-7 * scale   # central differences: O(step²)
    div = sum((point_force_stress(POINTS + step * np.eye(3)[j], force, NU)[:, :, j]
               - point_force_stress(POINTS - step * np.eye(3)[j], force, NU)[:, :, j])
              / (2 * step) for j in range(3))
    assert np.abs(div).max() <= 1e-6 * scale / np.linalg.norm(POINTS, axis=1).min()


@pytest.mark.parametrize("force", FORCES)
def test_the_surface_is_free_and_a_hemisphere_balances_the_force(force):
    surface = POINTS.copy()
    surface[:, 2] = 0.0
    sig = point_force_stress(surface, force, NU)
    assert np.abs(sig[:, :, 2]).max() <= 1e-13 * np.abs(sig).max()
    # The ball's cap r < 0.7 m is held by the force at the origin and by σ·n on its
    # hemisphere: their sum is zero (Gauss–Legendre in the polar angle, 1e-12).
    r = 0.7
    t, wt = np.polynomial.legendre.leggauss(48)
    theta = 0.25 * np.pi * (t + 1.0)
    phi = np.linspace(0.0, 2 * np.pi, 96, endpoint=False)
    T, F = np.meshgrid(theta, phi, indexing="ij")
    n = np.column_stack([(np.sin(T) * np.cos(F)).ravel(), (np.sin(T) * np.sin(F)).ravel(),
                         np.cos(T).ravel()])
    w = (np.outer(wt * 0.25 * np.pi * np.sin(theta), np.full(phi.size, 2 * np.pi / phi.size))
         .ravel() * r ** 2)
    traction = np.einsum("kij,kj->ki", point_force_stress(r * n, force, NU), n)
    assert np.allclose((w[:, None] * traction).sum(axis=0) + np.asarray(force), 0.0,
                       atol=1e-12)


def test_the_peak_under_a_normal_force_is_the_surface_tension():
    force_N, r = 0.75e6, 0.5
    value, where = peak_tension_Pa([force_N, 0.0, 0.0], [1.0, 0.0, 0.0], NU, r)
    assert value == pytest.approx((1 - 2 * NU) * force_N / (2 * np.pi * r ** 2), rel=1e-12)
    assert where[2] == 0.0 and np.linalg.norm(where) == pytest.approx(r)


def test_a_tangential_force_adds_tension_behind_it_and_a_static_stress_adds_on():
    r, Q = 0.5, 1.0e5
    # Behind a tangential force the surface is in tension (1 + ν) Q/(π r²) along it.
    behind = point_force_stress([[-r, 0.0, 0.0]], (Q, 0.0, 0.0), NU)[0]
    assert behind[0, 0] == pytest.approx((1 + NU) * Q / (np.pi * r ** 2), rel=1e-12)
    # On the face x = 0 of the dam, a push +x with friction −z: more tension than the push
    # alone; a uniform compression across the face takes it off one for one.
    push = peak_tension_Pa([7.5e5, 0.0, 0.0], [1.0, 0.0, 0.0], NU, r)[0]
    both = peak_tension_Pa([7.5e5, 0.0, -1.5e5], [1.0, 0.0, 0.0], NU, r)[0]
    assert both > push * 1.1
    static = -2.0e5 * np.eye(3)
    assert peak_tension_Pa([7.5e5, 0.0, -1.5e5], [1.0, 0.0, 0.0], NU, r,
                           static)[0] == pytest.approx(both - 2.0e5, rel=1e-12)


def test_the_frame_and_the_samples():
    for n in ([1.0, 0.0, 0.0], [0.3, -0.4, 0.866]):
        R = face_frame(n)
        assert np.allclose(R @ R.T, np.eye(3), atol=1e-15)
        assert np.linalg.det(R) == pytest.approx(1.0)
        assert np.allclose(R[2], np.asarray(n) / np.linalg.norm(n))
    pts = hemisphere_points(0.5)
    assert np.allclose(np.linalg.norm(pts, axis=1), 0.5)
    assert pts[:, 2].min() == 0.0 and np.count_nonzero(pts[:, 2] == 0.0) == 180
