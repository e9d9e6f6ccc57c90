"""Local 3D frictional contact solvers: ours (active_set, projection, newton_ac, dispatcher)
against Siconos (NSGS, NSN_AC) on local problems from this project's meshes.

Each problem is one increment's ``problem.local_problem`` of a ContactProblem (see
tests/crosscheck_problems.py): cases of the Siconos cross-check set plus one refined
block-on-base problem with several hundred pairs. Every answer is judged by both residuals,
since the two codes' tolerances mean different things: our natural-map residual (relative,
ρ = 1/W_nn per pair) and Siconos' fc3d_compute_error on the dimensionless problem handed to
it. Times are wall clock, median of 3 (one run when a solver fails or takes over
``--slow`` seconds), and include each library's own copy of W.

Run: `/usr/bin/python3 bench/solvers_vs_siconos.py [--h-large 0.004] [--tolerance 1e-10]`;
writes bench/solvers_vs_siconos.json.
"""
import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "dolfinx_ext" / "python"))
sys.path.insert(0, str(ROOT / "tests"))
import crosscheck_problems as cp  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("--tolerance", type=float, default=1e-10)
parser.add_argument("--h-large", type=float, default=0.004,
                    help="interface element size of the large block problem (m)")
parser.add_argument("--repeats", type=int, default=3)
parser.add_argument("--slow", type=float, default=30.0,
                    help="a run longer than this (s) is not repeated")
parser.add_argument("--max-iterations", type=int, default=100,
                    help="iteration cap of our solvers (the dispatcher's default)")
args = parser.parse_args()
comm = MPI.COMM_WORLD

OURS = [("dispatcher", None), ("active_set", ["active_set"]), ("projection", ["projection"]),
        ("newton_ac", ["newton_ac"])]
SICONOS = ["NSGS", "NSN_AC"]


def blas_in_use():
    """Shared BLAS/LAPACK libraries mapped into this process (which one MUMPS, Eigen's
    callers and Siconos really ran on)."""
    libs = set()
    with open("/proc/self/maps") as f:
        for line in f:
            path = line.split()[-1] if len(line.split()) >= 6 else ""
            name = Path(path).name
            if any(k in name for k in ("blas", "lapack")):
                libs.add(str(Path(path).resolve()))
    return sorted(libs)


def timed(run):
    """(last result, median time, runs, lu_failures) of up to args.repeats runs."""
    times, res, lu = [], None, 0
    for _ in range(args.repeats):
        with cp.CapturedOutput() as out:
            res, t = run()
        lu = out.text.count("DGETRF failed")
        times.append(t)
        if not res["converged"] or t > args.slow:
            break
    return res, statistics.median(times), len(times), lu


def bench_case(case):
    rows = []
    for label, chain in OURS:
        def run():
            rep, t = cp.ours(case, chain=chain, tolerance=args.tolerance,
                             max_iterations=args.max_iterations)
            return dict(lam=np.asarray(rep.lambda_), converged=bool(rep.converged),
                        iterations=int(rep.iterations), solver=str(rep.solver)), t
        res, t, n, lu = timed(run)
        rows.append(dict(code="flexcontact", solver=label, answered_by=res["solver"], time_s=t,
                         runs=n, iterations=res["iterations"], converged=res["converged"],
                         lam=res["lam"]))
    for name in SICONOS:
        def run():
            r = cp.siconos_solve(case, name, args.tolerance)
            return dict(lam=r.lam, converged=r.converged, iterations=r.iterations,
                        solver=name), r.time_s
        res, t, n, lu = timed(run)
        rows.append(dict(code="siconos", solver=name, answered_by=name, time_s=t, runs=n,
                         iterations=res["iterations"], converged=res["converged"],
                         lam=res["lam"], lu_failures=lu))
    ref = next(r["lam"] for r in rows if r["code"] == "siconos" and r["solver"] == "NSN_AC")
    lam_scale = cp.scales(case)[0]
    for r in rows:
        lam = r.pop("lam")
        r["natural_map_residual"] = cp.natural_residual(case, lam)
        r["fc3d_error"] = cp.siconos_error(case, lam)
        r["lambda_diff_to_nsn_ac"] = float(np.linalg.norm(lam - ref)
                                           / max(np.linalg.norm(ref), lam_scale))
        st = cp.state_counts(cp.states_of(case, lam))
        r["states"] = dict(zip(cp.STATE_NAMES, st.tolist()))
    return rows


