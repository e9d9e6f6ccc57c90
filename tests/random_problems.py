"""Random local contact problems u = W λ + q with a known solution, in classes.

Shared by tests/test_campaign.py (a sample in CI) and bench/campaign.py (the full campaign).
Every problem is built backwards from a solution: states are drawn per pair, then a λ* and a
u* that satisfy the contact laws in those states (stick: u = 0, |λ_t| < μ λ_n; slip: u_n = 0,
λ_t = μ λ_n d, u_t = −c d; open: λ = 0, u_n > 0), and q = u* − W λ*. So every problem has a
solution, whatever W is, and a solver that fails on one has no excuse of infeasibility.

Classes (W is m·d square):

* ``spd`` — W = A Aᵀ + ε I, like a FEM flexibility;
* ``zero_rows`` — positive semi-definite: the rows and columns of some pairs are zero, as for
  contact DOFs held by a Dirichlet condition (their u is q: the known solution keeps them open
  or in stick with u = 0);
* ``rank_deficient`` — W = G Gᵀ with G of m·d × r, r from a third of the size up: rigid bodies
  with redundant contacts;
* ``ill_conditioned`` — W = Q diag(σ) Qᵀ with σ spread over 10 decades.

μ is drawn from 0 to 2; sizes are given by the caller.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CLASSES = ("spd", "zero_rows", "rank_deficient", "ill_conditioned")
STATES = ("open", "stick", "slip")


@dataclass
class RandomProblem:
    name: str
    kind: str
    dim: int
    W: np.ndarray
    q: np.ndarray
    mu: np.ndarray
    lam_star: np.ndarray

    @property
    def m(self) -> int:
        return self.mu.size

    @property
    def unknowns(self) -> int:
        return self.q.size


def _unit(rng, k):
    v = rng.standard_normal(k)
    return v / np.linalg.norm(v)


def _operator(rng, kind, n, dim):
    if kind == "rank_deficient":
        r = int(rng.integers(max(1, n // 3), n))
        G = rng.standard_normal((n, r))
        return G @ G.T / r, None
    if kind == "ill_conditioned":
        Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
        sigma = np.logspace(0.0, -10.0, n)
        return (Q * sigma) @ Q.T, None
    A = rng.standard_normal((n, n))
    W = A @ A.T / n + 1e-3 * np.eye(n)
    if kind != "zero_rows":
        return W, None
    held = rng.random(n // dim) < 0.3
    rows = np.repeat(held, dim)
    W[rows, :] = 0.0
    W[:, rows] = 0.0
    return W, held


def _pair_solution(rng, dim, mu, state):
    """(λ, u) of one pair in the given state, in the local frame (normal first)."""
    lam, u = np.zeros(dim), np.zeros(dim)
    if state == "open":
        u[0] = rng.uniform(0.1, 1.0)
        u[1:] = rng.standard_normal(dim - 1)
        return lam, u
    lam[0] = rng.uniform(0.1, 1.0)
    d = _unit(rng, dim - 1)
    if state == "stick" or mu == 0.0:
        lam[1:] = rng.uniform(0.0, 0.9) * mu * lam[0] * d
        if mu == 0.0 and state == "slip":
            u[1:] = -rng.uniform(0.1, 1.0) * d
        return lam, u
    lam[1:] = mu * lam[0] * d
    u[1:] = -rng.uniform(0.1, 1.0) * d
    return lam, u


def make_problem(rng: np.random.Generator, kind: str, dim: int, m: int,
                 index: int = 0) -> RandomProblem:
    """One problem of class ``kind`` with m pairs in dimension dim."""
    if kind not in CLASSES:
        raise ValueError(f"kind={kind!r}; it must be one of {CLASSES}")
    n = m * dim
    W, held = _operator(rng, kind, n, dim)
    mu = np.where(rng.random(m) < 0.15, 0.0, rng.uniform(0.0, 2.0, m))
    lam, u = np.zeros(n), np.zeros(n)
    for k in range(m):
        state = STATES[int(rng.integers(0, 3))]
        if held is not None and held[k]:
            # A held pair cannot move: open with a positive gap, or closed with u = 0 and no
            # force (W's zero rows give u = q, whatever λ is).
            state = "open"
        lam[k * dim:(k + 1) * dim], u[k * dim:(k + 1) * dim] = _pair_solution(rng, dim, mu[k],
                                                                            state)
    q = u - W @ lam
    return RandomProblem(f"{kind}-{dim}d-m{m}-{index}", kind, dim, W, q, mu, lam)


def sample(seed: int, count: int, sizes=(1, 60), large: int = 0, large_m=(300, 1000)):
    """``count`` problems spread over the classes and over 2D/3D, m pairs drawn from
    ``sizes``; plus ``large`` ones with m from ``large_m`` (up to 3,000 unknowns in 3D)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count + large):
        kind, dim = kind_and_dim(i, count)
        lo, hi = sizes if i < count else large_m
        out.append(make_problem(rng, kind, dim, int(rng.integers(lo, hi + 1)), i))
    return out


