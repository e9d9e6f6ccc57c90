"""Run a demo as its own process (serial or mpirun) and read its summary.json."""
import json
import os
import subprocess
from pathlib import Path

from conftest import ROOT, mpirun


def run_demo(name, *args, results, ranks=1, timeout=900):
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
    folder = Path(results) / name
    return json.loads((folder / "summary.json").read_text()), folder
