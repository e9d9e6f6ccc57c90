"""One sweep from a checked config to its table and report (see the package docstring)."""
from __future__ import annotations

import math
import shutil
import time
from dataclasses import replace
from pathlib import Path
from typing import Optional, TextIO, Union

from . import engines, evaluators, sweep_report
from .config import SweepConfig, check_engine
from .errors import ConfigError
from .evaluators import EvaluatorSpec
from .progress import Progress
from .scenarios import build_scenarios, point_hash
from .table import ResultTable


DEFAULT_MODEL = "dam_model"
"""The folder, inside a sweep's output folder, of the dam model the "reuse" evaluator's
workers load when engine.model is not given."""


def prepare(cfg: SweepConfig, folder: Optional[Path] = None) -> dict:
    """Everything decided before computing: scenarios (all checked), the evaluator (it must
    import), the sweep's time step and water levels, and, for the "reuse" evaluator, the dam
    model every worker loads instead of factoring the dam: engine.model, or by default
    ``folder/dam_model``, prepared there once if it is not there yet, so that a resumed or
    repeated sweep factors nothing of the dam. ``engine.model = false`` has each worker
    factor the dam and compute its response functions itself (the driving process too, to
    check the scenarios): cheaper only for a few scenarios on the 3D block
    (docs/dam.md, "Sweeps")."""
    base, points, scenarios = build_scenarios(cfg)
    cls, _ = evaluators.resolve(cfg.engine["evaluator"])
    dt = evaluators.sweep_time_step(cfg.engine["evaluator"], scenarios)
    levels = [float(s.water_level_m) for s in scenarios]
    face = None
    if cfg.engine["evaluator"] == "reuse":
        from ..dam.dam_model import face_region_m
        strip, patch = face_region_m(base, scenarios, (min(levels), max(levels)))
        face = {"strip_m": strip, "patch_y_m": patch}
    spec = EvaluatorSpec(cfg.engine["evaluator"], base, dt, (min(levels), max(levels)),
                         face=face)
    prep = {"base": base, "points": points, "scenarios": scenarios, "spec": spec, "dt_s": dt,
            "checker": None}
    model, owned = model_path(cfg, folder)
    if model is not None:
        if owned:
            # A changed config is the table's refusal to make, before a model is prepared
            # for a sweep that will not run.
            ResultTable(folder, cfg.hash(), [point_hash(p) for p in points]).check()
        prep["model"] = dam_model(model, base, dt, levels, face, scenarios, owned=owned)
        spec = prep["spec"] = replace(spec, model=str(model.resolve()), model_if_seen=owned)
    if hasattr(cls, "check"):
        prep["checker"] = check_all(spec, points, scenarios)
    return prep


def model_path(cfg: SweepConfig, folder: Optional[Path]) -> tuple:
    """(the dam model directory the workers load or None, whether it is the sweep's own:
    ``folder/dam_model``, which this sweep may replace)."""
    m = cfg.engine.get("model")
    if cfg.engine["evaluator"] != "reuse" or m is False:
        return None, False
    if m is not None:
        return Path(m), False
    if folder is None:
        return None, False
    return Path(folder) / DEFAULT_MODEL, True


def dam_model(path: Path, base, dt: float, levels: list, face: Optional[dict] = None,
              scenarios=(), owned: bool = False) -> dict:
    """The dam model at ``path`` for this sweep: prepared there once (atomically) if absent,
    else checked against the sweep's dam and time step (ConfigError naming what differs);
    it keeps the log models of ``scenarios`` (model_file.logs_of). A sweep's own model
    (``owned``) that no longer matches (a model of an earlier format, or of other defaults)
    is prepared again instead; the reason is kept under "replaced".
    Returns {"path", "prepared_this_run", "counts"}: the factorizations its preparation
    cost."""
    from ..dam import model_file
    from ..errors import SavedFileError
    replaced = None
    if owned and (path / "manifest.json").is_file():
        try:
            _check_model(path, base, dt)
        except (ConfigError, SavedFileError) as e:
            replaced = str(e)
            shutil.rmtree(path)
    prepared = not (path / "manifest.json").is_file()
    try:
        if prepared:
            distinct = sorted(set(levels))
            manifest = model_file.prepare(base, dt, (min(levels), max(levels)), path,
                                          levels=distinct if len(distinct) <= 8 else None,
                                          progress=lambda *a: None,
                                          logs=model_file.logs_of(base, scenarios),
                                          **(face or {}))
        else:
            manifest = _check_model(path, base, dt)
    except SavedFileError as e:
        raise ConfigError(f"engine.model={str(path)!r}: {e}") from None
    lo, hi = manifest["inputs"]["water_levels_m"]
    if not (lo <= min(levels) and max(levels) <= hi):
        raise ConfigError(f"engine.model={str(path)!r}: its water levels {lo}..{hi} m do not "
                          f"cover the sweep's {min(levels)}..{max(levels)} m")
    out = {"path": str(path), "prepared_this_run": prepared, "counts": manifest["counts"]}
    if replaced is not None:
        out["replaced"] = replaced
    return out


