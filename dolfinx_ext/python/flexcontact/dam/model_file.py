"""A factored dam saved once, loaded in a new process to answer scenarios without factoring
it again (docs/dam.md, "A dam model file").

The model is one directory, written atomically (complete or absent):

* ``manifest.json``: the format, the flexcontact version, the inputs (the base scenario,
  the time step, the water-level range, the face strip) and their SHA-256, the hash of the
  dam's mesh, and the size and SHA-256 of every other file;
* ``arrays.npz``: the face's condensed flexibility W_face, the base section's response
  functions (dam/response.py), the face compliance of the re-contact bound, the static
  displacement of each water level it was asked for, and the config's small logs
  (log_model.SMALL_LOG_DOFS) as their sparse split factors;
* a larger log of the config: ``logN_arrays.npz`` (its K, M₁, front and W_front), and
  MUMPS's files of its Schur factor on the front and of its plain factor (the flight after
  the contact, dam/log_model.py), read when a scenario first asks for it;
* MUMPS's own files of the two factors, K (stage 1: another water level in the range is one
  back-substitution) and Ŵ (stage 2, with its Schur complement on the face, so that a
  restored dam condenses and expands as the one that factored it), written and checked by
  flexcontact.saved_factor; a Ŵ
  small enough for the sparse split factor (the 2D section, split_factor.SPLIT_LIMIT) is
  kept in ``arrays.npz`` instead (its pivot order and Cholesky factor), so that a restored
  2D dam condenses and expands as the one that factored it.

Loading rebuilds the dam's mesh and assembles its matrices (no factorization), checks that
the mesh numbers its DOFs as the saved one did, and restores the factors. Only a changed
input or format invalidates a model, not a new flexcontact version; a model from another
MUMPS must be prepared again (its factor files are tied to its version).
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from .. import saved_factor
from ..split_factor import SplitFactor
from ..errors import SavedFileError

MODEL_FORMAT = 5
"""The model directory's format (2: a factor may be held in arrays.npz, "kind": "split";
3: a large log kept as its own arrays file and MUMPS factor; 4: and its plain factor; 5: a
small log held as a sparse split factor, its entry's "kind" "split", where formats 2–4 held
it as dense blocks)."""

READABLE_FORMATS = (2, 3, 4, 5)
"""Formats this flexcontact loads (a format-2 model holds no large log; a format-3
model's large log flies after the contact on its Schur factor, the same answer to
round-off at three times the cost of a step); any other is refused."""

SPLIT = "split"
"""The manifest's "kind" of a factor kept in arrays.npz (split_factor.SplitFactor)."""


def inputs_of(base, dt_s: float, water_levels_m, strip_m, patch_y_m=None) -> dict:
    """What the model depends on, as plain JSON values (in 3D, the face patch's y range
    too)."""
    out = {"base": base.as_dict(), "dt_s": float(dt_s),
           "water_levels_m": [float(z) for z in water_levels_m],
           "strip_m": [float(z) for z in strip_m]}
    if patch_y_m is not None:
        out["patch_y_m"] = [float(y) for y in patch_y_m]
    return out


def inputs_hash(inputs: dict) -> str:
    return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()


