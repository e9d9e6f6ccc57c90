"""What one back-substitution costs when several scenarios share it (docs/architecture.md
§7, "Several right-hand sides at once").

A 3D scenario at the main job's mesh spends most of its time in the solves of its two
bodies: each coupled step condenses and expands the dam (27,342 DOFs) and the log
(18,927 DOFs), and the log then flies on its plain factor. Each solve streams the whole
factor from memory for one right-hand side. Scenarios of one sweep that share the dam and a
log geometry could hand MUMPS their right-hand sides together, and it would read the factor
once for all of them.

This bench prepares the main job's dam model (``examples/dam_model_main_job.toml``, or takes
``--model PATH``), restores its three factors and times, for k = 1, 2, 4, 8, 16 right-hand
sides, one ``condense_many`` + ``expand_many`` of the dam and of the log and one
``solve_many`` of the log's plain factor: the median of ``--runs`` calls, divided by k.
Beside them, the single calls the stepper makes today (PETSc Vecs in, ``condense`` then
``expand``; ``solve``). It also checks that each column equals the single call's (relative
difference, recorded). With the back-substitution counts of the main job's what-if (dam and
log 147 coupled steps, the log's flight 169 steps) it projects the seconds of solves a
scenario would cost at each k: a projection from these timings, not a measured sweep.
Writes bench/batched_solves.json.

    /usr/bin/python3 bench/batched_solves.py [--runs 7] [--model PATH]
"""
import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--runs", type=int, default=7)
ap.add_argument("--model", default=None, help="a prepared main-job dam model (else prepared)")
ap.add_argument("--out", default=str(Path(__file__).with_name("batched_solves.json")))
args = ap.parse_args()
sys.path.insert(0, str(ROOT / "bench"))
from machine import machine  # noqa: E402
from main_job_model import main_job_model  # noqa: E402
from timing import median_time as median_s  # noqa: E402

KS = (1, 2, 4, 8, 16)
STEPS = {"dam": 147, "log": 147, "log_flight": 169}  # the main job's what-if, per scenario


def single(factor, new_vector, plain: bool, B: np.ndarray):
    """The calls the stepper makes today, one column at a time."""
    out = []
    for j in range(B.shape[1]):
        b = new_vector()
        b.array[:] = B[:, j]
        x = b.duplicate()
        if plain:
            factor.solve(b, x)
        else:
            c = np.array(factor.condense(b))
            factor.expand(c, x)
        out.append(x.array.copy())
        b.destroy()
        x.destroy()
    return np.array(out).T


def many(factor, plain: bool, B: np.ndarray) -> np.ndarray:
    if plain:
        return factor.solve_many(B)
    return factor.expand_many(factor.condense_many(B))


def measure(name, factor, new_vector, plain, rng) -> dict:
    n = int(factor.size)
    B = np.asfortranarray(rng.standard_normal((n, max(KS))))
    X1 = single(factor, new_vector, plain, B[:, :4])
    Xk = many(factor, plain, B[:, :4])
    row = {"dofs": n, "difference_to_single": float(np.abs(Xk - X1).max() / np.abs(X1).max()),
           "single_ms": 1e3 * median_s(lambda: single(factor, new_vector, plain, B[:, :1]),
                                       args.runs),
           "per_rhs_ms": {}}
    for k in KS:
        Bk = np.asfortranarray(B[:, :k])
        row["per_rhs_ms"][str(k)] = 1e3 * median_s(lambda: many(factor, plain, Bk),
                                                   args.runs) / k
    print(name, json.dumps(row), flush=True)
    return row


def main(model: Path) -> dict:
    from flexcontact.dam import model_file
    t0 = time.perf_counter()
    ev = model_file.load(model)
    log = ev.log_model(ev.base)
    load_s = time.perf_counter() - t0
    rng = np.random.default_rng(0)
    rows = {"dam": measure("dam", ev.dam.factor, ev.dam.new_vector, False, rng),
            "log": measure("log", log.factor, log.new_vector, False, rng)}
    if log.flight_factor is not None:
        rows["log_flight"] = measure("log_flight", log.flight_factor, log.new_vector, True, rng)
    projected = {"single": sum(STEPS[b] * r["single_ms"] for b, r in rows.items()) / 1e3}
    for k in KS:
        projected[str(k)] = sum(STEPS[b] * r["per_rhs_ms"][str(k)] for b, r in rows.items()) / 1e3
    return {"model_load_s": load_s, "factors": rows, "steps_per_scenario": STEPS,
            "projected_solve_s_per_scenario": projected}


with tempfile.TemporaryDirectory() as tmp:
    model, prepare_s = main_job_model(args.model, tmp)
    load_before = os.getloadavg()[0]
    result = main(model)
    result.update({"runs": args.runs, "prepare_s": prepare_s,
                   "load_average_1min": [load_before, os.getloadavg()[0]],
                   "machine": machine()})
Path(args.out).write_text(json.dumps(result, indent=1))
print(json.dumps(result["projected_solve_s_per_scenario"]))
