"""The distributions a swept input can take, each mapping u ∈ (0, 1) to a value by its
inverse CDF (restricted to its truncation interval), so that Latin-hypercube strata and plain
random draws go through one function.

Config forms (``[parameters.<name>]``)::

    values = [1.0, 2.0, 3.0]                          # a grid axis; sampled: equally likely
    values = ["flat", "rounded"]                      # a categorical input: names only
    distribution = "uniform",    lo = 1.0, hi = 3.0
    distribution = "normal",     mean = 2.0, sd = 0.5, lo = 1.0, hi = 3.0   # truncated
    distribution = "lognormal",  median = 2.0, sigma = 0.3 [, lo = ..., hi = ...]
    distribution = "triangular", lo = 1.0, mode = 1.5, hi = 3.0

``sigma`` of the lognormal is the standard deviation of ln X. Every error names the key and
its value.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from .errors import ConfigError

_KEYS = {"uniform": ({"lo", "hi"}, set()),
         "normal": ({"mean", "sd", "lo", "hi"}, set()),
         "lognormal": ({"median", "sigma"}, {"lo", "hi"}),
         "triangular": ({"lo", "mode", "hi"}, set())}
KINDS = ("values",) + tuple(_KEYS)


def _number(where: str, value) -> float:
    if not (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and math.isfinite(value)):
        raise ConfigError(f"{where}={value!r}: must be a finite number")
    return float(value)


@dataclass(frozen=True)
class Distribution:
    """One swept input's distribution: ``kind`` (one of :data:`KINDS`) and its numbers."""

    name: str
    kind: str
    args: tuple  # values (kind "values") or the kind's keys as sorted (key, value) pairs

    @property
    def categorical(self) -> bool:
        """Whether the values are names (sampled uniformly, no order)."""
        return self.kind == "values" and all(isinstance(v, str) for v in self.args)

    def value(self, v):
        """One sampled value as the scenario takes it: a name, or a float."""
        return v if self.categorical else float(v)

    @property
    def values(self) -> tuple:
        if self.kind != "values":
            raise ConfigError(f"parameters.{self.name}: a grid needs values = [...], "
                              f"not distribution = {self.kind!r}")
        return self.args

    def _scipy(self):
        from scipy import stats
        a = dict(self.args)
        if self.kind == "uniform":
            return stats.uniform(loc=a["lo"], scale=a["hi"] - a["lo"]), a["lo"], a["hi"]
        if self.kind == "normal":
            return stats.norm(loc=a["mean"], scale=a["sd"]), a["lo"], a["hi"]
        if self.kind == "lognormal":
            return (stats.lognorm(s=a["sigma"], scale=a["median"]), a.get("lo", 0.0),
                    a.get("hi", math.inf))
        c = (a["mode"] - a["lo"]) / (a["hi"] - a["lo"])
        return stats.triang(c=c, loc=a["lo"], scale=a["hi"] - a["lo"]), a["lo"], a["hi"]

    def mass(self) -> float:
        """Probability of the truncation interval under the untruncated law."""
        if self.kind == "values":
            return 1.0
        law, lo, hi = self._scipy()
        return float(law.cdf(hi) - law.cdf(lo))

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Values at probabilities ``u`` ∈ [0, 1) of the (truncated) law."""
        u = np.asarray(u, dtype=float)
        if self.kind == "values":
            k = len(self.args)
            idx = np.minimum((u * k).astype(int), k - 1)
            return np.asarray(self.args, dtype=object if self.categorical else float)[idx]
        law, lo, hi = self._scipy()
        f_lo, f_hi = law.cdf(lo), law.cdf(hi)
        x = law.ppf(f_lo + u * (f_hi - f_lo))
        return np.clip(x, lo, hi)


def parse(name: str, table, categorical: bool = False) -> Distribution:
    """The Distribution of ``[parameters.<name>]`` (a dict); raises ConfigError. A
    ``categorical`` input takes ``values = [names]`` only."""
    where = f"parameters.{name}"
    if not isinstance(table, dict):
        raise ConfigError(f"{where}={table!r}: must be a table (values = [...] or "
                          f"distribution = ...)")
    if categorical:
        return _categorical(where, name, table)
    if "values" in table:
        extra = sorted(set(table) - {"values"})
        if extra:
            raise ConfigError(f"{where}.{extra[0]}={table[extra[0]]!r}: unknown key next to "
                              f"values = [...]")
        vals = table["values"]
        if not isinstance(vals, list) or not vals:
            raise ConfigError(f"{where}.values={vals!r}: must be a non-empty list of numbers")
        vals = tuple(_number(f"{where}.values[{i}]", v) for i, v in enumerate(vals))
        if len(set(vals)) != len(vals):
            raise ConfigError(f"{where}.values={list(vals)!r}: a value is repeated")
        return Distribution(name, "values", vals)
    kind = table.get("distribution")
    if kind not in _KEYS:
        raise ConfigError(f"{where}.distribution={kind!r}: must be one of "
                          f"{sorted(_KEYS)} (or give values = [...])")
    required, optional = _KEYS[kind]
    for key in sorted(set(table) - required - optional - {"distribution"}):
        raise ConfigError(f"{where}.{key}={table[key]!r}: unknown key for distribution = "
                          f"{kind!r} (keys: {sorted(required | optional)})")
    for key in sorted(required - set(table)):
        raise ConfigError(f"{where}.{key}: missing (distribution = {kind!r} needs "
                          f"{sorted(required)})")
    a = {k: _number(f"{where}.{k}", v) for k, v in table.items() if k != "distribution"}
    _check_support(where, kind, a)
    d = Distribution(name, kind, tuple(sorted(a.items())))
    if not d.mass() > 1e-12:
        raise ConfigError(f"{where}: lo={a.get('lo', 0.0)!r}, hi={a.get('hi', math.inf)!r}: "
                          f"the truncation interval has no probability under "
                          f"distribution = {kind!r} (no support)")
    return d


def _categorical(where: str, name: str, table: dict) -> Distribution:
    for key in sorted(set(table) - {"values"}):
        raise ConfigError(f"{where}.{key}={table[key]!r}: a categorical input takes "
                          f"values = [names] only")
    vals = table.get("values")
    if not isinstance(vals, list) or not vals:
        raise ConfigError(f"{where}.values={vals!r}: must be a non-empty list of names")
    for i, v in enumerate(vals):
        if not isinstance(v, str):
            raise ConfigError(f"{where}.values[{i}]={v!r}: must be a name (a string)")
    if len(set(vals)) != len(vals):
        raise ConfigError(f"{where}.values={vals!r}: a value is repeated")
    return Distribution(name, "values", tuple(vals))


def _check_support(where: str, kind: str, a: dict) -> None:
    lo, hi = a.get("lo", 0.0 if kind == "lognormal" else None), a.get("hi", math.inf)
    if lo is not None and not lo < hi:
        raise ConfigError(f"{where}.lo={lo!r} >= {where}.hi={hi!r}: the distribution has no "
                          f"support (need lo < hi)")
    for key in ("sd", "sigma", "median"):
        if key in a and not a[key] > 0:
            raise ConfigError(f"{where}.{key}={a[key]!r}: must be > 0")
    if kind == "lognormal" and lo < 0:
        raise ConfigError(f"{where}.lo={lo!r}: a lognormal value is > 0; need lo >= 0")
    if kind == "triangular" and not lo <= a["mode"] <= hi:
        raise ConfigError(f"{where}.mode={a['mode']!r}: must lie in [lo, hi] = "
                          f"[{lo!r}, {hi!r}]")
