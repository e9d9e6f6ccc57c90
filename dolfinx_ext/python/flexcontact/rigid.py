"""Rigid analytic contact targets: a plane, a circle (2D) or cylinder, a sphere.

A rigid target has no DOFs. Its pairs join each slave node to one *reference point* of the
target (a point of the plane, the centre of the circle or sphere), which the condensed
problem carries as an extra contact node whose DOFs are held (no flexibility, no reaction)
and whose displacement is the target's prescribed translation ``displacement_m``. The normal
is the surface's outward normal at the slave's closest point; for a circle or sphere the
pair's offset R makes the normal gap |x_s − c| − R. Pairs are re-made before every increment
from the current positions, so the curved gap is exact at the start of each increment.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np
from . import names
from .errors import InputError
from .names import check_option

RIGID_KINDS = names.RIGID_KINDS


@dataclass
class RigidTarget:
    """A rigid analytic surface; the slave bodies lie on the side its normal points to.

    Parameters
    ----------
    kind : "plane", "circle" (2D; a cylinder seen in plane strain) or "sphere" (3D).
    point_m : a point of the plane, or the centre of the circle or sphere [m].
    normal : the plane's normal, pointing out of the rigid body towards the slave
        (normalised here); not used for a circle or sphere (the slave lies outside).
    radius_m : the circle's or sphere's radius [m].
    name : used in messages.

    ``displacement_m`` is the target's prescribed translation [m], zero at first; set it
    before an increment (e.g. in ``ContactProblem.solve``'s ``load`` callback).
    """

    kind: str
    point_m: Sequence[float]
    normal: Optional[Sequence[float]] = None
    radius_m: float = 0.0
    name: str = ""
    displacement_m: np.ndarray = field(default=None)

    def __post_init__(self):
        label = self.name or f"rigid {self.kind}"
        check_option(self.kind, RIGID_KINDS, "kind", f"rigid target {label!r}")
        p = np.asarray(self.point_m, dtype=float).reshape(-1)
        if p.size not in (2, 3) or not np.all(np.isfinite(p)):
            raise InputError(f"rigid target {label!r}: point_m={self.point_m!r}; it must be "
                             "2 or 3 finite coordinates")
        self.point_m = p
        if self.kind == "circle" and p.size != 2:
            raise InputError(f"rigid target {label!r}: a circle lives in 2D, got point_m "
                             f"with {p.size} coordinates (use kind='sphere' in 3D)")
        if self.kind == "sphere" and p.size != 3:
            raise InputError(f"rigid target {label!r}: a sphere lives in 3D, got point_m "
                             f"with {p.size} coordinates (use kind='circle' in 2D)")
        if self.kind == "plane":
            n = np.asarray(self.normal if self.normal is not None else [], float).reshape(-1)
            length = float(np.linalg.norm(n)) if n.size == p.size else 0.0
            if not (np.isfinite(length) and length > 0):
                raise InputError(f"rigid target {label!r}: normal={self.normal!r}; a plane "
                                 f"needs a non-zero normal of {p.size} finite components")
            self.normal = n / length
        elif not (np.isfinite(self.radius_m) and self.radius_m > 0):
            raise InputError(f"rigid target {label!r}: radius_m={self.radius_m!r}; it must "
                             "be a finite number > 0")
        if self.displacement_m is None:
            self.displacement_m = np.zeros(p.size)
        self.name = label

    @property
    def dim(self) -> int:
        return self.point_m.size

    def current_displacement(self) -> np.ndarray:
        """The prescribed translation [m], checked."""
        u = np.asarray(self.displacement_m, float).reshape(-1)
        if u.size != self.dim or not np.all(np.isfinite(u)):
            raise InputError(f"rigid target {self.name!r}: displacement_m="
                             f"{self.displacement_m!r}; it must be {self.dim} finite numbers")
        return u

    def normals_and_offsets(self, x: np.ndarray):
        """Outward unit normals (n, d) at the closest points of the current positions x and
        the offsets (n,) of the surface from the current reference point."""
        if self.kind == "plane":
            return np.tile(self.normal, (x.shape[0], 1)), np.zeros(x.shape[0])
        c = self.point_m + self.current_displacement()
        r = x - c
        length = np.linalg.norm(r, axis=1)
        if np.any(length <= 1e-12 * self.radius_m):
            raise InputError(f"rigid target {self.name!r}: a slave node lies at the centre, "
                             "where the closest point of the surface is undefined")
        return r / length[:, None], np.full(x.shape[0], float(self.radius_m))
