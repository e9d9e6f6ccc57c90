"""The results table: ``results.jsonl``, one JSON row per finished scenario, that survives
a SIGKILL at any moment.

Only the parent process writes. Each row is one ``os.write`` of the whole line to a file
opened in append mode, then ``os.fsync``: a kill leaves at most one torn last line, which
:meth:`ResultTable.open` cuts off before resuming. Every row carries the scenario ``id``
(its index in the config's scenario list), the hash of its inputs (``point_hash``) and the
config's hash (``config_hash``); a row of another config, or of an id whose inputs differ,
is refused rather than mixed in. ``results.csv`` is rewritten from the JSON lines, sorted by
id, at the end of every run.
"""
from __future__ import annotations

import csv
import json
import os
from pathlib import Path

from .errors import TableError


class ResultTable:
    """``folder/results.jsonl`` for the config of hash ``config_hash`` whose scenario ids map
    to the input hashes ``expected`` (list, by id)."""

    def __init__(self, folder, config_hash: str, expected: list):
        self.folder = Path(folder)
        self.path = self.folder / "results.jsonl"
        self.config_hash, self.expected = config_hash, list(expected)
        self.rows = {}
        self._fd = None

    def open(self) -> set:
        """Read the rows already there (cutting a torn last line off) and open for
        appending; returns the finished ids."""
        self.folder.mkdir(parents=True, exist_ok=True)
        if self.path.exists():
            self._read()
        self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        return set(self.rows)

    def check(self) -> None:
        """Refuse (TableError) rows of another config or scenario list already in the
        folder, as :meth:`open` would, without creating or cutting anything."""
        if self.path.exists():
            *complete, _ = self.path.read_bytes().split(b"\n")
            self._accept_lines(complete, strict=False)  # open() names a corrupt table
            self.rows = {}

    def _read(self) -> None:
        data = self.path.read_bytes()
        *complete, tail = data.split(b"\n")  # tail: b"" or a line torn by a kill
        self._accept_lines(complete, strict=True)
        if tail:
            with open(self.path, "r+b") as f:
                f.truncate(len(data) - len(tail))
                f.flush()
                os.fsync(f.fileno())

    def _accept_lines(self, lines: list, strict: bool) -> None:
        for k, line in enumerate(lines):
            try:
                row = json.loads(line)
            except ValueError:
                if not strict:
                    continue
                raise TableError(f"{self.path}: line {k + 1} is not a JSON row; the table "
                                 f"is corrupt (not a torn last line)") from None
            self._accept(row, k + 1)

    def _accept(self, row: dict, line: int) -> None:
        where = f"{self.path}, line {line}"
        if row.get("config_hash") != self.config_hash:
            raise TableError(
                f"{where}: config_hash={row.get('config_hash')!r} differs from this "
                f"config's {self.config_hash!r}: the config changed since these rows were "
                f"computed. Use another output folder (--out), or delete {self.path} to "
                f"start over")
        i = row.get("id")
        if not (isinstance(i, int) and 0 <= i < len(self.expected)):
            raise TableError(f"{where}: id={i!r} is not a scenario of this config")
        if row.get("point_hash") != self.expected[i]:
            raise TableError(f"{where}: id={i} has point_hash={row.get('point_hash')!r}, "
                             f"not this config's {self.expected[i]!r}")
        if i in self.rows:
            raise TableError(f"{where}: id={i} is already in the table")
        self.rows[i] = row

    def append(self, row: dict) -> None:
        """Write one row (one write, then fsync) and keep it."""
        i = row["id"]
        if i in self.rows:
            raise TableError(f"id={i}: already in {self.path}; not written twice")
        row = {**row, "config_hash": self.config_hash, "point_hash": self.expected[i]}
        data = (json.dumps(row, sort_keys=True) + "\n").encode()
        view = memoryview(data)
        while view:  # a regular file takes it in one write; loop only on a short one
            view = view[os.write(self._fd, view):]
        os.fsync(self._fd)
        self.rows[i] = row

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def sorted_rows(self) -> list:
        return [self.rows[i] for i in sorted(self.rows)]

    def write_csv(self, names: list, outputs: list) -> Path:
        """``results.csv``: id, inputs, outputs, sorted by id (written then renamed)."""
        path, tmp = self.folder / "results.csv", self.folder / "results.csv.tmp"
        with open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["id", "point_hash", *names, *outputs])
            for r in self.sorted_rows():
                w.writerow([r["id"], r["point_hash"], *(repr(r["inputs"][n]) for n in names),
                            *(repr(r["outputs"].get(o)) for o in outputs)])
        os.replace(tmp, path)
        return path
