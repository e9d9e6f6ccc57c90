"""Stress fields of a dam state for output (cell-wise constant: exact for P1 displacements)."""
from __future__ import annotations

import dolfinx.fem

from .. import compat
from ..forms import lame_fields, max_principal_stress, sigma, von_mises


class StressFields:
    """DG0 Functions of the displacement Function ``u``: the vertical normal stress, the
    largest principal stress and the von Mises stress, in Pa (tension positive), each with
    the body's own material. The expressions are compiled once; :meth:`update` interpolates
    them for the current ``u`` (cheap enough for every time step)."""

    def __init__(self, V, u, cell_tags, materials: dict, kind: str):
        msh = V.mesh
        lame = lame_fields(msh, cell_tags, materials)
        V0 = compat.scalar_space(msh, "DG", 0)
        vert = msh.geometry.dim - 1
        exprs = {"sigma_vertical_Pa": sigma(u, lame, kind)[vert, vert],
                 "max_principal_stress_Pa": max_principal_stress(u, lame, kind),
                 "von_mises_Pa": von_mises(u, lame, kind)}
        self.functions = [dolfinx.fem.Function(V0, name=name) for name in exprs]
        points = compat.interpolation_points(V0)
        self._exprs = [dolfinx.fem.Expression(e, points) for e in exprs.values()]
        self._names = list(exprs)
        self._msh = msh

    def update(self) -> list:
        """Interpolate for the current displacement; returns the three Functions."""
        for f, e in zip(self.functions, self._exprs):
            f.interpolate(e)
            f.x.scatter_forward()
        return self.functions


def stress_fields(V, u, cell_tags, materials: dict, kind: str) -> list:
    """The three DG0 stress Functions of :class:`StressFields` for ``u`` as it is now."""
    return StressFields(V, u, cell_tags, materials, kind).update()
