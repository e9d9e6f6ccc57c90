"""The shape of a log's front end, in the log's own frame, for the meshes and the scenario.

The log is a solid of revolution about its axis (3D), or its axial section (2D, a slab):
axial coordinate ``x`` from -L/2 (back) to +L/2 (front), radius R = D/2. The back end is
flat; the front end is one of

* ``flat``: the sawn end, a disc (a segment in 2D) at x = L/2;
* ``chamfered``: a 45° bevel of size c (0 < c < R): the end disc has radius R - c, and a
  cone frustum joins it to the shaft at x = L/2 - c;
* ``rounded``: a spherical cap of radius ρ ≥ R (a circular arc in 2D) whose rim is the shaft's
  rim, so its depth is ρ - √(ρ² - R²): ρ = R is a hemisphere, a larger ρ is flatter.

The log's length stays L whatever the end: the shaping removes wood. Everything here is
pure geometry (no gmsh, no DOLFINx): the support function that places the log at its gap
from the dam, its point nearest the dam, and its exact volume.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from flexcontact.errors import InputError

SHAPES = ("flat", "chamfered", "rounded")


def _real(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


@dataclass(frozen=True)
class LogEnd:
    """A front-end shape. ``chamfer_m`` is read for ``chamfered`` only, ``radius_m`` (the
    cap's sphere radius) for ``rounded`` only; :meth:`check` names a bad one."""

    shape: str = "flat"
    chamfer_m: float = 0.0
    radius_m: float = 0.0

    def check(self, diameter_m: float, names=("log_end_shape", "log_end_chamfer_m",
                                              "log_end_radius_m")) -> LogEnd:
        """``self`` if it fits a log of ``diameter_m``, else InputError naming the parameter
        (``names``: the caller's names of shape, chamfer and radius)."""
        R = 0.5 * diameter_m
        if not isinstance(self.shape, str) or self.shape not in SHAPES:
            raise InputError(f"{names[0]}={self.shape!r}: unknown end shape (one of "
                             f"{list(SHAPES)})")
        if self.shape == "chamfered":
            c = self.chamfer_m
            if not (_real(c) and 0.0 < c < R):
                raise InputError(f"{names[1]}={c!r}: a chamfer must be > 0 and < D/2 = "
                                 f"{R!r} m (the log's radius)")
        if self.shape == "rounded":
            rho = self.radius_m
            if not (_real(rho) and rho >= R):
                raise InputError(f"{names[2]}={rho!r}: the end cap's radius must be >= D/2 = "
                                 f"{R!r} m (D/2 is a hemisphere, larger is flatter)")
        return self

    # ---- profile ------------------------------------------------------------------------
    def depth_m(self, radius_m: float) -> float:
        """Axial extent of the shaped end: 0 (flat), c (chamfered) or the cap's height."""
        if self.shape == "chamfered":
            return float(self.chamfer_m)
        if self.shape == "rounded":
            rho = float(self.radius_m)
            return rho - math.sqrt(max(rho * rho - radius_m * radius_m, 0.0))
        return 0.0

    def rims(self, length_m: float, radius_m: float) -> list:
        """The circles (axial x, radius) whose convex hull, with the cap, is the log."""
        h = 0.5 * length_m
        if self.shape == "flat":
            return [(-h, radius_m), (h, radius_m)]
        out = [(-h, radius_m), (h - self.depth_m(radius_m), radius_m)]
        if self.shape == "chamfered":
            out.append((h, radius_m - float(self.chamfer_m)))
        return out

    def cap(self, length_m: float, radius_m: float):
        """(axial centre, radius, cos of the cap's half-angle) of the rounded end's sphere,
        or None."""
        if self.shape != "rounded":
            return None
        rho = float(self.radius_m)
        return (0.5 * length_m - rho, rho,
                math.sqrt(max(rho * rho - radius_m * radius_m, 0.0)) / rho)

    # ---- placing the log ----------------------------------------------------------------
    def support(self, length_m: float, radius_m: float, axis, direction):
        """(h, x, q): the log's largest extent h beyond its centre along the unit
        ``direction``, for a log along the unit ``axis``, and where it is reached: the point
        x·axis + q from the centre. A face or rim square to ``direction`` gives its
        centre."""
        a, d = np.asarray(axis, float), np.asarray(direction, float)
        ad = float(a @ d)
        radial = d - ad * a
        n = float(np.linalg.norm(radial))
        best = None
        for x, r in self.rims(length_m, radius_m):
            h = x * ad + r * math.sqrt(max(1.0 - ad * ad, 0.0))
            if best is None or h > best[0]:
                best = (h, x, r * radial / n if n > 1e-12 else np.zeros_like(d))
        cap = self.cap(length_m, radius_m)
        if cap is not None and ad >= cap[2]:  # the direction meets the cap, not its rim
            x, rho, _ = cap
            h = x * ad + rho
            if h >= best[0]:
                best = (h, x, rho * d)
        return best

    # ---- mass ---------------------------------------------------------------------------
    def volume_m3(self, length_m: float, radius_m: float) -> float:
        """The 3D log's volume: πR²L less the wood the end's shape removes."""
        R, L = radius_m, length_m
        full = math.pi * R * R * L
        if self.shape == "chamfered":
            c = float(self.chamfer_m)
            return full - (math.pi * R * R * c - math.pi * (R ** 3 - (R - c) ** 3) / 3.0)
        if self.shape == "rounded":
            rho, d = float(self.radius_m), self.depth_m(R)
            return full - (math.pi * R * R * d - math.pi * d * d * (3.0 * rho - d) / 3.0)
        return full

    def area_m2(self, length_m: float, radius_m: float) -> float:
        """The 2D log's area (the slab's section): 2RL less what the end removes."""
        R, L = radius_m, length_m
        full = 2.0 * R * L
        if self.shape == "chamfered":
            c = float(self.chamfer_m)
            return full - c * c
        if self.shape == "rounded":
            rho, d = float(self.radius_m), self.depth_m(R)
            segment = rho * rho * math.asin(R / rho) - (rho - d) * R
            return full - (2.0 * R * d - segment)
        return full
