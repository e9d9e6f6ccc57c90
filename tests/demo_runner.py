"""Run a demo as its own process (serial or mpirun) and read its summary.json."""
import json
import os
import subprocess
from pathlib import Path

import numpy as np

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


DEMO_FIELDS = {"displacement": "Node", "contact_pressure": "Node",
               "tangential_traction": "Node", "contact_status": "Node", "von_mises": "Cell",
               "cell_tag": "Cell"}


def assert_xdmf(s, folder, name):
    """The demo's XDMF: one Grid per increment on one mesh, holding every field (double
    precision) and the two bodies' tags; the last step's contact pressure at the slave
    nodes equal to the summary's profile where the summary has one (2D, along x)."""
    from xdmf_case import read
    steps = read(folder / f"{name}.xdmf")
    assert [st["t"] for st in steps] == [float(i + 1) for i in range(len(s["increments"]))]
    assert len({st["seeks"] for st in steps}) == 1
    for st in steps:
        assert {k: v[0] for k, v in st["attributes"].items()} == DEMO_FIELDS
        assert all(v[2] == "8" for k, v in st["attributes"].items() if k != "cell_tag")
    last = steps[-1]["attributes"]
    assert set(np.unique(last["cell_tag"][3])) == {1, 2}
    if "profile" in s and np.ptp(steps[-1]["x"][:, 2]) == 0:
        x, pressure = steps[-1]["x"], last["contact_pressure"][3][:, 0]
        scale = max(s["profile"]["pressure"])
        for xi, pi in zip(s["profile"]["x"], s["profile"]["pressure"]):
            at = np.abs(x[:, 0] - xi) <= 1e-12 * np.abs(x).max()
            assert np.any(np.abs(pressure[at] - pi) <= 1e-12 * scale), (xi, pi)
