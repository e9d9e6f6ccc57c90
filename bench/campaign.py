"""Robustness campaign of the local contact solvers on random problems with known solutions.

Problems come from tests/random_problems.py (classes spd, zero_rows, rank_deficient,
ill_conditioned; 2D and 3D; μ 0–2; most with up to 60 pairs, ``--large`` ones with 300–1000
pairs, up to 3,000 unknowns). Each is solved by the default chain and by each of its solvers
alone, and, in 3D where Siconos is installed, by Siconos NSN_AC; every answer is judged by
the natural-map residual computed here, not by what the solver says. Writes
bench/campaign.json: per class, how many each solved, wrong answers claimed (must be 0),
problems the chain lost that another solver solved (must be 0), the worst residual of a
claimed answer, and median times.

    /usr/bin/python3 bench/campaign.py [--count 10000] [--large 8] [--seed 1]   # 25 min on a quiet machine
    /usr/bin/python3 bench/campaign.py --count 2000 --large 0 --also "$(python3 -c \
        'import json; print(",".join(x["problem"] for x in json.load(open("bench/campaign.json"))["lost_by_the_chain"]))')"
"""
import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from crosscheck_problems import CapturedOutput  # noqa: E402
from random_problems import SOLVERS, run_flexcontact, run_siconos, sample  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--count", type=int, default=10000, help="problems with up to 60 pairs")
ap.add_argument("--large", type=int, default=8, help="problems with 300-1000 pairs (minutes each)")
ap.add_argument("--seed", type=int, default=1)
ap.add_argument("--tolerance", type=float, default=1e-10)
ap.add_argument("--no-siconos", action="store_true")
ap.add_argument("--also", default="", help="comma-separated problem names of a larger sample "
                "of the same seed (e.g. those an earlier run lost) to run as well")
ap.add_argument("--out", default=str(HERE / "campaign.json"))
args = ap.parse_args()

try:
    import siconos.numerics  # noqa: F401
    siconos = not args.no_siconos
except ImportError:
    siconos = False


def progress(i, n, t0):
    if i % 250 == 0 or i == n:
        print(f"  {i}/{n} problems, {time.perf_counter() - t0:.0f} s", flush=True)


def summary(outcomes):
    claimed = [o.residual for o in outcomes if o.claimed]
    return {"problems": len(outcomes), "solved": sum(o.solved for o in outcomes),
            "claimed": len(claimed), "wrong": sum(o.wrong for o in outcomes),
            "worst_claimed_residual": max(claimed) if claimed else None,
            "median_time_s": float(np.median([o.time_s for o in outcomes])),
            "max_time_s": max(o.time_s for o in outcomes)}


def report(done, final):
    """Write campaign.json (also on the way, so that a long run leaves results)."""
    classes = {k: {s: summary(v) for s, v in rows.items()} for k, rows in sorted(by_class.items())}
    for rows in classes.values():
        if "siconos_NSN_AC" in rows:
            rows["chain_median_over_siconos"] = (rows["chain"]["median_time_s"]
                                                 / rows["siconos_NSN_AC"]["median_time_s"])
    result = {"tolerance": args.tolerance, "seed": args.seed, "count": args.count,
              "large": args.large, "also": sorted(set(args.also.split(",")) - {""}),
              "problems": len(problems),
              "done": done, "siconos": siconos, "wrong_answers": wrong,
              "lost_by_the_chain": lost, "classes": classes,
              "time_s": time.perf_counter() - t0}
    Path(args.out).write_text(json.dumps(result, indent=1))
    if not final:
        return
    for k, rows in classes.items():
        chain = rows["chain"]
        line = (f"{k:28s} chain {chain['solved']}/{chain['problems']} "
                f"median {1e3 * chain['median_time_s']:.2f} ms")
        for s in ("active_set", "projection", "newton_ac", "siconos_NSN_AC"):
            if s in rows:
                line += f" | {s} {rows[s]['solved']} ({1e3 * rows[s]['median_time_s']:.2f} ms)"
        print(line)
    print(f"{done} problems in {result['time_s']:.0f} s: {len(wrong)} wrong answers "
          f"claimed, {len(lost)} lost by the chain; wrote {args.out}")


t0 = time.perf_counter()
problems = sample(args.seed, args.count, sizes=(1, 60), large=args.large)
n_sample = len(problems)
if args.also:
    # Problem i of a seed is the same whatever the count, as long as i < count (large ones
    # come after): draw up to the last one asked for and keep those named.
    names = set(args.also.split(",")) - {p.name for p in problems}
    last = max(int(n.rsplit("-", 1)[1]) for n in names) if names else -1
    problems += [p for p in sample(args.seed, last + 1, sizes=(1, 60)) if p.name in names]
by_class = defaultdict(lambda: defaultdict(list))
lost, wrong = [], []
for i, p in enumerate(problems, 1):
    row = {s: run_flexcontact(p, s, args.tolerance) for s in SOLVERS}
    if siconos and p.dim == 3:
        # Siconos prints its LU failures (zero rows of W) on stdout: keep them off the table.
        with CapturedOutput():
            row["siconos_NSN_AC"] = run_siconos(p, args.tolerance)
    key = (f"{p.kind}/{p.dim}d" + ("/large" if p.m >= 300 else "")
           + ("/also" if i > n_sample else ""))
    for s, o in row.items():
        by_class[key][s].append(o)
        if o.wrong or (o.claimed and not o.finite):
            wrong.append({"problem": p.name, "solver": s, "residual": o.residual})
    if not row["chain"].solved and any(o.solved for o in row.values()):
        lost.append({"problem": p.name, **{s: o.residual for s, o in row.items()}})
    progress(i, len(problems), t0)
    if i % 1000 == 0:
        report(i, final=False)
report(len(problems), final=True)


