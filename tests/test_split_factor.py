"""The sparse split factor of a small body (flexcontact.split_factor) against MUMPS's Schur
factor of the same matrix (_cpp.flexibility "schur"), on a log's iteration matrix: the
flexibility, the condensation, the expansion and the full solve agree to 1e-10 (two direct
factorizations of one SPD matrix; measured about 1e-15). A factor rebuilt from its saved
arrays solves bitwise alike; misuse and a parallel matrix are refused by name."""
import numpy as np
import pytest
from mpi4py import MPI

from flexcontact import _cpp
from flexcontact.dam.log_model import LogModel
from flexcontact.errors import FlexcontactError
from flexcontact.split_factor import SPLIT_LIMIT, SplitFactor


@pytest.fixture(scope="module")
def log():
    return LogModel(6.0, 0.5, 680.0, 10e9, 0.3, 1e-4, h_m=0.25, comm=MPI.COMM_SELF)


def _random(log, seed):
    b = log.new_vector()
    b.array[:] = np.random.default_rng(seed).standard_normal(b.getLocalSize())
    return b


def test_split_factor_solves_as_the_mumps_schur_factor(log):
    A, dofs = log.W_hat, log.front_dofs
    F, schur, _ = _cpp.flexibility(A, dofs, "schur")
    split = SplitFactor(A, dofs)
    F = np.asarray(F)
    assert np.abs(split.W - F).max() <= 1e-10 * np.abs(F).max()
    b = _random(log, 3)
    got, ref = split.condense(b), np.asarray(schur.condense(b))
    assert np.abs(got - ref).max() <= 1e-10 * np.abs(ref).max()
    u_c = np.random.default_rng(4).standard_normal(dofs.size)
    x, y = log.new_vector(), log.new_vector()
    split.expand(u_c, x)
    schur.expand(u_c, y)
    assert np.abs(x.array_r - y.array_r).max() <= 1e-10 * np.abs(y.array_r).max()
    split.solve(b, x)
    r = log.new_vector()
    A.mult(x, r)  # the residual of A x = b
    assert np.abs(r.array_r - b.array_r).max() <= 1e-10 * np.abs(b.array_r).max()
    schur.destroy()


def test_rebuilt_from_its_arrays_it_solves_bitwise_alike(log):
    split = SplitFactor(log.W_hat, log.front_dofs)
    again = SplitFactor.from_arrays(split.arrays("dam_"), "dam_")
    b = _random(log, 5)
    x, y = log.new_vector(), log.new_vector()
    split.solve(b, x)
    again.solve(b, y)
    assert np.array_equal(x.array_r, y.array_r)
    assert np.array_equal(again.W, split.W) and again.n == split.n


def test_expand_needs_a_condense(log):
    split = SplitFactor(log.W_hat, log.front_dofs)
    with pytest.raises(FlexcontactError, match="expand without a condense"):
        split.expand(np.zeros(log.front_dofs.size), log.new_vector())
    split.condense(log.new_vector())
    with pytest.raises(ValueError, match="u_c has 1 entries"):
        split.expand(np.zeros(1), log.new_vector())


def test_only_small_serial_bodies_take_it():
    assert SplitFactor.worth_it(SPLIT_LIMIT) and not SplitFactor.worth_it(SPLIT_LIMIT + 1)
    assert not SplitFactor.worth_it(100, comm_size=2)
