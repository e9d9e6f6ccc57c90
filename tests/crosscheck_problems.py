"""3D frictional contact problems from this project's meshes, and Siconos as an oracle.

Shared by tests/test_siconos_crosscheck.py and bench/solvers_vs_siconos.py. Each case is one
increment of a ContactProblem: its local problem u = W λ + q (``problem.local_problem``, q
with the previous tangential gap removed, which is exactly Siconos' incremental form) plus
the λ and states the incremental driver found.

Siconos' fc3d error adds forces and displacements (‖λ − P_K(λ − (u + μ|u_T| n))‖ with ρ = 1)
and divides by ‖q‖, so on SI data (W ~ 1e-10 m/N, λ ~ 1e3 N) its absolute tolerance says
little. The problem handed to Siconos is therefore made dimensionless first:
λ = λ_ref λ̂, u = u_ref û, Ŵ = W λ_ref / u_ref, q̂ = q / u_ref. The Coulomb cone and the
complementarity conditions are invariant under these positive scalings, so λ_ref λ̂ solves the
original problem exactly; only the meaning of Siconos' tolerance changes (to O(1) entries).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import ufl

import flexcontact as fc
from flexcontact import _cpp, compat, forms
from flexcontact.meshes import block_on_base, hertz3d, tags

# Dissimilar materials on purpose: the Poisson mismatch makes slip under pure compression.
STEEL = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
ALUMINIUM = forms.Material(E_Pa=70e9, nu=0.33, name="aluminium")

STATE_NAMES = ("open", "stick", "slip")
"""The names of the pair states counted by ``state_counts``, in that order."""


def state_counts(states) -> np.ndarray:
    """How many pairs are open, stick and slip (flexcontact.states' codes)."""
    from flexcontact.states import OPEN, SLIP, STICK
    s = np.asarray(states)
    return np.array([(s == OPEN).sum(), (s == STICK).sum(), (s == SLIP).sum()])


@dataclass
class Model:
    """A meshed two-body geometry with its elasticity form, ready for ContactProblems."""

    name: str
    msh: object
    cells: object
    facets: object
    info: dict
    V: object
    a: object
    symmetric: bool  # quarter model: u_x = 0 on x = 0 and u_y = 0 on y = 0


@dataclass
class Case:
    """One increment's local problem and the incremental driver's answer to it."""

    name: str
    mu: float
    load: tuple
    W: np.ndarray
    q: np.ndarray
    mu_pairs: np.ndarray
    lam_incremental: np.ndarray
    states_incremental: np.ndarray
    extra: dict = field(default_factory=dict)

    @property
    def m(self) -> int:
        return self.mu_pairs.size


def _model(name, built, symmetric):
    msh, cells, facets, info = built
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: STEEL, tags.UPPER: ALUMINIUM}, dx, "3d")
    return Model(name, msh, cells, facets, info, V, a, symmetric)


def block_model(comm, **kw) -> Model:
    """Box on a wider base; ``gap`` > 0 lets the first increments stay open."""
    return _model("block", block_on_base.build_3d(comm, **kw), False)


def hertz_model(comm, **kw) -> Model:
    """Quarter sphere-ended column on a block: the contact zone grows with the load, so the
    candidate zone keeps open pairs."""
    return _model("hertz", hertz3d.build(comm, **kw), True)


def contact_problem(model: Model, mu: float, solver=None):
    """ContactProblem with the bottom clamped and the top's (ux, uy, uz) prescribed;
    returns (problem, (ux, uy, uz) Constants)."""
    V, facets = model.V, model.facets
    bcs, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, consts = fc.dirichlet(V, facets, tags.LOADED)
    bcs += top
    if model.symmetric:
        bcs += fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])[0]
        bcs += fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])[0]
    itf = fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, mu, name=model.name)
    problem = fc.ContactProblem(model.a, None, bcs, itf, solver=solver)
    return problem, consts


def run_path(model: Model, mu: float, loads, solver=None) -> list[Case]:
    """One ContactProblem (one factorization) driven through ``loads`` (top displacement
    triples in m); one Case per increment."""
    problem, consts = contact_problem(model, mu, solver)
    cases = []
    for i, load in enumerate(loads):
        for c, val in zip(consts, load):
            c.value = val
        inc = problem.step()
        lp = problem.local_problem
        cases.append(Case(
            name=f"{model.name} mu={mu:g} #{i + 1} top=({load[0]:.1e},{load[1]:.1e},{load[2]:.1e})",
            mu=mu, load=tuple(load), W=lp["W"], q=np.array(lp["q"], dtype=float),
            mu_pairs=np.array(lp["mu"], dtype=float),
            lam_incremental=inc.lam.reshape(-1).copy(), states_incremental=inc.states.copy()))
    return cases


# The cross-check set: (model, μ values, top displacement path in m). The block's gap of
# 10 µm keeps its first increment open; later ones close it, push it sideways (stick, then
# partial and gross slip) and, at the largest push, tip it so that an edge lifts. The Hertz
# column keeps most of its candidate zone open; its contact disc grows, then the top is
# pushed sideways and partly unloaded.
BLOCK_GAP_M = 1e-5
BLOCK_MUS = (0.1, 0.3, 0.6, 1.0)
BLOCK_PATH = ((0.0, 0.0, -5e-6), (0.0, 0.0, -1.5e-5), (2e-6, 0.0, -1.5e-5),
              (6e-6, 3e-6, -2e-5), (1.5e-5, 1e-5, -2e-5))
HERTZ_MUS = (0.1, 0.5, 1.0)
HERTZ_PATH = ((0.0, 0.0, -3e-4), (0.0, 0.0, -8e-4), (5e-5, 0.0, -8e-4), (5e-5, 5e-5, -5e-4))


