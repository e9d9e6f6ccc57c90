"""What holding F̂ as the models' shared blocks saves (docs/architecture.md §7, "Blocks shared
between runs").

At the main job's mesh a scenario's F̂ = diag(F̂_log, F̂_face) is 6,909² entries when formed
whole (the kernel's dense path, ``fhat="dense"``); held as the log's and the face's blocks
(``fhat="shared"``, the default) it is formed once per model and shared by every scenario.
This bench prepares the main job's dam model (``examples/dam_model_main_job.toml``, or takes
``--model PATH``) and times, each in a new process so that its peak memory is its own:

* one scenario alone (the main job's, ``evaluate``), and
* ``--k`` scenarios side by side (``evaluate_many``; the main job's log at speeds from 1.5
  to 3.25 m/s),

with each F̂, alternating the two ``--runs`` times. Per process: the wall time of the
evaluation (the log model's restoration excluded), the evaluator's split of it, its peak
resident memory, and the outputs, which must agree between the two to 1e-8 relative alone
and to 1e-6 side by side (there each differs from its run alone by MUMPS's round-off for
several columns, which a step's index set can amplify: tests/test_shared_solves.py).
Writes bench/shared_blocks.json with the machine's load before and after.

    /usr/bin/python3 bench/shared_blocks.py [--runs 1] [--k 8] [--model PATH]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--runs", type=int, default=1)
ap.add_argument("--k", type=int, default=8)
ap.add_argument("--model", default=None, help="a prepared main-job dam model (else prepared)")
ap.add_argument("--out", default=str(Path(__file__).with_name("shared_blocks.json")))
ap.add_argument("--one", nargs=3, metavar=("MODEL", "MODE", "FHAT"), help=argparse.SUPPRESS)
args = ap.parse_args()
KEYS = ("peak_force_N_per_m", "peak_force_filtered_N_per_m", "impulse_N_s_per_m",
        "heel_stress_impact_Pa", "peak_tensile_stress_Pa", "peak_contact_pressure_Pa",
        "log_rotation_rad", "steps", "dam_back_substitutions", "log_back_substitutions")


def one(model: str, mode: str, fhat: str) -> dict:
    """One process's measurement (run with --one)."""
    import resource
    from flexcontact.dam import model_file
    ev = model_file.load(model, fhat=fhat)
    base = ev.base.replace(log_speed_m_s=2.0)
    ev.log_model(base)  # restored before the clock: the same for both
    scenarios = ([base] if mode == "alone" else
                 [base.replace(log_speed_m_s=1.5 + 0.25 * i) for i in range(args.k)])
    t0 = time.perf_counter()
    outs = [ev.evaluate(base)] if mode == "alone" else ev.evaluate_many(scenarios)
    wall = time.perf_counter() - t0
    return {"fhat": fhat, "mode": mode, "scenarios": len(scenarios), "wall_s": wall,
            "peak_rss_GB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6,
            "split_s": ev.timings(),
            "outputs": [{k: o[k] for k in KEYS} if isinstance(o, dict) else repr(o)
                        for o in outs]}


if args.one:
    print(json.dumps(one(*args.one)))
    sys.exit(0)

sys.path.insert(0, str(ROOT / "bench"))
from machine import machine  # noqa: E402
from main_job_model import main_job_model  # noqa: E402


def measure(model: Path) -> dict:
    rows = []
    for _ in range(args.runs):
        for mode in ("alone", "together"):
            for fhat in ("dense", "shared"):
                r = subprocess.run([sys.executable, __file__, "--k", str(args.k), "--one",
                                    str(model), mode, fhat], check=True, cwd=ROOT,
                                   capture_output=True, text=True)
                rows.append(json.loads(r.stdout.strip().splitlines()[-1]))
                print(json.dumps({k: rows[-1][k] for k in ("fhat", "mode", "wall_s",
                                                           "peak_rss_GB")}), flush=True)
    worst = {"alone": (0.0, None), "together": (0.0, None)}
    for a, b in zip(rows[0::2], rows[1::2]):
        for oa, ob in zip(a["outputs"], b["outputs"]):
            for k, v in oa.items():
                if isinstance(v, float) and v != 0.0:
                    worst[a["mode"]] = max(worst[a["mode"]], (abs(ob[k] - v) / abs(v), k))
    for mode, tol in (("alone", 1e-8), ("together", 1e-6)):
        if worst[mode][0] > tol:
            sys.exit(f"the two F̂ disagree {mode}: {worst[mode][0]:.2e} relative in "
                     f"{worst[mode][1]}")
    ratio = {}
    for mode in ("alone", "together"):
        d = [r for r in rows if r["mode"] == mode and r["fhat"] == "dense"]
        s = [r for r in rows if r["mode"] == mode and r["fhat"] == "shared"]
        ratio[mode] = {"wall_shared_over_dense": [b["wall_s"] / a["wall_s"] for a, b in zip(d, s)],
                       "memory_shared_over_dense": [b["peak_rss_GB"] / a["peak_rss_GB"]
                                                    for a, b in zip(d, s)]}
    return {"rows": rows, "ratios": ratio, "largest_relative_difference": worst}


with tempfile.TemporaryDirectory() as tmp:
    model, prepare_s = main_job_model(args.model, tmp)
    load_before = os.getloadavg()[0]
    result = measure(model)
    result.update({"what": "the main job's scenario alone and k side by side, with F̂ formed "
                           "whole per scenario (dense) and held as the models' shared blocks",
                   "k": args.k, "runs": args.runs, "prepare_s": prepare_s,
                   "load_average_1min": [load_before, os.getloadavg()[0]],
                   "machine": machine()})
Path(args.out).write_text(json.dumps(result, indent=1))
print(json.dumps(result["ratios"]))
