"""What two MPI processes can gain on this machine: the ceiling of `mpirun -n 2` speed-ups.

Two measures, each serial and parallel back to back, repeated (the cores are shared):

* dense: one numpy dgemm (n = 3000, single-threaded OpenBLAS) alone, then two processes
  each doing the same dgemm at once. The ceiling of a perfectly parallel compute-bound phase
  is 2 × t_alone / t_pair (two cores, memory bandwidth and turbo shared);
* sparse: one MUMPS factorization of the bench's Hertz stiffness K (2D and 3D), on one
  process and with `mpirun -n 2`, with the MUMPS settings that can matter on two ranks:
  the ordering (MUMPS's own choice, AMD, or METIS nested dissection handed to MUMPS, as
  flexcontact does in 3D) and the analysis (ICNTL(28) = 1 sequential on the host, 2
  parallel: Debian's MUMPS has neither PT-SCOTCH nor ParMETIS, and INFOG(32) says which
  analysis ran).

    /usr/bin/python3 bench/mpi_ceiling.py            # writes bench/mpi_ceiling.json
    /usr/bin/python3 bench/mpi_ceiling.py --quick    # the small meshes, one repetition
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
N_DGEMM = 3000

# name: (mesh, build keywords); the bench's 2d_200k_c1600 and 3d_120k_c4000 meshes
MESHES = {
    "2d_200k": ("hertz2d", {"refine": 3}),
    "3d_120k": ("hertz3d", {"refine": 1, "zone_factor": 3.25, "h_far": 0.015}),
    "2d_tiny": ("hertz2d", {"refine": 0, "zone_factor": 1.25}),
    "3d_tiny": ("hertz3d", {"refine": 0, "zone_factor": 1.0, "h_far": 0.04}),
}
# name: how K is factored. "petsc": PETSc's MUMPS Cholesky with these ICNTL; "flexcontact":
# _cpp.flexibility without contact DOFs (the bench's plain factorization (a)) and this ordering.
VARIANTS = {
    "petsc_auto_seqanalysis": ("petsc", {7: 7, 28: 1}),
    "petsc_amd_seqanalysis": ("petsc", {7: 0, 28: 1}),
    "petsc_paranalysis": ("petsc", {28: 2}),
    "flexcontact_metis": ("flexcontact", "metis"),
    "flexcontact_mumps": ("flexcontact", "mumps"),
}


def env() -> dict:
    e = dict(os.environ)
    e["OPENBLAS_NUM_THREADS"] = "1"  # one core per process, as the serial runs have
    e["PYTHONPATH"] = os.pathsep.join([str(REPO / "dolfinx_ext" / "python")]
                                      + [p for p in [e.get("PYTHONPATH")] if p])
    return e


# ---- workers ---------------------------------------------------------------------------
def dgemm_worker(n: int, repeat: int) -> None:
    import numpy as np
    rng = np.random.default_rng(0)
    a, b = rng.random((n, n)), rng.random((n, n))
    a @ b  # warm-up
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        a @ b
        ts.append(time.perf_counter() - t0)
    print("RESULT " + json.dumps({"dgemm_s": min(ts), "samples_s": ts}), flush=True)


def factor_worker(mesh: str, variants: list[str], repeat: int) -> None:
    """Build the mesh and K on all ranks, then each variant's factorization ``repeat`` times."""
    import numpy as np
    from mpi4py import MPI
    from petsc4py import PETSc

    sys.path.insert(0, str(HERE))
    import case  # the bench's model of a Hertz case
    from flexcontact import _cpp
    from flexcontact.assembly import assemble_stiffness

    comm = MPI.COMM_WORLD
    kind, build = MESHES[mesh]
    spec = {"name": mesh, "mesh": kind, "build": build}
    m = case.model(spec, comm)
    K = assemble_stiffness(case.compiled_form(m["a"]), m["bcs"])
    K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    out = {"mesh": mesh, "dofs": m["dofs"], "ranks": comm.size, "variants": {}}
    for name in variants:
        how, arg = VARIANTS[name]
        rows = []
        for _ in range(repeat):
            comm.barrier()
            if how == "petsc":
                rows.append(_petsc_factor(K, arg))
            else:
                t0 = time.perf_counter()
                _, factor, info = _cpp.flexibility(K, np.zeros(0, np.int64), "schur", arg)
                rows.append({"s": time.perf_counter() - t0,
                             "ordering": info["mumps_ordering"],
                             "factor_entries": info["factor_entries"],
                             "flops": info["factor_flops"],
                             "analysis_s": info.get("analysis_s", 0.0) + info["ordering_s"]})
                factor.destroy()
        best = min(rows, key=lambda r: r["s"])
        out["variants"][name] = dict(best, samples_s=[r["s"] for r in rows])
    if comm.rank == 0:
        print("RESULT " + json.dumps(out), flush=True)


def _petsc_factor(K, icntl: dict) -> dict:
    from petsc4py import PETSc
    pc = PETSc.PC().create(K.comm)
    pc.setOperators(K)
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    pc.setFactorSetUpSolverType()
    F = pc.getFactorMatrix()
    F.setMumpsIcntl(24, 1)
    for k, v in icntl.items():
        F.setMumpsIcntl(k, v)
    t0 = time.perf_counter()
    pc.setUp()
    s = time.perf_counter() - t0
    # PETSc keeps a failed factorization as the factor's error type: MUMPS's INFOG(1) says
    row = {"s": s, "ordering": F.getMumpsInfog(7), "parallel_analysis": F.getMumpsInfog(32),
           "factor_entries": F.getMumpsInfog(29), "flops": F.getMumpsRinfog(3),
           "infog1": F.getMumpsInfog(1)}
    pc.destroy()
    return row


