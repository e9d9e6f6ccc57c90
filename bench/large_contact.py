"""Large contact sets: the dense path (F* and W formed) against the factor path (W applied
through the factor of K, ``contact_operator="factor"``) on growing candidate contact zones of
one mesh; writes bench/large_contact.json.

    /usr/bin/python3 bench/large_contact.py            # about 5 minutes here (load average 20)
    /usr/bin/python3 bench/large_contact.py --quick    # two zones, for a smoke run

Each (zone, path) runs in its own process (the peak memory is the process's, from the
set-up and the increments only: bench/case.py's memory_phase). Per run: set-up time, the
median time of increments 2.., the local solve's iterations and back-substitutions, the
peak memory. Then: the dense path's extra memory over the factor path fitted as c·n_c²
(n_c contact DOFs; W's (m·d)² follows n_c² on these zones), the n_c where it passes this
machine's memory (extrapolated, stated as such), the calibration of flexcontact.memory's
estimate against the measured extra, and where (if anywhere) the factor path is faster.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

# (mesh, build keywords): one mesh per dimension, the candidate zone widened.
ZONES_2D = [("hertz2d", {"refine": 1, "zone_factor": z}) for z in (1.25, 2.5, 5.0)]
ZONES_3D = [("hertz3d", {"refine": 0, "zone_factor": z, "h_far": 0.02}) for z in (1.0,)]


def child(spec: dict) -> dict:
    """One (zone, path) run, in this process."""
    import case  # bench/case.py: the Hertz model and the phase's memory high-water mark
    import flexcontact as fc
    m = case.model(spec)
    case.compiled_form(m["a"])
    out = {"spec": spec, "dim": m["dim"], "dofs": m["dofs"]}
    rows = []
    with case.memory_phase(out):
        t0 = time.perf_counter()
        problem = fc.ContactProblem(m["a"], None, m["bcs"], m["interface"],
                                    contact_operator=spec["path"])
        out["setup_s"] = time.perf_counter() - t0
        n = spec["increments"]
        for i in range(1, n + 1):
            m["approach"](m["delta_m"] * i / n)
            before = problem.contact.applications if spec["path"] == "factor" else 0
            t0 = time.perf_counter()
            s = problem.step().summary
            rows.append({"increment_s": time.perf_counter() - t0, "iterations": s.iterations,
                         "residual": s.residual, "solver": s.solver,
                         "closed_pairs": s.stick + s.slip, "normal_force": s.normal_force,
                         "backsolves_in_contact_solve":
                             (problem.contact.applications - before)
                             if spec["path"] == "factor" else 0})
    out["contact_dofs"] = int(problem.n_contact_dofs)
    out["pairs"] = int(problem.m)
    out["increments"] = rows
    out["increment_s"] = float(np.median([r["increment_s"] for r in rows[1:] or rows]))
    out["factor_memory_mb"] = problem.flex_info.get("factor_memory_mb")
    return out


def run_child(spec: dict, timeout_s: float) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(REPO / "dolfinx_ext" / "python")] + [p for p in [env.get("PYTHONPATH")] if p])
    t0 = time.perf_counter()
    try:
        done = subprocess.run([sys.executable, __file__, "--child", json.dumps(spec)],
                              capture_output=True, text=True, env=env, timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return {"spec": spec, "error": f"timeout after {timeout_s} s"}
    lines = [ln for ln in done.stdout.splitlines() if ln.startswith("RESULT ")]
    if done.returncode != 0 or not lines:
        return {"spec": spec, "error": f"exit status {done.returncode}",
                "log_tail": (done.stdout + done.stderr)[-2000:]}
    out = json.loads(lines[-1][len("RESULT "):])
    out["wall_s"] = time.perf_counter() - t0
    return out


def analyse(runs: list[dict], dim: int, mem_total_b: float) -> dict:
    """The dense path's extra memory as c·n_c², where it passes the machine, the estimate's
    calibration, and the speed ratio per zone."""
    from flexcontact.memory import dense_bytes
    pairs = {}
    for r in runs:
        if "error" not in r and r["dim"] == dim:
            pairs.setdefault(r["contact_dofs"], {})[r["spec"]["path"]] = r
    rows = []
    for n_c, by in sorted(pairs.items()):
        if {"dense", "factor"} <= set(by):
            d, f = by["dense"], by["factor"]
            extra = (d["peak_mb"] - f["peak_mb"]) * 2**20
            rows.append({"contact_dofs": n_c, "pairs": d["pairs"],
                         "dense_peak_mb": d["peak_mb"], "factor_peak_mb": f["peak_mb"],
                         "dense_extra_mb": extra / 2**20,
                         "estimate_mb": dense_bytes(n_c, d["pairs"], dim) / 2**20,
                         "dense_setup_s": d["setup_s"], "factor_setup_s": f["setup_s"],
                         "dense_increment_s": d["increment_s"],
                         "factor_increment_s": f["increment_s"],
                         "factor_over_dense_increment": f["increment_s"] / d["increment_s"],
                         "factor_over_dense_total":
                             (f["setup_s"] + sum(x["increment_s"] for x in f["increments"]))
                             / (d["setup_s"] + sum(x["increment_s"] for x in d["increments"]))})
    out = {"dim": dim, "zones": rows}
    big = [r for r in rows if r["dense_extra_mb"] > 0]
    if big:
        x = np.array([r["contact_dofs"] ** 2 for r in big], float)
        y = np.array([r["dense_extra_mb"] * 2**20 for r in big], float)
        c = float(x @ y / (x @ x))  # least squares through the origin
        out["dense_extra_bytes_per_nc2"] = c
        out["nc_where_dense_passes_machine"] = float(np.sqrt(mem_total_b / c))
        out["estimate_over_measured"] = [r["estimate_mb"] / r["dense_extra_mb"] for r in big]
    faster = [r["contact_dofs"] for r in rows if r["factor_over_dense_total"] < 1.0]
    out["factor_faster_in_total_from_nc"] = min(faster) if faster else None
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true", help="two 2D zones only")
    ap.add_argument("--increments", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=900.0, help="per run (s)")
    ap.add_argument("--out", default=str(HERE / "large_contact.json"))
    args = ap.parse_args()
    if args.child:
        print("RESULT " + json.dumps(child(json.loads(args.child))), flush=True)
        return
    import machine
    zones = ZONES_2D[:2] if args.quick else ZONES_2D + ZONES_3D
    runs = []
    for mesh, build in zones:
        for path in ("dense", "factor"):
            spec = {"name": f"{mesh}_{build['zone_factor']}_{path}", "mesh": mesh,
                    "build": build, "path": path, "increments": args.increments, "mu": 0.3}
            r = run_child(spec, args.timeout)
            runs.append(r)
            print(spec["name"], r.get("error") or
                  f"n_c {r['contact_dofs']} setup {r['setup_s']:.2f} s increment "
                  f"{r['increment_s']:.3f} s peak {r['peak_mb']:.0f} MB", flush=True)
    mem_total = float(Path("/proc/meminfo").read_text().split()[1]) * 1024
    result = {"machine": machine.machine(), "mem_total_bytes": mem_total, "runs": runs,
              "2d": analyse(runs, 2, mem_total), "3d": analyse(runs, 3, mem_total)}
    Path(args.out).write_text(json.dumps(result, indent=1))
    for d in ("2d", "3d"):
        a = result[d]
        print(d, {k: v for k, v in a.items() if k != "zones"})


if __name__ == "__main__":
    main()
