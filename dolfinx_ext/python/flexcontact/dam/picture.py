"""A ParaView picture of the dam's stress field (pvbatch under xvfb-run), if ParaView is
installed: the demo reports that it is missing rather than failing."""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np

SCRIPT = Path(__file__).with_name("pv_stress_picture.py")


def render_stress_picture(xdmf_path, png_path, scale: float,
                          field: str = "max_principal_stress_Pa", body_tag=None,
                          timeout_s: float = 120.0,
                          bound: float | None = None) -> tuple[bool, str]:
    """Render the last time of ``xdmf_path`` warped by ``scale`` and coloured by ``field``
    (cells tagged ``body_tag`` only, if given: one tag or several) to ``png_path``, on the colour scale
    ±``bound`` (values beyond it saturate; None: the field's largest magnitude). Returns
    (done, message): done is False, with the reason, when pvbatch or xvfb-run is missing
    or fails."""
    pvbatch, xvfb = shutil.which("pvbatch"), shutil.which("xvfb-run")
    if pvbatch is None:
        return False, "pvbatch not found (Debian packages paraview, python3-paraview)"
    cmd = [pvbatch, str(SCRIPT), str(xdmf_path), str(png_path), repr(float(scale)), field]
    tags = ([] if body_tag is None else
            [body_tag] if np.isscalar(body_tag) else list(body_tag))
    cmd.append(",".join(str(int(t)) for t in tags) if tags else "all")
    if bound is not None:
        cmd.append(repr(float(bound)))
    if xvfb is not None:
        # xvfb-run's default screen (8-bit, no GLX) cannot host an OpenGL window.
        cmd = [xvfb, "-a", "-s", "-screen 0 1280x1024x24 +extension GLX", *cmd]
    # Three tries: a virtual X server started while others start theirs can fail to
    # connect (seen here about one start in three on a busy machine).
    for _ in range(3):
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
        except (OSError, subprocess.TimeoutExpired) as err:
            return False, f"pvbatch failed: {err}"
        if proc.returncode == 0 and Path(png_path).exists():
            break
    else:
        tail = (proc.stderr or proc.stdout)[-400:].strip()
        return False, f"pvbatch exited with {proc.returncode}: {tail}"
    return True, "rendered by pvbatch" + (" under xvfb-run" if xvfb else "")
