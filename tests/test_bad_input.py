"""Bad input gets an exception that names the problem, and nothing half-written."""
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import block_on_base, tags

STEEL = forms.Material(E_Pa=200e9, nu=0.3, name="steel")


@pytest.fixture(scope="module")
def setup():
    msh, cells, facets, geo = block_on_base.build(MPI.COMM_WORLD)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: STEEL, tags.UPPER: STEEL}, dx, "plane_strain")
    return msh, cells, facets, V, a, geo


def _problem(setup, slave=tags.SLAVE, master=tags.MASTER, mu=0.3, bcs=None, **kw):
    msh, cells, facets, V, a, geo = setup
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, consts = fc.dirichlet(V, facets, tags.LOADED)
    bcs = fixed + top if bcs is None else bcs
    p = fc.ContactProblem(a, None, bcs, fc.ContactInterface(facets, slave, master, mu),
                          bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}), **kw)
    return p, consts


def test_tag_value_absent(setup):
    with pytest.raises(ValueError, match="99"):
        _problem(setup, slave=99)


def test_surfaces_with_different_node_counts(setup):
    # The base's bottom has other nodes than the block's bottom, and faces away from it:
    # the default pairing, surface–surface on non-matching surfaces, finds no slave node
    # that a facing master facet covers.
    with pytest.raises(ValueError, match=r"slave tag \d+ / master tag \d+.*none of the \d+ "
                                         r"slave nodes.*do not face each other"):
        _problem(setup, master=tags.FIXED)


@pytest.mark.parametrize("mu", [-0.1, math.nan, math.inf])
def test_bad_friction_coefficient(setup, mu):
    with pytest.raises(ValueError, match="friction coefficient"):
        fc.ContactInterface(setup[2], tags.SLAVE, tags.MASTER, mu)


def test_body_with_rigid_modes_is_named(setup):
    msh, cells, facets, V, a, geo = setup
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    # The block's top held only vertically: it can still slide along x.
    top_y, _ = fc.dirichlet(V, facets, tags.LOADED, components=[1])
    with pytest.raises(ValueError, match=r"body 'block'.*translation along x"):
        _problem(setup, bcs=fixed + top_y)
    with pytest.raises(ValueError, match=r"body 'block'"):
        _problem(setup, bcs=fixed)


def test_non_finite_load_keeps_finished_increments(setup, tmp_path):
    msh = setup[0]
    problem, (ux, uy) = _problem(setup)
    values = [-1e-6, -2e-6, math.nan]

    def load(i, t):
        uy.value = values[i - 1]

    with pytest.raises(ValueError, match="not finite"):
        with fc.ResultWriter(tmp_path, "out", msh) as w:
            problem.solve(3, load=load, writer=w, verbose=False)
    assert len(problem.increments) == 2
    # The XDMF written so far is complete and holds the two finished increments.
    grid = ET.parse(tmp_path / "out.xdmf").getroot()
    times = [float(t.get("Value")) for t in grid.iter("Time")]
    assert times == [1.0, 2.0]


def test_not_converging_is_reported(setup):
    opts = fc.SolverOptions()
    opts.chain = ["projection"]
    opts.max_iterations = 1
    opts.tolerance = 1e-14
    problem, (ux, uy) = _problem(setup, solver=opts)
    uy.value = -1e-6
    with pytest.raises(fc.ConvergenceError, match=r"(?s)projection.*residual"):
        problem.step()
    assert problem.increments == []


