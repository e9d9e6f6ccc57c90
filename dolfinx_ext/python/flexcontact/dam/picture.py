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
    (cells tagged ``body_tag`` only, if given) to ``png_path``, on the colour scale
    ±``bound`` (values beyond it saturate; None: the field's largest magnitude). Returns
    (done, message): done is False, with the reason, when pvbatch or xvfb-run is missing
    or fails."""
    pvbatch, xvfb = shutil.which("pvbatch"), shutil.which("xvfb-run")
    if pvbatch is None:
        return False, "pvbatch not found (Debian packages paraview, python3-paraview)"
    cmd = [pvbatch, str(SCRIPT), str(xdmf_path), str(png_path), repr(float(scale)), field]
    cmd.append(str(int(body_tag)) if body_tag is not None else "all")
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


def warp_scale(u, cell_tags, tag: int, length_m: float, fraction: float = 0.05) -> float:
    """Warp factor that moves the body tagged ``tag`` by ``fraction`` × ``length_m`` at its
    largest displacement (its own nodes only: the log's rigid travel would swamp the dam's
    millimetres). Collective."""
    import dolfinx.fem
    from mpi4py import MPI
    from .. import compat
    V = u.function_space
    tdim = V.mesh.topology.dim
    compat.create_connectivity(V.mesh, tdim, tdim)  # DOLFINx 0.9 needs it for cell entities
    cells = cell_tags.indices[cell_tags.values == tag]
    blocks = dolfinx.fem.locate_dofs_topological(V, tdim, cells)
    bs = V.dofmap.index_map_bs
    vals = u.x.array.reshape(-1, bs)[blocks]
    local = float(np.linalg.norm(vals, axis=1).max(initial=0.0))
    umax = V.mesh.comm.allreduce(local, op=MPI.MAX)
    return fraction * length_m / max(umax, 1e-30)
