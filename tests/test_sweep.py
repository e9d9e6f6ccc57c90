"""The sweep driver (flexcontact/sweep): config checks, seeded sampling, the table that
survives a kill, the engines, and what the report computes.

Most tests inject ``sweep_fakes:LinearEvaluator`` (tests/sweep_fakes.py), whose outputs are
analytic functions of the inputs, so that worst cases, exceedance curves and rank
correlations have exact expected values; one small real sweep runs the monolithic evaluator
on the default (smallest) dam mesh.
"""
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import sweep_fakes
from conftest import ROOT, mpirun
from flexcontact import sweep
from flexcontact.sweep import ConfigError, TableError
from flexcontact.sweep.scenarios import build_scenarios

FAKE = "sweep_fakes:LinearEvaluator"


def fake_config(n=24, seed=7, method="lhs", kind="serial", **extra):
    """An LHS sweep over speed, friction, log length and wood density."""
    raw = {"sample": {"method": method, "n": n, "seed": seed},
           "parameters": {
               "log_speed_m_s": {"distribution": "uniform", "lo": 0.5, "hi": 4.0},
               "friction_mu": {"distribution": "normal", "mean": 0.5, "sd": 0.15,
                               "lo": 0.1, "hi": 0.9},
               "log_length_m": {"values": [6.0, 8.0, 10.0]},
               "wood_density_kg_m3": {"distribution": "triangular", "lo": 450.0,
                                      "mode": 650.0, "hi": 900.0}},
           "engine": {"evaluator": FAKE, "kind": kind},
           "output": {"plots": False, "bootstrap": 200}}
    for key, value in extra.items():
        raw.setdefault(key, {}).update(value)
    return raw


def env_with_fakes(**extra):
    e = dict(os.environ)
    e["PYTHONPATH"] = os.pathsep.join([str(ROOT / "dolfinx_ext" / "python"),
                                       str(ROOT / "tests"), e.get("PYTHONPATH", "")])
    e.update({k: str(v) for k, v in extra.items()})
    return e


def write_toml(path: Path, raw: dict) -> Path:
    """A TOML file of ``raw`` (tables of scalars, lists and sub-tables only)."""
    lines = []

    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return repr(v)

    def table(name, d):
        lines.append(f"[{name}]")
        subs = {k: v for k, v in d.items() if isinstance(v, dict)}
        lines.extend(f"{k} = {value(v)}" for k, v in d.items() if not isinstance(v, dict))
        for k, v in subs.items():
            table(f"{name}.{k}", v)

    for name, d in raw.items():
        table(name, d)
    path.write_text("\n".join(lines) + "\n")
    return path


def table_of(folder: Path) -> list:
    """(id, inputs, outputs) of every row, sorted by id."""
    rows = [json.loads(l) for l in (folder / "results.jsonl").read_text().splitlines()]
    return sorted((r["id"], r["inputs"], r["outputs"]) for r in rows)


def same_tables(a: list, b: list, rtol=1e-12):
    assert [r[0] for r in a] == [r[0] for r in b]
    for (i, xa, ya), (_, xb, yb) in zip(a, b):
        assert xa == xb, i
        for k in ya:
            va, vb = ya[k], yb[k]
            assert (math.isnan(va) and math.isnan(vb)) or abs(va - vb) <= rtol * abs(va), \
                (i, k, va, vb)


# ---- config errors: key and value named, nothing computed --------------------------------

BAD = [
    ({"colour": {"x": 1}}, ["colour", "unknown"]),
    ({"sample": {"methd": "lhs"}}, ["sample.methd", "'lhs'"]),
    ({"sample": {"method": "sobol"}}, ["sample.method", "'sobol'"]),
    ({"sample": {"n": 0}}, ["sample.n", "0"]),
    ({"parameters": {"log_colour": {"values": [1.0]}}}, ["parameters.log_colour"]),
    ({"parameters": {"log_speed_m_s": {"distribution": "uniform", "lo": 3.0, "hi": 1.0}}},
     ["parameters.log_speed_m_s.lo=3.0", "hi=1.0", "no support"]),
    ({"parameters": {"friction_mu": {"distribution": "normal", "mean": 0.5, "sd": -0.1,
                                     "lo": 0.1, "hi": 0.9}}},
     ["parameters.friction_mu.sd=-0.1"]),
    ({"parameters": {"friction_mu": {"distribution": "normal", "mean": 0.5, "sd": 0.01,
                                     "lo": 5.0, "hi": 6.0}}},
     ["parameters.friction_mu", "lo=5.0", "no support"]),
    ({"parameters": {"friction_mu": {"distribution": "uniform", "lo": 0.1, "hi": 0.9,
                                     "mode": 0.3}}},
     ["parameters.friction_mu.mode=0.3", "unknown key"]),
    ({"parameters": {"log_speed_m_s": {"distribution": "uniform", "lo": -1.0, "hi": 1.0}}},
     ["parameters.log_speed_m_s=", "log_speed_m_s=-"]),
    ({"parameters": {"wood_density_kg_m3": {"distribution": "uniform", "lo": 900.0,
                                            "hi": 1100.0}}},
     ["parameters.wood_density_kg_m3=", "wood.rho_kg_m3=", "lighter than water"]),
    ({"parameters": {"log_yaw_deg": {"values": [0.0, 10.0]}}},
     ["parameters.log_yaw_deg", "base.dim"]),
    ({"base": {"dam_hight_m": 30.0}}, ["base.dam_hight_m=30.0", "unknown"]),
    ({"base": {"water_level_m": 40.0}}, ["water_level_m=40.0", "overtopped"]),
    ({"engine": {"kind": "cluster"}}, ["engine.kind", "'cluster'"]),
    ({"engine": {"model": True}}, ["engine.model=True", "or false"]),
    ({"engine": {"batch": 0}}, ["engine.batch=0", "integer >= 1"]),
    ({"engine": {"batch": 2.5}}, ["engine.batch=2.5", "integer >= 1"]),
    ({"engine": {"evaluator": "no_such_module:Evaluator"}},
     ["engine.evaluator", "no_such_module"]),
    ({"output": {"band": 1.5}}, ["output.band=1.5"]),
]