def test_failing_problem_is_saved_and_reruns_bitwise(setup, tmp_path, monkeypatch):
    """The error names a file holding the local problem; loading and re-running it gives the
    same failure, bitwise (docs/solvers.md, "A failing problem as a file")."""
    monkeypatch.setenv("FLEXCONTACT_PROBLEM_DIR", str(tmp_path))
    opts = fc.SolverOptions(chain=["projection"], max_iterations=1, tolerance=1e-14)
    problem, (ux, uy) = _problem(setup, solver=opts)
    uy.value = -1e-6
    with pytest.raises(fc.ConvergenceError) as info:
        problem.step()
    err = info.value
    path = err.problem_path
    assert path is not None and path.startswith(str(tmp_path)), path
    assert path in str(err) and "load_problem" in str(err)
    saved = fc.load_problem(path)
    assert saved.dim == 2 and saved.pairs >= 1
    assert saved.W.shape == (2 * saved.pairs, 2 * saved.pairs)
    assert list(saved.options.chain) == ["projection"]
    assert saved.options.max_iterations == 1 and saved.options.tolerance == 1e-14
    again = saved.solve()
    assert not again.converged
    assert again.residual == err.report["residual"]
    assert list(again.attempts) == list(err.report["attempts"])
    # The same failure again is the same file, not a second one.
    with pytest.raises(fc.ConvergenceError) as info2:
        problem.step()
    assert info2.value.problem_path == path
    assert len(list(tmp_path.iterdir())) == 1


def test_spent_work_budget_is_reported(setup):
    """A chain whose work budget is spent stops trying and says so in the error."""
    opts = fc.SolverOptions(work_budget_gflop=1e-9)
    problem, (ux, uy) = _problem(setup, solver=opts)
    uy.value = -1e-6
    with pytest.raises(fc.ConvergenceError, match=r"work budget of 1e-09 Gflop spent"):
        problem.step()
    assert problem.increments == []


@pytest.mark.parametrize("budget", [-1.0, math.inf, math.nan])
def test_bad_work_budget_is_named(budget):
    with pytest.raises(ValueError, match=r"work_budget_gflop = -?(1\.0+|inf|nan); it must be 0"):
        fc.SolverOptions(work_budget_gflop=budget)


def test_bad_increment_count(setup):
    problem, _ = _problem(setup)
    with pytest.raises(ValueError, match="increments"):
        problem.solve(0)


def test_held_pairs_pushed_together_are_named(setup):
    """Both contact surfaces held by Dirichlet conditions and moved into each other: no
    contact force can help, so the error says which pair and by how much."""
    msh, cells, facets, V, a, geo = setup
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    master, _ = fc.dirichlet(V, facets, tags.MASTER)
    slave, (sx, sy) = fc.dirichlet(V, facets, tags.SLAVE)
    problem, _ = _problem(setup, bcs=fixed + master + slave)
    sy.value = -1e-6
    with pytest.raises(fc.ConvergenceError, match=r"increment 1: .*held by Dirichlet.*penetrates by 1.000e-06 m"):
        problem.step()
    assert problem.increments == []


def test_free_body_names_each_mode_once(setup):
    msh, cells, facets, V, a, geo = setup
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    with pytest.raises(ValueError) as free:
        _problem(setup, bcs=fixed)               # nothing holds the block
    msg = str(free.value)
    for mode in ("translation along x", "translation along y", "rotation about z"):
        assert msg.count(mode) == 1, msg
    # The top held along x only: the block can move up and down and turn about a point of
    # its top line (a rotation plus a translation along x): both are named, x is not.
    top_x, _ = fc.dirichlet(V, facets, tags.LOADED, components=[0])
    with pytest.raises(ValueError) as turning:
        _problem(setup, bcs=fixed + top_x)
    msg = str(turning.value)
    assert "translation along y" in msg and "rotation about z" in msg, msg
    assert "translation along x" not in msg, msg


def test_missing_material_is_not_a_missing_support(setup):
    msh, cells, facets, V, a, geo = setup
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    base_only = forms.elasticity_form(u, v, {tags.BASE: STEEL}, dx, "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, _ = fc.dirichlet(V, facets, tags.LOADED)
    with pytest.raises(ValueError, match=r"body 'block'.*no material") as e:
        fc.ContactProblem(base_only, None, fixed + top,
                          fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.3),
                          bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}))
    assert "Dirichlet" not in str(e.value).split("body 'block'")[1]


@pytest.mark.parametrize("mu", [np.float32(0.3), np.array(0.3)])
def test_numpy_friction_coefficient_accepted(setup, mu):
    itf = fc.ContactInterface(setup[2], tags.SLAVE, tags.MASTER, mu)
    assert isinstance(itf.mu, float) and itf.mu == pytest.approx(0.3, rel=1e-7)
