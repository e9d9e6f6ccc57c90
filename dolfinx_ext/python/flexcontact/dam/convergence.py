"""Grid convergence of the dam job's numbers: Richardson extrapolation from three meshes.

Three meshes refined together by a constant ratio r in element size (the default mesh the
coarsest) give three values f₃ (default), f₂, f₁ (finest) of a quantity. If the error
behaves as C hᵖ, the observed order is

    p = ln((f₃ − f₂) / (f₂ − f₁)) / ln r,

the extrapolated value f_ext = f₁ + (f₁ − f₂) / (rᵖ − 1), and the default mesh's grid
convergence index, its error estimate with Roache's safety factor Fs = 1.25 for three
meshes,

    GCI_default = Fs |f₃ − f_ext| / |f₃|.

The estimate holds only in the asymptotic range: where the differences change sign
(oscillating convergence) or p falls outside [0.5, 3], the quantity is reported as "not
asymptotic" and no error is given (Roache, *Verification and Validation in Computational
Science and Engineering*, 1998; Celik et al., ASME J. Fluids Eng. 130, 2008).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence

from ..errors import InputError

SAFETY_FACTOR = 1.25
"""Roache's factor of safety for a three-mesh study."""
ORDER_RANGE = (0.5, 3.0)
"""Observed orders outside this range are not taken as asymptotic."""
RATIO = math.sqrt(2.0)
"""The refinement ratio of the dam job's study, in element size."""


@dataclass(frozen=True)
class Convergence:
    """The study of one quantity: its values from the default (coarsest) to the finest
    mesh, the observed order, the extrapolated value and the default mesh's relative error
    estimate (None where the meshes are not in the asymptotic range, with ``note`` saying
    why)."""

    values: tuple
    ratio: float
    order: Optional[float]
    extrapolated: Optional[float]
    gci_default: Optional[float]
    note: str

    @property
    def asymptotic(self) -> bool:
        return self.gci_default is not None


def richardson(values: Sequence[float], ratio: float = RATIO) -> Convergence:
    """The three-mesh study of one quantity; ``values`` from the default (coarsest) to the
    finest mesh, ``ratio`` > 1 the element-size ratio between neighbouring meshes."""
    if len(values) != 3:
        raise InputError(f"values={list(values)!r}: give the three meshes' values, default "
                         "(coarsest) first")
    if not (isinstance(ratio, (int, float)) and math.isfinite(ratio) and ratio > 1.0):
        raise InputError(f"ratio={ratio!r}: the refinement ratio must be a number > 1")
    f3, f2, f1 = (float(v) for v in values)
    if not all(math.isfinite(f) for f in (f1, f2, f3)):
        raise InputError(f"values={list(values)!r}: every value must be finite")
    e32, e21 = f3 - f2, f2 - f1
    vals = (f3, f2, f1)
    if e21 == 0.0 and e32 == 0.0:
        return Convergence(vals, ratio, None, f1, 0.0, "the same on the three meshes")
    if e21 == 0.0 or e32 / e21 <= 0.0:
        return Convergence(vals, ratio, None, None, None,
                           "not asymptotic: the changes differ in sign (oscillating)")
    p = math.log(e32 / e21) / math.log(ratio)
    if not ORDER_RANGE[0] <= p <= ORDER_RANGE[1]:
        return Convergence(vals, ratio, p, None, None,
                           f"not asymptotic: observed order {p:.2f} outside "
                           f"[{ORDER_RANGE[0]:g}, {ORDER_RANGE[1]:g}]")
    f_ext = f1 + (f1 - f2) / (ratio ** p - 1.0)
    gci = SAFETY_FACTOR * abs(f3 - f_ext) / abs(f3) if f3 != 0.0 else math.inf
    return Convergence(vals, ratio, p, f_ext, gci, "")
