"""From a checked config to the list of scenarios: the seeded sample, then one
:class:`~flexcontact.dam.DamScenario` per point, every one built (and so checked) before
anything is computed.

Scenario ids are the indices in that list: a grid in the order of
``itertools.product`` over the inputs sorted by name; a sample in the order drawn. Latin
hypercube: for each input (sorted by name) a random permutation of the n strata and a
uniform point in each, u = (perm + U)/n, then the input's inverse CDF; random: u uniform.
One ``numpy.random.default_rng(seed)`` draws them all, so the same config gives the same
scenarios.
"""
from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import fields

import numpy as np

from .errors import ConfigError

_MATERIALS = ("concrete", "rock", "wood")


def base_scenario(cfg):
    """The DamScenario of ``[base]`` (materials given as tables)."""
    from ..dam import DamScenario
    from ..forms import Material
    names = {f.name for f in fields(DamScenario)}
    kwargs = {}
    for key, value in cfg.base.items():
        if key not in names:
            raise ConfigError(f"base.{key}={value!r}: unknown DamScenario parameter")
        if key in _MATERIALS:
            kwargs[key] = _material(key, value, getattr(DamScenario, key), Material)
        else:
            kwargs[key] = value
    try:
        return DamScenario(**kwargs)
    except (ValueError, TypeError) as e:
        raise ConfigError(f"[base]: {e}") from None


def _material(key, table, default, Material):
    if not isinstance(table, dict):
        raise ConfigError(f"base.{key}={table!r}: must be a table (E_Pa, nu, rho_kg_m3)")
    allowed = {"E_Pa", "nu", "rho_kg_m3"}
    for k in sorted(set(table) - allowed):
        raise ConfigError(f"base.{key}.{k}={table[k]!r}: unknown key (allowed: "
                          f"{sorted(allowed)})")
    args = {"E_Pa": default.E_Pa, "nu": default.nu, "rho_kg_m3": default.rho_kg_m3}
    args.update(table)
    try:
        return Material(**args, name=default.name)
    except ValueError as e:
        raise ConfigError(f"base.{key}: {e}") from None


def sample_points(cfg) -> list:
    """The swept inputs of every scenario: a list of {name: float, or str for a categorical
    input}, in id order."""
    names = cfg.names
    dists = [cfg.parameters[n] for n in names]
    if cfg.method == "grid":
        return [{n: d.value(v) for n, d, v in zip(names, dists, p)}
                for p in itertools.product(*(d.values for d in dists))]
    rng = np.random.default_rng(cfg.seed)
    n, d = cfg.n, len(names)
    if cfg.method == "lhs":
        u = np.empty((n, d))
        for j in range(d):
            u[:, j] = (rng.permutation(n) + rng.random(n)) / n
    else:
        u = rng.random((n, d))
    cols = [cfg.parameters[name].ppf(u[:, j]) for j, name in enumerate(names)]
    return [{name: dists[j].value(cols[j][i]) for j, name in enumerate(names)}
            for i in range(n)]


def scenario_of(base, point: dict):
    """The DamScenario of ``base`` with the swept inputs of ``point``."""
    changes = dict(point)
    rho = changes.pop("wood_density_kg_m3", None)
    if rho is not None:
        from ..forms import Material
        w = base.wood
        changes["wood"] = Material(E_Pa=w.E_Pa, nu=w.nu, rho_kg_m3=rho, name=w.name)
    return base.replace(**changes)


def build_scenarios(cfg) -> tuple:
    """(base, points, scenarios): every scenario built and checked; a bad one raises
    ConfigError naming the scenario id, its inputs and the failing parameter's value."""
    base = base_scenario(cfg)
    for name, what in (("log_yaw_deg", "a yaw angle"),
                       ("log_across_m", "a place across the block")):
        if name in cfg.parameters and base.dim != 3:
            raise ConfigError(f"parameters.{name}: {what} needs base.dim = 3 "
                              f"(base.dim={base.dim!r})")
    points = sample_points(cfg)
    scenarios = []
    for i, p in enumerate(points):
        try:
            scenarios.append(scenario_of(base, p))
        except ValueError as e:
            inputs = ", ".join(f"parameters.{k}={v!r}" for k, v in p.items())
            raise ConfigError(f"scenario {i} ({inputs}): {e}") from None
    return base, points, scenarios


def point_hash(point: dict) -> str:
    """A short hash of one scenario's swept inputs (exact float values, names as such)."""
    text = json.dumps({k: v if isinstance(v, str) else float(v).hex()
                       for k, v in point.items()}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]
