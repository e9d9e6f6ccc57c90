"""Which evaluator computes a scenario, and the worker-side state that keeps one per process.

``engine.evaluator`` in the config selects it:

* ``"reuse"`` (default): ``flexcontact.dam.reuse.ScenarioEvaluator``, which factors the
  dam once per mesh and time step and reuses the factors for every scenario;
* ``"monolithic"``: :class:`flexcontact.sweep.monolithic.MonolithicEvaluator`, every
  scenario meshed and solved on its own;
* ``"package.module:Class"``: any importable class with the same interface — the hook the
  tests use to inject an evaluator whose outputs are analytic in the inputs.

The interface: ``Class(base, dt_s=None, water_levels_m=None, comm=MPI.COMM_SELF)``,
``evaluate(scenario) -> dict`` of plain floats, ``counts() -> {"factorizations": {...},
"back_substitutions": {...}}``; the class's module may define ``sweep_time_step_s(scenarios)``
(else the monolithic one is used). Optionally ``timings() -> {phase: seconds}`` (cumulative),
which the sweep sums like the counts (bench/sweep.py reports its split), and
``check(scenario)`` raising ValueError for a scenario the evaluator cannot compute (a log
leaving the face strip a reused dam was meshed for, ...): the sweep then builds one
evaluator before computing and checks every scenario with it.
"""
from __future__ import annotations

import importlib
import os
import socket
import time
from dataclasses import dataclass
from typing import Optional

from .errors import ConfigError

_BUILTIN = {"reuse": "flexcontact.dam.reuse:ScenarioEvaluator",
            "monolithic": "flexcontact.sweep.monolithic:MonolithicEvaluator"}


def resolve(name: str):
    """(class, its module) of an ``engine.evaluator`` value; ConfigError if not importable."""
    target = _BUILTIN.get(name, name)
    module_name, _, attr = target.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as e:
        if name == "reuse" and e.name in ("flexcontact.dam.reuse",):
            raise ConfigError(
                "engine.evaluator='reuse': flexcontact.dam.reuse (the factorization-reusing "
                "engine) is not in this installation; set engine.evaluator = 'monolithic' "
                "(every scenario meshed and factored on its own)") from None
        raise ConfigError(f"engine.evaluator={name!r}: cannot import {module_name!r} "
                          f"({e})") from None
    cls = getattr(module, attr, None)
    if cls is None:
        raise ConfigError(f"engine.evaluator={name!r}: {module_name!r} has no {attr!r}")
    return cls, module


def sweep_time_step(name: str, scenarios) -> float:
    """The sweep's one time step (s) by the evaluator module's rule."""
    _, module = resolve(name)
    fn = getattr(module, "sweep_time_step_s", None)
    if fn is None:
        from .monolithic import sweep_time_step_s as fn
    return float(fn(scenarios))


@dataclass(frozen=True)
class EvaluatorSpec:
    """What a worker needs to build its evaluator (picklable)."""

    name: str
    base: object
    dt_s: float
    water_levels_m: tuple
    model: Optional[str] = None
    """A dam model directory (dam/model_file.py) every worker loads instead of factoring
    the dam (the "reuse" evaluator only)."""
    face: Optional[dict] = None
    """The "reuse" evaluator's face region, {"strip_m", "patch_y_m"}, holding every
    scenario of the sweep (dam_model.face_region_m)."""
    model_if_seen: bool = False
    """``model`` is the sweep's own, in its output folder: a worker that does not see that
    folder (a Dask worker on another machine without a shared file system) factors the dam
    itself, and its counts say so."""

    def loads_model(self) -> bool:
        """Whether :meth:`build` loads the dam model (here, in this process)."""
        from pathlib import Path
        if self.model is None:
            return False
        return not self.model_if_seen or (Path(self.model) / "manifest.json").is_file()

    def build(self):
        from mpi4py import MPI
        if self.loads_model():
            from ..dam import model_file
            model_file.check_inputs(model_file.read_manifest(self.model), self.base,
                                    self.dt_s)
            return model_file.load(self.model, MPI.COMM_SELF)
        cls, _ = resolve(self.name)
        return cls(self.base, dt_s=self.dt_s, water_levels_m=list(self.water_levels_m),
                   comm=MPI.COMM_SELF, **(self.face or {}))


