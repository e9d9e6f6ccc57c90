"""Large contact sets: the dense path (F* and W formed) against the factor path (W applied
through the factor of K, ``contact_operator="factor"``) on growing candidate contact zones;
writes bench/large_contact.json.

    /usr/bin/python3 bench/large_contact.py            # about 25 minutes here (loaded machine)
    /usr/bin/python3 bench/large_contact.py --quick    # two small zones, for a smoke run
    /usr/bin/python3 bench/large_contact.py --full     # adds n_c = 12,004 (the dense path: ~6 GB)

Paths per zone: ``dense``; ``factor`` (the working set of W's columns, solve_working_set);
``factor_iteration`` (FLEXCONTACT_WORKING_SET_GB=0: the matrix-free accelerated fixed point
alone, the factor path as it was before the working set). Zones: the earlier Hertz zones
(2D refine 1, zone 1.25a to 5a; 3D one zone) and wide 2D zones of half-width 9a whose
spacing is refined so that n_c = 804 to 8,004 (12,004 with --full): about one pair in six
comes into contact, the rest stay open; the mesh is fine only in a layer 10 elements deep
along the zone (meshes/hertz2d.py: fine_depth). Each (zone, path) runs in its own process, so the
peak memory is the process's own (set-up and increments only: bench/case.py's
memory_phase). Per run: set-up time, each increment's time and iterations, the
back-substitutions and block columns of the local solve, the peak memory.

Then per dimension: the dense path's extra memory over the factor path fitted as c·n_c²
and the n_c where the dense path's peak passes this machine's memory (from the measured
curve), flexcontact.memory's estimate against the measured extra, the smallest n_c where
the factor path's peak is below the dense path's, and the speed ratios. Last, on the
largest zone with FLEXCONTACT_AVAILABLE_MEMORY_GB set between the two paths' needs: the
dense path raises ContactMemoryError before its allocation (its peak is recorded) while
the factor path solves the same case.
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

A_M = 0.005  # bench/case.py's aimed Hertz contact half-width (m)
# (mesh, build keywords): the earlier zones, then wide zones of half-width 9a (< R = 10a),
# the zone spacing w/n_side giving 2·n_side + 1 pairs and n_c = 4·pairs contact DOFs.
ZONES_2D = [("hertz2d", {"refine": 1, "zone_factor": z}) for z in (1.25, 2.5, 5.0)]
WIDE_SIDES = (100, 250, 500, 1000)
WIDE_SIDES_FULL = WIDE_SIDES + (1500,)
ZONES_3D = [("hertz3d", {"refine": 0, "zone_factor": z, "h_far": 0.02}) for z in (1.0,)]
PATHS = ("dense", "factor", "factor_iteration")
ITERATION_MAX_NC = 4100  # the matrix-free iteration alone: hundreds of solves per increment


def wide_zone(n_side: int) -> tuple:
    """Half-width 9a, n_side segments a side; 10 elements deep at the zone's spacing, then
    graded (meshes/hertz2d.py: fine_depth), so that the mesh grows as n_c, not n_c²."""
    h = 9.0 * A_M / n_side
    return ("hertz2d", {"refine": 0, "zone_factor": 9.0, "h_contact": h, "fine_depth": 10 * h})


def child(spec: dict) -> dict:
    """One (zone, path) run, in this process."""
    import case  # bench/case.py: the Hertz model and the phase's memory high-water mark
    import flexcontact as fc
    m = case.model(spec)
    case.compiled_form(m["a"])
    out = {"spec": spec, "dim": m["dim"], "dofs": m["dofs"]}
    rows = []
    factor = spec["path"] != "dense"
    with case.memory_phase(out):
        t0 = time.perf_counter()
        try:
            problem = fc.ContactProblem(m["a"], None, m["bcs"], m["interface"],
                                        contact_operator="factor" if factor else "dense")
        except fc.ContactMemoryError as e:
            out.update(raised="ContactMemoryError", message=str(e), needed_gb=e.needed_bytes / 1e9,
                       available_gb=e.available_bytes / 1e9, contact_dofs=e.n_contact_dofs,
                       pairs=e.pairs, raised_after_s=time.perf_counter() - t0)
            return out
        out["setup_s"] = time.perf_counter() - t0
        n = spec["increments"]
        for i in range(1, n + 1):
            m["approach"](m["delta_m"] * i / n)
            c = problem.contact
            before = (c.applications, c.block_columns, c.block_products) if factor else (0, 0, 0)
            t0 = time.perf_counter()
            s = problem.step().summary
            after = (c.applications, c.block_columns, c.block_products) if factor else (0, 0, 0)
            rows.append({"increment_s": time.perf_counter() - t0, "iterations": s.iterations,
                         "residual": s.residual, "solver": s.solver,
                         "closed_pairs": s.stick + s.slip, "normal_force": s.normal_force,
                         "backsolves_in_contact_solve": after[0] - before[0],
                         "block_columns": after[1] - before[1],
                         "block_products": after[2] - before[2]})
    out["contact_dofs"] = int(problem.n_contact_dofs)
    out["pairs"] = int(problem.m)
    out["increments"] = rows
    out["increment_s"] = (float(np.median([r["increment_s"] for r in rows[1:] or rows]))
                          if rows else None)
    out["factor_memory_mb"] = problem.flex_info.get("factor_memory_mb")
    if factor:
        out["cached_pairs"] = int(problem.contact.cached_pairs)
    return out


def run_child(spec: dict, timeout_s: float) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(REPO / "dolfinx_ext" / "python")] + [p for p in [env.get("PYTHONPATH")] if p])
    env.update(spec.get("env", {}))
    if spec["path"] == "factor_iteration":
        env["FLEXCONTACT_WORKING_SET_GB"] = "0"
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


def _total_s(r: dict) -> float:
    return r["setup_s"] + sum(x["increment_s"] for x in r["increments"])


def _zone_row(n_c: int, by: dict, dim: int) -> dict:
    """One zone's numbers: the dense path, the factor path, the iteration alone (if run)."""
    from flexcontact.memory import dense_bytes
    d, f = by["dense"], by["factor"]
    row = {"contact_dofs": n_c, "pairs": d["pairs"], "dofs": d["dofs"],
           "dense_peak_mb": d["peak_mb"], "factor_peak_mb": f["peak_mb"],
           "estimate_mb": dense_bytes(n_c, d["pairs"], dim) / 2**20,
           "dense_setup_s": d["setup_s"], "factor_setup_s": f["setup_s"],
           "dense_increment_s": d["increment_s"], "factor_increment_s": f["increment_s"],
           "factor_iterations": [x["iterations"] for x in f["increments"]],
           "factor_block_columns": [x["block_columns"] for x in f["increments"]],
           "factor_cached_pairs": f.get("cached_pairs"),
           "factor_over_dense_increment": f["increment_s"] / d["increment_s"],
           "factor_over_dense_total": _total_s(f) / _total_s(d)}
    it = by.get("factor_iteration")
    if it:
        # Its peak is the factor's alone (O(n_c) beyond it): the base of the dense extra.
        row["base_peak_mb"] = it["peak_mb"]
        row["dense_extra_mb"] = d["peak_mb"] - it["peak_mb"]
        row["factor_extra_mb"] = f["peak_mb"] - it["peak_mb"]
        if it["increments"]:
            row.update(iteration_increment_s=it["increment_s"],
                       iteration_iterations=[x["iterations"] for x in it["increments"]],
                       iteration_setup_s=it["setup_s"])
    return row


