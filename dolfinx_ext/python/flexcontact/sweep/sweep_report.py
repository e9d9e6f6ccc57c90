"""``summary.json`` and ``report.md`` of a finished sweep (and its figures).

The report reads as a design note: outputs named in words with their definition, forces in
MN and stresses in MPa to three significant figures, each stress against the concrete's
tensile strength, correlations of the design outputs with the inputs. summary.json and
results.csv keep SI values at full precision.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from . import plots, stats
from .plots import CONDITIONAL
from .quantities import quantity, three_figures

PROBABILITIES = (0.5, 0.1, 0.01)
"""Exceedance probabilities at which the report quotes the value exceeded."""
TENSION_LAYER = 0.085
"""Depth, over the distance r from a point force on a half-space's face, within which the
face's radial tension halves (docs/dam.md, "The peak principal stress near the impact")."""


def exceeded_at(curve: dict) -> dict:
    """The smallest sample value x with P[X > x] ≤ p, for each p the sample resolves."""
    x, p = np.array(curve["x"]), np.array(curve["p"])
    out = {}
    for q in PROBABILITIES:
        if curve["n"] and q >= 1.0 / curve["n"]:
            out[str(q)] = float(x[np.argmax(p <= q)])
    return out


def tensile_strengths(rows: list, base: dict) -> np.ndarray:
    """f_t of each row (Pa): its swept value, or the base scenario's."""
    ft = float(base.get("concrete_tensile_strength_Pa", math.nan))
    return np.array([float(r["inputs"].get("concrete_tensile_strength_Pa", ft)) for r in rows])


def summarize(run: dict, rows: list, inputs: list, outputs: list, cfg) -> dict:
    """The summary of the sorted ``rows`` of a run (see :func:`flexcontact.sweep.run`)."""
    s = dict(run)
    s["dim"] = int(run.get("base", {}).get("dim", 2))
    s["counts"] = stats.total_counts(rows)
    s["input_ranges"] = input_ranges(rows, inputs)
    key = stats.key_outputs(outputs) or list(stats.KEY_OUTPUTS)
    s["worst"] = {}
    for o in key:
        r = stats.worst(rows, o)
        s["worst"][o] = None if r is None else {"id": r["id"], "value": r["outputs"][o],
                                                "inputs": r["inputs"], "outputs": r["outputs"]}
    s["spearman"] = stats.spearman(rows, inputs, stats.design_outputs(outputs))
    s["by_category"] = {n: stats.by_category(rows, n, key)
                        for n in inputs if stats.categorical(rows, n)}
    if cfg.method != "grid":
        s["exceedance"] = {"note": CONDITIONAL}
        ft = tensile_strengths(rows, run.get("base", {}))
        for o in key:
            values = stats.column(rows, o)
            curve = stats.exceedance(values, cfg.output["bootstrap"], cfg.output["band"],
                                     cfg.seed)
            curve["exceeded_at"] = exceeded_at(curve)
            if quantity(o, s["dim"]).stress and np.isfinite(ft).all():
                curve["above_tensile_strength"] = stats.probability_above(
                    values, ft, cfg.output["bootstrap"], cfg.output["band"], cfg.seed)
                curve["tensile_strength_Pa"] = (float(ft[0]) if np.ptp(ft) == 0 else None)
            s["exceedance"][o] = curve
    return s


def figures(folder: Path, summary: dict, rows: list, inputs: list, outputs: list) -> list:
    dim = summary.get("dim", 2)
    plotted = [o for o in stats.ENVELOPE_OUTPUTS if o in outputs] or list(outputs)
    paths = plots.envelope_plots(folder, rows, inputs, plotted, dim)
    for o, curve in summary.get("exceedance", {}).items():
        if o != "note" and curve["n"]:
            paths.append(plots.exceedance_plot(folder, o, curve, dim))
    return [p.name for p in paths]


def _band(a: dict) -> str:
    """P[X > f_t] and its band, as the report and the figures write it."""
    return (f"{three_figures(a['p'])} ({100 * a['band']:.0f} % bootstrap band "
            f"{three_figures(a['lower'])}–{three_figures(a['upper'])}; {a['above']} of "
            f"{a['n']} scenarios)")


