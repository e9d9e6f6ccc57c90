"""The README's usage example runs as written and gives a Hertz-like contact."""
import os
import re
import subprocess

from conftest import ROOT


def test_readme_usage_example_runs(tmp_path):
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, "README has no python example"
    code = blocks[0]
    assert len(code.strip().splitlines()) <= 25
    script = tmp_path / "example.py"
    script.write_text(code)
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "dolfinx_ext" / "python")
    out = subprocess.run(["/usr/bin/python3", str(script)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    last = [l for l in out.stdout.splitlines() if l.startswith("increment  10")]
    assert last, out.stdout[-2000:]
    # The cylinder is pressed in: a positive normal force, closed pairs, tiny residual.
    n = float(re.search(r"N =\s*([-+0-9.e]+)", last[0]).group(1))
    assert n > 0
    assert (tmp_path / "results" / "mine" / "mine.xdmf").exists()
