"""Rigid-multibody local problems: walls of rigid bricks on the ground, one time step.

Shared by tests/test_rigid_multibody.py (a sample in CI) and bench/rigid_multibody.py (the
comparison with Siconos' NSN_AC). These are the problems a rigid-body code hands its
frictional contact solver at each time step (Moreau–Jean, velocity level): with body
velocities V (6 per brick: v, ω), masses M and the contact Jacobian H (3 rows per contact
point: the normal, then two tangents, of the upper body's velocity relative to the lower's),

    u = W λ + q,   W = H M⁻¹ Hᵀ,   q = H (V⁻ + h M⁻¹ f),

λ the contact impulses. A brick resting on two bricks of the course below touches them at the
8 corners of the two overlaps, 24 unknowns against its 6 degrees of freedom: W is rank-deficient
(rank ≤ 6 × bricks, a third to a half of its size), and the impulses are not unique, though
the velocities are. Several hundred contacts per wall; no known solution (judged by the
residuals only). Siconos' fc3d uses the same local frame and sign convention.
"""
from __future__ import annotations

import numpy as np

from random_problems import RandomProblem

GRAVITY_M_S2 = 9.81
DENSITY_KG_M3 = 2000.0


def _frame():
    return np.eye(3)[[2, 0, 1]]  # rows: normal +z, tangents x, y


def _rows(e3, point, centre):
    """3 × 6 Jacobian rows of a body at ``point`` for the directions in the rows of e3."""
    r = point - centre
    return np.hstack([e3, np.cross(r, e3)])


def make_wall(rng: np.random.Generator, courses: int, per_course: int, index: int = 0,
              h_s: float = 0.01, at_rest: bool = False) -> RandomProblem:
    """One wall in running bond: ``courses`` rows of ``per_course`` bricks (0.4 × 0.2 ×
    0.1 m, each jittered by up to 2 cm along the wall), the odd rows shifted by half a brick,
    the first row on the ground. μ is drawn from 0.2–1.0 for the whole wall; a few bricks are
    pushed sideways or moving already, so some contacts stick, some slip and some open."""
    a, b, c = 0.4, 0.2, 0.1
    mass = DENSITY_KG_M3 * a * b * c
    inertia = mass / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    bricks = []  # (x_left, course)
    for k in range(courses):
        # At rest: stack bond, every brick centred over the one below (in running bond the
        # last brick of a shifted course may overhang its support by half, and tip).
        shift = 0.0 if at_rest else 0.5 * a * (k % 2)
        for j in range(per_course):
            bricks.append((j * a + shift + rng.uniform(-0.02, 0.02), k))
    nb = len(bricks)
    centres = np.array([[x + a / 2, 0.0, (k + 0.5) * c] for x, k in bricks])
    e3 = _frame()
    rows, contacts = [], []
    for i, (x, k) in enumerate(bricks):
        supports = [(None, 0.0, 1e9)] if k == 0 else [
            (j, xj, xj + a) for j, (xj, kj) in enumerate(bricks) if kj == k - 1]
        for j, lo, hi in supports:
            left, right = max(x, lo if j is not None else x), min(x + a, hi)
            if right - left < 0.01:  # no overlap worth a contact (1 cm)
                continue
            for px in (left, right):
                for py in (-b / 2, b / 2):
                    point = np.array([px, py, k * c])
                    H = np.zeros((3, 6 * nb))
                    H[:, 6 * i:6 * i + 6] = _rows(e3, point, centres[i])
                    if j is not None:
                        H[:, 6 * j:6 * j + 6] = -_rows(e3, point, centres[j])
                    rows.append(H)
                    contacts.append((i, j))
    H = np.vstack(rows)
    Minv = np.tile(np.concatenate([np.full(3, 1.0 / mass), 1.0 / inertia]), nb)
    W = (H * Minv) @ H.T
    W = 0.5 * (W + W.T)
    # Velocities before the step and forces: gravity on all; a sideways push on a tenth of
    # the bricks (0.5–3 times the weight), and a few moving already (up to 0.2 m/s).
    V = np.zeros(6 * nb)
    f = np.zeros(6 * nb)
    f[2::6] = -mass * GRAVITY_M_S2
    pushed = rng.choice(nb, size=0 if at_rest else max(1, nb // 10), replace=False)
    f[6 * pushed + rng.integers(0, 2, pushed.size)] += (
        rng.choice([-1.0, 1.0], pushed.size) * rng.uniform(0.5, 3.0, pushed.size) * mass
        * GRAVITY_M_S2)
    moving = rng.choice(nb, size=0 if at_rest else max(1, nb // 20), replace=False)
    V[(6 * moving[:, None] + np.arange(3)).ravel()] = rng.uniform(-0.2, 0.2, 3 * moving.size)
    q = H @ (V + h_s * Minv * f)
    m = len(contacts)
    mu = np.full(m, rng.uniform(0.2, 1.0))
    name = f"rigid_multibody-3d-m{m}-{index}" + ("-at-rest" if at_rest else "")
    problem = RandomProblem(name, "rigid_multibody", 3, W, q, mu, np.full(3 * m, np.nan))
    problem.on_ground = np.array([j is None for _, j in contacts])
    problem.weight_N = nb * mass * GRAVITY_M_S2
    problem.h_s = h_s
    return problem


def sample(seed: int, count: int, courses=(3, 6), per_course=(4, 9)):
    """``count`` walls of random size, reproducible from the seed."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        k = int(rng.integers(courses[0], courses[1] + 1))
        n = int(rng.integers(per_course[0], per_course[1] + 1))
        out.append(make_wall(rng, k, n, i))
    return out
