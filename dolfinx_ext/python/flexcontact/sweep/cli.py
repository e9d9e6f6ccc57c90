"""The ``sweep`` sub-command of ``python3 -m flexcontact``."""
from __future__ import annotations

import sys

from .config import ENGINES


def add_parser(sub) -> None:
    p = sub.add_parser("sweep", help="run (or resume) a sweep of dam-impact scenarios",
                       description="Run or resume the sweep of a TOML config (docs/dam.md, "
                                   "'Sweeps'); the table is results.jsonl in the output "
                                   "folder, resumed if it is there.")
    p.add_argument("config", help="the sweep's TOML file")
    p.add_argument("--out", help="output folder (default: output.dir, else "
                                 "results/sweep/<config stem>)")
    p.add_argument("--engine", choices=ENGINES, help="overrides engine.kind")
    p.add_argument("--workers", type=int, help="overrides engine.workers")
    p.add_argument("--scheduler", help="Dask scheduler address (engine dask)")
    p.add_argument("--batch", type=int, help="overrides engine.batch: scenarios stepped side "
                                             "by side in a worker, sharing the dam's solves")
    m = p.add_mutually_exclusive_group()
    m.add_argument("--model", help="a dam model directory (flexcontact dam prepare) every "
                                   "worker loads instead of factoring the dam; prepared "
                                   "there once if absent (engine.model; default: "
                                   "dam_model/ in the output folder)")
    m.add_argument("--no-model", action="store_true",
                   help="every worker factors the dam itself (engine.model = false)")
    p.add_argument("--check-convergence", action="store_true",
                   help="rerun each output's most unfavourable scenario at refine + 1")


def main(args) -> int:
    from mpi4py import MPI

    from . import driver
    from .config import load
    from .errors import ConfigError, TableError
    if MPI.COMM_WORLD.size > 1 and "mpi4py.futures" not in sys.modules:
        # Every rank would run the whole sweep and write the same table.
        if MPI.COMM_WORLD.rank == 0:
            print(f"flexcontact sweep: {MPI.COMM_WORLD.size} MPI ranks run this command; "
                  f"under mpirun use 'mpirun -n K python3 -m mpi4py.futures -m flexcontact "
                  f"sweep ... --engine mpi' (rank 0 drives, the others compute)",
                  file=sys.stderr)
        return 2
    try:
        cfg = load(args.config)
        for key in ("workers", "scheduler", "batch"):
            if getattr(args, key) is not None:
                cfg.engine[key] = getattr(args, key)
        if getattr(args, "model", None):
            cfg.engine["model"] = args.model
        elif getattr(args, "no_model", False):
            cfg.engine["model"] = False
        if args.engine:
            cfg.engine["kind"] = args.engine
        elif args.scheduler:
            cfg.engine["kind"] = "dask"
        summary = driver.run(cfg, out=args.out, check_convergence=args.check_convergence)
    except (ConfigError, TableError) as e:
        print(f"flexcontact sweep: {e}", file=sys.stderr)
        return 2
    folder = args.out or cfg.output["dir"]
    print(f"{summary['scenarios']} scenarios, {summary['computed_this_run']} computed in "
          f"{summary['wall_s']:.1f} s; results in {folder}/ (results.csv, summary.json, "
          f"report.md)")
    from .quantities import quantity
    dim = summary.get("dim", 2)
    for o, w in summary["worst"].items():
        if w is not None:
            q = quantity(o, dim)
            name = q.words[:1].lower() + q.words[1:]   # keeps a proper name's capital
            print(f"  worst {name}: {q.show(w['value'])} {q.unit} (scenario "
                  f"{w['id']}: " + ", ".join(f"{k}={quantity(k, dim).show(v)}"
                                            for k, v in w["inputs"].items()) + ")")
    return 0
