"""flexcontact.mpi: rank 0's finding raised on every rank (serial here; the bad-input and
pairing tests exercise it under mpirun)."""
import copyreg
import json
from pathlib import Path

import pytest
from mpi4py import MPI

from flexcontact.memory import ContactMemoryError
from flexcontact.mpi import raise_on_every_rank

from conftest import on_two_ranks


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


def _refuse():
    raise TypeError("this exception cannot be unpickled")


def test_an_exception_is_not_pickled_in_serial(monkeypatch):
    # A library may re-register how exceptions pickle (tblib, which dask's distributed
    # installs, breaks MemoryError subclasses on Python 3.14): in serial the error is
    # raised as it is, never sent through pickle.
    monkeypatch.setitem(copyreg.dispatch_table, ContactMemoryError,
                        lambda error: (_refuse, ()))
    found = ContactMemoryError("F* needs 466560 bytes", needed_bytes=466560.0)
    with pytest.raises(ContactMemoryError) as caught:
        raise_on_every_rank(MPI.COMM_WORLD, found)
    assert caught.value is found


@pytest.mark.mpi
def test_an_exception_reaches_the_other_rank_with_its_numbers(tmp_path):
    on_two_ranks(Path(__file__).with_name("rank_error_case.py"), tmp_path / "rank1.json")
    seen = json.loads((tmp_path / "rank1.json").read_text())
    assert seen == {"message": "F* needs 466560 bytes", "needed_bytes": 466560.0,
                    "available_bytes": 1e4, "n_contact_dofs": 108, "pairs": 27}
