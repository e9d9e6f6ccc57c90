"""A block held only by contact (floating=True), pressed by N and pushed by Q: the block's
equilibrium from the contact forces (Σλ_n = N, Σλ_t = Q), partial slip below μN, no static
equilibrium past μN (named), the minimum-norm slide of a frictionless block, and the same
answer on two MPI ranks. References from the formulas, not from the demo's output."""
import json
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import ufl
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conftest import on_two_ranks  # noqa: E402
from demo_runner import run_demo  # noqa: E402

import dolfinx.fem  # noqa: E402

import flexcontact as fc  # noqa: E402
from flexcontact import compat, forms  # noqa: E402
from flexcontact.assembly import assemble_load, assemble_stiffness  # noqa: E402
from flexcontact.meshes import block_on_base, tags  # noqa: E402

N = 1e5       # N/m
MU = 0.3


def _block(mu=MU, pairing="auto", comm=MPI.COMM_WORLD):
    """The block (0.1 × 0.05 m) on its clamped base; the top traction (Q/b, −N/b)."""
    msh, cells, facets, geo = block_on_base.build(comm, h=0.01, h_far=0.02)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=facets)
    al = forms.Material(E_Pa=70e9, nu=0.33)
    steel = forms.Material(E_Pa=200e9, nu=0.3)
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: al}, dx, "plane_strain")
    traction = dolfinx.fem.Constant(msh, np.zeros(2))
    L = ufl.inner(traction, v) * ds(tags.LOADED)
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    problem = fc.ContactProblem(
        a, L, fixed, fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, mu, name="block/base",
                                         pairing=pairing),
        bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}), floating=True)
    return problem, traction, geo["block_width"]


def _push(problem, traction, b, fractions, mu=MU):
    """Steps at Q = f μN; returns the summaries and the NoEquilibriumError, if any."""
    out = []
    for f in fractions:
        traction.value = np.array([f * mu * N / b, -N / b])
        try:
            out.append(problem.step().summary)
        except fc.NoEquilibriumError as e:
            return out, e
    return out, None


@pytest.fixture(scope="module")
def pushed():
    problem, traction, b = _block()
    fractions = [0.0, 0.3, 0.6, 0.9, 0.95, 0.99, 0.995, 1.005]
    with warnings.catch_warnings():
        warnings.simplefilter("error", fc.TippingWarning)
        summaries, error = _push(problem, traction, b, fractions)
    # The load of the last converged increment, as problem.u holds it.
    traction.value = np.array([fractions[len(summaries) - 1] * MU * N / b, -N / b])
    return problem, fractions, summaries, error


def test_contact_forces_balance_the_loads(pushed):
    problem, fractions, summaries, _ = pushed
    assert len(summaries) == len(fractions) - 1
    for f, s in zip(fractions, summaries):
        assert s.normal_force == pytest.approx(N, rel=1e-9)
        # The friction on the block opposes the push: along +x it balances Q.
        assert s.tangential_force[0] == pytest.approx(-f * MU * N, abs=1e-9 * N)


def test_partial_slip_below_mu_n(pushed):
    problem, fractions, summaries, _ = pushed
    s = summaries[fractions.index(0.6)]
    assert s.stick > 0 and s.slip > 0, s.line()


def test_push_past_mu_n_has_no_static_equilibrium(pushed):
    problem, fractions, summaries, error = pushed
    assert error is not None
    assert isinstance(error, fc.ConvergenceError)
    msg = str(error)
    assert "body 'block'" in msg and "no static equilibrium" in msg, msg
    assert "translation along x" in msg, msg
    # Detected within 1 %: 0.995 μN held, 1.005 μN refused; the increments done stay.
    assert fractions[len(summaries)] - fractions[len(summaries) - 1] <= 0.01
    assert len(problem.increments) == len(summaries)


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial: reads K u − p on one rank")
def test_displacement_solves_k_u_equals_p_off_the_contact(pushed):
    """u = K⁺(p + Bᵀλ) + Rα solves K u = p at every DOF away from the contact surfaces,
    the fixing DOFs included (K⁺ is a generalized inverse on the block)."""
    problem = pushed[0]
    K = assemble_stiffness(problem.a_form, problem.bcs)
    p = assemble_load(problem.V, problem.a_form, problem.L_form, problem.bcs, problem.comm)
    Ku = K.createVecLeft()
    K.mult(compat.petsc_vec(problem.u), Ku)
    res = Ku.array - p.array
    off = np.ones(res.size, bool)
    off[problem.condensation.dofs] = False
    assert np.abs(res[off]).max() <= 1e-8 * np.abs(p.array).max()
    assert problem.floating.fixing.size == 3


def test_frictionless_slide_with_no_push_takes_the_minimum_norm():
    problem, traction, b = _block(mu=0.0)
    traction.value = np.array([0.0, -N / b])
    with pytest.warns(fc.FreeModeWarning, match=r"body 'block': translation along x"):
        inc = problem.step()
    assert inc.summary.normal_force == pytest.approx(N, rel=1e-9)
    names = problem.floating.names
    alpha = np.asarray(inc.alpha)
    assert abs(alpha[names.index(("block", "translation along x"))]) <= 1e-10 * np.abs(alpha).max()


