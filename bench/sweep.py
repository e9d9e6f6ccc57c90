"""Wall time of a sweep of many dam-impact scenarios, and where it goes.

Runs (or resumes) the sweep of ``--config`` (default bench/sweep_1000.toml: 1,000 LHS 2D
scenarios at the default mesh, 2 worker processes, the factorization-reusing evaluator)
into a fresh folder and reports, from the same run: the wall time and its phases (checking
the config and building every scenario; computing; the table, statistics, figures and
report), the evaluator's own split summed over workers (set-up and factorizations, time
steps, outputs: process seconds, so with 2 workers about twice the compute wall time), the
factorization and back-substitution counts, and the seconds per scenario. Writes
bench/sweep.json (with the machine's description); ``--config bench/sweep_1000_3d.toml
--json bench/sweep_3d.json --aim-s 1800`` the 3D sweep on the dam block.

    /usr/bin/python3 bench/sweep.py [--config bench/sweep_1000.toml] [--workers 2]
        [--evaluator reuse|monolithic] [--n N]     # --n: a smaller trial of the same sweep
        [--model DIR | --own-factors]

The folder is cleared first (unless --keep), so by default the dam model is prepared in the
run, as a first sweep prepares it; --model DIR with a model there measures a sweep that
reuses one, --own-factors one whose workers each factor the dam.
"""
import argparse
import json
import shutil
import time
import tomllib
from pathlib import Path

from flexcontact import sweep
from flexcontact.info import describe

here = Path(__file__).resolve().parent


def main():
    """Run the sweep and write the timings (the spawned workers import this file: guarded)."""
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--config", default=str(here / "sweep_1000.toml"))
    ap.add_argument("--workers", type=int, default=None, help="overrides engine.workers")
    ap.add_argument("--engine", choices=("serial", "processes", "mpi", "dask"), default=None)
    ap.add_argument("--evaluator", default=None, help="overrides engine.evaluator")
    ap.add_argument("--batch", type=int, default=None, help="overrides engine.batch")
    ap.add_argument("--n", type=int, default=None, help="overrides sample.n (a trial run)")
    ap.add_argument("--model", default=None,
                    help="engine.model: a dam model directory the workers load (prepared "
                         "there first if absent; default: dam_model/ in --out, prepared "
                         "in the run)")
    ap.add_argument("--own-factors", action="store_true",
                    help="engine.model = false: every worker factors the dam itself")
    ap.add_argument("--out", default="results/bench_sweep")
    ap.add_argument("--keep", action="store_true", help="resume the folder instead of clearing it")
    ap.add_argument("--json", default=str(here / "sweep.json"), help="where the timings go")
    ap.add_argument("--aim-s", type=float, default=600.0,
                    help="the wall-time aim recorded beside the result (s)")
    args = ap.parse_args()

    raw = tomllib.loads(Path(args.config).read_text())
    if args.n is not None:
        raw["sample"]["n"] = args.n
    for key, value in (("workers", args.workers), ("kind", args.engine),
                       ("evaluator", args.evaluator), ("model", args.model),
                       ("batch", args.batch)):
        if value is not None:
            raw.setdefault("engine", {})[key] = value
    if args.own_factors:
        raw.setdefault("engine", {})["model"] = False
    cfg = sweep.from_dict(raw, source=args.config)
    out = Path(args.out)
    if out.exists() and not args.keep:
        shutil.rmtree(out)
    t0 = time.perf_counter()
    s = sweep.run(cfg, out=out)
    wall = time.perf_counter() - t0

    ev = s["evaluator_timings_s"]
    # An evaluator's timings(): every phase but the steps and the outputs is set-up
    # (meshing, assembly, factorizations); evaluate_s alone (no timings()) gives no split.
    phases = {k: v for k, v in ev.items() if k != "evaluate_s"}
    # The parts of the steps (coupled steps, log-only steps, convolution) are inside steps_s.
    # So are those of the scenarios stepped side by side (shared_*_s: their shared calls and
    # their own code).
    inside = ("steps_s", "outputs_s", "coupled_steps_s", "log_only_steps_s", "convolution_s")
    setup = (sum(v for k, v in phases.items()
                 if k not in inside and not k.startswith("shared_")) if phases else None)
    result = {
        "config": args.config, "scenarios": s["scenarios"], "computed": s["computed_this_run"],
        "evaluator": s["evaluator"], "engine": s["engine"], "workers": s["workers"],
        "batch": cfg.engine.get("batch", 1),
        "dt_s": s["dt_s"], "wall_s": wall, "phases_wall_s": s["timings_s"],
        "evaluator_split_process_s": {"setup_and_factorizations": setup,
                                      "steps": ev.get("steps_s"), "outputs": ev.get("outputs_s"),
                                      **{f"detail_{k}": v for k, v in ev.items()}},
        "seconds_per_scenario_process_mean": s["seconds_per_scenario_mean"],
        "counts": s["counts"], "aim_s": args.aim_s, "machine": describe(),
    }
    Path(args.json).write_text(json.dumps(result, indent=2, default=str))
    print(f"{s['scenarios']} scenarios ({s['computed_this_run']} computed) in {wall:.1f} s wall "
          f"on {s['workers']} workers; phases {s['timings_s']}")
    if setup is None:
        print(f"the evaluator reports no timings(): evaluate() took {ev.get('evaluate_s', 0):.1f} "
              f"process s in all; no split")
    else:
        outputs = (f"outputs {ev['outputs_s']:.1f}" if "outputs_s" in ev
                   else "outputs: read inside the steps")
        print(f"evaluator split (process s): set-up/factorizations {setup:.1f}, steps "
              f"{ev.get('steps_s', float('nan')):.1f}, {outputs}; table and report "
              f"{s['timings_s'].get('report', float('nan')):.1f} s wall")
    print(f"factorizations {s['counts']['factorizations']}, back-substitutions "
          f"{s['counts']['back_substitutions']['total']}; wrote {args.json}")


if __name__ == "__main__":
    main()
