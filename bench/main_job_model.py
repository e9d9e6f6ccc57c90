"""The main job's dam model for the bench scripts (run as scripts: bench/ is on sys.path)."""
import subprocess
import sys
import time
from pathlib import Path
from typing import Optional

ROOT = Path(__file__).resolve().parents[1]


def main_job_model(given: Optional[str], tmp: str) -> tuple:
    """(the model's folder, the seconds its prepare took): the folder ``given``, or
    ``examples/dam_model_main_job.toml`` prepared into ``tmp`` (None seconds if given)."""
    if given:
        return Path(given), None
    model = Path(tmp) / "model"
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "flexcontact", "dam", "prepare",
                    str(ROOT / "examples/dam_model_main_job.toml"), "--out", str(model)],
                   check=True, cwd=ROOT, capture_output=True)
    return model, time.perf_counter() - t0