def prepare(base, dt_s: float, water_levels_m, path, levels=None,
            lags: int | None = None, progress=print, strip_m=None, patch_y_m=None,
            logs=()) -> dict:
    """Build and factor the dam of ``base`` at ``dt_s`` for the water levels
    ``water_levels_m`` = (lowest, highest), and write its model to the directory ``path``
    (replaced atomically if it exists). ``levels``: the water levels whose static state is
    stored (default: both ends of the range); ``lags``: response-function lags tabulated
    now (default: twice the steps of the base scenario's run; a longer run extends them on
    load, from the saved adjoint state, counted); ``strip_m``, ``patch_y_m``: the face
    region condensed (default: DamModel's); ``logs``: scenarios whose log models are kept
    too (one per distinct log: a small one's split factor in ``arrays.npz``, or a large log
    as its own arrays file and MUMPS's Schur factor files). Returns the manifest."""
    from .dam_model import DamModel
    path = Path(path)
    t0 = time.perf_counter()
    dam = DamModel(base, dt_s, water_levels_m, MPI.COMM_SELF, strip_m=strip_m,
                   patch_y_m=patch_y_m, saveable=True)
    imap = dam.V.dofmap.index_map
    progress(f"dam meshed, assembled and factored: {imap.size_global * dam.V.dofmap.index_map_bs} "
             f"DOFs, face strip {dam.strip_m[0]:.3f}..{dam.strip_m[1]:.3f} m "
             f"({dam.face_dofs.size} face DOFs), {time.perf_counter() - t0:.1f} s")
    levels = sorted({float(z) for z in (levels or dam.water_levels_m)})
    statics = {z: dam.static_state(z) for z in levels}
    compliance = dam.face_compliance(0)
    responses = dam.responses()
    if lags is None:
        from .coupled_step import run_steps
        lags = 2 * run_steps(base, dam)
    responses.ensure(int(lags))
    tmp = path.parent / f".{path.name}.tmp-{os.getpid()}"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    try:
        factors = {}
        arrays = {"W_face": dam.W_face, "face_dofs": dam.face_dofs,
                  "face_compliance_x": compliance}
        for name, f in (("stage1", dam._factor1), ("stage2", dam.factor)):
            if isinstance(f, SplitFactor):
                arrays.update(f.arrays(name + "_"))
                factors[name] = {"name": name, "kind": SPLIT, "rows": f.n}
            else:
                factors[name] = saved_factor.save_factor(f, tmp, name)
        arrays.update(responses.saved())
        kept_logs, log_factorizations = _log_arrays(base, dam, logs, arrays, tmp)
        counts = dam.counts()
        counts["factorizations"]["log"] = log_factorizations
        for i, (z, st) in enumerate(statics.items()):
            arrays[f"static_u_{i}"] = st.u.x.array
        np.savez(tmp / "arrays.npz", **arrays)
        inputs = inputs_of(base, dt_s, dam.water_levels_m, dam.strip_m, dam.patch_y_m)
        from .. import __version__
        manifest = {
            "format": MODEL_FORMAT, "flexcontact_version": __version__,
            "inputs": inputs, "inputs_sha256": inputs_hash(inputs),
            "mesh_sha256": dam.mesh_hash(), "levels_m": levels,
            "statics": {str(i): {"water_level_m": z,
                                 "section": statics[z].section.__dict__,
                                 "section_foundation": statics[z].section_foundation.__dict__}
                        for i, z in enumerate(levels)},
            "factors": factors, "counts": counts, "logs": kept_logs,
            "files": {name: _file_entry(tmp / name) for name in
                      ["arrays.npz", *(e["arrays"] for e in kept_logs if "arrays" in e)]}}
        (tmp / "manifest.json").write_text(json.dumps(manifest, indent=1, default=_plain))
        old = path.parent / f".{path.name}.old-{os.getpid()}"
        if path.exists():
            path.rename(old)
        tmp.rename(path)
        if old.exists():
            shutil.rmtree(old)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    progress(f"model written to {path} in {time.perf_counter() - t0:.1f} s")
    return manifest


def _plain(x):
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, tuple):
        return list(x)
    raise TypeError(f"{type(x)} is not JSON")


def _file_entry(p: Path) -> dict:
    return {"bytes": p.stat().st_size, "sha256": saved_factor.sha256(p)}


