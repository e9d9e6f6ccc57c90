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

With ``batch`` = k > 1 a task is k scenarios that share a log geometry where they can,
stepped side by side by the evaluator's ``evaluate_many`` (the dam's solves, and the log's,
made once per step for all of them: docs/architecture.md §7, "Several right-hand sides at
once"); the batches are cut from the scenarios still to compute in a fixed order, so the
same run gives the same answers.

A failing scenario stops the sweep with its error; the rows already written stay (in a
batch, the other scenarios' rows are written first).
"""
from __future__ import annotations

import os

from .evaluators import evaluate_task, evaluate_batch, init_worker
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
    runner(engine, spec, batches(tasks, engine.get("batch", 1)), _each(on_result))


def batches(tasks: list, k: int) -> list:
    """``tasks`` in units of at most ``k``: ordered by log (length, diameter, density, end
    shape), then by id, and cut in that order, so that a unit's scenarios share their log
    where the sample allows."""
    if k <= 1:
        return [[t] for t in tasks]
    ordered = sorted(tasks, key=lambda t: (t[1].log_length_m, t[1].log_diameter_m,
                                           t[1].wood.rho_kg_m3, str(t[1].log_end), t[0]))
    return [ordered[a:a + k] for a in range(0, len(ordered), k)]


def _each(on_result):
    """on_result for a unit's results: every computed row first, then the first error."""
    def take(results: list) -> None:
        failed = [r for r in results if "error" in r]
        for r in results:
            if "error" not in r:
                on_result(r)
        if failed:
            raise failed[0]["error"]
    return take


def _evaluate(spec, unit: list) -> list:
    if len(unit) == 1:
        return [evaluate_task(spec, unit[0])]
    return evaluate_batch(spec, unit)


def _serial(engine, spec, units, on_results):
    for u in units:
        on_results(_evaluate(spec, u))


def _drain(futures, on_result, as_completed):
    try:
        for f in as_completed(futures):
            on_result(f.result())
    except BaseException:
        for f in futures:
            f.cancel()
        raise


def _processes(engine, spec, units, on_results):
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed
    n = min(engine["workers"] or default_workers(), len(units))
    ctx = multiprocessing.get_context(engine["start_method"])
    with ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=init_worker,
                             initargs=(spec,)) as pool:
        _drain([pool.submit(_evaluate, spec, u) for u in units], on_results, as_completed)


def _mpi(engine, spec, units, on_results):
    from concurrent.futures import as_completed
    from mpi4py.futures import MPIPoolExecutor
    kwargs = {"max_workers": engine["workers"]} if engine["workers"] else {}
    with MPIPoolExecutor(**kwargs) as pool:
        _drain([pool.submit(_evaluate, spec, u) for u in units], on_results, as_completed)


def _dask(engine, spec, units, on_results):
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise SolveError("engine.kind='dask' needs Dask distributed (Debian package "
                           "python3-distributed; scripts/setup.sh installs it)") from None
    cluster = None
    if engine["scheduler"]:
        client = Client(engine["scheduler"])
    else:
        n = min(engine["workers"] or default_workers(), len(units))
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        futures = [client.submit(_evaluate, spec, u, pure=False) for u in units]
        _drain(futures, on_results, as_completed)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
