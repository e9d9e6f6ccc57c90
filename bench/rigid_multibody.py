"""The default chain against Siconos on rigid-multibody problems: walls of rigid bricks
(tests/rigid_multibody.py), a few hundred contacts each, W rank-deficient.

Each wall's local problem is solved by the chain (default options) and by Siconos' NSN_AC and
NSGS (tolerance 1e-12, 1,000 and 100,000 iterations), and every answer is judged by Siconos'
own error measure (fc3d_compute_error on the dimensionless problem; solved: ≤ 1e-8) and by
the natural-map residual. Writes bench/rigid_multibody.json.

    /usr/bin/python3 bench/rigid_multibody.py [--count 20] [--seed 1]   # a few minutes
"""
import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE.parent / "dolfinx_ext" / "python"))
import crosscheck_problems as cp  # noqa: E402
import rigid_multibody as rm  # noqa: E402
from random_problems import _AsCase  # noqa: E402

from flexcontact import _cpp  # noqa: E402

SOLVED = 1e-8

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--count", type=int, default=20)
ap.add_argument("--seed", type=int, default=1)
ap.add_argument("--out", default=str(HERE / "rigid_multibody.json"))
args = ap.parse_args()


def judged(p, lam, t):
    lam = np.asarray(lam, float)
    finite = bool(np.all(np.isfinite(lam)))
    err = cp.siconos_error(_AsCase(p), lam) if finite else float("inf")
    res = float(_cpp.natural_map_residual(3, p.W, p.q, p.mu, lam)) if finite else float("inf")
    return {"siconos_error": err, "natural_residual": res, "solved": bool(err <= SOLVED),
            "time_s": t}


rows = []
for p in rm.sample(args.seed, args.count):
    row = {"problem": p.name, "contacts": p.m, "unknowns": p.unknowns,
           "rank_W": int(np.linalg.matrix_rank(p.W)), "mu": float(p.mu[0])}
    t0 = time.perf_counter()
    r = _cpp.solve(3, p.W, p.q, p.mu)
    row["chain"] = judged(p, r.lambda_, time.perf_counter() - t0)
    row["chain"].update(work_gflop=r.work_gflop, attempts=len(r.attempts),
                        answered_by=r.solver)
    for solver in ("NSN_AC", "NSGS"):
        with cp.CapturedOutput():
            s = cp.siconos_solve(_AsCase(p), solver, tolerance=1e-12)
        row[solver] = judged(p, s.lam, s.time_s)
        row[solver].update(info=s.info, iterations=s.iterations)
    rows.append(row)
    print(f"{p.name:32s} n={p.unknowns:4d} rank {row['rank_W']:4d}  chain "
          f"{row['chain']['siconos_error']:.1e} {row['chain']['time_s']:6.2f} s  NSN_AC "
          f"{row['NSN_AC']['siconos_error']:.1e} {row['NSN_AC']['time_s']:6.2f} s  NSGS "
          f"{row['NSGS']['siconos_error']:.1e} {row['NSGS']['time_s']:6.2f} s", flush=True)


def summary(key):
    solved = [r[key] for r in rows if r[key]["solved"]]
    return {"solved": len(solved), "of": len(rows),
            "median_time_s": float(np.median([r[key]["time_s"] for r in rows])),
            "worst_error_solved": max((s["siconos_error"] for s in solved), default=None)}


out = {"seed": args.seed, "count": args.count, "solved_at": SOLVED,
       "load_average": os.getloadavg()[0],
       "summary": {k: summary(k) for k in ("chain", "NSN_AC", "NSGS")}, "problems": rows}
Path(args.out).write_text(json.dumps(out, indent=1))
print(json.dumps(out["summary"], indent=1))
