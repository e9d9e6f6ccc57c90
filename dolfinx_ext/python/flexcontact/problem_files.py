"""A failing local problem as a file a user can send (docs/solvers.md, "A failing problem
as a file").

When the chain of local solvers raises ``ConvergenceError``, the problem it was given (W, q,
μ, the caps, the start and the options) is written here and the error names the file
(``err.problem_path``). ``load_problem(path).solve()`` re-runs it, bitwise, on any machine:
the solvers' budgets count work, not time.
"""
from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

ENV_DIR = "FLEXCONTACT_PROBLEM_DIR"
"""Environment variable naming the folder of saved problems (default: a folder
``flexcontact-problems`` in the system's temporary folder)."""


def problem_dir() -> Path:
    """Where failing problems are saved."""
    chosen = os.environ.get(ENV_DIR)
    return Path(chosen) if chosen else Path(tempfile.gettempdir()) / "flexcontact-problems"


def save_failed(data: bytes) -> str:
    """Writes one problem's bytes under a name taken from their hash, so the same failure
    (on every MPI rank, or run after run) is one file, written whole or not at all."""
    folder = problem_dir()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"failed-{hashlib.sha256(data).hexdigest()[:16]}.lp"
    if not (path.exists() and path.stat().st_size == len(data)):
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".writing-")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    return str(path)


def load_problem(path):
    """The local problem saved at ``path`` (a ``LocalProblem``: ``dim``, ``W``, ``q``,
    ``mu``, ``cap``, ``lambda_start``, ``states_start``, ``options``, ``source``);
    ``.solve()`` re-runs the chain from the stored start with the stored options. Reads the
    files of ``ConvergenceError.problem_path`` and the recorded problems of tests/data."""
    from ._cpp import read_local_problem
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"load_problem: no file at {str(p)!r}")
    return read_local_problem(str(p))
