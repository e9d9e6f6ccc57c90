"""``summary.json`` and ``report.md`` of a finished sweep (and its figures)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from . import plots, stats
from .plots import CONDITIONAL

PROBABILITIES = (0.5, 0.1, 0.01)
"""Exceedance probabilities at which the report quotes the value exceeded."""


def exceeded_at(curve: dict) -> dict:
    """The smallest sample value x with P[X > x] ≤ p, for each p the sample resolves."""
    x, p = np.array(curve["x"]), np.array(curve["p"])
    out = {}
    for q in PROBABILITIES:
        if curve["n"] and q >= 1.0 / curve["n"]:
            out[str(q)] = float(x[np.argmax(p <= q)])
    return out


def summarize(run: dict, rows: list, inputs: list, outputs: list, cfg) -> dict:
    """The summary of the sorted ``rows`` of a run (see :func:`flexcontact.sweep.run`)."""
    s = dict(run)
    s["counts"] = stats.total_counts(rows)
    s["worst"] = {}
    for o in stats.KEY_OUTPUTS:
        r = stats.worst(rows, o)
        s["worst"][o] = None if r is None else {"id": r["id"], "value": r["outputs"][o],
                                                "inputs": r["inputs"], "outputs": r["outputs"]}
    s["spearman"] = stats.spearman(rows, inputs, outputs)
    s["by_category"] = {n: stats.by_category(rows, n, list(stats.KEY_OUTPUTS))
                        for n in inputs if stats.categorical(rows, n)}
    if cfg.method != "grid":
        s["exceedance"] = {"note": CONDITIONAL}
        for o in stats.KEY_OUTPUTS:
            curve = stats.exceedance(stats.column(rows, o), cfg.output["bootstrap"],
                                     cfg.output["band"], cfg.seed)
            curve["exceeded_at"] = exceeded_at(curve)
            s["exceedance"][o] = curve
    return s


def figures(folder: Path, summary: dict, rows: list, inputs: list, outputs: list) -> list:
    plotted = [o for o in outputs if o in stats.ENVELOPE_OUTPUTS] or list(outputs)
    paths = plots.envelope_plots(folder, rows, inputs, plotted)
    for o, curve in summary.get("exceedance", {}).items():
        if o != "note" and curve["n"]:
            paths.append(plots.exceedance_plot(folder, o, curve))
    return [p.name for p in paths]


def _fmt(v) -> str:
    if isinstance(v, str):
        return v
    if isinstance(v, int):
        return str(v)
    return "nan" if v is None or not math.isfinite(v) else f"{v:.6g}"


def markdown(summary: dict, inputs: list) -> str:
    """The engineer's report: worst cases, exceedance, rank correlations, counts."""
    s = summary
    L = [f"# Sweep `{s['config']}`", "",
         f"{s['scenarios']} scenarios ({s['method']}), evaluator `{s['evaluator']}`, engine "
         f"`{s['engine']}`, time step {s['dt_s']:.6g} s, wall time {s['wall_s']:.1f} s "
         f"this run ({s['computed_this_run']} scenarios computed, "
         f"{s['scenarios'] - s['computed_this_run']} from an earlier run).", "",
         "## Most unfavourable scenarios", "",
         "| output | value | id | " + " | ".join(inputs) + " |",
         "|---|---|---|" + "---|" * len(inputs)]
    for o, w in s["worst"].items():
        if w is None:
            L.append(f"| {o} | (no finite value) | | " + " | " * len(inputs))
            continue
        L.append(f"| {o} | {_fmt(w['value'])} | {w['id']} | "
                 + " | ".join(_fmt(w["inputs"][n]) for n in inputs) + " |")
    if "exceedance" in s:
        L += ["", "## Exceedance", "", f"P[X > x] among the sampled impacts: {CONDITIONAL}. "
              "The value x exceeded with probability p (empirical), figures "
              "`exceedance_<output>.png` with the bootstrap band.", "",
              "| output | " + " | ".join(f"p = {p}" for p in PROBABILITIES) + " |",
              "|---|" + "---|" * len(PROBABILITIES)]
        for o in stats.KEY_OUTPUTS:
            at = s["exceedance"][o]["exceeded_at"]
            L.append(f"| {o} | " + " | ".join(_fmt(at.get(str(p))) if str(p) in at else "—"
                                              for p in PROBABILITIES) + " |")
    numeric = [n for n in inputs if n not in s.get("by_category", {})]
    L += ["", "## Rank correlation (Spearman) of each output with each numeric input", "",
          "| output | " + " | ".join(numeric) + " |", "|---|" + "---|" * len(numeric)]
    for o, d in s["spearman"].items():
        L.append(f"| {o} | " + " | ".join(_fmt(d[n]) for n in numeric) + " |")
    for name, table in s.get("by_category", {}).items():
        L += ["", f"## By `{name}`", "",
              "Per category: its scenarios, their median and largest value, and the share "
              "of them above the median and above the value exceeded with probability 0.1 "
              "among all scenarios (1/2 and 1/10 if the category does not matter).", "",
              "| output | category | n | median | max | P[> median] | P[> 10 % value] |",
              "|---|---|---|---|---|---|---|"]
        for o, cats in table.items():
            for c, d in cats.items():
                if d["n"]:
                    L.append(f"| {o} | {c} | {d['n']} | {_fmt(d['median'])} | "
                             f"{_fmt(d['max'])} | {_fmt(d['p_over_median'])} | "
                             f"{_fmt(d['p_over_p10'])} |")
    c = s["counts"]
    keys = sorted((set(c["factorizations"]) | set(c["back_substitutions"])) - {"total"})
    keys.append("total")
    L += ["", "## Factorizations and back-substitutions (summed over workers and runs)", "",
          "| | " + " | ".join(keys) + " |", "|---|" + "---|" * len(keys)]
    for kind in ("factorizations", "back_substitutions"):
        L.append(f"| {kind.replace('_', '-')} | "
                 + " | ".join(str(c[kind].get(k, 0)) for k in keys) + " |")
    if "counts_driver_check" in s:
        d = s["counts_driver_check"]
        L += ["", "Not in these sums: the evaluator the driving process built to check every "
              f"scenario before computing: factorizations {d['factorizations']}, "
              f"back-substitutions {d['back_substitutions']}."]
    if s.get("convergence"):
        L += ["", "## Mesh convergence of the most unfavourable scenarios", "",
              "| output | id | refine | value | refine + 1 | value | relative change |",
              "|---|---|---|---|---|---|---|"]
        for o, c in s["convergence"].items():
            L.append(f"| {o} | {c['id']} | {c['refine']} | {_fmt(c['value'])} | "
                     f"{c['refine'] + 1} | {_fmt(c['value_refined'])} | "
                     f"{_fmt(c['relative_change'])} |")
    L += ["", "Figures: " + ", ".join(f"`{p}`" for p in s.get("figures", [])), ""]
    return "\n".join(L)
