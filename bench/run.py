"""The bench command: what the method costs on 2D and 3D meshes, against a plain
factorization, in one run; writes bench/RESULTS.md and bench/results.json.

    /usr/bin/python3 bench/run.py            # the default set, about 15 minutes here
    /usr/bin/python3 bench/run.py --full     # adds 2D ≥ 1M and 3D ≥ 300k DOFs (see README)
    /usr/bin/python3 bench/run.py --cases 2d_20k_c100 3d_11k_c160   # a subset
    /usr/bin/python3 bench/run.py --mpi      # adds serial vs `mpirun -n 2` (about 15 min)

Each case runs in its own process (bench/case.py) on a Hertz mesh: one plain linear-elastic
solve (assembly, the MUMPS factorization of K without Schur complement: (a), one
back-substitution: (d)), then flexcontact's ContactProblem (F* and W: (b); load
increments: (c); the local contact solve), each phase's peak memory measured on its own.
Ratios are taken within the run; the report checks the targets of the large meshes.

With --mpi the largest 2D and 3D cases (--mpi-cases) run again, serial and with
`mpirun -n 2` back to back, and the report gives each phase's speed-up and the largest
difference of the answers (u, contact pressure, normal force), next to what two processes
can gain on this machine at all (bench/mpi_ceiling.py's bench/mpi_ceiling.json).
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
import machine  # noqa: E402
import report  # noqa: E402

A = 0.005  # the Hertz meshes' aimed contact half-width (m), bench/case.py's A_M

# name: (mesh, build keywords). Contact DOFs follow h_contact and zone_factor (the
# candidate zone), the size mostly h_far and refine.
CASES = {
    "2d_20k_c100": ("hertz2d", {"refine": 1, "zone_factor": 1.25, "h_contact": A / 5,
                                "h_far": 0.05 / 8}),
    "2d_50k_c800": ("hertz2d", {"refine": 2}),
    "2d_200k_c1600": ("hertz2d", {"refine": 3}),
    "2d_800k_c4000": ("hertz2d", {"refine": 3, "zone_factor": 6.25}),  # the zone's band
    "3d_11k_c160": ("hertz3d", {"refine": 0, "zone_factor": 1.0, "h_far": 0.014}),
    "3d_12k_c700": ("hertz3d", {"refine": 0}),
    "3d_60k_c2500": ("hertz3d", {"refine": 1}),
    "3d_120k_c4000": ("hertz3d", {"refine": 1, "zone_factor": 3.25, "h_far": 0.015}),
    # --full only (not yet run here: sizes estimated from the refinement)
    "2d_800k_c3200": ("hertz2d", {"refine": 4}),
    "2d_1m_c4100": ("hertz2d", {"refine": 4, "zone_factor": 3.2}),
    "3d_390k_p1000": ("hertz3d", {"refine": 2, "zone_factor": 2.1}),
    "3d_390k_c8600": ("hertz3d", {"refine": 2}),
}
DEFAULT = list(CASES)[:8]
MPI_CASES = ["2d_800k_c4000", "3d_120k_c4000"]  # the default set's largest 2D and 3D
FULL = list(CASES)
TINY = ["2d_tiny", "3d_tiny"]  # the smoke test's set (tests/test_bench_command.py)
CASES["2d_tiny"] = ("hertz2d", {"refine": 0, "zone_factor": 1.25})
CASES["3d_tiny"] = ("hertz3d", {"refine": 0, "zone_factor": 1.0, "h_far": 0.04})


def run_case(name: str, timeout_s: float, increments: int, repeat: int, ranks: int = 1,
             answer_file: str = "") -> dict:
    """One case in a child process (``ranks`` > 1: under mpirun); its ru_maxrss (whole
    process, meshing included) comes from wait4, the phases' own peaks from the child (rank
    0's). With ``answer_file`` the child writes its answer there (case.write_answer)."""
    mesh, build = CASES[name]
    spec = {"name": name, "mesh": mesh, "build": build, "increments": increments,
            "repeat": repeat, "answer_file": answer_file}
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(REPO / "dolfinx_ext" / "python")] + [p for p in [env.get("PYTHONPATH")] if p])
    log = HERE / f".{name}.np{ranks}.log"
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    cmd = [sys.executable, str(HERE / "case.py"), "--spec", json.dumps(spec)]
    if ranks > 1:
        # not bound to cores: the serial run is not either, and the cores are shared
        cmd = ["mpirun", "-n", str(ranks), "--bind-to", "none"] + (
            ["--allow-run-as-root"] if os.geteuid() == 0 else []) + cmd
    with open(log, "w") as f:
        child = subprocess.Popen(cmd, stdout=f, stderr=subprocess.STDOUT, env=env, cwd=REPO,
                                 start_new_session=True)
        status, usage = _wait(child, timeout_s)
    wall = time.perf_counter() - t0
    text = log.read_text()
    lines = [ln for ln in text.splitlines() if ln.startswith("RESULT ")]
    if status != 0 or not lines:
        tail = "\n".join(text.splitlines()[-15:])
        return {"name": name, "spec": spec, "error": f"exit status {status}", "log_tail": tail,
                "wall_s": wall}
    log.unlink()
    out = json.loads(lines[-1][len("RESULT "):])
    out["wall_s"] = wall
    out["process_maxrss_mb"] = usage.ru_maxrss / 1024 if usage else None
    # CPU time well below the wall time: the case waited for the shared cores
    out["process_cpu_s"] = usage.ru_utime + usage.ru_stime if usage else None
    out["load_average"] = [load, os.getloadavg()[0]]
    return out


