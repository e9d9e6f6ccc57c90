"""Test set-up: import this checkout's package (not another clone's) and share helpers."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "dolfinx_ext" / "python"))


def mpirun(n, script, *args, timeout=600, cwd=None, env=None):
    """Run a Python script with `mpirun -n n`; returns the CompletedProcess (check=True)."""
    cmd = ["mpirun", "-n", str(n), "--oversubscribe"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    cmd += ["/usr/bin/python3", str(script), *map(str, args)]
    e = dict(os.environ)
    e["PYTHONPATH"] = str(ROOT / "dolfinx_ext" / "python") + os.pathsep + e.get("PYTHONPATH", "")
    e.update(env or {})
    return subprocess.run(cmd, cwd=cwd or ROOT, env=e, capture_output=True, text=True,
                          timeout=timeout, check=True)


@pytest.fixture
def results_dir(tmp_path, monkeypatch):
    """Demos write under a temporary results folder."""
    monkeypatch.setenv("FLEXCONTACT_RESULTS", str(tmp_path))
    return tmp_path


def pytest_configure(config):
    config.addinivalue_line("markers", "mpi: runs a case with mpirun -n 2")
    config.addinivalue_line("markers", "slow: takes minutes (builds or installs the package)")
    if shutil.which("mpirun") is None:
        raise RuntimeError("mpirun not found: install openmpi-bin (scripts/setup.sh does)")