_STATE: dict = {}

TIMING_OUTPUTS = ("evaluate_s",)
"""Keys an evaluator may return among its outputs that are wall times, not results: moved
to the row's timings so that the table is the same whichever engine and machine ran it."""


def init_worker(spec: EvaluatorSpec, evaluator=None) -> None:
    """Build this process's evaluator once (a pool's initializer, or lazily), or adopt
    ``evaluator`` (built from ``spec`` already, counts included)."""
    _STATE.clear()
    _STATE.update(spec=spec, evaluator=evaluator or spec.build(), reported=_zero(), timed={})


def _zero() -> dict:
    return {"factorizations": {}, "back_substitutions": {}}


def _delta(now: dict, before: dict) -> dict:
    return {kind: {k: int(v) - int(before.get(kind, {}).get(k, 0))
                   for k, v in now.get(kind, {}).items()}
            for kind in ("factorizations", "back_substitutions", "restorations")
            if kind in now or kind != "restorations"}


def _added(ev) -> tuple:
    """(counts, timings) that ``ev`` added since this process last reported them."""
    now = ev.counts()
    delta = _delta(now, _STATE["reported"])
    _STATE["reported"] = now
    timed = {}
    if hasattr(ev, "timings"):
        t = {k: float(v) for k, v in ev.timings().items()}
        timed = {k: v - _STATE["timed"].get(k, 0.0) for k, v in t.items()}
        _STATE["timed"] = t
    return delta, timed


def evaluate_task(spec: EvaluatorSpec, task: tuple) -> dict:
    """Evaluate one (id, scenario) in this process: its outputs, the counts it added (the
    first task of a process also carries its evaluator's set-up) and who computed it."""
    if _STATE.get("spec") != spec:
        init_worker(spec)
    i, scenario = task
    ev = _STATE["evaluator"]
    t0 = time.perf_counter()
    outputs = ev.evaluate(scenario)
    seconds = time.perf_counter() - t0
    delta, added = _added(ev)
    outputs = dict(outputs)
    timed = {k: float(outputs.pop(k)) for k in TIMING_OUTPUTS if k in outputs}
    result = {"id": i, "outputs": outputs, "counts": delta, "seconds": seconds,
              "worker": f"{socket.gethostname()}:{os.getpid()}"}
    timed.update(added)
    if timed:
        result["timings_s"] = timed
    return result


def evaluate_batch(spec: EvaluatorSpec, tasks: list) -> list:
    """Evaluate several (id, scenario) side by side in this process, by the evaluator's
    ``evaluate_many`` (one after the other if it has none): per task, its result as
    :func:`evaluate_task` gives it, or {"id", "error"} for a scenario that failed. The
    counts and timings the batch added go to its first computed row (the summary sums
    them); each row's seconds are the batch's wall time shared equally."""
    if _STATE.get("spec") != spec:
        init_worker(spec)
    ev = _STATE["evaluator"]
    if not hasattr(ev, "evaluate_many"):
        out = []
        for t in tasks:
            try:
                out.append(evaluate_task(spec, t))
            except Exception as err:  # noqa: BLE001: reported with the others
                out.append({"id": t[0], "error": err})
        return out
    t0 = time.perf_counter()
    results = ev.evaluate_many([s for _, s in tasks])
    seconds = (time.perf_counter() - t0) / len(tasks)
    worker = f"{socket.gethostname()}:{os.getpid()}"
    delta, timed_batch = _added(ev)
    out, first = [], True
    for (i, _), res in zip(tasks, results):
        if isinstance(res, BaseException):
            out.append({"id": i, "error": res})
            continue
        outputs = dict(res)
        timed = {k: float(outputs.pop(k)) for k in TIMING_OUTPUTS if k in outputs}
        row = {"id": i, "outputs": outputs, "seconds": seconds, "worker": worker,
               "counts": delta if first else _zero_like(delta)}
        if first:
            timed.update(timed_batch)
        if timed:
            row["timings_s"] = timed
        first = False
        out.append(row)
    return out


def _zero_like(counts: dict) -> dict:
    return {kind: {k: 0 for k in v} for kind, v in counts.items()}

