"""The sweep's config file (TOML), read and checked in full before anything is computed.

Tables and keys (every other key is an error naming it)::

    [base]                   # DamScenario overrides (flexcontact.dam.scenario), e.g.
    water_level_m = 27.0     #   materials as tables: [base.wood] E_Pa = 10e9, rho_kg_m3 = 650
    [sample]
    method = "lhs"           # "grid" | "lhs" | "random"
    n = 100                  # number of scenarios (lhs, random; not for grid)
    seed = 1                 # numpy Generator seed (lhs, random)
    [parameters.log_speed_m_s]
    distribution = "uniform" # or values = [...]; see flexcontact.sweep.distributions
    lo = 1.0
    hi = 3.0
    [engine]                 # how, not what: not part of the config's hash except evaluator
    evaluator = "reuse"      # "reuse" | "monolithic" | "package.module:Class"
    kind = "processes"       # "serial" | "processes" | "mpi" | "dask"
    workers = 2
    scheduler = "tcp://host:8786"  # dask only; none: a LocalCluster
    start_method = "spawn"   # processes: "spawn" | "forkserver"
    batch = 1                # scenarios stepped side by side, sharing the dam's solves
    [output]
    dir = "results/sweep"    # default results/sweep/<config file's stem>
    plots = true
    bootstrap = 1000         # bootstrap resamples of the exceedance band
    band = 0.9               # its two-sided level
"""
from __future__ import annotations

import hashlib
import json
import numbers
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from . import distributions
from .errors import ConfigError

SWEPT = ("log_length_m", "log_diameter_m", "wood_density_kg_m3", "log_speed_m_s",
         "log_pitch_deg", "log_yaw_deg", "log_across_m", "friction_mu", "water_level_m",
         "added_mass_coefficient", "wood_crushing_strength_Pa", "log_end_shape",
         "log_end_chamfer_m", "log_end_radius_m", "concrete_tensile_strength_Pa")
"""Inputs a sweep may vary; ``wood_density_kg_m3`` is the wood Material's ``rho_kg_m3``.
``concrete_tensile_strength_Pa`` changes no computation: the report compares each
scenario's stresses with its own f_t."""
CATEGORICAL = ("log_end_shape",)
"""Swept inputs that take names, not numbers: ``values = ["flat", "rounded"]`` only."""
METHODS = ("grid", "lhs", "random")
ENGINES = ("serial", "processes", "mpi", "dask")
EVALUATORS = ("reuse", "monolithic")
_TABLES = {"base", "sample", "parameters", "engine", "output"}
_SAMPLE = {"method", "n", "seed"}
_ENGINE = {"evaluator", "kind", "workers", "scheduler", "start_method", "model", "batch"}
_OUTPUT = {"dir", "plots", "bootstrap", "band"}