def _wait(child: subprocess.Popen, timeout_s: float):
    """Wait for the child with its resource usage; kill it (by its id) after timeout_s."""
    deadline = time.monotonic() + timeout_s
    while True:
        pid, status, usage = os.wait4(child.pid, os.WNOHANG)
        if pid == child.pid:
            child.returncode = os.waitstatus_to_exitcode(status)
            return child.returncode, usage
        if time.monotonic() > deadline:
            os.killpg(child.pid, 9)  # the child's own group: mpirun and its ranks
            _, status, usage = os.wait4(child.pid, 0)
            child.returncode = -9
            return f"killed after the timeout of {timeout_s:.0f} s", usage
        time.sleep(0.2)


def run_mpi(names: list[str], args, save=lambda section: None) -> dict:
    """Each case serial then with ``mpirun -n 2``, back to back; speed-ups and answers.
    ``save(section)`` is called after each case (a long run leaves its results on the way)."""
    ceiling = HERE / "mpi_ceiling.json"
    section = {"cases": [],
               "ceiling": json.loads(ceiling.read_text()) if ceiling.exists() else None}
    rows = section["cases"]
    for name in names:
        runs, answers = {}, {}
        for ranks in (1, 2):
            print(f"{name} on {ranks} rank(s) ...", flush=True)
            answer = HERE / f".{name}.np{ranks}.answer.npz"
            runs[ranks] = run_case(name, args.timeout, args.increments, args.repeat, ranks,
                                   str(answer))
            if answer.exists():
                answers[ranks] = dict(np.load(answer))
                answer.unlink()
        row = report.mpi_compare(runs[1], runs[2], answers.get(1), answers.get(2))
        print("  " + report.mpi_line(row), flush=True)
        rows.append(row)
        save(section)
    return section


def run_peers(args) -> dict:
    """The GetFEM and PETSc SNES peers (bench/peers.py), when present."""
    peers = HERE / "peers.py"
    if not peers.exists():
        return {"error": "bench/peers.py is not in this checkout"}
    done = subprocess.run([sys.executable, str(peers)], cwd=REPO, capture_output=True,
                          text=True, check=False)
    return {"returncode": done.returncode, "stdout_tail": done.stdout[-4000:],
            "stderr_tail": done.stderr[-2000:]}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--full", action="store_true", help="the full set (2D to ≥ 1M, 3D to 415k "
                    "DOFs; about 12 min more on the quiet machine, up to 8.3 GB)")
    ap.add_argument("--cases", nargs="+", choices=list(CASES), help="run these cases only")
    ap.add_argument("--increments", type=int, default=4, help="load increments per case")
    ap.add_argument("--repeat", type=int, default=5, help="back-substitutions timed (median)")
    ap.add_argument("--timeout", type=float, default=1800, help="per case (s)")
    ap.add_argument("--peers", action="store_true", help="also run bench/peers.py")
    ap.add_argument("--mpi", action="store_true", help="also run the largest 2D and 3D cases "
                    "of the default set serial and with mpirun -n 2 (about 15 min)")
    ap.add_argument("--mpi-only", action="store_true",
                    help="only the serial vs mpirun -n 2 comparison (--mpi-cases)")
    ap.add_argument("--mpi-cases", nargs="+", choices=list(CASES), default=MPI_CASES)
    ap.add_argument("--out", type=Path, default=HERE,
                    help="folder for RESULTS.md and results.json (default bench/)")
    ap.add_argument("--rewrite", action="store_true",
                    help="rewrite RESULTS.md from the results.json in --out (no run)")
    args = ap.parse_args(argv)
    if args.rewrite:
        results = json.loads((args.out / "results.json").read_text())
        results["targets"] = report.targets(results["cases"])
        (args.out / "RESULTS.md").write_text(report.markdown(results))
        return
    names = [] if args.mpi_only else (args.cases or (FULL if args.full else DEFAULT))
    t0 = time.perf_counter()
    results = {"command": " ".join(["bench/run.py"] + (argv if argv is not None
                                                        else sys.argv[1:])),
               "started_utc": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime()),
               "machine": machine.machine(), "flexcontact": machine.commit(REPO),
               "cases": []}
    args.out.mkdir(parents=True, exist_ok=True)
    for name in names:
        print(f"{name} ...", flush=True)
        case = report.derive(run_case(name, args.timeout, args.increments, args.repeat))
        results["cases"].append(case)
        print("  " + report.one_line(case), flush=True)
        write(results, args.out, t0)
    if args.mpi or args.mpi_only:
        def save(section):
            results["mpi"] = section
            write(results, args.out, t0)
        results["mpi"] = run_mpi(args.mpi_cases, args, save)
    if args.peers:
        results["peers"] = run_peers(args)
    write(results, args.out, t0)
    print(f"written {args.out / 'RESULTS.md'} and {args.out / 'results.json'}")


def write(results: dict, out: Path, t0: float) -> None:
    """Rewrite both files (after every case: a long run leaves its results on the way)."""
    results["total_s"] = time.perf_counter() - t0
    done = [c for c in results["cases"] if "error" not in c]
    if done and "libraries" not in results:  # dpkg once per run
        results["libraries"] = machine.libraries(done[0].get("loaded_libraries", []))
        results["versions"] = done[0]["system"]
    results["targets"] = report.targets(results["cases"])
    (out / "results.json").write_text(json.dumps(results, indent=1) + "\n")
    (out / "RESULTS.md").write_text(report.markdown(results))


if __name__ == "__main__":
    main()
