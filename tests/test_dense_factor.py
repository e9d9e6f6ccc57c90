"""The small-body factors — dense blocks (flexcontact.dense_factor) and the sparse split
Cholesky factor (flexcontact.split_factor) — against MUMPS's Schur factor of the same
matrix (_cpp.flexibility "schur"): the flexibility, the condensation, the expansion and the
full solve agree to 1e-10 (two direct factorizations of one SPD matrix; measured about
1e-14)."""
import numpy as np
import pytest
from mpi4py import MPI

from flexcontact import _cpp
from flexcontact.dam.log_model import LogModel
from flexcontact.dense_factor import DenseFactor
from flexcontact.split_factor import SplitFactor


@pytest.fixture(scope="module")
def log():
    return LogModel(6.0, 0.5, 680.0, 10e9, 0.3, 1e-4, h_m=0.25, comm=MPI.COMM_SELF)


@pytest.mark.parametrize("Factor", [DenseFactor, SplitFactor])
def test_small_body_factors_solve_as_the_mumps_schur_factor(log, Factor):
    A, dofs = log.W_hat, log.front_dofs
    F, schur, _ = _cpp.flexibility(A, dofs, "schur")
    small = Factor(A, dofs)
    F = np.asarray(F)
    assert np.abs(small.W - F).max() <= 1e-10 * np.abs(F).max()
    rng = np.random.default_rng(3)
    b = log.new_vector()
    b.array[:] = rng.standard_normal(b.getLocalSize())
    got, ref = small.condense(b), np.asarray(schur.condense(b))
    assert np.abs(got - ref).max() <= 1e-10 * np.abs(ref).max()
    u_c = rng.standard_normal(dofs.size)
    x, y = log.new_vector(), log.new_vector()
    small.expand(u_c, x)
    schur.expand(u_c, y)
    assert np.abs(x.array_r - y.array_r).max() <= 1e-10 * np.abs(y.array_r).max()
    small.solve(b, x)
    r = log.new_vector()
    A.mult(x, r)  # the residual of A x = b
    assert np.abs(r.array_r - b.array_r).max() <= 1e-10 * np.abs(b.array_r).max()


def test_the_log_holds_a_small_body_as_a_split_factor(log):
    assert log.factor_kind == "split" and log.factorizations == 1


def test_expand_needs_a_condense(log):
    dense = DenseFactor(log.W_hat, log.front_dofs)
    with pytest.raises(RuntimeError, match="without a condense"):
        dense.expand(np.zeros(log.front_dofs.size), log.new_vector())
