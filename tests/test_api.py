"""The public API: every name of ``__all__`` imports, errors are catchable from the package,
and a misspelt method or solver name fails at once, naming itself and the allowed names."""
from typing import get_args

import pytest
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import _cpp, compat, forms
from flexcontact.meshes import block_on_base, tags


def test_every_public_name_imports():
    namespace = {}
    exec("from flexcontact import *", namespace)
    missing = [n for n in fc.__all__ if n not in namespace]
    assert not missing


@pytest.mark.parametrize("name", ["SingularStiffnessError", "MumpsError", "PetscError",
                                  "ConvergenceError"])
def test_errors_are_the_compiled_ones(name):
    error = getattr(fc, name)
    assert error is getattr(_cpp, name)
    assert issubclass(error, RuntimeError)


def test_names_match_the_kernel():
    assert fc.FLEXIBILITY_METHODS == get_args(fc.FlexibilityMethod)
    assert fc.SOLVER_NAMES == get_args(fc.SolverName)
    assert set(fc.SOLVER_NAMES) == set(_cpp.solver_names())
    assert set(_cpp.default_chain()) <= set(fc.SOLVER_NAMES)


@pytest.fixture(scope="module")
def parts():
    msh, cells, facets, geo = block_on_base.build(MPI.COMM_WORLD)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, _ = fc.dirichlet(V, facets, tags.LOADED)
    return a, None, fixed + top, fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.3)


def test_bad_flexibility_method_is_named(parts):
    with pytest.raises(ValueError, match=r"'shur'.*schur, inverse_entries, matmatsolve"):
        fc.ContactProblem(*parts, flexibility="shur")


def test_bad_solver_name_is_named(parts):
    options = fc.SolverOptions(chain=["newton_ac", "gauss_seidel"])
    with pytest.raises(ValueError, match=r"'gauss_seidel'.*newton_ac, active_set, projection"):
        fc.ContactProblem(*parts, solver=options)