@pytest.mark.parametrize("change, words", BAD)
def test_bad_config_names_key_and_value_before_computing(tmp_path, change, words):
    raw = fake_config()
    for key, value in change.items():
        if key == "parameters":
            raw["parameters"].update(value)
        else:
            raw.setdefault(key, {}).update(value)
    out = tmp_path / "out"
    with pytest.raises(ConfigError) as e:
        sweep.run(sweep.from_dict(raw), out=out)
    for w in words:
        assert w in str(e.value), (w, str(e.value))
    assert not out.exists()  # nothing computed, no table started


def test_log_out_of_the_water_is_named_with_its_scenario(tmp_path):
    """A low water level with a long, steeply pitched log: the log would touch the bed."""
    raw = fake_config(parameters={"water_level_m": {"values": [1.0, 27.0]}},
                      base={"log_pitch_deg": 30.0}, sample={"method": "grid"})
    del raw["sample"]["n"], raw["sample"]["seed"]
    for name in ("log_speed_m_s", "friction_mu", "wood_density_kg_m3"):
        del raw["parameters"][name]
    with pytest.raises(ConfigError) as e:
        sweep.run(sweep.from_dict(raw), out=tmp_path / "out")
    msg = str(e.value)
    assert "scenario 0" in msg and "parameters.water_level_m=1.0" in msg, msg
    assert "water_level_m=1.0: too shallow" in msg, msg
    assert not (tmp_path / "out").exists()


def test_reuse_evaluator_missing_is_a_clear_error(tmp_path):
    try:
        import flexcontact.dam.reuse  # noqa: F401
        pytest.skip("flexcontact.dam.reuse is installed")
    except ModuleNotFoundError:
        pass
    raw = fake_config(engine={"evaluator": "reuse"})
    with pytest.raises(ConfigError, match="engine.evaluator='reuse'.*'monolithic'"):
        sweep.run(sweep.from_dict(raw), out=tmp_path / "out")


def test_scenario_the_evaluator_cannot_compute_is_named_before_computing(tmp_path):
    """An evaluator with a ``check`` (the reusing one refuses a log off its face strip):
    every scenario is checked by one evaluator before anything is computed."""
    raw = fake_config(engine={"evaluator": "sweep_fakes:CheckedLinearEvaluator"})
    cfg = sweep.from_dict(raw)
    _, points, _ = build_scenarios(cfg)
    first = next(i for i, p in enumerate(points) if p["log_speed_m_s"] > 3.5)
    with pytest.raises(ConfigError) as e:
        sweep.run(cfg, out=tmp_path / "out")
    v = points[first]["log_speed_m_s"]
    assert f"scenario {first} (" in str(e.value) and f"log_speed_m_s={v!r}" in str(e.value)
    assert not (tmp_path / "out").exists()
    # Below 3.5 m/s it runs; serially the checking evaluator computes, counted once.
    raw["parameters"]["log_speed_m_s"]["hi"] = 3.5
    s = sweep.run(sweep.from_dict(raw), out=tmp_path / "ok")
    assert s["counts"]["factorizations"]["dam"] == 2 and "counts_driver_check" not in s


# ---- sampling -----------------------------------------------------------------------------