def input_ranges(rows: list, inputs: list) -> dict:
    """{input: {"min", "median", "max"}} over the rows, or {"values": [...]} for a
    categorical one."""
    out = {}
    for n in inputs:
        values = [r["inputs"][n] for r in rows]
        if any(isinstance(v, str) for v in values):
            out[n] = {"values": sorted(set(map(str, values)))}
        elif values:
            v = np.array(values, float)
            out[n] = {"min": float(v.min()), "median": float(np.median(v)),
                      "max": float(v.max())}
    return out


def _inputs_table(dim: int, ranges: dict) -> list:
    L = ["| input | smallest | median | largest |", "|---|---|---|---|"]
    for n, r in ranges.items():
        q = quantity(n, dim)
        if "values" in r:
            L.append(f"| {q.words} | " + ", ".join(r["values"]) + " | | |")
        else:
            L.append(f"| {q.label()} | {q.show(r['min'])} | {q.show(r['median'])} | "
                     f"{q.show(r['max'])} |")
    return L


def markdown(summary: dict, inputs: list) -> str:
    """The engineer's report: what was swept, the design outputs in words, the most
    unfavourable scenarios, exceedance and the tensile strength, what drives the outputs,
    and (last) what the computation cost."""
    s = summary
    dim = s.get("dim", 2)
    base = s.get("base", {})
    q = {o: quantity(o, dim) for o in set(s["worst"]) | set(s["spearman"])}
    where = ("the 2D plane-strain section of the dam: forces and impulses are per metre of "
             "dam, as if a raft of logs abreast struck the whole crest — not one log"
             if dim == 2 else "the 3D dam block, one log: forces and impulses are totals")
    L = [f"# Debris impact on the dam: sweep `{s['config']}`", "",
         f"{s['scenarios']} impacts of a floating log on {where}. Scenarios drawn by "
         f"{'a grid' if s['method'] == 'grid' else s['method'].upper()} over "
         f"{len(inputs)} inputs; every other parameter is the base scenario's"
         + (f" (dam {three_figures(base['dam_height_m'])} m high"
            f", concrete tensile strength "
            f"{three_figures(base['concrete_tensile_strength_Pa'], 1e-6)} MPa)"
            if "dam_height_m" in base else "") + ". " + _end(base, inputs) + _mesh(s), ""]
    if s.get("input_ranges"):
        L += ["## Inputs", "", "The range each input took over the sweep.", "",
              *_inputs_table(dim, s["input_ranges"]), ""]
    L += ["## Design outputs", "", "| output | unit | definition |", "|---|---|---|"]
    offset = _stress_offset(s)
    for o in s["spearman"] or s["worst"]:
        d = q[o].definition
        if o in ("peak_tensile_stress_Pa", "halfspace_tension_Pa") and offset is not None:
            d += f" Read at {three_figures(offset)} m from it."
        L.append(f"| {q[o].words} | {q[o].unit} | {d} |")
    L += ["", "## Most unfavourable scenarios", "",
          "| output | value | scenario | " + " | ".join(quantity(n, dim).label()
                                                         for n in inputs) + " |",
          "|---|---|---|" + "---|" * len(inputs)]
    for o, w in s["worst"].items():
        if w is None:
            L.append(f"| {q[o].words} | (no finite value) | | " + " | " * len(inputs))
            continue
        L.append(f"| {q[o].words} | {q[o].show(w['value'])} {q[o].unit} | {w['id']} | "
                 + " | ".join(quantity(n, dim).show(w["inputs"][n]) for n in inputs) + " |")
    if "exceedance" in s:
        L += ["", "## Exceedance", "",
              f"P[X > x | impact]: the share of the sampled impacts above x, {CONDITIONAL}. "
              "The table gives the value exceeded with each probability (empirical; "
              "— where the sample is too small to resolve it). The figures "
              "`exceedance_<output>.png` show the whole curve with its bootstrap band.", "",
              "| output | " + " | ".join(f"p = {p}" for p in PROBABILITIES) + " |",
              "|---|" + "---|" * len(PROBABILITIES)]
        for o in s["worst"]:
            at = s["exceedance"][o]["exceeded_at"]
            L.append(f"| {q[o].label()} | " + " | ".join(
                q[o].show(at[str(p)]) if str(p) in at else "—" for p in PROBABILITIES) + " |")
        strength = [(o, s["exceedance"][o]) for o in s["worst"]
                    if "above_tensile_strength" in s["exceedance"][o]]
        if strength:
            ft = strength[0][1]["tensile_strength_Pa"]
            L += ["", "### Against the concrete's tensile strength", "",
                  (f"f_t = {three_figures(ft, 1e-6)} MPa." if ft is not None else
                   "f_t is swept: each scenario is compared with its own.")
                  + " The probability that an impact takes the stress above it:", ""]
            for o, c in strength:
                L.append(f"- {q[o].words}: P[X > f_t | impact] = "
                         f"{_band(c['above_tensile_strength'])}.")
    numeric = [n for n in inputs if n not in s.get("by_category", {})]
    if s["spearman"] and numeric:
        L += ["", "## What drives the design outputs", "",
              "Spearman's rank correlation of each design output with each numeric input: "
              "+1 when the output always grows with the input, −1 when it always falls, near "
              "0 when the input does not matter over its range (— where the input or the "
              "output did not vary).", "",
              "| output | " + " | ".join(quantity(n, dim).words for n in numeric) + " |",
              "|---|" + "---|" * len(numeric)]
        for o, d in s["spearman"].items():
            L.append(f"| {q[o].words} | " + " | ".join(
                "—" if not math.isfinite(d[n]) else f"{d[n]:+.2f}" for n in numeric) + " |")
    for name, table in s.get("by_category", {}).items():
        L += ["", f"## By {quantity(name, dim).words.lower()} (`{name}`)", "",
              "Per category: its scenarios, their median and largest value, and the share "
              "of them above the median and above the value exceeded with probability 0.1 "
              "among all scenarios (1/2 and 1/10 if the category does not matter).", "",
              "| output | category | n | median | largest | P[> median] | P[> 10 % value] |",
              "|---|---|---|---|---|---|---|"]
        for o, cats in table.items():
            qo = quantity(o, dim)
            for c, d in cats.items():
                if d["n"]:
                    L.append(f"| {qo.label()} | {c} | {d['n']} | {qo.show(d['median'])} | "
                             f"{qo.show(d['max'])} | {three_figures(d['p_over_median'])} | "
                             f"{three_figures(d['p_over_p10'])} |")
    if s.get("convergence"):
        L += ["", "## Mesh convergence of the most unfavourable scenarios", ""]
        by = {c.get("evaluator_refined") for c in s["convergence"].values()}
        if "monolithic" in by and s.get("evaluator") == "reuse":
            L += ["Re-run at refine + 1 by the monolithic evaluator (dam and log meshed and "
                  "factored together): the change covers the mesh and the factored dam's "
                  "face patch.", ""]
        L += ["| output | scenario | refine | value | refine + 1 | value | relative change |",
              "|---|---|---|---|---|---|---|"]
        for o, c in s["convergence"].items():
            L.append(f"| {q[o].label()} | {c['id']} | {c['refine']} | {q[o].show(c['value'])} "
                     f"| {c['refine'] + 1} | {q[o].show(c['value_refined'])} | "
                     f"{three_figures(100 * c['relative_change'])} % |")
    L += _computation(s)
    L += ["", "Figures: " + ", ".join(f"`{p}`" for p in s.get("figures", [])),
          "", "results.csv and summary.json hold every output of every scenario in SI units "
          "at full precision.", ""]
    return "\n".join(L)


