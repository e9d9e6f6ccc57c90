"""Run a demo as its own process (serial or mpirun) and read its summary.json."""
import json
import os
import subprocess
from pathlib import Path

from conftest import ROOT, mpirun


def run_demo(name, *args, results, ranks=1, timeout=900, subfolder=""):
    env = {"FLEXCONTACT_RESULTS": str(results)}
    script = ROOT / "demos" / f"{name}.py"
    if ranks == 1:
        e = dict(os.environ)
        e["PYTHONPATH"] = str(ROOT / "dolfinx_ext" / "python") + os.pathsep + e.get("PYTHONPATH", "")
        e.update(env)
        proc = subprocess.run(["/usr/bin/python3", str(script), *map(str, args)], cwd=ROOT,
                              env=e, capture_output=True, text=True, timeout=timeout)
        if proc.returncode != 0:
            raise AssertionError(f"{name} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    else:
        try:
            mpirun(ranks, script, *args, env=env, timeout=timeout)
        except subprocess.CalledProcessError as e:
            raise AssertionError(f"{name} failed on {ranks} ranks:\n{e.stdout[-3000:]}\n{e.stderr[-3000:]}")
    folder = Path(results) / name / subfolder
    return json.loads((folder / "summary.json").read_text()), folder


# What the tests know of the demos' set-up (their defaults). The analytic references are
# recomputed from these and the loads the demos reached, never read back from the demos;
# a demo that changes a default without its test fails here instead of shifting its own
# reference.
STEEL = {"E_Pa": 200e9, "nu": 0.3}
ALUMINIUM = {"E_Pa": 70e9, "nu": 0.33}
R_HERTZ = 0.05        # cylinder and sphere radius [m]
A_TARGET = 0.1 * R_HERTZ  # contact half-width / radius the load aims at [m]
MU = 0.3              # friction coefficient of the sliding and Cattaneo–Mindlin demos
NORMAL_INCREMENTS = 2  # normal stage of the two sliding-block demos


def assert_inputs(s, materials, **values):
    """The demo ran with the materials and inputs the test computes its references from."""
    assert s["materials"] == materials, s["materials"]
    for key, value in values.items():
        assert s[key] == value, (key, s[key], value)


def first_gross_slip(s, n1=NORMAL_INCREMENTS):
    """Index of the first increment after the normal stage in which no pair sticks."""
    return next(i for i, inc in enumerate(s["increments"])
                if i >= n1 and inc["stick"] == 0 and inc["slip"] > 0)
