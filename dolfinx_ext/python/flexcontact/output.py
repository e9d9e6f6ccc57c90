"""Results on disk: XDMF time series for ParaView, summary.json, the increment table."""
from __future__ import annotations

import json
import os
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Sequence, Union

import numpy as np
from mpi4py import MPI

import dolfinx.io

from . import compat

# DOLFINx 0.9's class names; 0.5 spells them *MetaClass, so never imported at run time.
if TYPE_CHECKING:
    from dolfinx.mesh import Mesh, MeshTags

    from .problem import ContactProblem


class ResultWriter:
    """One XDMF file, one time step per increment; closed (and so complete) on every exit.

    Use as a context manager so that a failing increment leaves a readable file with the
    increments done before it.
    """

    def __init__(self, folder: Union[str, os.PathLike], name: str, msh: Mesh,
                 tags: Sequence[MeshTags] = ()):
        self.folder = Path(folder)
        if msh.comm.rank == 0:
            self.folder.mkdir(parents=True, exist_ok=True)
        msh.comm.barrier()
        self.path = self.folder / f"{name}.xdmf"
        self._xdmf = dolfinx.io.XDMFFile(msh.comm, str(self.path), "w")
        compat.write_mesh_and_tags(self._xdmf, msh, tags)

    def write(self, problem: ContactProblem, t: float) -> None:
        for f in problem.fields():
            self._xdmf.write_function(f, t)

    def close(self) -> None:
        if self._xdmf is not None:
            self._xdmf.close()
            self._xdmf = None

    def __enter__(self) -> ResultWriter:
        return self

    def __exit__(self, *exc) -> bool:
        self.close()
        return False


def results_folder(name: str) -> Path:
    """``results/<name>/`` under the current directory (or $FLEXCONTACT_RESULTS)."""
    base = Path(os.environ.get("FLEXCONTACT_RESULTS", "results"))
    return base / name


def write_summary(folder: Union[str, os.PathLike], data: dict,
                  comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Write ``summary.json`` on rank 0 (NumPy values become plain numbers)."""
    if comm.rank != 0:
        return
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)

    def plain(o):
        if isinstance(o, (np.floating, np.integer)):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
        if hasattr(o, "__dataclass_fields__"):
            return asdict(o)
        raise TypeError(f"cannot write {type(o)} to JSON")

    tmp = folder / "summary.json.tmp"
    tmp.write_text(json.dumps(data, indent=2, default=plain))
    tmp.replace(folder / "summary.json")


def increments_table(summaries) -> list[dict]:
    return [asdict(s) for s in summaries]


def mesh_info(V, **extra) -> dict:
    """Size of the problem for a summary: cells, DOFs, ranks (+ any extra entries)."""
    msh = V.mesh
    tdim = msh.topology.dim
    return {"cells": int(msh.topology.index_map(tdim).size_global),
            "dofs": int(V.dofmap.index_map.size_global * V.dofmap.index_map_bs),
            "ranks": msh.comm.size, **extra}


def run_record(problem, summaries, t_start: float, **timings_s) -> dict:
    """What every demo summary holds about the run: the solver per increment (who answered,
    iterations, worst residual), timings in seconds (set-up, factorization, each increment,
    total since ``t_start`` on ``time.perf_counter``, plus ``timings_s``) and the
    per-increment table."""
    import time
    return {
        "solver": {"iterations": [s.iterations for s in summaries],
                   "answered_by": [s.solver for s in summaries],
                   "residual_max": max(s.residual for s in summaries)},
        "timings_s": {**timings_s, **problem.timings,
                      **{k: v for k, v in problem.flex_info.items() if k.endswith("_s")},
                      "increments": [s.time_s for s in summaries],
                      "total": time.perf_counter() - t_start},
        "increments": increments_table(summaries),
        # One factorization serves every increment; pairs re-made without refactorizing.
        "factorizations": int(getattr(problem, "factorizations", 1)),
        "pairings": int(getattr(problem, "pairings", 1)),
    }


def pyplot():
    """matplotlib.pyplot drawing to files (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt
