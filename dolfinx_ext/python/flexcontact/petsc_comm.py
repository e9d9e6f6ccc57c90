"""PETSc's world communicator when flexcontact runs under ``python3 -m mpi4py.futures``.

PETSc's initialisation is collective over its world communicator (MPI_COMM_WORLD by
default). Under ``mpirun -n K python3 -m mpi4py.futures ...`` rank 0 drives and the other
ranks serve tasks, each process computing on its own: the first to import PETSc would wait
for the others forever. There PETSc is initialised on MPI_COMM_SELF; everywhere else this
does nothing.
"""
import sys


def init_for_futures() -> None:
    """petsc4py.init(comm=COMM_SELF) if mpi4py.futures runs this process and PETSc is not
    initialised yet."""
    if "mpi4py.futures" not in sys.modules or "petsc4py.PETSc" in sys.modules:
        return
    import petsc4py
    from mpi4py import MPI
    petsc4py.init(sys.argv[:1], comm=MPI.COMM_SELF)
