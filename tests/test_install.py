"""The wheel is complete: built from the checkout, installed into a fresh virtual
environment, it holds every subpackage of the source tree and runs from outside the
checkout: ``python -m flexcontact info``, a sweep of two scenarios, and a two-increment
Hertz problem.

The build must work offline: pip may use only the system's setuptools and the Debian
packages seen through --system-site-packages. The C++ build reuses build/temp.* of the
checkout, so only the first run compiles everything.
"""
import importlib.util
import json
import os
import subprocess
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PYTHON = "/usr/bin/python3"
PACKAGE = ROOT / "dolfinx_ext" / "python" / "flexcontact"

HERTZ = """
from mpi4py import MPI
import ufl, flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import hertz2d, tags
msh, cells, facets, geo = hertz2d.build(MPI.COMM_WORLD, refine=0)
V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
steel = forms.Material(E_Pa=200e9, nu=0.3)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")
fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
push, (ux, uy) = fc.dirichlet(V, facets, tags.LOADED)
pb = fc.ContactProblem(a, None, fixed + push,
                       fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=0.3))
pb.solve(2, load=lambda i, t: setattr(uy, "value", -2e-5 * t), verbose=False)
s = pb.increments[-1].summary
print(fc.__file__)
print(s.normal_force, s.stick + s.slip, s.residual)
"""

SWEEP = """
[parameters.log_speed_m_s]
values = [2.0, 3.0]

[engine]
evaluator = "reuse"
kind = "serial"

[output]
plots = false
"""


def source_subpackages() -> set[str]:
    """Dotted names of every package of the source tree, forms/ and meshes/ included."""
    out = {"flexcontact", "flexcontact.forms", "flexcontact.meshes"}
    for init in PACKAGE.rglob("__init__.py"):
        rel = init.parent.relative_to(PACKAGE)
        out.add(".".join(("flexcontact",) + rel.parts))
    return out


def _venv_available():
    # Debian puts ensurepip, which venv needs, in the separate package python3-venv.
    return Path(PYTHON).exists() and importlib.util.find_spec("ensurepip") is not None


def test_the_source_tree_lists_its_subpackages():
    """What the wheel is checked against: the package, its dam and sweep, forms/, meshes/."""
    assert {"flexcontact.dam", "flexcontact.sweep"} <= source_subpackages()


@pytest.mark.slow
@pytest.mark.skipif(not _venv_available(),
                    reason="python3 -m venv needs ensurepip (Debian package python3-venv)")
def test_wheel_installs_complete_and_runs_outside_the_checkout(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    # No index: any dependency pip would try to fetch makes the build fail here.
    env.update(PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    # The build from scratch is the suite's longest test: let it use every core (setup.py
    # builds serially otherwise), as the other pytest workers finish.
    env.setdefault("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
    dist = tmp_path / "dist"
    build = subprocess.run([PYTHON, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps",
                            "-w", str(dist), str(ROOT)], env=env, capture_output=True,
                           text=True, timeout=1800)
    assert build.returncode == 0, build.stdout[-4000:] + build.stderr[-4000:]
    wheel, = dist.glob("flexcontact-*.whl")
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
    in_wheel = {str(Path(n).parent).replace("/", ".") for n in names
                if n.endswith("/__init__.py")}
    missing = source_subpackages() - in_wheel
    assert not missing, f"subpackages missing from the wheel: {sorted(missing)}"
    assert any(n.startswith("flexcontact/_cpp") for n in names), "no compiled module"

    venv = tmp_path / "venv"
    subprocess.run([PYTHON, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    py = str(venv / "bin" / "python")
    pip = subprocess.run([py, "-m", "pip", "install", "--no-deps", str(wheel)], env=env,
                         capture_output=True, text=True, timeout=600)
    assert pip.returncode == 0, pip.stdout[-4000:] + pip.stderr[-4000:]

    # Everything below runs from a folder outside the checkout.
    work = tmp_path / "work"
    work.mkdir()

    def run(*args, timeout=900):
        r = subprocess.run([py, *args], cwd=work, env=env, capture_output=True, text=True,
                           timeout=timeout)
        assert r.returncode == 0, f"{args}: {r.stdout[-3000:]}{r.stderr[-3000:]}"
        return r.stdout

    info = json.loads(run("-m", "flexcontact", "info"))
    assert info["mumps"] is True and info["flexcontact"]

    out = run("-c", HERTZ).strip().splitlines()
    installed = Path(out[-2]).resolve()
    assert venv.resolve() in installed.parents, installed
    links = [str(p) for p in installed.parent.rglob("*") if p.is_symlink()]
    assert not links, f"the installed package holds links: {links}"
    normal, closed, residual = out[-1].split()
    assert float(normal) > 0 and int(closed) > 0 and float(residual) < 1e-8

    (work / "two.toml").write_text(SWEEP)
    run("-m", "flexcontact", "sweep", "two.toml", "--out", "sweep")
    rows = (work / "sweep" / "results.jsonl").read_text().splitlines()
    assert len(rows) == 2
    assert (work / "sweep" / "results.csv").is_file()


def test_the_suite_runs_this_checkout_whichever_clone_is_registered():
    """The tests import this checkout's package with its forms/ and meshes/, and so do
    their subprocesses, even when scripts/setup.sh of another clone registered that clone
    for /usr/bin/python3 last (tests/conftest.py)."""
    import flexcontact
    from flexcontact import forms, meshes
    for module in (flexcontact, forms, meshes):
        assert Path(module.__file__).resolve().is_relative_to(ROOT), module.__file__
    code = ("import flexcontact, flexcontact.forms, flexcontact.meshes as m; "
            "print(flexcontact.__file__); print(m.__file__)")
    out = subprocess.run([PYTHON, "-c", code], cwd="/", capture_output=True, text=True,
                         check=True).stdout.split()
    assert [Path(p).resolve().is_relative_to(ROOT) for p in out] == [True, True], out
