"""Stress fields of a dam state for output (cell-wise constant: exact for P1 displacements)."""
from __future__ import annotations

import dolfinx.fem

from .. import compat
from ..forms import lame_fields, max_principal_stress, sigma, von_mises


def stress_fields(V, u, cell_tags, materials: dict, kind: str) -> list:
    """DG0 Functions: the vertical normal stress, the largest principal stress and the von
    Mises stress, in Pa (tension positive), each with the body's own material."""
    msh = V.mesh
    lame = lame_fields(msh, cell_tags, materials)
    V0 = compat.scalar_space(msh, "DG", 0)
    vert = msh.geometry.dim - 1
    exprs = {"sigma_vertical_Pa": sigma(u, lame, kind)[vert, vert],
             "max_principal_stress_Pa": max_principal_stress(u, lame, kind),
             "von_mises_Pa": von_mises(u, lame, kind)}
    out = []
    for name, e in exprs.items():
        f = dolfinx.fem.Function(V0, name=name)
        compat.interpolate_expression(f, e)
        f.x.scatter_forward()
        out.append(f)
    return out
