"""One load increment on one process and on two (`mpirun -n 2`), phase by phase.

On the bench's Hertz cases (bench/run.py's CASES; bench/case.py builds them) this runs
ContactProblem's increments with a timer around each phase of ``ContactProblem.step``:

* ``assemble_s``: the load vector p;
* ``condense_s``: the factor's condensation of p (forward elimination; on two ranks
  split by DistributedSchur into ``gather_s``, b handed to MUMPS, and ``mumps_condense_s``);
* ``kernel_s``: the kernel's contact step on rank 0 (``last_contact_step_s``);
* ``expand_s``: the expansion from the contact values (backward substitution; on two ranks
  ``mumps_expand_s`` and ``scatter_s``, the solution into u);
* ``record_s``, ``write_back_s``: the increment's summary and the contact fields;
* ``other_s``: the rest of the increment's wall time (on rank 1 mostly the wait for rank
  0's kernel step; Python).

On two ranks the increments cycle through three variants on the same factor (so the
machine's load drifts alike for all):

* ``before``: DistributedSchur's right-hand side and solution centralised (b gathered on
  rank 0, the solution scattered from it: ICNTL(20) = ICNTL(21) = 0) and rank 1 waiting for
  rank 0's kernel step in a blocking MPI call (spinning on a core), as before;
* ``distributed_io``: each rank's own rows to and from MUMPS (ICNTL(20) = 10,
  ICNTL(21) = 1), rank 1 still spinning;
* ``distributed_io_idle_wait``: the same, rank 1 asleep meanwhile (mpi.wait_for_root): the
  default now.

Also one back-substitution (d, ``factor.solve``) after each increment. Medians over the
increments after the first (which closes the contact). Writes bench/mpi_increment.json.

    /usr/bin/python3 bench/mpi_increment.py                        # the default cases
    /usr/bin/python3 bench/mpi_increment.py --cases 2d_200k_c1600 --repeat 4
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

DEFAULT_CASES = ["2d_200k_c1600", "2d_1m_c4100", "3d_120k_c4000"]
PHASES = ("assemble_s", "condense_s", "kernel_s", "expand_s", "record_s", "write_back_s",
          "other_s", "total_s")
SUB_PHASES = {"gather_s": "gather_s", "condense_s": "mumps_condense_s",
              "expand_s": "mumps_expand_s", "scatter_s": "scatter_s"}


# ---- the child: one case on 1 or 2 ranks -------------------------------------------------
class PhaseClock:
    """Wall time of the phases of the increment being run (this rank)."""

    def __init__(self):
        self.t = {}

    def add(self, key: str, seconds: float) -> None:
        self.t[key] = self.t.get(key, 0.0) + seconds

    def wrap(self, key: str, fn):
        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                self.add(key, time.perf_counter() - t0)
        return timed


class TimedFactor:
    """The factor seen by ContactProblem.step, with its condense/expand timed."""

    def __init__(self, factor, clock: PhaseClock):
        self._f, self._clock = factor, clock
        self.has_condense = getattr(factor, "has_condense", False)

    def _split(self, which: tuple) -> None:
        times = getattr(self._f, "last_times", None)  # DistributedSchur only
        if times is not None:
            for k in which:
                self._clock.add(SUB_PHASES[k], times[k])

    def condense(self, p):
        out = self._clock.wrap("condense_s", self._f.condense)(p)
        self._split(("gather_s", "condense_s"))
        return out

    def expand(self, u_c, x):
        self._clock.wrap("expand_s", self._f.expand)(u_c, x)
        self._split(("expand_s", "scatter_s"))

    def __getattr__(self, name):
        return getattr(self._f, name)


def instrument(problem, clock: PhaseClock) -> None:
    """Timers around the phases of problem.step (module functions it calls by name)."""
    import flexcontact.problem as fp
    fp.assemble_load = clock.wrap("assemble_s", fp.assemble_load)
    fp.record_increment = clock.wrap("record_s", fp.record_increment)
    problem.outputs.write_back = clock.wrap("write_back_s", problem.outputs.write_back)
    problem.factor = TimedFactor(problem.factor, clock)


def one_increment(problem, clock: PhaseClock) -> dict:
    clock.t = {}
    problem.timings["last_contact_step_s"] = 0.0
    t0 = time.perf_counter()
    problem.step()
    t = dict(clock.t)
    t["total_s"] = time.perf_counter() - t0
    t["kernel_s"] = problem.timings.get("last_contact_step_s", 0.0) if problem.comm.rank == 0 \
        else 0.0
    known = sum(t.get(k, 0.0) for k in PHASES if k not in ("other_s", "total_s"))
    t["other_s"] = t["total_s"] - known
    return t


VARIANTS = {"before": {"distributed_io": False, "idle_wait": False},
            "distributed_io": {"distributed_io": True, "idle_wait": False},
            "distributed_io_idle_wait": {"distributed_io": True, "idle_wait": True}}


def set_variant(problem, name: str) -> None:
    """DistributedSchur's right-hand side and solution, and how the ranks wait for rank 0."""
    import flexcontact.mpi
    import flexcontact.problem as fp
    v = VARIANTS[name]
    problem.factor._f.distributed_io = v["distributed_io"]
    fp.wait_for_root = flexcontact.mpi.wait_for_root if v["idle_wait"] else (lambda comm: None)


