"""Test set-up: import this checkout's package (not another clone's) and share helpers."""
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

# gmsh installs a signal handler when imported, which Python allows only in the main thread.
# Imported here first, because pytest-xdist's controller imports the module of a warning
# raised in a worker (flexcontact.dam's, whose import reaches gmsh) from another thread.
import gmsh  # noqa: F401

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "dolfinx_ext" / "python"))
# Subprocesses (demos, the command line) find this checkout first too, not the clone that
# scripts/setup.sh registered for /usr/bin/python3 last.
os.environ["PYTHONPATH"] = os.pathsep.join(
    [str(ROOT / "dolfinx_ext" / "python")]
    + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])
import flexcontact_checkout  # noqa: E402,F401  (forms/ and meshes/ as flexcontact's subpackages)


def mpirun(n, script, *args, timeout=600, cwd=None, env=None):
    """Run a Python script with `mpirun -n n`; returns the CompletedProcess (check=True)."""
    cmd = ["mpirun", "-n", str(n), "--oversubscribe"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    cmd += ["/usr/bin/python3", str(script), *map(str, args)]
    e = dict(os.environ)
    e["PYTHONPATH"] = str(ROOT / "dolfinx_ext" / "python") + os.pathsep + e.get("PYTHONPATH", "")
    e.update(env or {})
    # Its own process group, so that a timeout ends the ranks too: a rank left waiting in
    # a collective call would otherwise spin on after the test has failed.
    with subprocess.Popen(cmd, cwd=cwd or ROOT, env=e, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, start_new_session=True) as proc:
        try:
            out, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            out, err = proc.communicate()
            raise subprocess.TimeoutExpired(cmd, timeout, out, err)
    if proc.returncode != 0:
        raise subprocess.CalledProcessError(proc.returncode, cmd, out, err)
    return subprocess.CompletedProcess(cmd, 0, out, err)


def on_two_ranks(script, *args, timeout=600, **kwargs):
    """Run ``script`` with ``mpirun -n 2`` from a serial pytest (the MPI tests' pattern);
    skipped when pytest itself runs under MPI or mpirun is missing."""
    from mpi4py import MPI
    if MPI.COMM_WORLD.size > 1:
        pytest.skip("runs its own mpirun")
    if shutil.which("mpirun") is None:
        pytest.skip("mpirun not available")
    return mpirun(2, script, *args, timeout=timeout, **kwargs)


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


# The files that take minutes (a module fixture at the main job's mesh, the wheel's build,
# the 3D sweeps), run first: with one pytest worker per core (scripts/test.sh), a long file
# started last would leave the other cores idle at the end.
LONG_FILES = ("test_dam_reuse_3d.py", "test_install.py", "test_sweep.py", "test_demos_3d.py",
              "test_node_surface.py")


def pytest_collection_modifyitems(config, items):
    rank = {name: k for k, name in enumerate(LONG_FILES)}
    items.sort(key=lambda item: rank.get(item.path.name, len(LONG_FILES)))
