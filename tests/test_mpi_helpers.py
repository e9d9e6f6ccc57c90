"""flexcontact.mpi: rank 0's finding raised on every rank (serial here; the bad-input and
pairing tests exercise it under mpirun)."""
import pytest
from mpi4py import MPI

from flexcontact.mpi import raise_on_every_rank


def test_nothing_found_raises_nothing():
    assert raise_on_every_rank(MPI.COMM_WORLD, None) is None
    assert raise_on_every_rank(MPI.COMM_WORLD, "") is None


def test_a_message_becomes_the_given_exception_type():
    with pytest.raises(ValueError, match="tag 7 is missing"):
        raise_on_every_rank(MPI.COMM_WORLD, "tag 7 is missing")
    with pytest.raises(RuntimeError, match="no pivots"):
        raise_on_every_rank(MPI.COMM_WORLD, "no pivots", RuntimeError)


def test_an_exception_is_raised_as_it_is():
    with pytest.raises(KeyError):
        raise_on_every_rank(MPI.COMM_WORLD, KeyError("gmsh group"))
