"""A factor kept on disk: a body factored once is restored in another process instead of
being factored again (docs/architecture.md §7, "A factor kept on disk").

:func:`save_factor` writes MUMPS's own files (JOB=7) beside a manifest entry that records
each file's size and SHA-256, the matrix size and the MUMPS version; :func:`restore_factor`
checks all of it before MUMPS reads a byte (a truncated or altered file would otherwise stop
the process inside MUMPS's Fortran reader) and restores the factor (JOB=8). The restored
object has ``solve(b, x)``, so the steppers take it like any factor.

Two kinds are saved: a plain factor (``SavedFactor``) and a factor with a Schur complement
on a body's contact DOFs (the ``DistributedSchur`` that ``flexibility(K, dofs, "schur")``
returns on one rank; its entry says ``"kind": "schur"``). The latter comes back with its
split — ``condense`` and ``expand``, one partial solve each — given its Schur rows and F*.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from . import _cpp
from .errors import SavedFileError

FACTOR_FORMAT = 1
"""The manifest entry's format (the files' own format is MUMPS's, tied to its version)."""

SCHUR = "schur"
"""The entry's "kind" of a factor saved with its Schur complement (a DistributedSchur)."""


def sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def factor_matrix(A) -> "_cpp.SavedFactor":
    """The LDLᵀ factor of the serial symmetric petsc4py Mat ``A`` (one factorization)."""
    return _cpp.SavedFactor(A)


def save_factor(factor, folder, name: str) -> dict:
    """Write ``factor`` (a SavedFactor, or a serial DistributedSchur) as ``folder/name_*``
    and return its manifest entry: {"name", "rows", "mumps_version", "format", "files":
    {file: {"bytes", "sha256"}}}, and for a DistributedSchur "kind": "schur" and
    "schur_rows" (how many)."""
    folder = Path(folder)
    before = {p.name for p in folder.iterdir()}
    factor.save(str(folder), name)
    files = sorted(p for p in folder.iterdir() if p.name not in before
                   and p.name.startswith(name + "_"))
    if not files:
        raise SavedFileError(f"{folder}/{name}: MUMPS wrote no file")
    entry = {"name": name, "rows": int(factor.size), "format": FACTOR_FORMAT,
             "mumps_version": _cpp.mumps_version,
             "files": {p.name: {"bytes": p.stat().st_size, "sha256": sha256(p)} for p in files}}
    if isinstance(factor, _cpp.DistributedSchur):
        entry.update(kind=SCHUR, schur_rows=int(factor.n_schur))
    return entry


def check_factor_files(folder, entry: dict, contents: bool = True) -> None:
    """SavedFileError naming the first file, format or version that does not match
    ``entry``. ``contents=False`` checks each file's presence and size but not its SHA-256:
    for a listing of a model whose factors are checked whole when restored."""
    folder = Path(folder)
    if entry.get("format") != FACTOR_FORMAT:
        raise SavedFileError(f"{folder}: factor '{entry.get('name')}' has format "
                             f"{entry.get('format')!r}; this flexcontact reads {FACTOR_FORMAT}")
    if entry.get("mumps_version") != _cpp.mumps_version:
        raise SavedFileError(f"{folder}: factor '{entry['name']}' was saved by MUMPS "
                             f"{entry.get('mumps_version')}, this build has MUMPS "
                             f"{_cpp.mumps_version}: factor it again")
    for name, want in entry["files"].items():
        check_file(folder / name, want, contents, f" (factor '{entry['name']}')")


def check_file(path: Path, want: dict, contents: bool = True, whose: str = "") -> None:
    """SavedFileError if the saved file ``path`` is missing (``whose`` says what it
    belongs to), or its size (and with ``contents`` its SHA-256) differs from ``want``
    ({"bytes", "sha256"})."""
    if not path.is_file():
        raise SavedFileError(f"{path}: missing{whose}")
    size = path.stat().st_size
    if size != want["bytes"]:
        raise SavedFileError(f"{path}: {size} bytes, {want['bytes']} were saved (a "
                             "truncated or replaced file)")
    if contents and sha256(path) != want["sha256"]:
        raise SavedFileError(f"{path}: its SHA-256 differs from the saved one (the file "
                             "was altered)")


def restore_factor(folder, entry: dict, schur_dofs=None, flexibility=None):
    """The factor that :func:`save_factor` wrote (checked first, then one restoration). A
    factor saved with its Schur complement needs ``schur_dofs`` (its rows, in the order it
    was factored with) and ``flexibility`` (F* on them, for full solves)."""
    check_factor_files(folder, entry)
    if entry.get("kind") != SCHUR:
        return _cpp.SavedFactor.restore(str(Path(folder)), entry["name"], int(entry["rows"]))
    if schur_dofs is None or flexibility is None:
        raise SavedFileError(f"{folder}: factor '{entry['name']}' has a Schur complement; "
                             "its rows and flexibility are needed to restore it")
    dofs = np.asarray(schur_dofs, np.int64).reshape(-1)
    if dofs.size != entry["schur_rows"]:
        raise SavedFileError(f"{folder}: factor '{entry['name']}' was saved with "
                             f"{entry['schur_rows']} Schur rows, {dofs.size} are given")
    return _cpp.DistributedSchur.restore(str(Path(folder)), entry["name"], int(entry["rows"]),
                                         dofs, np.asarray(flexibility, float))