def child(spec: dict) -> None:
    import numpy as np
    from mpi4py import MPI

    import case
    import flexcontact as fc
    from timing import median_time

    comm = MPI.COMM_WORLD
    m = case.model(spec, comm)
    case.compiled_form(m["a"])
    t0 = time.perf_counter()
    problem = fc.ContactProblem(m["a"], None, m["bcs"], m["interface"])
    setup_s = time.perf_counter() - t0
    clock = PhaseClock()
    instrument(problem, clock)
    variants = list(VARIANTS) if comm.size > 1 else ["serial"]
    repeat = spec["repeat"]
    n = 1 + repeat * len(variants)  # the first increment closes the contact: not counted
    rows = {v: [] for v in variants}
    b = problem.K.createVecLeft()
    b.set(1.0)
    x = problem.K.createVecRight()
    backsolve = {v: [] for v in variants}
    for i in range(1, n + 1):
        v = variants[i % len(variants)]
        if comm.size > 1:
            set_variant(problem, v)
        m["approach"](m["delta_m"] * i / n)
        t = one_increment(problem, clock)
        backsolve[v].append(median_time(lambda: problem.factor.solve(b, x), 1))
        if i > 1:
            rows[v].append(comm.gather(t))
    out = {"name": spec["name"], "dofs": m["dofs"], "dim": m["dim"], "ranks": comm.size,
           "contact_dofs": int(problem.n_contact_dofs), "setup_s": setup_s,
           "increments": n, "variants": {}}
    if comm.size > 1:
        out["io_refusal"] = int(problem.factor.io_refusal)
    for v in variants:
        per_rank = {}
        for r in range(comm.size):
            samples = [row[r] for row in rows[v]] if comm.rank == 0 else []
            keys = sorted({k for s in samples for k in s})
            per_rank[f"rank{r}"] = {k: float(np.median([s.get(k, 0.0) for s in samples]))
                                    for k in keys}
        out["variants"][v] = {"phases": per_rank,
                              "increment_s": per_rank["rank0"].get("total_s"),
                              "increment_samples_s": [row[0]["total_s"] for row in rows[v]]
                              if comm.rank == 0 else [],
                              "backsolve_s": float(np.median(backsolve[v])),
                              "backsolve_samples_s": backsolve[v]}
    for vec in (b, x):
        vec.destroy()
    if comm.rank == 0:
        print("RESULT " + json.dumps(out), flush=True)


# ---- the parent: each case serial and on two ranks, back to back --------------------------
def run_child(name: str, ranks: int, repeat: int, timeout_s: float) -> dict:
    import run
    mesh, build = run.CASES[name]
    spec = {"name": name, "mesh": mesh, "build": build, "repeat": repeat}
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(REPO / "dolfinx_ext" / "python")] + [p for p in [env.get("PYTHONPATH")] if p])
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", json.dumps(spec)]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks), "--bind-to", "none"] + (
            ["--allow-run-as-root"] if os.geteuid() == 0 else []) + cmd
    load = os.getloadavg()
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=REPO,
                          timeout=timeout_s)
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
    if proc.returncode != 0 or not lines:
        return {"name": name, "ranks": ranks, "error": f"exit status {proc.returncode}",
                "log_tail": (proc.stdout + proc.stderr)[-3000:]}
    out = json.loads(lines[-1][len("RESULT "):])
    out["wall_s"] = time.perf_counter() - t0
    out["load_average_before"] = list(load)
    out["load_average_after"] = list(os.getloadavg())
    return out


def summary_line(serial: dict, np2: dict) -> str:
    s = serial["variants"]["serial"]
    parts = [f"{serial['name']} ({serial['dofs']:,} DOFs, {serial['contact_dofs']} contact "
             f"DOFs): increment serial {s['increment_s']:.3f} s"]
    for v in VARIANTS:
        r = np2["variants"][v]
        parts.append(f"2 ranks {v} {r['increment_s']:.3f} s "
                     f"(×{s['increment_s'] / r['increment_s']:.2f})")
    return ", ".join(parts)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", nargs="+", default=DEFAULT_CASES)
    ap.add_argument("--repeat", type=int, default=4,
                    help="timed increments per variant (plus one untimed first increment)")
    ap.add_argument("--timeout", type=float, default=1800, help="per run (s)")
    ap.add_argument("--out", type=Path, default=HERE / "mpi_increment.json")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(json.loads(args.child))
        return
    import machine
    result = {"command": " ".join(sys.argv), "machine": machine.machine(),
              "flexcontact": machine.commit(REPO), "cases": []}
    for name in args.cases:
        row = {"name": name}
        for ranks in (1, 2):
            print(f"{name} on {ranks} rank(s) ...", flush=True)
            row["serial" if ranks == 1 else "np2"] = run_child(name, ranks, args.repeat,
                                                               args.timeout)
        if "error" not in row["serial"] and "error" not in row["np2"]:
            print("  " + summary_line(row["serial"], row["np2"]), flush=True)
        result["cases"].append(row)
        result["machine"]["load_average_at_end"] = list(os.getloadavg())
        args.out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"written {args.out}")


if __name__ == "__main__":
    main()