def cross_check_set(comm):
    """[(model name, μ, path)] of the cross-check set and a builder for its two models."""
    plan = [("block", mu, BLOCK_PATH) for mu in BLOCK_MUS]
    plan += [("hertz", mu, HERTZ_PATH) for mu in HERTZ_MUS]
    builders = {"block": lambda: block_model(comm, gap=BLOCK_GAP_M),
                "hertz": lambda: hertz_model(comm)}
    return plan, builders


# ---- the project's side -----------------------------------------------------------------
def ours(case: Case, chain=None, tolerance=1e-12, max_iterations=200):
    """Solve the case's local problem from scratch with the kernel; returns the SolveReport
    and the wall time."""
    opts = _cpp.SolverOptions()
    opts.tolerance = tolerance
    opts.max_iterations = max_iterations
    if chain is not None:
        opts.chain = list(chain)
    t0 = time.perf_counter()
    rep = _cpp.solve(3, case.W, case.q, case.mu_pairs, options=opts)
    return rep, time.perf_counter() - t0


def natural_residual(case: Case, lam) -> float:
    return float(_cpp.natural_map_residual(3, case.W, case.q, case.mu_pairs, np.asarray(lam)))


def states_of(case: Case, lam, tol=1e-8) -> np.ndarray:
    return np.asarray(_cpp.classify_states(3, case.W, case.q, case.mu_pairs, np.asarray(lam), tol))


# ---- Siconos --------------------------------------------------------------------------
def _sn():
    import siconos.numerics as sn
    return sn


SICONOS_SOLVERS = {"NSN_AC": "SICONOS_FRICTION_3D_NSN_AC", "NSGS": "SICONOS_FRICTION_3D_NSGS",
                   "DSFP": "SICONOS_FRICTION_3D_DSFP"}


def scales(case: Case):
    """(λ_ref, u_ref): u_ref the largest |q|, λ_ref the force that moves a typical pair by
    u_ref along its normal."""
    u_ref = float(np.abs(case.q).max()) or 1.0
    wn = np.diag(case.W)[0::3]
    w_ref = float(np.mean(wn[wn > 0])) if np.any(wn > 0) else 1.0
    return u_ref / w_ref, u_ref


def siconos_problem(case: Case):
    sn = _sn()
    lam_ref, u_ref = scales(case)
    W = np.ascontiguousarray(case.W * (lam_ref / u_ref))
    q = case.q / u_ref
    return sn.FrictionContactProblem(3, case.m, W, q, case.mu_pairs.copy()), q, lam_ref, u_ref


@dataclass
class SiconosResult:
    solver: str
    lam: np.ndarray        # in the case's units (N)
    info: int              # 0: converged
    iterations: int
    error: float           # Siconos' own error estimate at exit (dimensionless problem)
    time_s: float

    @property
    def converged(self) -> bool:
        return self.info == 0


def siconos_solve(case: Case, solver="NSN_AC", tolerance=1e-12, max_iterations=None):
    """One fc3d_driver call on the dimensionless problem; λ comes back in N."""
    sn = _sn()
    t0 = time.perf_counter()
    prob, _, lam_ref, _ = siconos_problem(case)
    opts = sn.SolverOptions(getattr(sn, SICONOS_SOLVERS[solver]))
    opts.dparam[sn.SICONOS_DPARAM_TOL] = tolerance
    if max_iterations is None:
        max_iterations = 1000 if solver == "NSN_AC" else 100000
    opts.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iterations
    r = np.zeros(3 * case.m)
    u = np.zeros(3 * case.m)
    info = sn.fc3d_driver(prob, r, u, opts)
    elapsed = time.perf_counter() - t0
    return SiconosResult(solver, r * lam_ref, int(info), int(opts.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
                         float(opts.dparam[sn.SICONOS_DPARAM_RESIDU]), elapsed)


def siconos_error(case: Case, lam) -> float:
    """fc3d_compute_error of λ (in N) on the dimensionless problem, normalised by ‖q̂‖ as
    Siconos' own solvers do."""
    sn = _sn()
    prob, q, lam_ref, u_ref = siconos_problem(case)
    lam = np.asarray(lam, dtype=float)
    z = lam / lam_ref
    w = (case.W @ lam + case.q) / u_ref
    opts = sn.SolverOptions(sn.SICONOS_FRICTION_3D_NSN_AC)
    info, err = sn.fc3d_compute_error(prob, z, w, 1e-300, opts, float(np.linalg.norm(q)))
    return float(err)


def siconos_with_fallback(case: Case, tolerance=1e-12):
    """NSN_AC first; if it does not converge, NSGS. Returns (result used, list of attempts)."""
    attempts = [siconos_solve(case, "NSN_AC", tolerance)]
    if not attempts[-1].converged:
        attempts.append(siconos_solve(case, "NSGS", tolerance))
    best = next((a for a in attempts if a.converged), min(attempts, key=lambda a: a.error))
    return best, attempts


class CapturedOutput:
    """Collects what C code writes to stdout/stderr (Siconos prints its LU failures there)
    into a temporary file instead of the terminal; ``text`` holds it afterwards."""

    def __enter__(self):
        import os
        import sys
        import tempfile
        sys.stdout.flush()
        sys.stderr.flush()
        self._file = tempfile.TemporaryFile(mode="w+b")
        self._saved = [os.dup(1), os.dup(2)]
        os.dup2(self._file.fileno(), 1)
        os.dup2(self._file.fileno(), 2)
        self.text = ""
        return self

    def __exit__(self, *exc):
        import os
        import sys
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(self._saved[0], 1)
        os.dup2(self._saved[1], 2)
        for fd in self._saved:
            os.close(fd)
        self._file.seek(0)
        self.text = self._file.read().decode(errors="replace")
        self._file.close()
        return False
