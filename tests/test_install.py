"""`pip install .` into a fresh virtual environment gives an importable flexcontact.

The install must work offline: pip may use only the system's setuptools and the Debian
packages seen through --system-site-packages. The C++ build reuses build/temp.* of the
checkout, so only the first run compiles everything.
"""
import importlib.util
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PYTHON = "/usr/bin/python3"
CHECK = ("import flexcontact, flexcontact.forms, flexcontact.meshes, flexcontact._cpp; "
         "print(flexcontact.__file__)")


def _venv_available():
    # Debian puts ensurepip, which venv needs, in the separate package python3-venv.
    return Path(PYTHON).exists() and importlib.util.find_spec("ensurepip") is not None


@pytest.mark.slow
@pytest.mark.skipif(not _venv_available(),
                    reason="python3 -m venv needs ensurepip (Debian package python3-venv)")
def test_pip_install_in_fresh_venv(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([PYTHON, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    py = venv / "bin" / "python"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    # No index: any dependency pip would try to fetch makes the install fail here.
    env.update(PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    pip = subprocess.run([str(py), "-m", "pip", "install", "--no-build-isolation", str(ROOT)],
                         env=env, capture_output=True, text=True, timeout=1800)
    assert pip.returncode == 0, pip.stdout[-4000:] + pip.stderr[-4000:]

    # Run from elsewhere so that the checkout's own package cannot be the one imported.
    run = subprocess.run([str(py), "-c", CHECK], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    installed = Path(run.stdout.strip().splitlines()[-1]).resolve()
    assert venv.resolve() in installed.parents, installed

    package = installed.parent
    links = [str(p) for p in package.rglob("*") if p.is_symlink()]
    assert not links, f"the installed package holds links: {links}"
    for sub in ("forms", "meshes"):
        assert (package / sub / "__init__.py").is_file()
