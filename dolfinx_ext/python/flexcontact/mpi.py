"""MPI patterns the package uses in several places, written once."""
from __future__ import annotations

import time
from typing import Optional, Union

from .errors import InputError


def raise_on_every_rank(comm, error: Optional[Union[str, BaseException]],
                        kind: Optional[type] = None) -> None:
    """Raise on every rank what rank 0 found wrong; do nothing if it found nothing.

    Checks made on rank 0 alone (where the gathered data lives) must fail on all ranks, or
    the others would wait forever in their next collective call.

    Args:
        comm: the communicator (mpi4py).
        error: rank 0's finding: None (all is well), a message, or an exception to re-raise.
            Other ranks' values are ignored.
        kind: the exception type raised for a message (default InputError, a ValueError).
    """
    if comm.size > 1:
        error = _bcast_error(comm, error)
    if error is None or error == "":
        return
    if isinstance(error, BaseException):
        raise error
    raise (kind or InputError)(error)


def _bcast_error(comm, error):
    """Rank 0's finding on every rank. An exception crosses as its class, arguments and
    attributes, and is rebuilt from them as pickle's default does. It is not pickled whole:
    a library that changes how every exception pickles (tblib, which dask's distributed
    installs) would otherwise turn some of ours (a MemoryError subclass on Python 3.14)
    into an unpickling TypeError on the other ranks, hiding the message."""
    packed = error
    if comm.rank == 0 and isinstance(error, BaseException):
        packed = (type(error), error.args, dict(vars(error)))
    packed = comm.bcast(packed, root=0)
    if comm.rank == 0:
        return error
    if isinstance(packed, tuple):
        cls, args, state = packed
        rebuilt = cls(*args)
        rebuilt.__dict__.update(state)
        return rebuilt
    return packed


def wait_for_root(comm, poll_s: float = 2e-4) -> None:
    """Hold the other ranks here until rank 0 arrives, asleep rather than spinning.

    While rank 0 works alone (the kernel's contact solve of an increment), a blocking MPI
    call keeps each waiting rank polling at full speed on a core; on a machine with fewer
    free cores than busy processes that core is taken from rank 0. A non-blocking barrier
    tested every ``poll_s`` seconds lets them sleep instead (rank 0 waits for nothing: the
    others arrived first). Collective.
    """
    if comm.size == 1:
        return
    request = comm.Ibarrier()
    if comm.rank == 0:
        request.Wait()
        return
    while not request.Test():
        time.sleep(poll_s)