def print_table(name, m, rows):
    print(f"\n{name}  ({m} pairs, {3 * m} unknowns)")
    print(f"  {'code':11s} {'solver':11s} {'time [s]':>10s} {'runs':>4s} {'iter':>5s} "
          f"{'conv':>5s} {'nat.res':>9s} {'fc3d err':>9s} {'|dλ|/|λ|':>9s}  open/stick/slip")
    for r in rows:
        s = r["states"]
        by = "" if r["answered_by"] == r["solver"] else f" ({r['answered_by']})"
        print(f"  {r['code']:11s} {r['solver']:11s} {r['time_s']:10.4f} {r['runs']:4d} "
              f"{r['iterations']:5d} {str(r['converged']):>5s} {r['natural_map_residual']:9.1e} "
              f"{r['fc3d_error']:9.1e} {r['lambda_diff_to_nsn_ac']:9.1e}  "
              f"{s['open']}/{s['stick']}/{s['slip']}{by}", flush=True)


t_start = time.perf_counter()
plan, builders = cp.cross_check_set(comm)
# A few increments of the cross-check set: each μ's hardest step (push, tip, growth).
picks = {("block", 0.1): 2, ("block", 0.6): 3, ("block", 1.0): 4,
         ("hertz", 0.1): 1, ("hertz", 0.5): 2, ("hertz", 1.0): 3}
models, cases = {}, []
for name, mu, path in plan:
    if (name, mu) not in picks:
        continue
    if name not in models:
        models[name] = builders[name]()
    cases.append(cp.run_path(models[name], mu, path)[picks[(name, mu)]])

t0 = time.perf_counter()
large_model = cp.block_model(comm, gap=cp.BLOCK_GAP_M, h=args.h_large, h_far=0.03)
large = cp.run_path(large_model, 0.3, [(0.0, 0.0, -1.5e-5), (4e-6, 2e-6, -1.5e-5)])[-1]
large.name = f"LARGE block h={args.h_large:g} mu=0.3 push (4e-6,2e-6,-1.5e-5)"
large_setup_s = time.perf_counter() - t0
cases.append(large)

results = []
for case in cases:
    rows = bench_case(case)
    print_table(case.name, case.m, rows)
    results.append(dict(case=case.name, pairs=case.m, mu=case.mu, load_m=list(case.load),
                        rows=rows))

big = results[-1]["rows"]


def time_of(code, solver):
    return next(r["time_s"] for r in big if r["code"] == code and r["solver"] == solver)


ratios = {f"{o}/{s}": time_of("flexcontact", o) / time_of("siconos", s)
          for o, _ in OURS for s in SICONOS}
print(f"\nlargest problem ({large.m} pairs): time ratio ours/Siconos")
for k, v in ratios.items():
    print(f"  {k:24s} {v:8.2f}")

out = dict(tolerance=args.tolerance, max_iterations_ours=args.max_iterations,
           repeats=args.repeats, blas=blas_in_use(), python=platform.python_version(),
           large_problem=dict(pairs=large.m, h=args.h_large, setup_s=large_setup_s,
                              dofs=int(large_model.V.dofmap.index_map.size_global * 3),
                              time_ratio_ours_over_siconos=ratios),
           cases=results, total_s=time.perf_counter() - t_start)
path = Path(__file__).with_suffix(".json")
path.write_text(json.dumps(out, indent=1))
print(f"\nBLAS/LAPACK: {', '.join(out['blas'])}\nwritten {path} in {out['total_s']:.0f} s")