@dataclass(frozen=True)
class SweepConfig:
    """A checked sweep config; ``raw`` is the parsed TOML the hash is taken of."""

    base: dict
    method: str
    n: int | None
    seed: int
    parameters: dict  # name -> Distribution, sorted by name
    engine: dict
    output: dict
    raw: dict = field(repr=False)
    source: str = "<dict>"

    @property
    def names(self) -> list:
        return list(self.parameters)

    def hash(self) -> str:
        """SHA-256 of what decides the table: base, sample, parameters and the evaluator
        (not the engine, the worker count nor the output options)."""
        what = {k: self.raw.get(k, {}) for k in ("base", "sample", "parameters")}
        what["evaluator"] = self.engine["evaluator"]
        text = json.dumps(what, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()


def load(path) -> SweepConfig:
    """Read and check the TOML file at ``path``; raises ConfigError naming key and value."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            raw = tomllib.load(f)
    except OSError as e:
        raise ConfigError(f"config={str(path)!r}: cannot read it ({e.strerror})") from None
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"config={str(path)!r}: not valid TOML ({e})") from None
    cfg = from_dict(raw, source=str(path))
    if "dir" not in cfg.output:
        cfg.output["dir"] = str(Path("results") / "sweep" / path.stem)
    return cfg


def _int(where, value, low):
    if not (isinstance(value, numbers.Integral) and not isinstance(value, bool)
            and value >= low):
        raise ConfigError(f"{where}={value!r}: must be an integer >= {low}")
    return int(value)


def _unknown(table: str, given, allowed) -> None:
    for key in sorted(set(given) - set(allowed)):
        raise ConfigError(f"{table}.{key}={given[key]!r}: unknown key (allowed: "
                          f"{sorted(allowed)})")


def from_dict(raw: dict, source: str = "<dict>") -> SweepConfig:
    """Check a parsed config (the TOML's tables as dicts); see the module docstring."""
    for key in sorted(set(raw) - _TABLES):
        raise ConfigError(f"{key}={raw[key]!r}: unknown table or key (allowed: "
                          f"{sorted(_TABLES)})")
    for key in _TABLES & set(raw):
        if not isinstance(raw[key], dict):
            raise ConfigError(f"{key}={raw[key]!r}: must be a table [{key}]")
    sample = raw.get("sample", {})
    _unknown("sample", sample, _SAMPLE)
    method = sample.get("method", "grid")
    if method not in METHODS:
        raise ConfigError(f"sample.method={method!r}: must be one of {list(METHODS)}")
    n = sample.get("n")
    if method == "grid" and n is not None:
        raise ConfigError(f"sample.n={n!r}: a grid's size is the product of its values "
                          f"lists; leave n out")
    if method != "grid":
        if n is None:
            raise ConfigError(f"sample.n: missing (method = {method!r} needs n)")
        n = _int("sample.n", n, 1)
    seed = _int("sample.seed", sample.get("seed", 0), 0)
    params = _parameters(raw.get("parameters", {}), method)
    engine = _engine(raw.get("engine", {}))
    output = _output(raw.get("output", {}))
    return SweepConfig(dict(raw.get("base", {})), method, n, seed, params, engine, output,
                       raw, source)


def _parameters(table: dict, method: str) -> dict:
    if not table:
        raise ConfigError("parameters={}: a sweep needs at least one [parameters.<name>] "
                          f"(names: {list(SWEPT)})")
    out = {}
    for name in sorted(table):
        if name not in SWEPT:
            raise ConfigError(f"parameters.{name}={table[name]!r}: unknown swept input "
                              f"(allowed: {list(SWEPT)})")
        d = distributions.parse(name, table[name], categorical=name in CATEGORICAL)
        if method == "grid":
            d.values  # raises unless a values list
        out[name] = d
    return out


def _engine(table: dict) -> dict:
    _unknown("engine", table, _ENGINE)
    e = {"evaluator": table.get("evaluator", "reuse"), "kind": table.get("kind", "processes"),
         "workers": table.get("workers"), "scheduler": table.get("scheduler"),
         "start_method": table.get("start_method", "spawn"), "model": table.get("model"),
         "batch": table.get("batch", 1)}
    ev = e["evaluator"]
    if not isinstance(ev, str) or not (ev in EVALUATORS or ":" in ev):
        raise ConfigError(f"engine.evaluator={ev!r}: must be one of {list(EVALUATORS)} or "
                          f"an importable 'package.module:Class'")
    check_engine(e)
    return e


def check_engine(e: dict) -> None:
    """Check the engine keys (after command-line overrides too)."""
    if e["kind"] not in ENGINES:
        raise ConfigError(f"engine.kind={e['kind']!r}: must be one of {list(ENGINES)}")
    if e["workers"] is not None:
        _int("engine.workers", e["workers"], 1)
    _int("engine.batch", e.get("batch", 1), 1)
    if e["scheduler"] is not None and not isinstance(e["scheduler"], str):
        raise ConfigError(f"engine.scheduler={e['scheduler']!r}: must be an address string")
    m = e.get("model")
    if m is not None and m is not False and not (isinstance(m, str) and m):
        raise ConfigError(f"engine.model={m!r}: must be the path of a dam model directory, "
                          "or false for every worker to factor the dam itself")
    if e["start_method"] not in ("spawn", "forkserver"):
        raise ConfigError(f"engine.start_method={e['start_method']!r}: must be 'spawn' or "
                          f"'forkserver'")


def _output(table: dict) -> dict:
    _unknown("output", table, _OUTPUT)
    out = {"plots": table.get("plots", True), "bootstrap": table.get("bootstrap", 1000),
           "band": table.get("band", 0.9)}
    if "dir" in table:
        if not isinstance(table["dir"], str) or not table["dir"]:
            raise ConfigError(f"output.dir={table['dir']!r}: must be a folder path")
        out["dir"] = table["dir"]
    if not isinstance(out["plots"], bool):
        raise ConfigError(f"output.plots={out['plots']!r}: must be true or false")
    _int("output.bootstrap", out["bootstrap"], 10)
    b = out["band"]
    if not (isinstance(b, numbers.Real) and not isinstance(b, bool) and 0 < b < 1):
        raise ConfigError(f"output.band={b!r}: must be a level strictly between 0 and 1")
    return out
