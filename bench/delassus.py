"""W = B F* Bᵀ at set-up: the kernel's build time on contact sets of the bench's size.

    /usr/bin/python3 bench/delassus.py [--repeat 5]      # under a minute; prints a table

Synthetic problems shaped as bench/run.py's large cases: node–node pairs (slave k, master
m + k, as pairing.NodePairs numbers them), two bodies so that F* is block-diagonal (slaves'
block, masters' block), random frames; 2D with 1,001 pairs (4,004 contact DOFs, as
2d_800k_c4000) and 3D with 674 pairs (4,044, as 3d_120k_c4000), plus a 3D surface-pair
case whose master points have three nodes. For each: ``_cpp.delassus`` alone (B from the
pairs and W) and the whole ``_cpp.CondensedContact`` construction (the copy of F* into the
kernel, its checks, B, x0, W, the incremental solver), least CPU time of ``--repeat``
calls (and of the first construction, which also pays the first touch of its memory),
and W's relative difference from the dense product B F* Bᵀ (NumPy).
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from flexcontact import _cpp


def problem(dim: int, m: int, masters_per_pair: int, seed: int = 0):
    """(F, X, pairs, mu): two bodies of 2m·d... contact DOFs, F* block-diagonal by body."""
    rng = np.random.default_rng(seed)
    n_m = m if masters_per_pair == 1 else m + 2
    n_nodes = m + n_m
    n_c = n_nodes * dim
    F = np.zeros((n_c, n_c))
    for lo, hi in ((0, m * dim), (m * dim, n_c)):
        G = rng.standard_normal((hi - lo, hi - lo)) * 1e-12
        F[lo:hi, lo:hi] = G @ G.T / (hi - lo) + 1e-12 * np.eye(hi - lo)
    if masters_per_pair == 1:
        masters = (m + np.arange(m))[:, None]
    else:
        masters = m + np.stack([np.arange(m) + j for j in range(masters_per_pair)], axis=1)
    weights = rng.dirichlet(np.ones(masters_per_pair), size=m)
    normals = rng.standard_normal((m, dim))
    X = rng.standard_normal((n_nodes, dim))
    pairs = _cpp.pairs_from_normals(np.arange(m), masters, weights, normals, None)
    # Column-major, as _cpp.flexibility returns F*: the kernel takes it without a transpose.
    return np.asfortranarray(F), X, pairs, np.full(m, 0.3)


def dense_product(F, pairs, n_nodes: int, dim: int) -> np.ndarray:
    rows, cols, vals, shape = _cpp.gap_operator(dim, n_nodes, pairs)
    B = np.zeros(shape)
    np.add.at(B, (rows, cols), vals)
    W = B @ F @ B.T
    return 0.5 * (W + W.T)


def least(f, repeat: int) -> float:
    """Least process CPU time of ``repeat`` calls [s]: the kernel runs on one thread, and on
    a shared machine the wall time mostly measures the other processes."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        f()
        best = min(best, time.process_time() - t0)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    print(f"{'case':28} {'n_c':>6} {'m·d':>6} {'delassus CPU s':>14} "
          f"{'CondensedContact CPU s':>22} "
          f"{'first call CPU s':>17} {'rel. diff':>10}")
    for name, dim, m, k in (("2D node-node (2d_800k)", 2, 1001, 1),
                            ("3D node-node (3d_120k)", 3, 674, 1),
                            ("3D surface, 3 masters", 3, 674, 3)):
        F, X, pairs, mu = problem(dim, m, k)
        n_nodes = X.shape[0]
        t0 = time.process_time()
        _cpp.CondensedContact(dim, F, X, pairs, mu)
        t_first = time.process_time() - t0
        t_w = least(lambda: _cpp.delassus(pairs, n_nodes, dim, F), args.repeat)
        t_c = least(lambda: _cpp.CondensedContact(dim, F, X, pairs, mu), args.repeat)
        W = _cpp.delassus(pairs, n_nodes, dim, F)
        ref = dense_product(F, pairs, n_nodes, dim)
        diff = np.abs(W - ref).max() / np.abs(ref).max()
        print(f"{name:28} {F.shape[0]:6d} {m * dim:6d} {t_w:14.4f} {t_c:22.4f} "
              f"{t_first:17.4f} {diff:10.1e}",
              flush=True)


if __name__ == "__main__":
    main()
