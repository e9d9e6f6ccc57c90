"""Rank 0's ContactMemoryError raised on rank 1 too, with its message and numbers, while
every ContactMemoryError's pickling is broken (as a library that re-registers how exceptions
pickle can break it). Run with mpirun -n 2: rank 1 writes what it caught to the JSON file
named by the first argument."""
import copyreg
import json
import sys

from mpi4py import MPI

from flexcontact.memory import ContactMemoryError
from flexcontact.mpi import raise_on_every_rank


def _refuse():
    raise TypeError("this exception cannot be unpickled")


copyreg.pickle(ContactMemoryError, lambda error: (_refuse, ()))

comm = MPI.COMM_WORLD
found = (ContactMemoryError("F* needs 466560 bytes", needed_bytes=466560.0,
                            available_bytes=1e4, n_contact_dofs=108, pairs=27)
         if comm.rank == 0 else None)
try:
    raise_on_every_rank(comm, found)
except ContactMemoryError as caught:
    if comm.rank == 0:
        assert caught is found
    else:
        with open(sys.argv[1], "w") as f:
            json.dump({"message": str(caught), "needed_bytes": caught.needed_bytes,
                       "available_bytes": caught.available_bytes,
                       "n_contact_dofs": caught.n_contact_dofs, "pairs": caught.pairs}, f)
else:
    raise SystemExit(f"rank {comm.rank}: nothing was raised")
