"""What the engineer reads off a finished table: the most unfavourable scenario of each
output, its empirical exceedance curve with a bootstrap band, the rank correlation of each
output with each input, and the factorization counts summed over workers.

The exceedance probability is P[X > x] among the swept scenarios: for a sampled sweep, the
probability that an impact drawn from the configured distributions exceeds x — conditional
on an impact happening, not an annual probability.
"""
from __future__ import annotations

import numpy as np

KEY_OUTPUTS = ("peak_force_N_per_m", "heel_stress_impact_Pa", "peak_tensile_stress_Pa",
               "halfspace_tension_Pa")
"""The outputs whose most unfavourable case is reported (largest is worst), with the
filtered peak force where the evaluator gives it (:func:`key_outputs`)."""
DESIGN_OUTPUTS = ("peak_force_filtered_N_per_m", "peak_force_N_per_m", "impulse_N_s_per_m",
                  "heel_stress_impact_Pa", "toe_stress_impact_Pa", "peak_tensile_stress_Pa",
                  "halfspace_tension_Pa")
"""The outputs a design reads: their rank correlations with the inputs are reported (the
others — counts, steps, the time step, the log's own kinematics — stay in the table)."""
ENVELOPE_OUTPUTS = DESIGN_OUTPUTS + ("contact_duration_s", "peak_contact_pressure_Pa")
"""The outputs an engineer reads off envelope plots."""


def key_outputs(outputs) -> list:
    """The outputs whose worst case and exceedance are reported, among ``outputs``: the
    filtered peak force first where there is one."""
    return [o for o in ("peak_force_filtered_N_per_m",) + KEY_OUTPUTS if o in outputs]


def design_outputs(outputs) -> list:
    """:data:`DESIGN_OUTPUTS` among ``outputs``, in that order."""
    return [o for o in DESIGN_OUTPUTS if o in outputs]


def column(rows: list, output: str) -> np.ndarray:
    return np.array([float(r["outputs"].get(output, np.nan)) for r in rows])


def worst(rows: list, output: str):
    """The row with the largest finite value of ``output`` (None if there is none)."""
    x = column(rows, output)
    ok = np.isfinite(x)
    if not ok.any():
        return None
    return rows[int(np.flatnonzero(ok)[np.argmax(x[ok])])]


def exceedance(values, bootstrap: int, band: float, seed: int) -> dict:
    """Empirical P[X > x] at the sorted finite values, and its two-sided ``band`` from
    ``bootstrap`` resamples (numpy Generator of ``seed``), percentiles of the resampled
    curves at the same x."""
    x = np.sort(np.asarray(values, float)[np.isfinite(values)])
    n = x.size
    if n == 0:
        return {"x": [], "p": [], "lower": [], "upper": [], "n": 0}
    p = _survival(x, x)
    rng = np.random.default_rng(seed)
    curves = np.empty((bootstrap, n))
    for b in range(bootstrap):
        curves[b] = _survival(np.sort(rng.choice(x, size=n, replace=True)), x)
    q = 100.0 * (1.0 - band) / 2.0
    lower, upper = np.percentile(curves, [q, 100.0 - q], axis=0)
    return {"x": x.tolist(), "p": p.tolist(), "lower": lower.tolist(),
            "upper": upper.tolist(), "n": int(n), "band": band, "bootstrap": bootstrap}


def probability_above(values, limits, bootstrap: int, band: float, seed: int) -> dict:
    """P[X > limit] as the fraction of finite ``values`` above their ``limits`` (one per
    value, or one for all), and its two-sided ``band`` from ``bootstrap`` resamples of the
    (value, limit) pairs (numpy Generator of ``seed``)."""
    x = np.asarray(values, float)
    f = np.broadcast_to(np.asarray(limits, float), x.shape)
    ok = np.isfinite(x)
    above = (x[ok] > f[ok]).astype(float)
    n = above.size
    if n == 0:
        return {"p": float("nan"), "lower": float("nan"), "upper": float("nan"), "n": 0}
    rng = np.random.default_rng(seed)
    resampled = np.array([above[rng.integers(0, n, n)].mean() for _ in range(bootstrap)])
    q = 100.0 * (1.0 - band) / 2.0
    lower, upper = np.percentile(resampled, [q, 100.0 - q])
    return {"p": float(above.mean()), "lower": float(lower), "upper": float(upper),
            "n": int(n), "above": int(above.sum()), "band": band, "bootstrap": bootstrap}


def _survival(sample_sorted: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Fraction of the sample strictly greater than each value of ``at``."""
    n = sample_sorted.size
    return (n - np.searchsorted(sample_sorted, at, side="right")) / n


def categorical(rows: list, name: str) -> bool:
    """Whether the input ``name`` takes names (a categorical input), not numbers."""
    return any(isinstance(r["inputs"][name], str) for r in rows)


def spearman(rows: list, inputs: list, outputs: list) -> dict:
    """{output: {input: Spearman ρ}} over the numeric inputs; NaN where an input or output
    is constant."""
    from scipy.stats import spearmanr
    out = {}
    numeric = [n for n in inputs if not categorical(rows, n)]
    for o in outputs:
        y = column(rows, o)
        out[o] = {}
        for name in numeric:
            x = np.array([float(r["inputs"][name]) for r in rows])
            ok = np.isfinite(y)
            if ok.sum() < 3 or np.ptp(x[ok]) == 0 or np.ptp(y[ok]) == 0:
                out[o][name] = float("nan")
            else:
                out[o][name] = float(spearmanr(x[ok], y[ok]).correlation)
    return out


def by_category(rows: list, name: str, outputs: list) -> dict:
    """{output: {category: {n, median, max, p_over_median, p_over_p10}}} for a categorical
    input ``name``: per category, the share of its scenarios above the value all scenarios
    exceed with probability 1/2 and 1/10 (so a category that carries the tail shows it)."""
    cats = sorted({r["inputs"][name] for r in rows})
    out = {}
    for o in outputs:
        y = column(rows, o)
        ok = np.isfinite(y)
        if not ok.any():
            continue
        x50, x10 = np.quantile(y[ok], [0.5, 0.9])
        out[o] = {}
        for c in cats:
            yc = np.array([v for v, r in zip(y, rows) if r["inputs"][name] == c])
            yc = yc[np.isfinite(yc)]
            out[o][c] = ({"n": int(yc.size), "median": float(np.median(yc)),
                          "max": float(yc.max()), "p_over_median": float(np.mean(yc > x50)),
                          "p_over_p10": float(np.mean(yc > x10))} if yc.size else
                         {"n": 0})
    return out


def total_counts(rows: list) -> dict:
    """Factorizations and back-substitutions summed over rows (each row carries what its
    worker added, the first row of a worker its set-up too), per stage and in all."""
    tot = {"factorizations": {}, "back_substitutions": {}}
    for r in rows:
        for kind, d in r.get("counts", {}).items():
            for k, v in d.items():
                d_kind = tot.setdefault(kind, {})
                d_kind[k] = d_kind.get(k, 0) + int(v)
    for kind in list(tot):
        tot[kind]["total"] = sum(v for k, v in tot[kind].items() if k != "total")
    return tot
