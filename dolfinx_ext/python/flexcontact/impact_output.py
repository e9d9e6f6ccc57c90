"""What an impact run reports: contact force history, its peak, duration and impulse, the
energy account against time, as CSV, PNG and summary entries (rank 0 writes)."""
from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Optional, Sequence, Union

import numpy as np

ENERGY_COLUMNS = ("kinetic", "strain", "external_work", "friction", "damping", "contact",
                  "crushing", "numerical", "total", "balance_error")


def moving_average(values: np.ndarray, window_steps: int) -> np.ndarray:
    """Centred moving average over ``window_steps`` steps (made odd; 1: the values as they
    are), zero outside the history."""
    k = max(int(window_steps), 1)
    k += 1 - k % 2
    return np.convolve(np.asarray(values, float), np.full(k, 1.0 / k), mode="same")


def filter_steps(window_s: Optional[float], dt_s: float) -> int:
    """Steps of the peak-force filter: ``window_s`` / dt rounded, odd, at least 1."""
    if window_s is None or not window_s > 0:
        return 1
    k = max(int(round(window_s / dt_s)), 1)
    return k + 1 - k % 2


def force_at_filtered_peak(normal_force, force_vectors, window_steps: int) -> np.ndarray:
    """The force vector (d,) at the step where the filtered normal force peaks, filtered
    the same way (the centred moving average of :func:`contact_metrics`): the direction of
    the force the filtered peak force stands for. ``normal_force`` (n,), ``force_vectors``
    (n, d), one row per step."""
    F = np.asarray(normal_force, float)
    V = np.asarray(force_vectors, float).reshape(F.size, -1)
    if not F.size:
        return np.zeros(V.shape[1])
    i = int(np.argmax(moving_average(F, window_steps)))
    return np.array([moving_average(V[:, k], window_steps)[i] for k in range(V.shape[1])])


def contact_metrics(records: Sequence, dt_s: float, threshold: float = 1e-6,
                    filter_window_s: Optional[float] = None) -> dict:
    """Peak force, filtered peak force, contact start, end and duration, impulse, mean force
    and episodes.

    A step is in contact when its mean normal force exceeds ``threshold`` × the peak. The
    duration runs from the start of the first such step to the end of the last one;
    ``episodes`` counts separate runs of contact steps (1 for a clean impact).

    ``peak_force_filtered`` is the peak of the force's centred moving average over
    ``filter_window_s`` (rounded to an odd number of steps; None: no filter, the raw peak).
    A discrete wave front overshoots: the first steps of an elastic bar's force pulse exceed
    the plateau ρcAv by 8–28 % (Courant number 1 to 0.5), a ringing of the mesh, not of the
    bar. Averaged over a tenth of the pulse (2L/c/10), the rectangle of the exact pulse keeps
    its plateau and the overshoot is gone (docs/impact.md).
    """
    F = np.array([r.normal_force for r in records])
    peak = float(F.max(initial=0.0))
    on = F > threshold * peak if peak > 0 else np.zeros(F.size, bool)
    window = filter_steps(filter_window_s, dt_s)
    if not on.any():
        return {"peak_force": 0.0, "peak_force_filtered": 0.0,
                "filter_window_s": window * dt_s, "contact_duration_s": 0.0, "impulse": 0.0,
                "mean_force": 0.0, "contact_start_s": None, "contact_end_s": None,
                "episodes": 0}
    idx = np.flatnonzero(on)
    t_end = np.array([r.t_s for r in records])
    start, end = float(t_end[idx[0]] - dt_s), float(t_end[idx[-1]])
    impulse = float(F.sum() * dt_s)
    episodes = int(on[0]) + int(np.count_nonzero(np.diff(on.astype(int)) == 1))
    return {"peak_force": peak,
            "peak_force_filtered": float(moving_average(F, window).max(initial=0.0)),
            "filter_window_s": window * dt_s,
            "contact_duration_s": end - start, "impulse": impulse,
            "mean_force": impulse / (end - start), "contact_start_s": start,
            "contact_end_s": end, "episodes": episodes}


def write_history_csv(path: Union[str, os.PathLike], records: Sequence, energy0: float) -> None:
    """One row per step: time, normal force, the slave force components, the energies."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    d = len(records[0].slave_force) if records else 0
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["t_s", "normal_force"] + [f"force_{c}" for c in "xyz"[:d]]
                   + list(ENERGY_COLUMNS) + ["active_pairs", "back_substitutions"])
        w.writerow([0.0, 0.0] + [0.0] * d + [0.0] * (len(ENERGY_COLUMNS) - 2)
                   + [energy0, 0.0] + [0, 0])
        for r in records:
            w.writerow([repr(r.t_s), repr(r.normal_force)] + [repr(x) for x in r.slave_force]
                       + [repr(r.energy[k]) for k in ENERGY_COLUMNS]
                       + [r.active, r.back_substitutions])


def plot_history(path: Union[str, os.PathLike], records: Sequence, title: str,
                 force_ref: float = None, duration_ref: float = None,
                 start_s: float = 0.0, force_unit: str = "N", energy_unit: str = "J") -> None:
    """Contact force and energies against time, one PNG with two panels (units as given:
    per unit thickness in 2D)."""
    from .output import pyplot
    plt = pyplot()
    t = np.array([r.t_s for r in records]) * 1e3
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    a1.step(t, [r.normal_force for r in records], where="pre", label="contact force")
    if force_ref is not None and duration_ref is not None:
        a1.plot(np.array([start_s, start_s, start_s + duration_ref, start_s + duration_ref])
                * 1e3, [0, force_ref, force_ref, 0], "k--", lw=0.8, label="1D theory")
    a1.set_xlabel("t [ms]")
    a1.set_ylabel(f"contact force [{force_unit}]")
    a1.set_title(title)
    a1.legend()
    a1.grid(alpha=0.3)
    for key, style in (("kinetic", "-"), ("strain", "-"), ("contact", "--"),
                       ("friction", "--"), ("damping", "--"), ("numerical", ":"),
                       ("total", "k-")):
        a2.plot(t, [r.energy[key] for r in records], style, label=key)
    a2.set_xlabel("t [ms]")
    a2.set_ylabel(f"energy [{energy_unit}]")
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def cost_summary(records: Sequence) -> dict:
    """Back-substitutions per step: mean, and medians of steps with and without contact."""
    b = np.array([r.back_substitutions for r in records])
    on = np.array([r.active > 0 for r in records])
    med = lambda x: float(np.median(x)) if x.size else None  # noqa: E731
    return {"back_substitutions_per_step": float(b.mean()) if b.size else 0.0,
            "median_with_contact": med(b[on]), "median_without_contact": med(b[~on]),
            "steps": int(b.size), "steps_with_contact": int(on.sum())}
