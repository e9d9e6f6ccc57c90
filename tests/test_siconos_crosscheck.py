"""The kernel's 3D frictional contact answers against Siconos (fc3d), an independent code.

Every case is one increment of a ContactProblem on this project's own 3D meshes (a box on a
base, a Hertz quarter model), with μ from 0.1 to 1.0 and a load path that closes, pushes and
tips the bodies, so that the set holds open, stick and slip pairs. The local problem of the
increment (``problem.local_problem``) goes to Siconos' Alart–Curnier Newton (NSN_AC) at a
tight tolerance and to our dispatcher; the two λ must agree, and each code's residual must
accept the other code's answer.
"""
import warnings

import numpy as np
import pytest
from mpi4py import MPI

import crosscheck_problems as cp

pytest.importorskip("siconos.numerics", reason="the peer code Siconos (python3-siconos) is not installed; Debian 13 does not carry it")

TOL = 1e-12
LAMBDA_RTOL = 1e-6
# Our natural-map residual is relative (‖λ − P(λ − ρ û)‖ / max(‖λ‖, ‖ρ q‖)); Siconos' error
# is its own normalisation of the dimensionless problem. A converged answer of one code
# should pass the other's measure well below these.
OUR_RESIDUAL_MAX = 1e-9
SICONOS_ERROR_MAX = 1e-9

PLAN, BUILDERS = cp.cross_check_set(MPI.COMM_WORLD)
CASE_IDS = [(name, mu, i) for name, mu, path in PLAN for i in range(len(path))]


def _id(key):
    name, mu, i = key
    return f"{name}-mu{mu:g}-inc{i + 1}"


_models, _paths, _solved = {}, {}, {}


def _case(key) -> cp.Case:
    """One ContactProblem (one factorization) per mesh and μ, run through its whole path
    the first time any of its increments is asked for."""
    name, mu, i = key
    if (name, mu) not in _paths:
        if name not in _models:
            _models[name] = BUILDERS[name]()
        path = next(p for n, m, p in PLAN if n == name and m == mu)
        _paths[(name, mu)] = cp.run_path(_models[name], mu, path)
    return _paths[(name, mu)][i]


def _solved_case(key):
    if key in _solved:
        return _solved[key]
    case = _case(key)
    with cp.CapturedOutput() as out:
        sic, attempts = cp.siconos_with_fallback(case, TOL)
    if len(attempts) > 1:
        warnings.warn(f"{case.name}: Siconos NSN_AC did not converge (info {attempts[0].info}, "
                      f"error {attempts[0].error:.1e}); {sic.solver} used "
                      f"({'converged' if sic.converged else 'not converged either'})")
    rep, _ = cp.ours(case, tolerance=TOL)
    _solved[key] = dict(case=case, siconos=sic, attempts=attempts, ours=rep,
                        lu_failures=out.text.count("DGETRF failed"))
    return _solved[key]


def _lambda_difference(case, lam, ref):
    """‖λ − λ_ref‖ / ‖λ_ref‖ over the components that W determines.

    A component whose row of W is zero (the tangential DOFs of a pair on a symmetry plane,
    held by its Dirichlet condition) moves nothing: any value in the Coulomb disc solves the
    problem, so there is nothing to compare (the residuals still check it is in the disc).
    The force scale λ_ref = u_ref / w_ref stands in for ‖λ_ref‖ when every pair is open.
    """
    determined = ~np.all(case.W == 0.0, axis=1)
    lam_scale = cp.scales(case)[0]
    num = np.linalg.norm((np.asarray(lam) - ref)[determined])
    return num / max(np.linalg.norm(ref[determined]), lam_scale)


@pytest.mark.parametrize("key", CASE_IDS, ids=[_id(k) for k in CASE_IDS])
def test_lambda_agrees_with_siconos(key):
    s = _solved_case(key)
    case, sic, rep = s["case"], s["siconos"], s["ours"]
    assert sic.converged, (f"{case.name}: Siconos converged with neither "
                           + ", ".join(f"{a.solver} (info {a.info}, error {a.error:.1e})"
                                       for a in s["attempts"]))
    assert rep.converged, f"{case.name}: ours did not converge: {list(rep.attempts)}"

    lam = np.asarray(rep.lambda_)
    diff = _lambda_difference(case, lam, sic.lam)
    assert diff <= LAMBDA_RTOL, f"{case.name}: |λ_ours − λ_siconos|/|λ_siconos| = {diff:.2e}"
    # The incremental driver's own λ for this increment answers the same local problem: this
    # ties problem.local_problem (q with the previous tangential gap removed) to what ran.
    diff_inc = _lambda_difference(case, case.lam_incremental, sic.lam)
    assert diff_inc <= LAMBDA_RTOL, (f"{case.name}: incremental driver's λ differs from "
                                     f"Siconos by {diff_inc:.2e}")

    nat_sic = cp.natural_residual(case, sic.lam)
    assert nat_sic <= OUR_RESIDUAL_MAX, f"{case.name}: our residual of Siconos' λ = {nat_sic:.2e}"
    err_ours = cp.siconos_error(case, lam)
    assert err_ours <= SICONOS_ERROR_MAX, (f"{case.name}: fc3d_compute_error of our λ = "
                                           f"{err_ours:.2e}")


def test_set_mixes_open_stick_and_slip():
    counts = {"ours": np.zeros(3, int), "siconos": np.zeros(3, int)}
    cases_with = np.zeros(3, int)
    worst, worst_inc, fallbacks, lu = (0.0, ""), 0.0, [], 0
    for key in CASE_IDS:
        s = _solved_case(key)
        diff = _lambda_difference(s["case"], np.asarray(s["ours"].lambda_), s["siconos"].lam)
        worst = max(worst, (diff, s["case"].name))
        worst_inc = max(worst_inc, _lambda_difference(s["case"], s["case"].lam_incremental,
                                                      s["siconos"].lam))
        lu += s["lu_failures"]
        if len(s["attempts"]) > 1:
            fallbacks.append(s["case"].name)
        ours = cp.state_counts(s["ours"].states)
        sic = cp.state_counts(cp.states_of(s["case"], s["siconos"].lam))
        counts["ours"] += ours
        counts["siconos"] += sic
        cases_with += sic > 0
    names = cp.STATE_NAMES
    print("\npairs over the set, " + ", ".join(
        f"{who}: " + " / ".join(f"{n} {c}" for n, c in zip(names, cnt))
        for who, cnt in counts.items()))
    print(f"largest |λ_ours − λ_siconos|/|λ_siconos| = {worst[0]:.2e} ({worst[1]}); "
          f"incremental driver's λ: {worst_inc:.2e}; Siconos LU failures: {lu}; "
          f"Siconos fell back to NSGS on {len(fallbacks)} case(s) {fallbacks}")
    print("cases holding each state: " + ", ".join(f"{n} {c}" for n, c in zip(names, cases_with)))
    assert len(CASE_IDS) >= 20
    for n, c in zip(names, counts["siconos"]):
        assert c > 0, f"no {n} pair in the whole set: the set does not test that state"
    # Several cases per state, not one borderline pair.
    assert np.all(cases_with >= 3), dict(zip(names, cases_with.tolist()))
