"""Will the dense condensed problem fit in memory? Checked before anything large is allocated.

The dense path (``contact_operator="dense"``) holds, on rank 0, MUMPS's Schur complement on
the n_c contact DOFs and F* (n_c² each, with the copies made while they are handed over), and
W = B F* Bᵀ of the m pairs ((m·d)², with the solvers' dense Jacobian and its factor). The
``"factor"`` path forms none of them (operator_contact.hpp). bench/large_contact.py measured
the peak of the dense path's set-up and first increment and calibrated the factors below.
"""
from __future__ import annotations

import os
from typing import Optional
from .errors import FlexcontactError, InputError

ENV_AVAILABLE = "FLEXCONTACT_AVAILABLE_MEMORY_GB"

# 8-byte copies of each dense matrix alive at the peak: MUMPS's Schur complement, F* in the
# kernel, its NumPy copy and the conversion between them; W in the kernel, its NumPy copy,
# the Newton Jacobian and its LU factor. bench/large_contact.py measured the dense path's
# peak over the factor path's as 36·n_c² bytes in 2D and 49·n_c² in 3D (one small zone:
# 1.2 MB, within the noise) with m·d = n_c/2; these copies give 40·n_c² there.
FSTAR_COPIES = 4
W_COPIES = 4


class ContactMemoryError(FlexcontactError, MemoryError):
    """The dense condensed contact problem would not fit in the memory available.

    ``needed_bytes``, ``available_bytes``, ``n_contact_dofs`` and ``pairs`` hold the numbers
    of the message; the message names the option to use instead (``contact_operator="factor"``).
    """

    # Defaults: on the other ranks it is rebuilt from its message, then its attributes set
    # (flexcontact.mpi.raise_on_every_rank).
    def __init__(self, text: str, needed_bytes: float = 0.0, available_bytes: float = 0.0,
                 n_contact_dofs: int = 0, pairs: int = 0):
        super().__init__(text)
        self.needed_bytes = needed_bytes
        self.available_bytes = available_bytes
        self.n_contact_dofs = n_contact_dofs
        self.pairs = pairs


def dense_bytes(n_contact_dofs: int, pairs: int, dim: int) -> float:
    """Bytes of the dense path's matrices at its peak (F* and Schur: n_c², W: (m·d)²)."""
    return 8.0 * (FSTAR_COPIES * float(n_contact_dofs) ** 2 + W_COPIES * float(pairs * dim) ** 2)


def _env_gb(name: str, zero_allowed: bool) -> Optional[float]:
    """Bytes from the environment variable ``name`` given in GB, None when it is not set;
    a ValueError naming it and its value otherwise."""
    env = os.environ.get(name)
    if not env:
        return None
    try:
        value = float(env)
    except ValueError:
        raise InputError(f"{name}={env!r}; it must be a number of GB") from None
    if not (value >= 0 if zero_allowed else value > 0):
        raise InputError(f"{name}={env!r}; it must be "
                         + ("≥ 0 GB" if zero_allowed else "a positive number of GB"))
    return value * 1e9


def available_bytes() -> float:
    """The memory available now: ``MemAvailable`` of /proc/meminfo, or the environment
    variable FLEXCONTACT_AVAILABLE_MEMORY_GB (in GB) when set (tests, or to leave room for
    other processes). Infinite if neither can be read."""
    env = _env_gb(ENV_AVAILABLE, zero_allowed=False)
    if env is not None:
        return env
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return float("inf")


def check_dense_memory(n_contact_dofs: int, pairs: int, dim: int,
                       available: Optional[float] = None) -> None:
    """Raise ContactMemoryError if the dense path needs more than ``available`` bytes (default
    available_bytes()). Call on rank 0 with its numbers and raise on every rank
    (mpi.raise_on_every_rank)."""
    needed = dense_bytes(n_contact_dofs, pairs, dim)
    avail = available_bytes() if available is None else float(available)
    if needed <= avail:
        return
    text = (f"the dense condensed contact problem needs about {needed / 1e9:.2f} GB "
            f"(F* and the Schur complement on n_c = {n_contact_dofs} contact DOFs: "
            f"{FSTAR_COPIES} x 8·n_c² bytes; W of m = {pairs} pairs: {W_COPIES} x 8·(m·d)² "
            f"bytes, d = {dim}) but only {avail / 1e9:.2f} GB are available; use "
            "contact_operator=\"factor\" (ContactProblem or ImpactProblem), which works "
            "through the factor of K (or Ŵ) without forming F* or the whole W, or tag a "
            "smaller candidate contact zone")
    raise ContactMemoryError(text, needed, avail, n_contact_dofs, pairs)


def check_dense_memory_collective(comm, n_contact_dofs: Optional[int], pairs: Optional[int],
                                  dim: int) -> None:
    """check_dense_memory with rank 0's numbers and memory, raised on every rank."""
    from .mpi import raise_on_every_rank
    error = None
    if comm.rank == 0:
        try:
            check_dense_memory(n_contact_dofs, pairs, dim)
        except ContactMemoryError as e:
            error = e
    raise_on_every_rank(comm, error)


ENV_WORKING_SET = "FLEXCONTACT_WORKING_SET_GB"
# Of the memory available, what the factor path may hold of W's columns for the pairs in
# contact (operator_contact.hpp: solve_working_set); the rest is left to the factor's solves.
WORKING_SET_SHARE = 0.25


def working_set_bytes() -> float:
    """Memory for the factor path's columns of W (bytes): FLEXCONTACT_WORKING_SET_GB when
    set (0 turns the working set off: the matrix-free iteration only), otherwise a quarter
    of available_bytes()."""
    env = _env_gb(ENV_WORKING_SET, zero_allowed=True)
    if env is not None:
        return env
    avail = available_bytes()
    return WORKING_SET_SHARE * avail if avail < float("inf") else 1e12