def analyse(runs: list[dict], dim: int, mem_total_b: float) -> dict:
    """The dense path's extra memory as c·n_c², where its peak passes the machine, the
    estimate's calibration, the memory crossover and the speed ratios per zone."""
    by_zone = {}  # (n_c, DOFs): two meshes may have the same n_c
    for r in runs:
        if "error" not in r and "raised" not in r and r["dim"] == dim and not r["spec"].get("env"):
            by_zone.setdefault((r["contact_dofs"], r["dofs"]), {})[r["spec"]["path"]] = r
    rows = [_zone_row(key[0], by, dim) for key, by in sorted(by_zone.items())
            if {"dense", "factor"} <= set(by)]
    out = {"dim": dim, "zones": rows}
    big = [r for r in rows if r.get("dense_extra_mb", 0) > 0]
    if big:
        x = np.array([r["contact_dofs"] ** 2 for r in big], float)
        y = np.array([r["dense_extra_mb"] * 2**20 for r in big], float)
        c = float(x @ y / (x @ x))  # least squares through the origin
        out["dense_extra_bytes_per_nc2"] = c
        # The largest zone's base (the factor) plus c·n_c²: where the dense peak passes.
        base = big[-1]["base_peak_mb"] * 2**20
        out["nc_where_dense_passes_machine"] = float(np.sqrt(max(mem_total_b - base, 0) / c))
        out["estimate_over_measured"] = [r["estimate_mb"] / r["dense_extra_mb"] for r in big]
    below = [r["contact_dofs"] for r in rows if r["factor_peak_mb"] < 0.95 * r["dense_peak_mb"]]
    out["factor_peak_below_dense_from_nc"] = min(below) if below else None
    faster = [r["contact_dofs"] for r in rows if r["factor_over_dense_total"] < 1.0]
    out["factor_faster_in_total_from_nc"] = min(faster) if faster else None
    return out


