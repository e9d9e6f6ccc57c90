"""MPI patterns the package uses in several places, written once."""
from __future__ import annotations

from typing import Optional, Union


def raise_on_every_rank(comm, error: Optional[Union[str, BaseException]],
                        kind: type = ValueError) -> None:
    """Raise on every rank what rank 0 found wrong; do nothing if it found nothing.

    Checks made on rank 0 alone (where the gathered data lives) must fail on all ranks, or
    the others would wait forever in their next collective call.

    Args:
        comm: the communicator (mpi4py).
        error: rank 0's finding: None (all is well), a message, or an exception to re-raise.
            Other ranks' values are ignored.
        kind: the exception type raised for a message.
    """
    error = comm.bcast(error, root=0)
    if error is None or error == "":
        return
    if isinstance(error, BaseException):
        raise error
    raise kind(error)