def read_manifest(path, every_file: bool = False) -> dict:
    """The checked manifest of the model at ``path``: SavedFileError naming what is missing,
    truncated, altered or of another format. The files read only through a factor's
    restoration or a large log's first use (MUMPS's factor files, ``logN_arrays.npz``) are
    checked here for presence and size, and their SHA-256 when they are read: hashing them
    here too read each of them twice. ``every_file``: hash those too (a sweep's check of its
    model, once, before its workers load it)."""
    path = Path(path)
    mpath = path / "manifest.json"
    if not mpath.is_file():
        raise SavedFileError(f"{path}: not a dam model (no manifest.json); write one with "
                             "`python3 -m flexcontact dam prepare CONFIG.toml`")
    try:
        manifest = json.loads(mpath.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise SavedFileError(f"{mpath}: not readable JSON ({e}): a truncated or altered "
                             "model") from None
    if manifest.get("format") not in READABLE_FORMATS:
        raise SavedFileError(f"{path}: model format {manifest.get('format')!r}; this "
                             f"flexcontact reads formats {READABLE_FORMATS[0]} to "
                             f"{READABLE_FORMATS[-1]}: prepare it again")
    if inputs_hash(manifest["inputs"]) != manifest.get("inputs_sha256"):
        raise SavedFileError(f"{mpath}: its inputs do not match their SHA-256 (the manifest "
                             "was edited)")
    later = {e["arrays"] for e in manifest.get("logs", []) if "arrays" in e}
    for name, want in manifest["files"].items():
        check_file(path / name, want, contents=every_file or name not in later)
    for entry in [*manifest["factors"].values(),
                  *(e[k] for e in manifest.get("logs", []) for k in LOG_FACTORS if k in e)]:
        if entry.get("kind") != SPLIT:  # a split factor's arrays were checked above
            saved_factor.check_factor_files(path, entry, contents=every_file)
    return manifest


def check_file(p: Path, want: dict, contents: bool = True) -> None:
    saved_factor.check_file(p, want, contents, " from the model")


def check_inputs(manifest: dict, base=None, dt_s=None) -> None:
    """SavedFileError naming the first input of ``base`` / ``dt_s`` that differs from the
    model's (only the dam's parameters matter: see reuse.DAM_PARAMETERS)."""
    from .reuse import DAM_PARAMETERS
    saved = manifest["inputs"]
    if base is not None:
        now = base.as_dict()
        for name in DAM_PARAMETERS:
            if json.loads(json.dumps(now[name], default=_plain)) != saved["base"][name]:
                raise SavedFileError(f"{name}={now[name]!r} differs from the model's "
                                     f"{saved['base'][name]!r}: prepare a model for it")
    if dt_s is not None and float(dt_s) != saved["dt_s"]:
        raise SavedFileError(f"dt_s={dt_s!r} differs from the model's {saved['dt_s']!r}")


def load(path, comm=MPI.COMM_SELF, **evaluator_options):
    """The ScenarioEvaluator of the model at ``path``: the dam rebuilt (mesh and assembly,
    no factorization), its factors and operators restored. Raises SavedFileError if a file
    or the rebuilt mesh does not match."""
    from .dam_model import DamModel, StaticState
    from .reuse import ScenarioEvaluator
    from .scenario import DamScenario
    from .section import BaseSection
    path = Path(path)
    manifest = read_manifest(path)
    inputs = manifest["inputs"]
    base = DamScenario.from_dict(inputs["base"])
    with np.load(path / "arrays.npz") as z:
        arrays = {k: z[k] for k in z.files}
    # Ŵ's MUMPS factor comes back with its Schur split on the face (kind "schur"); a plain
    # factor (K, or Ŵ of a model saved without the split) ignores the face's arrays.
    restored = {name: (SplitFactor.from_arrays(arrays, name + "_") if entry.get("kind") == SPLIT
                       else saved_factor.restore_factor(path, entry, arrays["face_dofs"],
                                                        arrays["W_face"]))
                for name, entry in manifest["factors"].items()}
    restored["W_face"] = arrays["W_face"]
    restored["face_compliance_x"] = arrays["face_compliance_x"]
    dam = DamModel(base, inputs["dt_s"], tuple(inputs["water_levels_m"]), comm,
                   strip_m=tuple(inputs["strip_m"]), restored=restored,
                   patch_y_m=inputs.get("patch_y_m"))
    if dam.mesh_hash() != manifest["mesh_sha256"] or not np.array_equal(
            dam.face_dofs, arrays["face_dofs"]):
        import gmsh
        from .. import compat
        raise SavedFileError(
            f"{path}: the dam's mesh rebuilt here ({compat.STACK}, gmsh {gmsh.__version__}) "
            "numbers its nodes differently from the saved one: prepare the model again on "
            "this installation")
    dam.responses().restore(arrays)
    for i, st in manifest["statics"].items():
        import dolfinx.fem
        u = dolfinx.fem.Function(dam.V, name="displacement_m")
        u.x.array[:] = arrays[f"static_u_{i}"]
        dam._statics[float(st["water_level_m"])] = StaticState(
            float(st["water_level_m"]), u, BaseSection(**_section(st["section"])),
            BaseSection(**_section(st["section_foundation"])))
    ev = ScenarioEvaluator(base, comm=comm, dam=dam, **evaluator_options)
    for entry in manifest.get("logs", []):
        from ..dense_factor import DenseFactor
        from .log_model import LogMesh
        p, s = entry["prefix"], DamScenario.from_dict(entry["scenario"])
        if "factor" in entry:
            ball = entry.get("ball")
            want = manifest["files"][entry["arrays"]]
            ev.logs.restore_later(s, None if ball is None else tuple(ball),
                                  lambda entry=entry, want=want: _large_log(path, entry, want))
        else:
            small = SplitFactor if entry.get("kind") == SPLIT else DenseFactor
            ev.logs.restore(s, LogMesh.from_arrays(arrays, p), small.from_arrays(arrays, p + "f_"))
    return ev


LOG_FACTORS = ("factor", "flight_factor")
"""A large log's factors in its manifest entry: the Schur factor on its front, and the
plain factor of its flight after the contact (format 4)."""


def _large_log(path: Path, entry: dict, want: dict):
    """(LogMesh, restored Schur factor, W_front, restored plain factor or None) of a log
    that the model keeps factored by MUMPS: its own arrays file (checked against ``want``,
    its manifest entry) and factor files, read when a scenario first asks for it."""
    from .log_model import LogMesh
    p = entry["prefix"]
    check_file(path / entry["arrays"], want)
    with np.load(path / entry["arrays"]) as z:
        arrays = {k: z[k] for k in z.files}
    mesh = LogMesh.from_arrays(arrays, p)
    W_front = arrays[p + "W_front"]
    factor = saved_factor.restore_factor(path, entry["factor"], mesh.front_dofs, W_front)
    flight = (saved_factor.restore_factor(path, entry["flight_factor"])
              if "flight_factor" in entry else None)
    return mesh, factor, W_front, flight


MAX_LOGS = 16
"""A model keeps at most this many log models of its config."""


def logs_of(base, scenarios) -> list:
    """One scenario per distinct log of a config (the base's first), when there are at
    most MAX_LOGS of them (a continuous density gives one log per scenario: the base's
    alone then)."""
    from .reuse import log_key
    distinct = {}
    for s in [base, *scenarios]:
        distinct.setdefault(log_key(s), s)
    return list(distinct.values()) if len(distinct) <= MAX_LOGS else [base]


def _log_arrays(base, dam, logs, arrays: dict, folder: Path) -> tuple[list, int]:
    """Build the log model of each distinct log among ``logs`` at the dam's time step and
    return the manifest's entries and the factorizations this cost. A small log (its split
    factor) goes into ``arrays``; a log factored by MUMPS (its Schur factor on the front)
    gets its own arrays file in ``folder`` (its K, M₁, front and W_front) and MUMPS's
    factor files, read only when a scenario asks for it."""
    from .reuse import LogCache, log_key
    cache = LogCache(dam.dt, dam.comm, dam.theta)
    entries = []
    for s in logs:
        if log_key(s) in cache.models:
            continue  # one entry per distinct log
        log = cache.get(s)
        p = f"log{len(entries)}_"
        entry = {"prefix": p, "scenario": s.as_dict()}
        if log.factor_kind in (SPLIT, "dense"):
            arrays.update(log.mesh.arrays(p))
            arrays.update(log.factor.arrays(p + "f_"))
            entry["kind"] = log.factor_kind
        else:
            entry["arrays"] = p + "arrays.npz"
            np.savez(folder / entry["arrays"], **log.mesh.arrays(p),
                     **{p + "W_front": log.W_front})
            entry["factor"] = saved_factor.save_factor(log.factor, folder, p + "factor")
            entry["flight_factor"] = saved_factor.save_factor(log.flight_factor, folder,
                                                              p + "flight")
            entry["ball"] = None if log.mesh.ball is None else list(log.mesh.ball)
        entries.append(entry)
    return entries, cache.total("factorizations")


def _section(d: dict) -> dict:
    return {**d, "force_N": tuple(d["force_N"])}
