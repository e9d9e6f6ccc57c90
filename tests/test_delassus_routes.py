"""W = B F* Bᵀ per body by the cheaper route (docs/architecture.md §7).

A block pressed onto a base whose candidate patch is 2.9× the block's width: the base has
n ≈ 2·(0.29/h + 1) contact DOFs, of which the pairs' r ≈ 2·(0.1/h + 1) rows touch a third, so
the flop model (triangular n²r + nr² against the inverse's ⅔n³) takes the triangular route on
the base and the inverse on the block (r = n). References:

* the same factors by the inverse route (F* dense, W = B F* Bᵀ): W, λ and the contact
  values of the solution agree to 1e-12 of their largest entry (round-off of two orders of
  summation);
* the problem on two MPI ranks: the same forces and displacements to 1e-10.
"""
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import ufl
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conftest import on_two_ranks  # noqa: E402

import flexcontact as fc  # noqa: E402
from flexcontact import _cpp, compat, forms  # noqa: E402
from flexcontact.condensation import kernel_pairs  # noqa: E402
from flexcontact.meshes import block_on_base, tags  # noqa: E402

H = 0.005
PATCH = (-0.145, 0.145)   # the base's candidate patch [m]; the block is 0.1 m wide
DOWN, SIDE = 4e-6, 1e-6   # the block top's prescribed displacement [m]


def _problem(comm=MPI.COMM_WORLD):
    msh, cells, facets, _ = block_on_base.build(comm, h=H, h_far=0.01, patch=PATCH)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: forms.Material(E_Pa=200e9, nu=0.3),
                                     tags.UPPER: forms.Material(E_Pa=70e9, nu=0.33)},
                              dx, "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, (top_x, top_y) = fc.dirichlet(V, facets, tags.LOADED)
    problem = fc.ContactProblem(a, None, fixed + top,
                                fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.3,
                                                    name="block/base"))

    def load(i, t):
        top_y.value = -DOWN * min(i, 2) / 2
        top_x.value = SIDE * max(i - 2, 0) / 2

    summaries = problem.solve(4, load=load, verbose=False)
    return problem, summaries


@pytest.fixture(scope="module")
def pressed():
    return _problem()


def test_the_flop_model_takes_the_triangular_route_on_the_wide_patch(pressed):
    problem, _ = pressed
    if problem.comm.rank:
        return
    info = problem.flex_info
    assert info["form"] == "factors"
    sizes, routes = info["block_sizes"], info["delassus_routes"]
    assert sorted(routes) == ["inverse", "triangular"], routes
    # The wide patch is the larger block, and the one W is formed from triangularly.
    assert routes[int(np.argmax(sizes))] == "triangular"
    assert info["delassus_flops"] < info["delassus_flops_by_inverse"]


def test_both_routes_give_the_same_contact_problem(pressed):
    problem, _ = pressed
    if problem.comm.rank:
        return
    cond = problem.stepper.condensation
    F, _, _ = _cpp.flexibility(problem.K, cond.dofs, "schur", factors=True)
    constrained = cond._constrained_mask(problem.K, problem.bcs)
    args = (cond.pairs.x, kernel_pairs(cond.pairs), np.full(cond.pairs.m, 0.3), constrained)
    by_factors = _cpp.CondensedContact(2, F, *args)
    by_inverse = _cpp.CondensedContact(2, F.dense(), *args)
    assert "triangular" in by_factors.delassus_routes
    assert by_inverse.delassus_routes == ["dense"]
    W1, W0 = by_factors.W, by_inverse.W
    assert np.max(np.abs(W1 - W0)) <= 1e-12 * np.max(np.abs(W0))
    # One increment moving the slave nodes (the first m contact nodes) down and sideways:
    # λ with stick and slip, and u_c from F* v by triangular solves on the base.
    m = cond.pairs.m
    up_c = np.zeros(cond.dofs.size)
    up_c[1:2 * m:2] = -DOWN
    up_c[0:2 * m:2] = SIDE * np.linspace(0.0, 1.0, m)
    s1, s0 = by_factors.step(up_c), by_inverse.step(up_c)
    assert np.max(np.abs(s0["lambda"])) > 0
    for key in ("lambda", "solution_c", "reaction"):
        scale = np.max(np.abs(s0[key]))
        assert np.max(np.abs(s1[key] - s0[key])) <= 1e-12 * scale, key
    assert np.array_equal(s1["states"], s0["states"])


@pytest.mark.mpi
def test_two_ranks_give_the_serial_answer(pressed, tmp_path):
    problem, summaries = pressed
    on_two_ranks(__file__, tmp_path / "two.json", timeout=300)
    two = json.loads((tmp_path / "two.json").read_text())
    assert two["routes"] == problem.flex_info["delassus_routes"]
    for s, t in zip(summaries, two["summaries"]):
        assert t["normal_force"] == pytest.approx(s.normal_force, rel=1e-10)
        assert t["tangential_force"] == pytest.approx(s.tangential_force[0],
                                                      abs=1e-10 * s.normal_force)


if __name__ == "__main__":
    p, ss = _problem()
    if p.comm.rank == 0:
        Path(sys.argv[1]).write_text(json.dumps({
            "routes": p.flex_info["delassus_routes"],
            "summaries": [{"normal_force": s.normal_force,
                           "tangential_force": s.tangential_force[0]} for s in ss]}))
