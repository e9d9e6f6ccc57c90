"""Where the scenarios run. Every engine hands each finished scenario's result to
``on_result`` in the parent process, which alone writes the table, so the table is the same
whichever engine computed it (only the order rows were appended in differs).

* ``serial``: in this process;
* ``processes`` (default): a ``concurrent.futures.ProcessPoolExecutor`` (spawn or
  forkserver), each worker building its evaluator once in the pool's initializer;
* ``mpi``: ``mpi4py.futures.MPIPoolExecutor``, run as
  ``mpirun -n K python3 -m mpi4py.futures -m flexcontact sweep CONFIG --engine mpi``
  (rank 0 drives, the K − 1 others compute);
* ``dask``: a ``distributed.Client`` at ``scheduler`` (``tcp://host:8786``), or without
  one a LocalCluster of worker processes, one thread each.

A failing scenario stops the sweep with its error; the rows already written stay.
"""
from __future__ import annotations

import os

from .evaluators import evaluate_task, init_worker
from ..errors import SolveError


def default_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
               else os.cpu_count() or 1)


def run(engine: dict, spec, tasks: list, on_result, local=None) -> None:
    """Evaluate ``tasks`` ((id, scenario) pairs) on ``engine``; ``on_result(result)`` per
    finished one, in the parent; ``local``: an evaluator of ``spec`` already built in this
    process, which the serial engine uses."""
    if not tasks:
        return
    kind = engine["kind"]
    runner = {"serial": _serial, "processes": _processes, "mpi": _mpi, "dask": _dask}[kind]
    if kind == "serial":
        init_worker(spec, local)
    runner(engine, spec, tasks, on_result)


def _serial(engine, spec, tasks, on_result):
    for t in tasks:
        on_result(evaluate_task(spec, t))


def _drain(futures, on_result, as_completed):
    try:
        for f in as_completed(futures):
            on_result(f.result())
    except BaseException:
        for f in futures:
            f.cancel()
        raise


def _processes(engine, spec, tasks, on_result):
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed
    n = min(engine["workers"] or default_workers(), len(tasks))
    ctx = multiprocessing.get_context(engine["start_method"])
    with ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=init_worker,
                             initargs=(spec,)) as pool:
        _drain([pool.submit(evaluate_task, spec, t) for t in tasks], on_result, as_completed)


def _mpi(engine, spec, tasks, on_result):
    from concurrent.futures import as_completed
    from mpi4py.futures import MPIPoolExecutor
    kwargs = {"max_workers": engine["workers"]} if engine["workers"] else {}
    with MPIPoolExecutor(**kwargs) as pool:
        _drain([pool.submit(evaluate_task, spec, t) for t in tasks], on_result, as_completed)


def _dask(engine, spec, tasks, on_result):
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise SolveError("engine.kind='dask' needs Dask distributed (Debian package "
                           "python3-distributed; scripts/setup.sh installs it)") from None
    cluster = None
    if engine["scheduler"]:
        client = Client(engine["scheduler"])
    else:
        n = min(engine["workers"] or default_workers(), len(tasks))
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        futures = [client.submit(evaluate_task, spec, t, pure=False) for t in tasks]
        _drain(futures, on_result, as_completed)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