def _end(base: dict, inputs: list = ()) -> str:
    """What the log's end does, in one sentence (the force depends on it first); its shape
    is the base scenario's unless the sweep samples it."""
    if "log_end_crushes" not in base:
        return ""
    end = ("end, its shape swept," if "log_end_shape" in inputs
           else f"{base.get('log_end_shape', 'flat')} end")
    if base["log_end_crushes"]:
        return (f"The log's {end} crushes at "
                f"{three_figures(base['wood_crushing_strength_Pa'], 1e-6)} MPa.")
    return (f"The log's {end} does not crush: the forces are the elastic bound of an "
            "intact log, above what a crushing end transmits.")


def _stress_offset(s: dict):
    """The distance from the first contact at which the stresses near the impact are read
    (the same in every scenario), or None."""
    return next((w["outputs"].get("stress_offset_m") for w in s.get("worst", {}).values()
                 if w), None)


def _mesh(s: dict) -> str:
    """The element sizes, and in 3D whether they resolve the stress near the impact."""
    m = s.get("mesh")
    if not m:
        return ""
    text = (f" Elements: the dam {three_figures(m['h_far_m'])} m far from the impact and "
            f"{three_figures(m['h_impact_m'])} m near it, the log "
            f"{three_figures(m['h_log_m'])} m")
    if m["h_contact_m"] < m["h_log_m"]:
        text += (f", its end {three_figures(m['h_contact_m'], 1e3)} mm within "
                 f"{three_figures(m['contact_zone_m'])} m of the first contact")
        if m.get("contact_layer_m") is not None:
            text += f" and {three_figures(m['contact_layer_m'], 1e3)} mm deep"
    text += "."
    offset = _stress_offset(s)
    if s.get("dim") == 3 and offset is not None and m["h_impact_m"] > TENSION_LAYER * offset:
        text += (f" At {three_figures(offset)} m from the impact the face's tension lies in a "
                 f"layer about {three_figures(TENSION_LAYER * offset, 1e2)} cm deep, "
                 f"thinner than the {three_figures(m['h_impact_m'])} m elements: the peak "
                 "principal stress read there is low and grows as the mesh is refined; the "
                 "half-space tension does not depend on the mesh.")
    return text + _crushing_steps(s)


