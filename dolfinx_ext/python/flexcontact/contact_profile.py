"""Interface profiles and the measurements the demos compare with theory (rank 0 data)."""
from __future__ import annotations

import numpy as np
from .errors import SolveError


def profile(problem, inc=None, axis: int = 0):
    """Slave-node positions along ``axis`` [m], pressure [Pa], tangential traction [Pa] and
    states of an increment (the last by default), sorted by position. Rank 0 only."""
    inc = inc if inc is not None else problem.increments[-1]
    pr = problem.pairs
    s = pr.x[:pr.m, axis]
    order = np.argsort(s)
    area = pr.area[order]
    lam = inc.lam[order]
    return (s[order], lam[:, 0] / area, lam[:, 1:] / area[:, None], inc.states[order],
            inc.slip_increment[order])


def hertz_fit(x, p, frac: float = 0.9):
    """Contact half-width a and peak pressure p0 from nodal pressures.

    a is the edge of the closed zone, located between the last loaded node and the first
    unloaded one by fitting p² = p0²(1 − x²/a²) to the nodes in the inner ``frac`` of the
    zone (the nodal pressure is smooth there, while the edge node carries a partial
    element). p0 is the largest nodal pressure. Returns (a, p0, a_extent) with a_extent the
    midpoint between the outermost loaded and the first unloaded node (an estimate good to
    half an element).
    """
    x, p = np.asarray(x), np.asarray(p)
    loaded = p > 1e-9 * p.max()
    xl = np.abs(x[loaded])
    outer = xl.max()
    beyond = np.abs(x[~loaded])
    beyond = beyond[beyond > outer]
    a_extent = 0.5 * (outer + beyond.min()) if beyond.size else outer
    inner = loaded & (np.abs(x) <= frac * outer)
    A = np.vstack([np.ones(inner.sum()), x[inner] ** 2]).T
    c0, c1 = np.linalg.lstsq(A, p[inner] ** 2, rcond=None)[0]
    a = float(np.sqrt(-c0 / c1)) if c1 < 0 < c0 else float("nan")
    return a, float(p.max()), float(a_extent)


def zone_halfwidth(x, mask):
    """Half-width of the zone where ``mask`` holds [m]: half the distance between the
    midpoints that separate it from its neighbours on each side (half an element each)."""
    x = np.asarray(x)
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return 0.0
    lo, hi = idx.min(), idx.max()
    left = 0.5 * (x[lo] + x[lo - 1]) if lo > 0 else x[lo]
    right = 0.5 * (x[hi] + x[hi + 1]) if hi + 1 < x.size else x[hi]
    return 0.5 * (right - left)


def elliptic_fit(x, p, frac: float = 0.9):
    """Half-width a [m] and peak p0 [Pa] of the ellipse p² = p0²(1 − x²/a²) fitted by least
    squares to the loaded nodes inside ``frac`` of the closed zone. Unlike the largest nodal
    pressure, the fitted p0 averages out node-to-node oscillations (those of single-pass
    node–surface pairs on non-matching meshes)."""
    x, p = np.asarray(x), np.asarray(p)
    loaded = p > 1e-9 * p.max()
    inner = loaded & (np.abs(x) <= frac * np.abs(x[loaded]).max())
    A = np.vstack([np.ones(inner.sum()), x[inner] ** 2]).T
    c0, c1 = np.linalg.lstsq(A, p[inner] ** 2, rcond=None)[0]
    if not c1 < 0 < c0:
        return float("nan"), float("nan")
    return float(np.sqrt(-c0 / c1)), float(np.sqrt(c0))


def approach_to_load(problem, set_approach, trial_m: float, target_force: float,
                     increments: int, exponent: float = 1.0, force_scale: float = 1.0):
    """A ``load(i, t)`` callback for ``ContactProblem.solve`` that reaches a target contact
    force by prescribed approach δ, when the δ that gives it is not known beforehand.

    Increment 1 applies ``trial_m``; its normal force P₁ (times ``force_scale``, e.g. 4 for
    a quarter model) fixes the final approach δ = trial · (target_force / P₁)^``exponent``
    (1 in 2D, where P grows almost linearly with δ; 2/3 for Hertz in 3D, δ ∝ P^(2/3)), and
    the remaining increments ramp δ linearly from the trial to it (``increments`` ≥ 2).
    ``set_approach(δ)`` applies an approach in metres (a Dirichlet value, a rigid target's
    displacement, ...).
    """
    final = []

    def load(i, t):
        if i == 1:
            set_approach(trial_m)
            return
        if not final:
            P1 = force_scale * problem.increments[-1].summary.normal_force
            if P1 <= 0:
                raise SolveError("the trial approach produced no contact force")
            final.append(trial_m * (target_force / P1) ** exponent)
        set_approach(trial_m + (final[0] - trial_m) * (i - 1) / (max(increments, 2) - 1))

    return load