def kind_and_dim(i: int, count: int) -> tuple:
    """Class and dimension of problem i: the classes in turn, 2D and 3D in alternate rounds
    of them; the large ones (i ≥ count) alternate 2D/3D within a round too, so that even a
    few of them reach the 3D sizes (3,000 unknowns)."""
    kind = CLASSES[i % len(CLASSES)]
    j = i if i < count else (i - count) + (i - count) // len(CLASSES)
    return kind, 2 + (j // len(CLASSES) if i < count else j) % 2


# ---- judging --------------------------------------------------------------------------
SOLVERS = ("chain", "active_set", "projection", "newton_ac")


@dataclass
class Outcome:
    """One solver on one problem, judged by the natural-map residual computed here."""

    solver: str
    claimed: bool      # the solver reported convergence
    residual: float    # relative natural-map residual of its λ, computed independently
    finite: bool
    time_s: float
    solved: bool       # residual within the acceptance tolerance

    @property
    def wrong(self) -> bool:
        """Claimed an answer that does not satisfy the contact laws."""
        return self.claimed and not self.solved


def judge(problem: RandomProblem, solver: str, lam, claimed: bool, time_s: float,
          tolerance: float) -> Outcome:
    from flexcontact import _cpp
    lam = np.asarray(lam, dtype=float)
    finite = lam.size == problem.unknowns and bool(np.all(np.isfinite(lam)))
    res = (float(_cpp.natural_map_residual(problem.dim, problem.W, problem.q, problem.mu, lam))
           if finite else float("inf"))
    # A converged solver stops at `tolerance`; the independent residual may differ from its
    # own by rounding, so 10× is accepted.
    return Outcome(solver, bool(claimed), res, finite, time_s, res <= 10.0 * tolerance)


def in_cache(problem: RandomProblem) -> float:
    """Reads W and q once, so that whichever solver is timed first on a problem does not
    pay alone for bringing them into the cache (the campaign's problems are drawn long
    before they are solved; on sub-millisecond solves this made the first one look slower)."""
    return float(problem.W.sum() + problem.q.sum() + problem.mu.sum())


def run_flexcontact(problem: RandomProblem, solver: str, tolerance: float) -> Outcome:
    import time

    from flexcontact import _cpp
    opts = _cpp.SolverOptions(tolerance=tolerance)
    fn = _cpp.solve if solver == "chain" else getattr(_cpp, f"solve_{solver}")
    in_cache(problem)
    t0 = time.perf_counter()
    r = fn(problem.dim, problem.W, problem.q, problem.mu, options=opts)
    dt = time.perf_counter() - t0
    return judge(problem, solver, r.lambda_, r.converged, dt, tolerance)


def run_siconos(problem: RandomProblem, tolerance: float) -> Outcome:
    """Siconos' NSN_AC (fc3d; 3D problems only) on the same problem, judged the same way."""
    from crosscheck_problems import siconos_solve
    in_cache(problem)
    r = siconos_solve(_AsCase(problem), "NSN_AC", tolerance=min(tolerance, 1e-12))
    return judge(problem, "siconos_NSN_AC", r.lam, r.converged, r.time_s, tolerance)


class _AsCase:
    """The fields of crosscheck_problems.Case that its Siconos helpers read."""

    def __init__(self, p: RandomProblem):
        self.W, self.q, self.mu_pairs, self.m = p.W, p.q, p.mu, p.m


# ---- stored problems (kernel/tests/test_hard_random.cpp) ------------------------------
def write_problem(problem: RandomProblem, path) -> None:
    """Store one problem for the kernel's GoogleTests: an ASCII header (name, dim, pairs),
    then little-endian float64 μ (m), W's upper triangle by rows, q and the constructed
    solution λ* (n = m·d each)."""
    n = problem.unknowns
    header = (f"flexcontact-random-problem 1\nname {problem.name}\ndim {problem.dim}\n"
              f"pairs {problem.m}\nbinary float64 little-endian: mu, W upper by rows, q, "
              f"lambda_star\n")
    body = np.concatenate([problem.mu, problem.W[np.triu_indices(n)], problem.q,
                           problem.lam_star]).astype("<f8")
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(body.tobytes())


def problem_by_name(name: str, seed: int = 1, count: int = 10000, sizes=(1, 60),
                    large: int = 0) -> RandomProblem:
    """The problem of that name in ``sample(seed, count, sizes, large)`` (as bench/campaign.py
    names them), regenerated from its seed: problems are drawn in sequence, so all those
    before it are drawn too."""
    index = int(name.rsplit("-", 1)[1])
    rng = np.random.default_rng(seed)
    for i in range(index + 1):
        kind, dim = kind_and_dim(i, count)
        lo, hi = sizes if i < count else (300, 1000)
        p = make_problem(rng, kind, dim, int(rng.integers(lo, hi + 1)), i)
    if p.name != name:
        raise ValueError(f"name={name!r}: problem {index} of seed {seed} is {p.name!r}")
    return p
