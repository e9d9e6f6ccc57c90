"""Results on disk: the XDMF time series for ParaView, summary.json, the increment table."""
from __future__ import annotations

import json
import os
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Optional, Sequence, Union

import numpy as np
from mpi4py import MPI

from .xdmf import XdmfSeries
from .xdmf_gather import MeshGather, raise_on_any_rank
from .errors import InputTypeError

# DOLFINx 0.9's class names; 0.5 spells them *MetaClass, so never imported at run time.
if TYPE_CHECKING:
    from dolfinx.fem import Function
    from dolfinx.mesh import Mesh, MeshTags

    from .problem import ContactProblem


class ResultWriter:
    """``<name>.xdmf`` (+ ``<name>.bin``): one time step per :meth:`write`, every field of a
    step on one mesh in double precision (see :mod:`flexcontact.xdmf`).

    The file is complete after every step, so a failing increment leaves a readable file with
    the increments done before it; use as a context manager all the same, so that the data
    file is closed. Cell tags (``tags``) are written at every step as integer cell attributes
    (``cell_tag`` for DOLFINx's default names, else the tags' name). Collective on the mesh's
    communicator; rank 0 writes, and the file is the same on any number of ranks.
    """

    def __init__(self, folder: Union[str, os.PathLike], name: str, msh: Mesh,
                 tags: Sequence[MeshTags] = ()):
        self.folder = Path(folder)
        self.path = self.folder / f"{name}.xdmf"
        self.comm = msh.comm
        if hasattr(tags, "indices"):  # one MeshTags rather than a sequence of them
            tags = (tags,)
        self._mesh = MeshGather(msh)
        static = self._mesh.cell_tags(tuple(tags))
        self._series = None
        error = None
        if self.comm.rank == 0:
            try:
                self.folder.mkdir(parents=True, exist_ok=True)
                self._series = XdmfSeries(self.path, self._mesh.topology_type, self._mesh.x,
                                          self._mesh.cells, static)
            except OSError as e:
                error = f"ResultWriter: cannot write {self.path}: {e}"
        raise_on_any_rank(self.comm, error, OSError)

    def write(self, obj: Union[ContactProblem, Sequence[Function], Function],
              t: float) -> None:
        """Write the fields of ``obj`` at time ``t`` as one step (collective).

        ``obj`` is anything with a ``fields()`` method returning DOLFINx Functions (a
        ContactProblem), a sequence of Functions, or one Function: continuous degree-1 fields
        become node attributes, DG0 fields cell attributes, 2D vectors padded to 3D.
        """
        if hasattr(obj, "fields"):
            functions = list(obj.fields())
        elif hasattr(obj, "function_space"):
            functions = [obj]
        else:
            functions = list(obj)
        message = None
        if self._mesh is None:
            message = f"ResultWriter: {self.path} is closed"
        elif not np.isfinite(t):
            message = f"ResultWriter: time t = {t} is not finite"
        raise_on_any_rank(self.comm, message)
        fields = self._mesh.gather(functions)
        error = None
        if self._series is not None:
            try:
                self._series.add_step(float(t), fields)
            except OSError as e:
                error = f"ResultWriter: cannot write {self.path}: {e}"
        raise_on_any_rank(self.comm, error, OSError)

    def close(self) -> None:
        if self._series is not None:
            self._series.close()
            self._series = None
        self._mesh = None

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
        raise InputTypeError(f"cannot write {type(o)} to JSON")

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


def plot_hertz_profile(path: Union[str, os.PathLike], x_m, p_Pa, a_ref_m: float,
                       p0_ref_Pa: float, *, ref_label: str = "Hertz",
                       label: str = "flexcontact", title: Optional[str] = None,
                       ylabel: str = "pressure [MPa]", extra=()) -> None:
    """A line contact's computed pressure against Hertz's ellipse over ±1.5 a, in mm and MPa.

    ``extra``: more computed series as ``(x_m, y_Pa, marker, label)`` (e.g. the tangential
    traction)."""
    from .analytic import hertz_pressure
    plt = pyplot()
    xs = np.linspace(-1.5 * a_ref_m, 1.5 * a_ref_m, 400)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(xs * 1e3, [hertz_pressure(xi, a_ref_m, p0_ref_Pa) / 1e6 for xi in xs], "k-",
            label=ref_label)
    ax.plot(np.asarray(x_m) * 1e3, np.asarray(p_Pa) / 1e6, "o", ms=4, label=label)
    for xe, ye, marker, lab in extra:
        ax.plot(np.asarray(xe) * 1e3, np.asarray(ye) / 1e6, marker, ms=3, label=lab)
    ax.set_xlim(-1.5 * a_ref_m * 1e3, 1.5 * a_ref_m * 1e3)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