def test_same_config_same_scenarios_and_latin_hypercube_strata():
    n = 30
    cfg = sweep.from_dict(fake_config(n=n, seed=11))
    _, p1, s1 = build_scenarios(cfg)
    _, p2, s2 = build_scenarios(sweep.from_dict(fake_config(n=n, seed=11)))
    assert p1 == p2 and s1 == s2
    _, p3, _ = build_scenarios(sweep.from_dict(fake_config(n=n, seed=12)))
    assert p3 != p1
    # Latin hypercube: the uniform input puts exactly one scenario in each of n strata.
    v = np.array([p["log_speed_m_s"] for p in p1])
    strata = np.floor((v - 0.5) / 3.5 * n).astype(int)
    assert sorted(strata) == list(range(n))
    # The truncated normal stays in its bounds; the 3-value input takes each value n/3 times.
    mu = np.array([p["friction_mu"] for p in p1])
    assert mu.min() >= 0.1 and mu.max() <= 0.9
    lengths = [p["log_length_m"] for p in p1]
    assert all(lengths.count(x) == n // 3 for x in (6.0, 8.0, 10.0))
    # The wood density is the wood Material's density in the scenario.
    assert all(s.wood.rho_kg_m3 == p["wood_density_kg_m3"] for s, p in zip(s1, p1))


def test_grid_is_the_product_of_the_values_lists():
    raw = {"parameters": {"log_speed_m_s": {"values": [1.0, 2.0, 3.0]},
                          "friction_mu": {"values": [0.2, 0.6]}},
           "engine": {"evaluator": FAKE}}
    _, points, scenarios = build_scenarios(sweep.from_dict(raw))
    # Inputs sorted by name: friction_mu varies slowest.
    assert points == [{"friction_mu": m, "log_speed_m_s": v}
                      for m in (0.2, 0.6) for v in (1.0, 2.0, 3.0)]
    assert [s.log_speed_m_s for s in scenarios] == [1.0, 2.0, 3.0] * 2


# ---- what the report computes, against the fake's analytic outputs ----------------------

def ranks(x):
    r = np.empty(len(x))
    r[np.argsort(x)] = np.arange(len(x))
    return r


def test_worst_exceedance_rank_correlation_and_counts_are_exact(tmp_path):
    n = 40
    cfg = sweep.from_dict(fake_config(n=n, seed=5))
    summary = sweep.run(cfg, out=tmp_path / "out")
    _, points, _ = build_scenarios(cfg)
    expected = [sweep_fakes.expected_outputs(p["log_speed_m_s"], p["friction_mu"],
                                             p["log_length_m"], p["wood_density_kg_m3"], 27.0)
                for p in points]
    for o in ("peak_force_N_per_m", "heel_stress_impact_Pa", "peak_tensile_stress_Pa"):
        values = np.array([e[o] for e in expected])
        w = summary["worst"][o]
        assert w["id"] == int(np.argmax(values)) and w["value"] == values.max()
        assert w["inputs"] == points[w["id"]]
        # Empirical exceedance at the k-th smallest of n distinct values: (n − k)/n.
        curve = summary["exceedance"][o]
        assert curve["x"] == sorted(values.tolist())
        assert curve["p"] == [(n - k) / n for k in range(1, n + 1)]
        assert all(lo <= hi for lo, hi in zip(curve["lower"], curve["upper"]))
        # Spearman's ρ from its rank formula, 1 − 6 Σ d² / (n (n² − 1)) (no ties here).
        for name in ("log_speed_m_s", "friction_mu", "wood_density_kg_m3"):
            d = ranks(values) - ranks(np.array([p[name] for p in points]))
            rho = 1 - 6 * (d ** 2).sum() / (n * (n * n - 1))
            assert abs(summary["spearman"][o][name] - rho) <= 1e-12
    # The peak force is 10⁶ × speed: perfectly rank-correlated with the speed alone.
    assert summary["spearman"]["peak_force_N_per_m"]["log_speed_m_s"] == pytest.approx(1, abs=1e-15)
    # One process: the dam's 2 set-up factorizations, one per log length, one
    # back-substitution per step.
    c = summary["counts"]
    assert c["factorizations"] == {"dam": 2, "log": 3, "total": 5}
    assert c["back_substitutions"]["steps"] == sum(e["steps"] for e in expected)
    report = (tmp_path / "out" / "report.md").read_text()
    assert "not an annual probability" in report
    # The 2D section's default sizes, stated beside the numbers they decide.
    assert "Elements: the dam 3.00 m far from the impact and 0.200 m near it, the log 0.200 m." \
        in report


def test_bootstrap_band_is_seeded(tmp_path):
    a = sweep.run(sweep.from_dict(fake_config(n=20)), out=tmp_path / "a")
    b = sweep.run(sweep.from_dict(fake_config(n=20)), out=tmp_path / "b")
    for o in ("peak_force_N_per_m", "peak_tensile_stress_Pa"):
        assert a["exceedance"][o]["lower"] == b["exceedance"][o]["lower"]
        assert a["exceedance"][o]["upper"] == b["exceedance"][o]["upper"]


def test_check_convergence_reruns_the_worst_at_refine_plus_one(tmp_path):
    """The fake's outputs do not depend on the mesh: both values equal, change 0."""
    s = sweep.run(sweep.from_dict(fake_config(n=8)), out=tmp_path / "o",
                  check_convergence=True)
    c = s["convergence"]["peak_force_N_per_m"]
    assert c["id"] == s["worst"]["peak_force_N_per_m"]["id"] and c["refine"] == 0
    assert c["value_refined"] == c["value"] and c["relative_change"] == 0.0


# ---- the table: resume, torn line, changed config -----------------------------------------

def test_torn_last_line_is_cut_and_resume_adds_no_duplicate(tmp_path):
    cfg = sweep.from_dict(fake_config(n=12))
    out = tmp_path / "out"
    sweep.run(cfg, out=out)
    full = (out / "results.jsonl").read_text().splitlines(keepends=True)
    # Keep 5 rows and half of the 6th, as a kill in the middle of a write would.
    (out / "results.jsonl").write_text("".join(full[:5]) + full[5][:len(full[5]) // 2])
    log = tmp_path / "evaluations.log"
    os.environ["SWEEP_FAKE_LOG"] = str(log)
    try:
        s = sweep.run(cfg, out=out)
    finally:
        del os.environ["SWEEP_FAKE_LOG"]
    assert s["computed_this_run"] == 7 and len(log.read_text().splitlines()) == 7
    ids = [json.loads(l)["id"] for l in (out / "results.jsonl").read_text().splitlines()]
    assert sorted(ids) == list(range(12))
    csv_ids = [int(l.split(",")[0]) for l in (out / "results.csv").read_text().splitlines()[1:]]
    assert csv_ids == list(range(12))


def test_changed_config_is_refused(tmp_path):
    out = tmp_path / "out"
    sweep.run(sweep.from_dict(fake_config(n=6)), out=out)
    before = (out / "results.jsonl").read_bytes()
    with pytest.raises(TableError, match="config changed"):
        sweep.run(sweep.from_dict(fake_config(n=6, seed=99)), out=out)
    assert (out / "results.jsonl").read_bytes() == before  # nothing lost or added


def test_sigkill_then_resume_gives_the_uninterrupted_table(tmp_path):
    n, k = 16, 4
    cfg = write_toml(tmp_path / "sweep.toml", fake_config(n=n, kind="processes"))
    reference = tmp_path / "reference"
    sweep.run(sweep.from_dict(fake_config(n=n)), out=reference)
    out, log1, log2 = tmp_path / "out", tmp_path / "run1.log", tmp_path / "run2.log"
    cmd = [sys.executable, "-m", "flexcontact", "sweep", str(cfg), "--out", str(out),
           "--workers", "2"]
    proc = subprocess.Popen(cmd, env=env_with_fakes(SWEEP_FAKE_LOG=log1,
                                                    SWEEP_FAKE_SLEEP_S=0.5),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    table = out / "results.jsonl"
    deadline = time.monotonic() + 300
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if table.exists() and table.read_bytes().count(b"\n") >= k:
                break
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the driver and its workers
        proc.wait()
    done = {json.loads(l)["id"] for l in table.read_text().splitlines()
            if l.endswith("}")}
    assert k <= len(done) < n, len(done)
    subprocess.run(cmd + ["--engine", "serial"], env=env_with_fakes(SWEEP_FAKE_LOG=log2),
                   check=True, capture_output=True, timeout=300)
    same_tables(table_of(out), table_of(reference), rtol=0.0)
    ids = [json.loads(l)["id"] for l in table.read_text().splitlines()]
    assert sorted(ids) == list(range(n))  # every id once: none lost, none duplicated
    # The resumed run evaluated exactly the scenarios that had no row.
    _, points, scenarios = build_scenarios(sweep.from_dict(fake_config(n=n)))
    keys = [sweep_fakes.log_key(s) for s in scenarios]
    second = log2.read_text().splitlines()
    assert sorted(second) == sorted(keys[i] for i in range(n) if i not in done)


# ---- engines give the same table ----------------------------------------------------------

def test_serial_processes_and_dask_give_the_same_table(tmp_path):
    pytest.importorskip("distributed")
    tables = {}
    for kind in ("serial", "processes", "dask"):
        raw = fake_config(n=12, engine={"workers": 2})
        raw["engine"]["kind"] = kind
        sweep.run(sweep.from_dict(raw), out=tmp_path / kind)
        tables[kind] = table_of(tmp_path / kind)
    same_tables(tables["processes"], tables["serial"])
    same_tables(tables["dask"], tables["serial"])
    assert ((tmp_path / "dask" / "results.csv").read_text()
            == (tmp_path / "serial" / "results.csv").read_text())


def test_batches_group_the_scenarios_by_log_and_keep_their_order():
    """Units of at most k, cut from the scenarios ordered by log then id: the same tasks
    always make the same units."""
    _, _, scenarios = build_scenarios(sweep.from_dict(fake_config(n=12)))
    tasks = list(enumerate(scenarios))
    units = sweep.engines.batches(tasks, 5)
    assert [len(u) for u in units] == [5, 5, 2]
    flat = [t for u in units for t in u]
    assert sorted(i for i, _ in flat) == list(range(12))
    keys = [(s.log_length_m, s.wood.rho_kg_m3, i) for i, s in flat]
    assert keys == sorted(keys)
    assert sweep.engines.batches(tasks[::-1], 5) == units
    assert sweep.engines.batches(tasks, 1) == [[t] for t in tasks]


def test_batched_sweep_gives_the_same_table_and_keeps_the_rows_before_an_error(tmp_path):
    """engine.batch = 5, with an evaluator that has evaluate_many and with one that has
    not: the same table as one by one (bitwise), the same counts. A scenario that fails
    stops the sweep with its error, after the rows of its batch that were computed are
    written."""
    one = sweep.run(sweep.from_dict(fake_config(n=12)), out=tmp_path / "one")
    for name in ("LinearEvaluator", "BatchingEvaluator"):
        raw = fake_config(n=12, engine={"batch": 5})
        raw["engine"]["evaluator"] = f"sweep_fakes:{name}"
        five = sweep.run(sweep.from_dict(raw), out=tmp_path / name)
        same_tables(table_of(tmp_path / name), table_of(tmp_path / "one"), rtol=0.0)
        assert five["counts"] == one["counts"], name
    raw = fake_config(n=12, engine={"batch": 5})
    raw["engine"]["evaluator"] = "sweep_fakes:BatchingEvaluator"
    os.environ["SWEEP_FAKE_FAIL_SPEED_ABOVE"] = "3.5"
    try:
        with pytest.raises(RuntimeError, match="speed .* above 3.5"):
            sweep.run(sweep.from_dict(raw), out=tmp_path / "failing")
    finally:
        del os.environ["SWEEP_FAKE_FAIL_SPEED_ABOVE"]
    _, _, scenarios = build_scenarios(sweep.from_dict(raw))
    units = sweep.engines.batches(list(enumerate(scenarios)), 5)
    first_bad = next(k for k, u in enumerate(units) if any(s.log_speed_m_s > 3.5 for _, s in u))
    written = {r[0] for r in table_of(tmp_path / "failing")}
    expected = {i for u in units[:first_bad] for i, _ in u}
    expected |= {i for i, s in units[first_bad] if s.log_speed_m_s <= 3.5}
    assert written == expected and len(written) < 12


@pytest.mark.mpi
def test_mpi_futures_engine_gives_the_same_table(tmp_path):
    raw = fake_config(n=12)
    sweep.run(sweep.from_dict(raw), out=tmp_path / "serial")
    cfg = write_toml(tmp_path / "sweep.toml", raw)
    mpirun(3, "-m", "mpi4py.futures", "-m", "flexcontact", "sweep", cfg, "--out",
           tmp_path / "mpi", "--engine", "mpi", timeout=300,
           env={"PYTHONPATH": env_with_fakes()["PYTHONPATH"]})
    same_tables(table_of(tmp_path / "mpi"), table_of(tmp_path / "serial"))
    workers = {json.loads(l)["worker"]
               for l in (tmp_path / "mpi" / "results.jsonl").read_text().splitlines()}
    assert 1 <= len(workers) <= 2  # ranks 1 and 2 computed, rank 0 drove
    # Without mpi4py.futures every rank would run the sweep: refused, nothing written.
    with pytest.raises(subprocess.CalledProcessError) as e:
        mpirun(2, "-m", "flexcontact", "sweep", cfg, "--out", tmp_path / "plain",
               timeout=300, env={"PYTHONPATH": env_with_fakes()["PYTHONPATH"]})
    assert "mpi4py.futures" in e.value.stderr and not (tmp_path / "plain").exists()


# ---- a real sweep: the monolithic evaluator on the default dam mesh ---------------------

def test_monolithic_sweep_over_speeds_scales_and_counts(tmp_path):
    """Two speeds on the default mesh. The dam is linear, Coulomb's cone and the impact law
    are positively homogeneous and the dam starts at rest in equilibrium, so the impact part
    of every output scales with the speed (to round-off: measured 1e-11); the impulse equals
    the log's momentum change (conservation); each scenario costs its own 2 factorizations.
    """
    raw = {"parameters": {"log_speed_m_s": {"values": [2.0, 3.0]}},
           "engine": {"evaluator": "monolithic", "kind": "serial"},
           "output": {"plots": True}}
    s = sweep.run(sweep.from_dict(raw), out=tmp_path / "out")
    rows = table_of(tmp_path / "out")
    a, b = rows[0][2], rows[1][2]
    for o in ("peak_force_N_per_m", "impulse_N_s_per_m"):
        assert abs(b[o] / a[o] - 1.5) <= 1e-6, (o, b[o] / a[o])
    for r in (a, b):
        assert abs(r["impulse_N_s_per_m"] + r["log_momentum_change_N_s_per_m"]) \
            <= 1e-9 * r["impulse_N_s_per_m"]
        assert r["heel_stress_static_Pa"] == a["heel_stress_static_Pa"]
    rise_a = a["heel_stress_impact_Pa"] - a["heel_stress_static_Pa"]
    rise_b = b["heel_stress_impact_Pa"] - b["heel_stress_static_Pa"]
    assert rise_a > 0 and abs(rise_b / rise_a - 1.5) <= 1e-6, (rise_a, rise_b)
    assert s["worst"]["peak_force_N_per_m"]["id"] == 1
    assert s["counts"]["factorizations"] == {"stage1": 2, "stage2": 2, "total": 4}
    assert (tmp_path / "out" / "envelope_peak_force_N_per_m.png").stat().st_size > 0
    # The same sweep on two worker processes: the same table (MUMPS and the contact solver
    # are deterministic for a given matrix).
    raw["engine"].update(kind="processes", workers=2)
    sweep.run(sweep.from_dict(raw), out=tmp_path / "processes")
    same_tables(table_of(tmp_path / "processes"), rows)


def test_reuse_sweep_factors_the_dam_twice_and_the_log_once(tmp_path):
    """Over speeds, pitch angles, friction and water levels on one dam mesh and one log
    geometry, the reusing evaluator factors K (stage 1) and K_eff (stage 2) once each, plus
    the log's own factorization: three in all, whatever the number of scenarios (serial:
    one evaluator; engine.model = false). With a dam model (engine.model) it is prepared
    once (K and K_eff factored once each, as the factors it saves, and the log's model
    kept), the evaluator restores both factors and the log and factors nothing, and the
    table is the same to 1e-10."""
    pytest.importorskip("flexcontact.dam.reuse")
    raw = {"parameters": {"log_speed_m_s": {"values": [1.5, 3.0]},
                          "log_pitch_deg": {"values": [5.0, 10.0]},
                          "friction_mu": {"values": [0.3, 0.6]},
                          "water_level_m": {"values": [26.0, 27.0]}},
           "engine": {"evaluator": "reuse", "kind": "serial", "model": False},
           "output": {"plots": False}}
    own = sweep.run(sweep.from_dict(raw), out=tmp_path / "own")
    assert own["scenarios"] == 16
    assert own["counts"]["factorizations"]["total"] == 3, own["counts"]
    assert "dam_model" not in own
    raw["engine"]["model"] = str(tmp_path / "model")
    s = sweep.run(sweep.from_dict(raw), out=tmp_path / "out")
    assert s["counts"]["factorizations"]["total"] == 0, s["counts"]
    assert s["counts"]["restorations"] == {"dam_stage1": 1, "dam_stage2": 1, "log": 1,
                                           "total": 3}, s["counts"]  # K, K_eff, the log
    assert s["dam_model"]["prepared_this_run"]
    assert s["dam_model"]["counts"]["factorizations"] == {"dam_stage1": 1, "dam_stage2": 1,
                                                          "log": 1}
    for o, w in own["worst"].items():
        assert s["worst"][o]["id"] == w["id"]
        assert s["worst"][o]["value"] == pytest.approx(w["value"], rel=1e-10)
    # Run again with the model there: reused, not prepared, the same table.
    again = sweep.run(sweep.from_dict(raw), out=tmp_path / "again")
    assert not again["dam_model"]["prepared_this_run"]
    assert again["worst"] == s["worst"]
    # A model of another dam is refused, naming the parameter, before any computing.
    raw["base"] = {"crest_width_m": 6.0}
    with pytest.raises(ConfigError, match="crest_width_m=6.0"):
        sweep.run(sweep.from_dict(raw), out=tmp_path / "other")
    assert not (tmp_path / "other" / "results.jsonl").exists()
    # The same dam with a shorter log: the sample's time step changed, and the error says
    # that it is the sample's, not the dam's.
    del raw["base"]
    raw["parameters"]["log_length_m"] = {"values": [6.0]}
    with pytest.raises(ConfigError, match="time step .* differs from the model's .*"
                                          "follows from the sampled scenarios"):
        sweep.run(sweep.from_dict(raw), out=tmp_path / "shorter")
    assert not (tmp_path / "shorter" / "results.jsonl").exists()


def test_default_model_is_the_sweeps_own_prepared_once_and_replaced_if_stale(tmp_path):
    """Without engine.model the "reuse" sweep prepares its dam model in its output folder
    (dam_model/) and its evaluator factors nothing; run again, it reuses it. A changed
    config is refused by the table before any model is prepared. A stale model in that
    folder (here one of another time step) is prepared again, and the summary says why."""
    pytest.importorskip("flexcontact.dam.reuse")
    raw = {"parameters": {"log_speed_m_s": {"values": [1.5, 3.0]},
                          "log_length_m": {"values": [8.0]}},
           "engine": {"evaluator": "reuse", "kind": "serial"}, "output": {"plots": False}}
    out = tmp_path / "out"
    s = sweep.run(sweep.from_dict(raw), out=out)
    assert s["dam_model"]["path"] == str(out / "dam_model")
    assert s["dam_model"]["prepared_this_run"] and "replaced" not in s["dam_model"]
    assert s["counts"]["factorizations"]["total"] == 0, s["counts"]
    manifest = (out / "dam_model" / "manifest.json").read_bytes()
    again = sweep.run(sweep.from_dict(raw), out=out)
    assert again["computed_this_run"] == 0 and not again["dam_model"]["prepared_this_run"]
    changed = {**raw, "parameters": {**raw["parameters"],
                                     "log_speed_m_s": {"values": [1.0, 3.0]}}}
    with pytest.raises(TableError, match="config changed"):
        sweep.run(sweep.from_dict(changed), out=out)
    assert (out / "dam_model" / "manifest.json").read_bytes() == manifest
    # The same model under a sweep of a longer log: another time step, so prepared again.
    longer = {**raw, "parameters": {**raw["parameters"], "log_length_m": {"values": [12.0]}}}
    shutil.copytree(out / "dam_model", tmp_path / "longer" / "dam_model")
    s = sweep.run(sweep.from_dict(longer), out=tmp_path / "longer")
    assert s["dam_model"]["prepared_this_run"]
    assert "time step" in s["dam_model"]["replaced"]
    assert "It replaced this sweep's earlier model" in (tmp_path / "longer" /
                                                         "report.md").read_text()
    m = json.loads((tmp_path / "longer" / "dam_model" / "manifest.json").read_text())
    assert m["inputs"]["dt_s"] == pytest.approx(s["dt_s"], rel=0)
    # A worker that does not see the sweep's folder (a Dask worker elsewhere) factors the
    # dam itself rather than fail; one given a model path of its own still needs it.
    from dataclasses import replace
    from flexcontact.sweep.driver import prepare
    spec = prepare(sweep.from_dict(raw), out)["spec"]
    assert spec.loads_model() and spec.model == str((out / "dam_model").resolve())
    elsewhere = replace(spec, model=str(tmp_path / "not_here" / "dam_model"))
    assert not elsewhere.loads_model()
    assert elsewhere.build().counts()["factorizations"]["dam_stage1"] == 1
    assert replace(elsewhere, model_if_seen=False).loads_model()
    # --no-model: the (serial) evaluator factors K, K_eff and the log itself.
    cfg = write_toml(tmp_path / "own.toml", raw)
    proc = subprocess.run([sys.executable, "-m", "flexcontact", "sweep", str(cfg), "--out",
                           str(tmp_path / "own"), "--no-model"], capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    own = json.loads((tmp_path / "own" / "summary.json").read_text())
    assert "dam_model" not in own and not (tmp_path / "own" / "dam_model").exists()
    assert own["counts"]["factorizations"]["total"] == 3, own["counts"]


def test_3d_reuse_sweep_over_yaw_and_place_factors_the_block_once(tmp_path):
    """The 3D block: a grid over yaw and the log's place across the block, on the dam
    block's face patch that holds them all. The sweep's dam model factors K and K_eff of
    the block once each (K_eff twice: with its face's Schur complement for the steps, plainly
    for the response functions), and the round log; the evaluator restores the three and
    factors nothing. Every scenario's impulse is the log's loss of momentum along x
    (1e-9); the report speaks of the 3D block and of totals, not per metre. With
    --check-convergence the worst are re-run by the monolithic evaluator at refine + 1, whose
    impulse is again the log's loss of momentum (1e-9). (Measured: the worst filtered peak
    force moves by +2.9 % at refine + 1, the mesh's share of its error.)"""
    pytest.importorskip("flexcontact.dam.reuse")
    raw = {"base": {"dim": 3, "mesh_size_far_m": 6.0, "mesh_size_impact_m": 0.4},
           "parameters": {"log_yaw_deg": {"values": [-10.0, 10.0]},
                          "log_across_m": {"values": [4.0, 11.0]}},
           "engine": {"evaluator": "reuse", "kind": "serial"}, "output": {"plots": False}}
    s = sweep.run(sweep.from_dict(raw), out=tmp_path / "out", check_convergence=True)
    assert s["scenarios"] == 4
    assert s["counts"]["factorizations"]["total"] == 0, s["counts"]
    assert s["counts"]["restorations"] == {"dam_stage1": 1, "dam_stage2": 1, "log": 1,
                                           "total": 3}, s["counts"]
    # Ŵ factored once more without its Schur complement, for the response functions.
    assert s["dam_model"]["counts"]["factorizations"] == {"dam_stage1": 1, "dam_stage2": 1,
                                                          "dam_response": 1, "log": 1}
    c = s["convergence"]["peak_force_filtered_N_per_m"]
    assert c["evaluator_refined"] == "monolithic" and c["refine"] == 0
    fine = c["outputs_refined"]
    assert abs(fine["impulse_N_s_per_m"] + fine["log_momentum_change_N_s_per_m"]) \
        <= 1e-9 * fine["impulse_N_s_per_m"]
    for _, _, o in table_of(tmp_path / "out"):
        assert o["impulse_N_s_per_m"] > 0
        assert abs(o["impulse_N_s_per_m"] + o["log_momentum_change_N_s_per_m"]) \
            <= 1e-9 * o["impulse_N_s_per_m"]
    report = (tmp_path / "out" / "report.md").read_text()
    assert "3D dam block" in report and "MN/m" not in report
    assert "by the monolithic evaluator" in report
    # 0.4 m elements against Boussinesq's tension layer 0.085 m deep at 1 m: not resolved.
    assert ("Elements: the dam 6.00 m far from the impact and 0.400 m near it, the log "
            "0.400 m. At 1.00 m from the impact the face's tension lies in a layer about "
            "8.50 cm deep, thinner than the 0.400 m elements") in report


# ---- a categorical input: the log's end shape ---------------------------------------------

def shape_config(n=30, method="lhs"):
    raw = fake_config(n=n, seed=9, method=method)
    raw["parameters"] = {"log_speed_m_s": {"distribution": "uniform", "lo": 0.5, "hi": 4.0},
                         "log_end_shape": {"values": ["flat", "chamfered", "rounded"]}}
    raw["engine"]["evaluator"] = "sweep_fakes:EndShapeEvaluator"
    return raw


def test_end_shape_is_sampled_uniformly_and_reported_per_name(tmp_path):
    """LHS gives each of the 3 names n/3 scenarios; the report has no rank correlation for
    the name but, per name, its count, median, largest value and the share above the
    median and the 10 % value of all, exactly as from the fake's outputs."""
    n = 30
    cfg = sweep.from_dict(shape_config(n))
    _, points, scenarios = build_scenarios(cfg)
    shapes = [p["log_end_shape"] for p in points]
    assert all(shapes.count(x) == n // 3 for x in sweep_fakes.END_FACTOR)
    assert [s.log_end_shape for s in scenarios] == shapes
    summary = sweep.run(sweep.from_dict(shape_config(n) | {"output": {"plots": True,
                                                                    "bootstrap": 50}}),
                        out=tmp_path / "out")
    force = np.array([1e6 * p["log_speed_m_s"] * sweep_fakes.END_FACTOR[p["log_end_shape"]]
                      for p in points])
    assert set(summary["spearman"]["peak_force_N_per_m"]) == {"log_speed_m_s"}
    x50, x10 = np.quantile(force, [0.5, 0.9])
    table = summary["by_category"]["log_end_shape"]["peak_force_N_per_m"]
    for name in sweep_fakes.END_FACTOR:
        f = force[[s == name for s in shapes]]
        assert table[name] == {"n": n // 3, "median": float(np.median(f)),
                               "max": float(f.max()),
                               "p_over_median": float(np.mean(f > x50)),
                               "p_over_p10": float(np.mean(f > x10))}
    w = summary["worst"]["peak_force_N_per_m"]
    assert w["value"] == force.max() and w["inputs"] == points[int(np.argmax(force))]
    report = (tmp_path / "out" / "report.md").read_text()
    assert "## By log end shape (`log_end_shape`)" in report
    assert "The log's end, its shape swept, " in report  # not the base scenario's shape
    assert (tmp_path / "out" / "envelope_peak_force_N_per_m.png").exists()
    rows = (tmp_path / "out" / "results.csv").read_text()
    assert "'rounded'" in rows


@pytest.mark.parametrize("table, words", [
    ({"values": ["flat", 2.0]}, "parameters.log_end_shape.values[1]=2.0: must be a name"),
    ({"values": []}, "parameters.log_end_shape.values=[]: must be a non-empty list"),
    ({"distribution": "uniform", "lo": 0, "hi": 1},
     "parameters.log_end_shape.distribution='uniform': a categorical input takes values"),
    ({"values": ["flat", "flat"]}, "a value is repeated"),
])
def test_bad_categorical_input_is_named(table, words):
    raw = shape_config()
    raw["parameters"]["log_end_shape"] = table
    with pytest.raises(ConfigError) as e:
        sweep.from_dict(raw)
    assert words in str(e.value)


def test_unknown_end_shape_is_named_with_its_scenario():
    raw = shape_config(method="grid")
    raw["sample"] = {"method": "grid"}
    raw["parameters"] = {"log_end_shape": {"values": ["flat", "pointed"]}}
    with pytest.raises(ConfigError, match=r"scenario 1 .*log_end_shape='pointed'"):
        build_scenarios(sweep.from_dict(raw))


def test_command_line_names_the_worst_end_shape(tmp_path):
    """`python -m flexcontact sweep` with a categorical input: it finishes and prints each
    worst scenario's inputs, the end shape by its name."""
    cfg = write_toml(tmp_path / "shapes.toml", shape_config(n=6))
    proc = subprocess.run([sys.executable, "-m", "flexcontact", "sweep", str(cfg), "--out",
                           str(tmp_path / "out")], env=env_with_fakes(), capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    worst = summary["worst"]["peak_force_N_per_m"]
    assert f"log_end_shape={worst['inputs']['log_end_shape']}" in proc.stdout


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "examples").glob("sweep_*.toml")))
def test_the_example_sweeps_build_every_scenario(name):
    """Each shipped sweep config is checked and builds all its scenarios before anything is
    computed (a stale key would otherwise surface only in the main job)."""
    cfg = sweep.config.load(ROOT / "examples" / name)
    base, points, scenarios = build_scenarios(cfg)
    assert scenarios and len(scenarios) == len(points) == (cfg.n or len(points))


def test_the_elastic_and_crushing_example_sweeps_differ_only_by_the_crushing_end():
    """docs/dam.md sets their forces side by side as the crushing end's effect: the same
    sample, ranges and log mesh, the crushing end and its refinement only in one."""
    elastic = sweep.config.load(ROOT / "examples" / "sweep_3d.toml").raw
    crushing = sweep.config.load(ROOT / "examples" / "sweep_3d_crushing.toml").raw
    for table in ("sample", "parameters", "engine", "output"):
        assert elastic.get(table) == crushing.get(table), table
    end_only = {"log_end_crushes", "mesh_size_contact_m", "contact_zone_m", "contact_layer_m"}
    differ = {k for k in set(elastic["base"]) | set(crushing["base"])
              if elastic["base"].get(k) != crushing["base"].get(k)}
    assert differ == end_only


def test_the_main_jobs_sweep_is_the_measured_30_minute_mesh():
    """docs/dam.md states the closing sweep's error from the trade-off row of
    bench/sweep_1000_3d_crushing.toml's mesh: the two must stay the same mesh and physics."""
    closing = sweep.config.load(ROOT / "examples" / "sweep_3d_crushing.toml")
    bench = sweep.config.load(ROOT / "bench" / "sweep_1000_3d_crushing.toml")
    b_close, _, _ = build_scenarios(closing)
    b_bench, _, _ = build_scenarios(bench)
    keys = ("dim", "log_end_crushes", "h_far_m", "h_impact_m", "h_log_m", "h_contact_m",
            "contact_zone_m", "contact_layer_m", "time_scheme_theta")
    assert {k: getattr(b_close, k) for k in keys} == {k: getattr(b_bench, k) for k in keys}
    assert b_close.log_end_crushes
    assert "sweep_3d_crushing.toml" in (ROOT / "scripts" / "main.sh").read_text()