# ---- orchestration ---------------------------------------------------------------------
def _result(text: str) -> dict:
    lines = [ln for ln in text.splitlines() if ln.startswith("RESULT ")]
    if not lines:
        raise RuntimeError("no RESULT line:\n" + text[-3000:])
    return json.loads(lines[-1][len("RESULT "):])


def _run(cmd: list[str], timeout_s: float) -> dict:
    done = subprocess.run(cmd, env=env(), cwd=REPO, capture_output=True, text=True,
                          timeout=timeout_s, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stdout[-2000:]}{done.stderr[-3000:]}")
    return _result(done.stdout)


def _mpirun(n: int) -> list[str]:
    cmd = ["mpirun", "-n", str(n), "--oversubscribe"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    return cmd


def dgemm_pair(repeat: int) -> dict:
    """One dgemm process alone, then two at once (started together)."""
    me = [sys.executable, str(Path(__file__)), "--worker", "dgemm", "--repeat", str(repeat)]
    alone = _run(me, 600)["dgemm_s"]
    procs = [subprocess.Popen(me, env=env(), cwd=REPO, stdout=subprocess.PIPE, text=True)
             for _ in range(2)]
    pair = [_result(p.communicate(timeout=600)[0])["dgemm_s"] for p in procs]
    flops = 2 * N_DGEMM**3
    return {"alone_s": alone, "pair_s": pair, "gflops_alone": flops / alone / 1e9,
            "gflops_pair_total": sum(flops / t for t in pair) / 1e9,
            "ceiling": 2 * alone / max(pair), "load_average": list(os.getloadavg())}


def factored(row: dict) -> bool:
    """A factor was made: MUMPS reported no error and a factor with entries (a failed
    PETSc factorization has INFOG(1) < 0 and no entries)."""
    return row.get("infog1", 0) >= 0 and row.get("factor_entries", 0) != 0


def factor_pair(mesh: str, variants: list[str], repeat: int) -> dict:
    """The factorizations on one process, then on two (same mesh built on each)."""
    out = {}
    for n in (1, 2):
        cmd = _mpirun(n) + [sys.executable, str(Path(__file__)), "--worker", "factor",
                            "--mesh", mesh, "--variants", *variants, "--repeat", str(repeat)]
        load = os.getloadavg()[0]
        res = _run(cmd, 3600)
        res["load_average"] = [load, os.getloadavg()[0]]
        out[f"np{n}"] = res
    serial, par = out["np1"]["variants"], out["np2"]["variants"]
    ok = [v for v in variants if factored(serial[v]) and factored(par[v])]
    out["failed"] = [v for v in variants if v not in ok]
    out["speedup_vs_best_serial"] = {
        v: min(serial[w]["s"] for w in ok if factored(serial[w])) / par[v]["s"] for v in ok}
    out["speedup_same_variant"] = {v: serial[v]["s"] / par[v]["s"] for v in ok}
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--worker", choices=["dgemm", "factor"], help=argparse.SUPPRESS)
    ap.add_argument("--mesh", choices=list(MESHES), help=argparse.SUPPRESS)
    ap.add_argument("--variants", nargs="+", choices=list(VARIANTS), default=list(VARIANTS))
    ap.add_argument("--repeat", type=int, default=2, help="timings per measure (best kept)")
    ap.add_argument("--rounds", type=int, default=2,
                    help="serial/parallel comparisons repeated back to back")
    ap.add_argument("--meshes", nargs="+", choices=list(MESHES), default=["2d_200k", "3d_120k"])
    ap.add_argument("--quick", action="store_true", help="tiny meshes, one round")
    ap.add_argument("--out", type=Path, default=HERE / "mpi_ceiling.json")
    args = ap.parse_args(argv)
    if args.worker == "dgemm":
        return dgemm_worker(N_DGEMM, args.repeat)
    if args.worker == "factor":
        return factor_worker(args.mesh, args.variants, args.repeat)
    if args.quick:
        args.meshes, args.rounds, args.repeat = ["2d_tiny", "3d_tiny"], 1, 1
    started = time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime())
    res = {"started_utc": started, "cores": os.cpu_count(),
           "load_average_at_start": list(os.getloadavg()), "dgemm_n": N_DGEMM,
           "dgemm": [], "factorization": {m: [] for m in args.meshes}}
    for r in range(args.rounds):
        res["dgemm"].append(dgemm_pair(3))
        print(f"round {r + 1}: dgemm ceiling {res['dgemm'][-1]['ceiling']:.2f}", flush=True)
        for mesh in args.meshes:
            res["factorization"][mesh].append(factor_pair(mesh, args.variants, args.repeat))
            print(f"  {mesh}: {res['factorization'][mesh][-1]['speedup_same_variant']}",
                  flush=True)
        args.out.write_text(json.dumps(res, indent=1) + "\n")
    res["ceiling"] = max(d["ceiling"] for d in res["dgemm"])
    res["load_average_at_end"] = list(os.getloadavg())
    args.out.write_text(json.dumps(res, indent=1) + "\n")
    print(f"written {args.out}")


if __name__ == "__main__":
    main()