def _check_model(path: Path, base, dt: float) -> dict:
    """The manifest of the model at ``path`` if it is of this dam and time step; else
    SavedFileError or ConfigError naming what differs."""
    from ..dam import model_file
    manifest = model_file.read_manifest(path, every_file=True)
    model_file.check_inputs(manifest, base)
    saved_dt = manifest["inputs"]["dt_s"]
    if float(dt) != saved_dt:
        # The step is the sample's, not the dam's: say so, or a trial with another n looks
        # like a broken model.
        raise ConfigError(
            f"engine.model={str(path)!r}: the sweep's time step {dt:.6g} s differs "
            f"from the model's {saved_dt:.6g} s. The step follows from the sampled "
            "scenarios (the shortest log wave round trip over 40 steps, "
            "stage2.sweep_time_step_s), so another sample (sample.n or seed, or "
            "the ranges of log length, wood density or added mass) has another: "
            "point engine.model at a new directory to prepare a model for this one")
    return manifest


def check_all(spec: EvaluatorSpec, points: list, scenarios: list):
    """One evaluator of ``spec`` (returned) checks every scenario; ConfigError naming the
    first it cannot compute, with its inputs."""
    try:
        ev = spec.build()
    except ValueError as e:
        raise ConfigError(f"engine.evaluator={spec.name!r} cannot be set up for [base]: "
                          f"{e}") from None
    for i, (p, s) in enumerate(zip(points, scenarios)):
        try:
            ev.check(s)
        except ValueError as e:
            inputs = ", ".join(f"parameters.{k}={v!r}" for k, v in p.items())
            raise ConfigError(f"scenario {i} ({inputs}): {e} (engine.evaluator="
                              f"{spec.name!r} cannot compute it)") from None
    return ev


def run(cfg: SweepConfig, out: Optional[Union[str, Path]] = None,
        check_convergence: bool = False, stream: Optional[TextIO] = None) -> dict:
    """Run (or resume) the sweep of ``cfg`` into ``out`` (default ``output.dir``); returns
    the summary also written to ``summary.json``."""
    check_engine(cfg.engine)
    t0 = time.perf_counter()
    folder = Path(out or cfg.output["dir"])
    prep = prepare(cfg, folder)
    prep["timings_s"] = {"prepare": time.perf_counter() - t0}
    points, scenarios = prep["points"], prep["scenarios"]
    table = ResultTable(folder, cfg.hash(), [point_hash(p) for p in points])
    done = table.open()
    tasks = [(i, s) for i, s in enumerate(scenarios) if i not in done]
    progress = Progress(len(scenarios), len(done), stream)

    def on_result(res: dict) -> None:
        i = res["id"]
        row = {"id": i, "inputs": points[i], "outputs": res["outputs"],
               "counts": res["counts"], "seconds": res["seconds"], "worker": res["worker"],
               "dt_s": prep["dt_s"]}
        if "timings_s" in res:
            row["timings_s"] = res["timings_s"]
        table.append(row)
        progress.update()

    t1 = time.perf_counter()
    try:
        engines.run(cfg.engine, prep["spec"], tasks, on_result, local=prep["checker"])
    finally:
        progress.close()
        table.close()
    prep["timings_s"]["compute"] = time.perf_counter() - t1
    return finish(cfg, folder, table, prep, len(tasks), time.perf_counter() - t0,
                  check_convergence)