def _specs(args) -> list[dict]:
    """The (zone, path) runs, in order; the iteration alone on large zones: set-up only."""
    zones = (ZONES_2D[:2] if args.quick else
             ZONES_2D + [wide_zone(n) for n in (WIDE_SIDES_FULL if args.full else WIDE_SIDES)]
             + ZONES_3D)
    specs = []
    for mesh, build in zones:
        pairs_estimate = 2 * round(build["zone_factor"] * A_M / build["h_contact"]) + 1 \
            if "h_contact" in build else 0
        for path in PATHS:
            name = f"{mesh}_{build['zone_factor']}_{build.get('h_contact', 'r')}_{path}"
            inc = args.increments
            if path == "factor_iteration" and 4 * pairs_estimate > ITERATION_MAX_NC:
                inc = 0
            specs.append({"name": name, "mesh": mesh, "build": build, "path": path,
                          "increments": inc, "mu": 0.3})
    return specs


def _low_memory_specs(args, largest: dict, runs: list[dict]) -> list[dict]:
    """The largest 2D zone again with the memory available set between the two paths'
    needs: the dense path must refuse before allocating, the factor path solve."""
    from flexcontact.memory import dense_bytes
    done = [r for r in runs if r["spec"]["build"] == largest["build"] and "error" not in r]
    dense = [r for r in done if r["spec"]["path"] == "dense"]
    factor = [r for r in done if r["spec"]["path"] == "factor"]
    if not dense or not factor:
        return []
    need = dense_bytes(dense[0]["contact_dofs"], dense[0]["pairs"], 2)
    avail_gb = max(0.5 * need / 1e9, 1.5 * factor[0]["peak_mb"] * 2**20 / 1e9)
    if avail_gb * 1e9 >= need:
        return []
    env = {"FLEXCONTACT_AVAILABLE_MEMORY_GB": f"{avail_gb:.3f}"}
    return [dict(largest, path=p, name=largest["name"].rsplit("_", 1)[0] + f"_{p}_low_memory",
                 env=env, increments=args.increments) for p in ("dense", "factor")]


def _line(r: dict) -> str:
    if "error" in r:
        return r["error"]
    if "raised" in r:
        return f"raised {r['raised']} after {r['raised_after_s']:.2f} s, peak {r['peak_mb']:.0f} MB"
    its = [x["iterations"] for x in r["increments"]]
    inc = f"increment {r['increment_s']:.3f} s, iterations {its}, " if r["increments"] else ""
    return (f"n_c {r['contact_dofs']} dofs {r['dofs']} setup {r['setup_s']:.2f} s {inc}"
            f"peak {r['peak_mb']:.0f} MB")


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true", help="two small 2D zones only")
    ap.add_argument("--full", action="store_true", help="adds the n_c = 12,004 zone")
    ap.add_argument("--increments", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=1800.0, help="per run (s)")
    ap.add_argument("--out", default=str(HERE / "large_contact.json"))
    ap.add_argument("--analyse", action="store_true",
                    help="recompute the analysis of the runs already in --out")
    args = ap.parse_args()
    if args.analyse:
        result = json.loads(Path(args.out).read_text())
        for d, dim in (("2d", 2), ("3d", 3)):
            result[d] = analyse(result["runs"], dim, result["mem_total_bytes"])
        Path(args.out).write_text(json.dumps(result, indent=1))
        return
    if args.child:
        print("RESULT " + json.dumps(child(json.loads(args.child))), flush=True)
        return
    import machine
    load_start = os.getloadavg()
    specs = _specs(args)
    runs = []
    for spec in specs:
        r = run_child(spec, args.timeout)
        r["load_average"] = os.getloadavg()
        runs.append(r)
        print(spec["name"], _line(r), flush=True)
    largest = [s for s in specs if s["mesh"] == "hertz2d" and s["path"] == "dense"][-1]
    for spec in _low_memory_specs(args, largest, runs):
        r = run_child(spec, args.timeout)
        r["load_average"] = os.getloadavg()
        runs.append(r)
        print(spec["name"], _line(r), flush=True)
    mem_total = float(Path("/proc/meminfo").read_text().split()[1]) * 1024
    result = {"machine": machine.machine(), "mem_total_bytes": mem_total,
              "load_average_start": load_start, "load_average_end": os.getloadavg(),
              "runs": runs, "2d": analyse(runs, 2, mem_total), "3d": analyse(runs, 3, mem_total)}
    Path(args.out).write_text(json.dumps(result, indent=1))
    for d in ("2d", "3d"):
        a = result[d]
        print(d, {k: v for k, v in a.items() if k != "zones"})


if __name__ == "__main__":
    main()
