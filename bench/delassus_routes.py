"""W = B F* Bᵀ by the route the flop model picks per body, against the inverse route for all.

    /usr/bin/python3 bench/delassus_routes.py        # about a minute; writes bench/delassus_routes.json

Synthetic 2D problems, one run: a slave body of m = 500 node–surface pairs (2m contact DOFs,
every one on a row of B) on a master body whose candidate zone has N nodes, of which the
pairs touch the first m + 1 (each row two master nodes), so the master block has n = 2N
contact DOFs and r = 2m rows: r/n = m/N. Both blocks are held as Cholesky factors
(random symmetric positive definite blocks: the flops do not depend on the values). For each
N: the CPU time of W by the routes as chosen (BlockFlexibility.delassus) and by the inverse
for every body (dpotri of each block, then W from the dense F*, as before the routes
existed), their ratio, the flop model's ratio, and W's difference between the two.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from flexcontact import _cpp
from flexcontact.info import describe

M = 500
ZONES = (M + 1, 1000, 1500, 2500, 4000)


def _spd(n: int, rng) -> np.ndarray:
    G = rng.standard_normal((n, n))
    return G + G.T + 2.0 * n * np.eye(n)


def case(N: int, seed: int = 0) -> dict:
    rng = np.random.default_rng(seed)
    ns, nm = 2 * M, 2 * N
    rows, cols, vals = [], [], []
    for k in range(M):
        th = rng.uniform(-0.2, 0.2)
        n_, t_ = np.array([np.sin(th), np.cos(th)]), np.array([np.cos(th), -np.sin(th)])
        for row, e in ((2 * k, n_), (2 * k + 1, t_)):
            for c in range(2):
                rows.append(row), cols.append(2 * k + c), vals.append(e[c])
                for j, w in ((k, -0.5), (k + 1, -0.5)):
                    rows.append(row), cols.append(ns + 2 * j + c), vals.append(w * e[c])
    B = sp.csc_matrix((vals, (rows, cols)), shape=(2 * M, ns + nm))
    L = [np.linalg.cholesky(_spd(ns, rng)), np.linalg.cholesky(_spd(nm, rng))]
    blocks = [list(range(ns)), list(range(ns, ns + nm))]

    chosen = _cpp.BlockFlexibility(ns + nm, blocks, L)
    t0 = time.process_time()
    W1 = chosen.delassus(B)
    t_chosen = time.process_time() - t0

    inverse = _cpp.BlockFlexibility(ns + nm, blocks, L)
    t0 = time.process_time()
    W0 = _cpp.BlockFlexibility(inverse.dense()).delassus(B)
    t_inverse = time.process_time() - t0
    return {"zone_nodes": N, "master_dofs": nm, "rows_on_master": 2 * M,
            "r_over_n": 2 * M / nm, "routes": list(chosen.routes),
            "flops_chosen": chosen.flops_taken, "flops_inverse": chosen.flops_inverse,
            "flop_ratio": chosen.flops_taken / chosen.flops_inverse,
            "chosen_cpu_s": t_chosen, "inverse_cpu_s": t_inverse,
            "time_ratio": t_chosen / t_inverse,
            "W_rel_diff": float(np.abs(W1 - W0).max() / np.abs(W0).max())}


def main():
    rows = [case(N) for N in ZONES]
    print("| zone nodes | r/n (master) | routes | flops chosen / inverse | CPU s chosen | "
          "CPU s inverse | time ratio | W rel. diff |")
    print("|---:|---:|---|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['zone_nodes']} | {r['r_over_n']:.2f} | {', '.join(r['routes'])} | "
              f"{r['flop_ratio']:.2f} | {r['chosen_cpu_s']:.2f} | {r['inverse_cpu_s']:.2f} | "
              f"{r['time_ratio']:.2f} | {r['W_rel_diff']:.1e} |")
    out = Path(__file__).with_suffix(".json")
    out.write_text(json.dumps({"pairs": M, "cases": rows, "machine": describe(),
                               "started": time.strftime("%Y-%m-%d %H:%M:%S %Z")}, indent=1))


if __name__ == "__main__":
    main()
