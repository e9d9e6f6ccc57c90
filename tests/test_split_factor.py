"""The sparse split factor of a small body (flexcontact.split_factor; its agreement with
MUMPS's Schur factor is in test_dense_factor.py): a factor rebuilt from its saved arrays
solves bitwise alike; misuse is refused by name; only small serial bodies take it."""
import numpy as np
import pytest
from mpi4py import MPI

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
