"""The ordering of the 2D factorization with the Schur complement: MUMPS's (AMD) or METIS.

    /usr/bin/python3 bench/schur_ordering_2d.py [--cases 2d_200k_c1600 2d_800k_c4000] [--repeat 2]

With a Schur complement MUMPS keeps only AMD of its own orderings; flexcontact can hand it
a METIS nested dissection of the mesh nodes with the contact DOFs last (ordering.h, the 3D
default). On the bench's 2D Hertz meshes and contact sets (bench/run.py's CASES, the same
K and contact DOFs as ContactProblem), this calls ``_cpp.flexibility(K, dofs, "schur",
ordering)`` for "mumps" and "metis" alternately, ``--repeat`` times each, and reports the
run of least CPU time (ordering, analysis, factorization, Schur complement, per-body inverse),
its process CPU time (one thread: on a shared machine the wall time mostly measures the
other processes), its parts and MUMPS's entries and flops (deterministic), plus the plain
factorization
(no Schur complement, MUMPS's choice: PORD) for scale. Writes schur_ordering_2d.json.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from flexcontact import _cpp  # noqa: E402
from flexcontact.assembly import assemble_stiffness  # noqa: E402
from flexcontact.info import describe  # noqa: E402
from flexcontact.pairing import pair_interfaces  # noqa: E402

import case as bench_case  # noqa: E402
from run import CASES  # noqa: E402

KEYS = ("ordering", "mumps_ordering", "ordering_s", "analysis_s", "factorization_s", "schur_s",
        "inverse_s", "factor_entries", "factor_flops", "factor_memory_mb")


def one_call(K, dofs, ordering: str) -> dict:
    t0, c0 = time.perf_counter(), time.process_time()
    F, factor, info = _cpp.flexibility(K, dofs, "schur", ordering)
    total, cpu = time.perf_counter() - t0, time.process_time() - c0
    rec = {"total_s": total, "cpu_s": cpu, **{k: info[k] for k in KEYS}}
    if dofs.size:
        rec["F_norm"] = float(np.linalg.norm(F))
    factor.destroy()
    del F
    return rec


def run_case(name: str, repeat: int) -> dict:
    mesh, build = CASES[name]
    m = bench_case.model({"name": name, "mesh": mesh, "build": build})
    a_form = bench_case.compiled_form(m["a"])
    K = assemble_stiffness(a_form, m["bcs"])
    pairs, _, n_pairs = pair_interfaces(m["V"], [m["interface"]], MPI.COMM_SELF)
    dofs = pairs.dofs.reshape(-1).astype(np.int64)
    runs = {"mumps": [], "metis": [], "plain": []}
    for _ in range(repeat):
        for ordering in ("mumps", "metis"):
            runs[ordering].append(one_call(K, dofs, ordering))
            print(name, ordering, runs[ordering][-1], flush=True)
    runs["plain"].append(one_call(K, np.zeros(0, np.int64), "auto"))
    print(name, "plain", runs["plain"][-1], flush=True)
    K.destroy()
    best = {k: min(v, key=lambda r: r["cpu_s"]) for k, v in runs.items()}
    f_diff = abs(best["metis"]["F_norm"] / best["mumps"]["F_norm"] - 1)
    return {"case": name, "dofs": m["dofs"], "contact_dofs": int(dofs.size), "pairs": n_pairs,
            "runs": runs, "best": best, "F_norm_rel_diff": f_diff,
            "metis_over_mumps_cpu": best["metis"]["cpu_s"] / best["mumps"]["cpu_s"],
            "metis_over_mumps_entries": (best["metis"]["factor_entries"]
                                         / best["mumps"]["factor_entries"]),
            "load_average": os.getloadavg()[0]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="+", default=["2d_200k_c1600", "2d_800k_c4000"])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--out", default=str(HERE / "schur_ordering_2d.json"))
    args = ap.parse_args()
    t0 = time.perf_counter()
    cases = [run_case(c, args.repeat) for c in args.cases]
    result = {"machine": describe(), "cases": cases, "total_s": time.perf_counter() - t0}
    Path(args.out).write_text(json.dumps(result, indent=1, default=float))
    print(f"{'case':15} {'ordering':8} {'CPU s':>8} {'wall s':>8} {'order s':>8} {'factor s':>9} "
          f"{'Schur s':>8} {'inverse s':>9} {'entries':>9} {'flops':>9}")
    for c in cases:
        for k, r in c["best"].items():
            print(f"{c['case']:15} {k:8} {r['cpu_s']:8.2f} {r['total_s']:8.2f} "
                  f"{r['ordering_s']:8.2f} "
                  f"{r['factorization_s']:9.2f} {r['schur_s']:8.2f} {r['inverse_s']:9.2f} "
                  f"{r['factor_entries'] / 1e6:8.1f}M {r['factor_flops']:9.2e}")
    print(f"written {args.out} ({result['total_s']:.0f} s)")


if __name__ == "__main__":
    main()