def finish(cfg, folder: Path, table: ResultTable, prep: dict, computed: int, wall_s: float,
           check_convergence: bool) -> dict:
    """results.csv, summary.json, the figures and report.md of a complete table."""
    from ..output import write_summary
    from mpi4py import MPI
    t0 = time.perf_counter()
    rows = table.sorted_rows()
    inputs = list(cfg.parameters)
    outputs = list(rows[0]["outputs"]) if rows else []
    table.write_csv(inputs, outputs)
    e = cfg.engine
    run_info = {"config": cfg.source, "config_hash": cfg.hash(), "method": cfg.method,
                "scenarios": len(prep["scenarios"]), "computed_this_run": computed,
                "evaluator": e["evaluator"], "engine": e["kind"],
                "workers": (1 if e["kind"] == "serial" else
                            e["workers"] or (engines.default_workers()
                                             if e["kind"] != "mpi" else None)),
                "dt_s": prep["dt_s"], "wall_s": wall_s,
                "seconds_per_scenario_mean": (sum(r["seconds"] for r in rows) / len(rows)
                                              if rows else math.nan),
                "base": prep["base"].as_dict(),
                "mesh": _element_sizes(prep["base"]),
                "evaluator_timings_s": _sum_timings(rows)}
    if "model" in prep:
        run_info["dam_model"] = prep["model"]
    summary = sweep_report.summarize(run_info, rows, inputs, outputs, cfg)
    if prep["checker"] is not None and e["kind"] != "serial":
        # The evaluator that checked the scenarios in this process computed none of them.
        summary["counts_driver_check"] = prep["checker"].counts()
    t_conv = time.perf_counter()
    if check_convergence:
        summary["convergence"] = convergence(prep, summary["worst"])
    t_conv = time.perf_counter() - t_conv
    summary["figures"] = (sweep_report.figures(folder, summary, rows, inputs, outputs)
                          if cfg.output["plots"] and rows else [])
    summary["timings_s"] = {**prep["timings_s"],
                            "report": time.perf_counter() - t0 - t_conv,
                            "convergence": t_conv}
    write_summary(folder, summary, comm=MPI.COMM_SELF)
    (folder / "report.md").write_text(sweep_report.markdown(summary, inputs))
    return summary


def _sum_timings(rows: list) -> dict:
    """The evaluators' own timings (s), summed over rows (over workers: CPU-side seconds,
    not wall time)."""
    tot = {}
    for r in rows:
        for k, v in r.get("timings_s", {}).items():
            tot[k] = tot.get(k, 0.0) + float(v)
    return tot


def convergence(prep: dict, worst: dict) -> dict:
    """Each output's most unfavourable scenario again at refine + 1 (in this process, with
    an evaluator of its own on the finer base and the sweep's time step). On the 3D block
    the factored-dam evaluator's worst are re-run by the monolithic one: the check then
    covers the face patch's condensation as well as the mesh."""
    spec = prep["spec"]
    name = spec.name
    if name == "reuse" and spec.base.dim == 3:
        name = "monolithic"
    face = spec.face if name == spec.name else None
    fine = EvaluatorSpec(name, spec.base.replace(refine=spec.base.refine + 1),
                         spec.dt_s, spec.water_levels_m, face=face)
    ev, cache, out = fine.build(), {}, {}
    for o, w in worst.items():
        if w is None:
            continue
        s = prep["scenarios"][w["id"]]
        if w["id"] not in cache:
            cache[w["id"]] = ev.evaluate(s.replace(refine=s.refine + 1))
        v, v1 = float(w["value"]), float(cache[w["id"]][o])
        out[o] = {"id": w["id"], "refine": s.refine, "value": v, "value_refined": v1,
                  "evaluator_refined": name,
                  "relative_change": (v1 - v) / abs(v) if v else math.nan,
                  "outputs_refined": cache[w["id"]]}
    return out


def _element_sizes(base) -> dict:
    """The element sizes every scenario is meshed with (m), resolved from the base scenario's
    defaults, for the report: its numbers mean little without them."""
    return {"h_far_m": base.h_far_m, "h_impact_m": base.h_impact_m, "h_log_m": base.h_log_m,
            "h_contact_m": base.h_contact_m, "contact_zone_m": base.contact_zone_m,
            "contact_layer_m": base.contact_layer_m}