def test_frictionless_push_has_no_static_equilibrium():
    problem, traction, b = _block(mu=0.0)
    traction.value = np.array([0.01 * N / b, -N / b])
    with pytest.raises(fc.NoEquilibriumError, match=r"body 'block'.*translation along x"):
        problem.step()
    assert problem.increments == []


def test_without_floating_the_free_block_is_an_error():
    msh, cells, facets, geo = block_on_base.build(MPI.COMM_WORLD, h=0.01, h_far=0.02)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: forms.Material(E_Pa=1e9, nu=0.3),
                                     tags.UPPER: forms.Material(E_Pa=1e9, nu=0.3)},
                              dx, "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    with pytest.raises(ValueError, match=r"body 'block'.*floating=True"):
        fc.ContactProblem(a, None, fixed, fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.3),
                          bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}))


def _mpi_record():
    problem, traction, b = _block()
    summaries, error = _push(problem, traction, b, [0.5, 0.9, 1.01])
    u = problem.u
    norm = float(np.sqrt(problem.comm.allreduce(float(np.sum(
        u.x.array[:u.function_space.dofmap.index_map.size_local * 2] ** 2)), op=MPI.SUM)))
    return {"N": [s.normal_force for s in summaries],
            "T": [s.tangential_force[0] for s in summaries],
            "stick": [s.stick for s in summaries], "u_norm": norm,
            "error": str(error) if error else None}


@pytest.mark.mpi
def test_two_ranks_equal_serial(tmp_path):
    serial = _mpi_record()
    on_two_ranks(__file__, tmp_path, timeout=300)
    par = json.loads((tmp_path / "pushed.json").read_text())
    for key in ("N", "T"):
        np.testing.assert_allclose(par[key], serial[key], rtol=1e-10, atol=1e-10 * N)
    assert par["stick"] == serial["stick"]
    assert par["u_norm"] == pytest.approx(serial["u_norm"], rel=1e-10)
    assert par["error"] is not None and "body 'block'" in par["error"]
    assert serial["error"] is not None


if __name__ == "__main__":
    record = _mpi_record()
    if MPI.COMM_WORLD.rank == 0:
        Path(sys.argv[1], "pushed.json").write_text(json.dumps(record))


def test_tall_block_tips_before_it_slides():
    """μh > b/2: the block tips at Q = N b / (2h) (moment balance about the leading edge),
    before μN. Close below it the resultant of the contact forces is at the edge of the
    contact zone (TippingWarning); past it the error names the body and says it tips."""
    comm = MPI.COMM_WORLD
    msh, cells, facets, geo = block_on_base.build(comm, block=(0.1, 0.3), h=0.005, h_far=0.02)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=facets)
    steel = forms.Material(E_Pa=200e9, nu=0.3)
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")
    traction = dolfinx.fem.Constant(msh, np.zeros(2))
    L = ufl.inner(traction, v) * ds(tags.LOADED)
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    problem = fc.ContactProblem(
        a, L, fixed, fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.8),
        bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}), floating=True)
    b, h = geo["block_width"], geo["block_height"]
    Q_tip = N * b / (2 * h)
    assert Q_tip < 0.8 * N
    traction.value = np.array([0.5 * Q_tip / b, -N / b])
    with warnings.catch_warnings():
        warnings.simplefilter("error", fc.TippingWarning)
        problem.step()                       # half way: no warning
    traction.value = np.array([0.999 * Q_tip / b, -N / b])
    with pytest.warns(fc.TippingWarning, match=r"body 'block' is about to tip"):
        problem.step()
    traction.value = np.array([1.02 * Q_tip / b, -N / b])
    with pytest.raises(fc.NoEquilibriumError, match=r"body 'block'.*rotation about z.*tips"):
        problem.step()
    assert len(problem.increments) == 2


def test_demo_against_the_formulas(tmp_path):
    """demos/pushed_block.py at its defaults (N = 1e5 N/m, μ = 0.3): totals against N and Q,
    partial slip below μN, the refusal bracketing μN within 1 %, naming the block."""
    s, _ = run_demo("pushed_block", "--no-plot", results=tmp_path)
    mu_n = 0.3 * 1e5
    q = np.array(s["Q_over_muN"]) * mu_n
    np.testing.assert_allclose(s["normal_total"], 1e5, rtol=1e-9)
    np.testing.assert_allclose(s["tangential_total"], q, rtol=0, atol=1e-9 * 1e5)
    assert 0.6 in s["partial_slip_at_Q_over_muN"]
    fail = s["no_equilibrium"]
    assert "body 'block'" in fail["message"] and "no static equilibrium" in fail["message"]
    assert q[-1] < mu_n < fail["Q"] and (fail["Q"] - q[-1]) <= 0.01 * mu_n
