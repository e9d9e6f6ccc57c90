"""Sweeps of the dam-impact scenario: many scenarios from one config, the most unfavourable
found, a table that survives being killed.

``python3 -m flexcontact sweep CONFIG.toml [--out DIR] [--engine serial|processes|mpi|dask]
[--workers N] [--scheduler ADDRESS] [--check-convergence]``; docs/dam.md ("Sweeps").

* :mod:`.config` reads and checks the TOML; :mod:`.distributions` the inputs' laws;
  :mod:`.scenarios` draws the seeded sample and builds every DamScenario before computing;
* :mod:`.evaluators` picks the evaluator (:mod:`.monolithic` until the reusing one is there);
  :mod:`.engines` runs it serially, on processes, under MPI or on Dask;
* :mod:`.table` appends one fsynced JSON row per finished scenario and resumes;
* :mod:`.stats`, :mod:`.plots`, :mod:`.sweep_report` write what the engineer reads.
"""
from .config import SweepConfig, from_dict, load
from .driver import prepare, run
from .errors import ConfigError, TableError

__all__ = ["ConfigError", "SweepConfig", "TableError", "from_dict", "load", "prepare", "run"]
