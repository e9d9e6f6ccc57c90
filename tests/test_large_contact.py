"""Large contact sets: the memory check of the dense path and the path that never forms W
(``contact_operator="factor"``, factor_path.py, kernel's operator_contact.hpp).

The factor path solves the same local problem as the dense one with only W·x; each answer
is certified by the natural-map residual to the solver tolerance (1e-10), so both must
agree to that tolerance times W's conditioning in λ. The references are the dense path's
λ and u on the same mesh and load.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.states import OPEN
from flexcontact.memory import ENV_AVAILABLE, ENV_WORKING_SET, dense_bytes
from flexcontact.meshes import hertz2d, hertz3d, tags

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conftest import on_two_ranks  # noqa: E402

R_M, A_M = 0.05, 0.005
STEEL = forms.Material(E_Pa=200e9, nu=0.3)
# Agreement of two answers each certified to 1e-10 in the natural-map residual: W's
# conditioning on these meshes (≈ 1e3) makes it 1e-7 relative in λ and u.
AGREE = 1e-6


def hertz(dim: int, mu: float, operator: str, build: dict, comm=MPI.COMM_WORLD):
    builder = hertz2d if dim == 2 else hertz3d
    msh, cells, facets, _ = builder.build(comm, R=R_M, a_expected=A_M, **build)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: STEEL, tags.UPPER: STEEL}, dx,
                              "plane_strain" if dim == 2 else "3d")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, consts = fc.dirichlet(V, facets, tags.LOADED)
    bcs = fixed + top
    if dim == 3:
        bcs += fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])[0]
        bcs += fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])[0]
    problem = fc.ContactProblem(a, None, bcs, fc.ContactInterface(facets, tags.SLAVE,
                                                                   tags.MASTER, mu),
                                contact_operator=operator)
    return problem, consts[dim - 1], msh


def run(dim, mu, operator, build, increments=2, comm=MPI.COMM_WORLD):
    """λ (rank 0), the global displacement norm and the summaries of `increments` steps
    pushing down to a²/R and then sideways (friction path)."""
    problem, top, msh = hertz(dim, mu, operator, build, comm)
    out = []
    for i in range(1, increments + 1):
        top.value = -A_M**2 / R_M * i / increments
        inc = problem.step()
        out.append(inc)
    u = compat.petsc_vec(problem.u)
    return problem, out, u.norm()


@pytest.mark.parametrize("mu, working_set", [(0.0, None), (0.3, None), (0.3, "0")])
def test_factor_path_matches_dense_on_2d_hertz(mu, working_set, monkeypatch):
    # working_set "0": no columns of W held, the matrix-free iteration alone.
    if working_set is not None:
        monkeypatch.setenv(ENV_WORKING_SET, working_set)
    build = {"refine": 0, "zone_factor": 1.25}
    dense, d_inc, d_norm = run(2, mu, "dense", build)
    fact, f_inc, f_norm = run(2, mu, "factor", build)
    solver = "operator" if working_set == "0" else "working_set"
    assert fact.W is None and fact.flex_info["method"] == "factor"
    assert abs(f_norm - d_norm) <= AGREE * d_norm
    if MPI.COMM_WORLD.rank == 0:
        for a, b in zip(d_inc, f_inc):
            scale = np.abs(a.lam).max()
            assert scale > 0
            assert np.abs(a.lam - b.lam).max() <= AGREE * scale
            assert np.abs(a.gap - b.gap).max() <= AGREE * np.abs(a.gap).max()
            assert np.array_equal(a.states > OPEN, b.states > OPEN)
            assert b.summary.solver == solver and b.summary.residual < 1e-10
            assert b.summary.iterations > 0
    if working_set is None:
        # Each pair's columns computed once over both increments (kept between them), every
        # pair that closed among them, and no single back-substitution in the local solve.
        assert fact.contact.block_columns == 2 * fact.contact.cached_pairs <= 2 * fact.m
        if MPI.COMM_WORLD.rank == 0:
            closed = {k for inc in f_inc for k in np.flatnonzero(inc.states > OPEN)}
            assert 0 < len(closed) <= fact.contact.cached_pairs
        assert fact.contact.applications == 0


def test_factor_columns_of_W_are_the_dense_ones():
    # W[:, pairs] through blocks of back-substitutions against the dense path's W.
    if MPI.COMM_WORLD.size > 1:
        pytest.skip("the dense W is on rank 0 only")
    build = {"refine": 0, "zone_factor": 1.25}
    dense, _, _ = hertz(2, 0.3, "dense", build)
    fact, _, _ = hertz(2, 0.3, "factor", build)
    some = [0, fact.m // 2, fact.m - 1]
    cols = fact.contact.W_columns(some)
    W = np.asarray(dense.W)
    ref = np.hstack([W[:, 2 * k:2 * k + 2] for k in some])
    assert cols.shape == ref.shape
    assert np.abs(cols - ref).max() <= 1e-9 * np.abs(W).max()
    assert fact.contact.block_columns == 2 * len(some)


def test_factor_path_matches_dense_in_3d():
    build = {"refine": 0, "zone_factor": 1.0, "h_far": 0.04}
    dense, d_inc, d_norm = run(3, 0.3, "dense", build, increments=1)
    fact, f_inc, f_norm = run(3, 0.3, "factor", build, increments=1)
    assert abs(f_norm - d_norm) <= AGREE * d_norm
    if MPI.COMM_WORLD.rank == 0:
        a, b = d_inc[0], f_inc[0]
        assert np.abs(a.lam - b.lam).max() <= AGREE * np.abs(a.lam).max()
        assert b.summary.residual < 1e-10


def test_dense_memory_error_names_the_option_and_the_numbers(monkeypatch):
    # 10 kB "available": the dense path of the smallest Hertz mesh needs more.
    monkeypatch.setenv(ENV_AVAILABLE, "0.00001")
    with pytest.raises(fc.ContactMemoryError) as err:
        hertz(2, 0.3, "dense", {"refine": 0, "zone_factor": 1.25})
    e = err.value
    assert isinstance(e, MemoryError)
    text = str(e)
    assert "contact_operator=\"factor\"" in text
    assert e.available_bytes == pytest.approx(1e4)
    assert e.needed_bytes == pytest.approx(dense_bytes(e.n_contact_dofs, e.pairs, 2))
    assert e.needed_bytes > 1e4 and e.n_contact_dofs > 0 and e.pairs > 0
    for number in (f"{e.needed_bytes / 1e9:.2f} GB", "0.00 GB", f"n_c = {e.n_contact_dofs}",
                   f"m = {e.pairs}"):
        assert number in text
    # The factor path needs none of it: the same case runs.
    problem, top, _ = hertz(2, 0.3, "factor", {"refine": 0, "zone_factor": 1.25})
    top.value = -A_M**2 / R_M
    assert problem.step().summary.normal_force > 0


def test_bad_contact_operator_is_named():
    with pytest.raises(ValueError, match="contact_operator='sparse'"):
        hertz(2, 0.3, "sparse", {"refine": 0, "zone_factor": 1.25})


def _summary(build):
    """The frictional 2D case's displacement norm and last summary, for the MPI test."""
    _, inc, norm = run(2, 0.3, "factor", build)
    s = inc[-1].summary
    return {"norm": norm, "normal_force": s.normal_force, "iterations": s.iterations}


def test_factor_path_two_ranks_give_the_serial_answer(tmp_path):
    # Every rank runs the same iteration on replicated contact vectors, each product a
    # collective solve: the answer is the serial one to rounding (MUMPS's parallel solve).
    build = {"refine": 0, "zone_factor": 1.25}
    serial = _summary(build)
    on_two_ranks(__file__, tmp_path, timeout=600)
    parallel = json.loads((tmp_path / "parallel.json").read_text())
    assert parallel["norm"] == pytest.approx(serial["norm"], rel=1e-10)
    assert parallel["normal_force"] == pytest.approx(serial["normal_force"], rel=1e-10)
    assert abs(parallel["iterations"] - serial["iterations"]) <= 2


if __name__ == "__main__":
    out = _summary({"refine": 0, "zone_factor": 1.25})
    if MPI.COMM_WORLD.rank == 0:
        Path(sys.argv[1], "parallel.json").write_text(json.dumps(out))
