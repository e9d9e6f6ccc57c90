"""The stress of a point force on the surface of an elastic half-space, and its largest
principal value on a hemisphere around the force.

Near the impact the dam's face is, at the scale of a few log diameters, the surface of a
half-space. Boussinesq's solution (the normal part of the force) puts the face in radial
tension (1 − 2ν) F/(2π r²) in a layer about 0.1 r deep, which the impact zone's elements do
not resolve (docs/dam.md, "The peak principal stress near the impact"); Cerruti's solution
(the tangential part: friction, a pitched or yawed log) adds a tension behind the force of
order Q/(π r²). Both are closed forms (Johnson, Contact Mechanics, 1985, §3.2; the Green's
tensor of Landau & Lifshitz, Theory of Elasticity, §8), so the largest principal stress on
the hemisphere is read from them exactly, with the dam's static stress added as a uniform
field. No DOLFINx here: the callers bring the force and the static stress.

Local frame: z is the depth into the solid (the inward normal), x and y span the surface.
"""
from __future__ import annotations

import numpy as np


def point_force_stress(p, force_local, nu: float) -> np.ndarray:
    """Stress (k, 3, 3) in Pa, tension positive, at the points ``p`` (k, 3) of the half-space
    z ≥ 0 (local frame, m) under the force ``force_local`` = (Q_x, Q_y, P) in N at the
    origin; P > 0 pushes into the solid. Boussinesq for P, Cerruti for Q_x and for Q_y (the
    Q_x field turned by 90° about z)."""
    p = np.atleast_2d(np.asarray(p, float))
    qx, qy, P = (float(f) for f in force_local)
    sig = P * _boussinesq(p, nu) + qx * _cerruti(p, nu)
    if qy != 0.0:
        turn = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # y → x
        s = _cerruti(p @ turn.T, nu)
        sig += qy * np.einsum("ji,kjl,lm->kim", turn, s, turn)
    return sig


def _boussinesq(p, nu: float) -> np.ndarray:
    """Stress per newton of a normal force pushing into the solid at the origin. In
    cylindrical components (r from the axis, ρ from the origin), with
    1/r² (1 − z/ρ) written as 1/(ρ(ρ + z)) so that the axis is regular (there σ_r = σ_θ and
    τ_rz = 0, so any radial direction serves)."""
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    r, R = np.hypot(x, y), np.linalg.norm(p, axis=1)
    a, c = 1.0 - 2.0 * nu, 1.0 / (2.0 * np.pi)
    s_rr = c * (a / (R * (R + z)) - 3.0 * z * r ** 2 / R ** 5)
    s_tt = -c * a * (1.0 / (R * (R + z)) - z / R ** 3)
    s_zz = -3.0 * c * z ** 3 / R ** 5
    s_rz = -3.0 * c * r * z ** 2 / R ** 5
    on_axis = r <= 1e-14 * R
    safe = np.where(on_axis, 1.0, r)
    cx, cy = np.where(on_axis, 1.0, x / safe), np.where(on_axis, 0.0, y / safe)
    sig = np.zeros((p.shape[0], 3, 3))
    sig[:, 0, 0] = s_rr * cx ** 2 + s_tt * cy ** 2
    sig[:, 1, 1] = s_rr * cy ** 2 + s_tt * cx ** 2
    sig[:, 0, 1] = sig[:, 1, 0] = (s_rr - s_tt) * cx * cy
    sig[:, 2, 2] = s_zz
    sig[:, 0, 2] = sig[:, 2, 0] = s_rz * cx
    sig[:, 1, 2] = sig[:, 2, 1] = s_rz * cy
    return sig


def _cerruti(p, nu: float) -> np.ndarray:
    """Stress per newton of a tangential force along +x at the origin (Cartesian closed
    form, regular everywhere but the origin)."""
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    R = np.linalg.norm(p, axis=1)
    Rz = R + z
    a, c = 1.0 - 2.0 * nu, 1.0 / (2.0 * np.pi)
    R3, R5 = R ** 3, R ** 5
    e = 1.0 / (R3 * Rz ** 2) + 2.0 / (R ** 2 * Rz ** 3)   # the (1 − 2ν) terms' common part
    sig = np.zeros((p.shape[0], 3, 3))
    sig[:, 0, 0] = c * (-3 * x ** 3 / R5 + a * (x / R3 - 3 * x / (R * Rz ** 2) + x ** 3 * e))
    sig[:, 1, 1] = c * (-3 * x * y ** 2 / R5 + a * (x / R3 - x / (R * Rz ** 2) + x * y ** 2 * e))
    sig[:, 2, 2] = -3 * c * x * z ** 2 / R5
    sig[:, 0, 1] = sig[:, 1, 0] = c * (-3 * x ** 2 * y / R5
                                       + a * (-y / (R * Rz ** 2) + x ** 2 * y * e))
    sig[:, 0, 2] = sig[:, 2, 0] = -3 * c * x ** 2 * z / R5
    sig[:, 1, 2] = sig[:, 2, 1] = -3 * c * x * y * z / R5
    return sig


def hemisphere_points(r_m: float, polar_steps: int = 90, azimuth_steps: int = 180) -> np.ndarray:
    """Points (k, 3) of the hemisphere of radius ``r_m`` in the local frame: polar angle
    from the inward normal in ``polar_steps`` equal steps up to the surface itself (depth
    0, where the tension is largest), ``azimuth_steps`` azimuths."""
    t = np.linspace(0.0, 0.5 * np.pi, polar_steps + 1)[1:]
    f = np.linspace(0.0, 2.0 * np.pi, azimuth_steps, endpoint=False)
    T, F = np.meshgrid(t, f, indexing="ij")
    T[-1] = 0.5 * np.pi
    pts = np.column_stack([np.sin(T).ravel() * np.cos(F).ravel(),
                           np.sin(T).ravel() * np.sin(F).ravel(), np.cos(T).ravel()])
    pts[-azimuth_steps:, 2] = 0.0   # the surface ring exactly: cos(π/2) is 6e-17
    return r_m * np.vstack([[0.0, 0.0, 1.0], pts])


def face_frame(inward_normal) -> np.ndarray:
    """Rotation (3, 3) whose rows are the local axes in global coordinates: z along
    ``inward_normal``; x along the global axis least aligned with it, projected on the
    surface; y = z × x."""
    n = np.asarray(inward_normal, float)
    n = n / np.linalg.norm(n)
    e = np.eye(3)[int(np.argmin(np.abs(n)))]
    ex = e - (e @ n) * n
    ex /= np.linalg.norm(ex)
    return np.vstack([ex, np.cross(n, ex), n])


def peak_tension_Pa(force_on_solid_N, inward_normal, nu: float, r_m: float,
                    background_Pa=None) -> tuple:
    """(largest principal stress in Pa over the hemisphere of radius ``r_m`` around a point
    force on a half-space, its point in the local frame of :func:`face_frame`).

    ``force_on_solid_N`` (3,) and ``inward_normal`` (3,) are in global axes;
    ``background_Pa`` (3, 3), global, is a uniform stress added to the point force's (the
    dam's static stress there), or None."""
    R = face_frame(inward_normal)
    local = R @ np.asarray(force_on_solid_N, float)
    pts = hemisphere_points(r_m)
    sig = point_force_stress(pts, local, nu)
    if background_Pa is not None:
        sig += R @ np.asarray(background_Pa, float) @ R.T
    s1 = np.linalg.eigvalsh(sig)[:, -1]
    i = int(np.argmax(s1))
    return float(s1[i]), pts[i]