def _crushing_steps(s: dict) -> str:
    """In 3D a crushing end's force is the crushing strength times its crushed area, which
    the end's elements count: where only a few crush, the force comes in steps of about
    σ_c·h², and scenarios share one peak force to the last digit. Said where the sample
    shows it, since such a tie looks like a bug or a cap."""
    base, m = s.get("base") or {}, s["mesh"]
    x = (s.get("exceedance") or {}).get("peak_force_filtered_N_per_m", {}).get("x")
    if s.get("dim") != 3 or not base.get("log_end_crushes") or not x:
        return ""
    tied = len(x) - len(set(x))  # each repeated value counted from its second scenario on
    if not tied:
        return ""
    step = base["wood_crushing_strength_Pa"] * m["h_contact_m"] ** 2
    return (f" The crushing end's force is the crushing strength times its crushed area, "
            f"counted in the end's {three_figures(m['h_contact_m'], 1e3)} mm elements: "
            f"where only a few of them crush, the force comes in steps of about σ_c·h² = "
            f"{three_figures(step, 1e-6)} MN, and {tied} of the {len(x)} scenarios "
            f"{'shares its' if tied == 1 else 'share their'} filtered peak force with another "
            "that came before it in the sample (docs/dam.md, \"The 3D sweep's trade-off\", "
            "gives this end's error).")


def _computation(s: dict) -> list:
    dt = s.get("dt_s")
    L = ["", "## Computation", "",
         f"Evaluator `{s['evaluator']}`, engine `{s['engine']}`"
         + (f", time step {three_figures(dt, 1e6)} µs" if dt is not None else "")
         + f"; {s['wall_s']:.1f} s this run ({s['computed_this_run']} scenarios computed, "
         f"{s['scenarios'] - s['computed_this_run']} from an earlier run).", ""]
    c = s["counts"]
    keys = sorted((set(c["factorizations"]) | set(c["back_substitutions"])
                   | set(c.get("restorations", {}))) - {"total"})
    keys.append("total")
    L += ["Factorizations and back-substitutions, summed over workers and runs:", "",
          "| | " + " | ".join(keys) + " |", "|---|" + "---|" * len(keys)]
    for kind in ("factorizations", "restorations", "back_substitutions"):
        if kind in c:
            L.append(f"| {kind.replace('_', '-')} | "
                     + " | ".join(str(c[kind].get(k, 0)) for k in keys) + " |")
    if "dam_model" in s:
        m = s["dam_model"]
        f = m["counts"]["factorizations"]
        L += ["", (f"The dam model `{m['path']}` was prepared by this run (factorizations of "
                   f"the dam and of the logs it keeps, once: {_named_counts(f)}; not in the "
                   "sums above) and every worker loaded it: "
                   if m["prepared_this_run"] else
                   f"Every worker loaded the dam model `{m['path']}`, prepared before: ")
              + "the dam's factors and the kept logs' are restored, not factored (row "
              "`restorations`)."]
        if "replaced" in m:
            L += ["", f"It replaced this sweep's earlier model, which no longer matched: "
                      f"{m['replaced']}"]
    if "counts_driver_check" in s:
        d = s["counts_driver_check"]
        L += ["", "Not in these sums: the evaluator the driving process built to check every "
              "scenario before computing: factorizations "
              f"{_named_counts(d['factorizations'])}; back-substitutions "
              f"{_named_counts(d['back_substitutions'])}."]
    return L


def _named_counts(counts: dict) -> str:
    """Counts named as the table's columns: "dam_stage1 1, dam_stage2 1, log 3"."""
    return ", ".join(f"{k} {v}" for k, v in counts.items())
