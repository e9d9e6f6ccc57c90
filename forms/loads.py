"""Linear forms for loads, and the mass form (SI units).

The vertical axis is the last coordinate (y in 2D, z in 3D) unless ``vertical_axis`` says
otherwise; gravity points towards negative values of it.
"""

import ufl
from ufl.domain import extract_unique_domain

from .material import Material
from flexcontact.errors import InputError

WATER_DENSITY_KG_M3 = 1000.0
STANDARD_GRAVITY_M_S2 = 9.81


def _as_vector(t):
    """A UFL vector from a UFL expression or a sequence of numbers/expressions."""
    if isinstance(t, ufl.core.expr.Expr):
        return t
    return ufl.as_vector(list(t))


def _density(rho):
    if isinstance(rho, Material):
        return rho.rho_kg_m3
    return rho


def _axis(v, vertical_axis):
    d = v.ufl_shape[0]
    axis = d - 1 if vertical_axis is None else vertical_axis
    if not -d <= axis < d:
        raise InputError(f"vertical_axis={vertical_axis!r} out of range for dimension {d}")
    return d, axis % d


def surface_traction(v, t_vector, ds):
    """L(v) = ∫ t·v ds, traction t in Pa (force per area; per length·thickness in 2D).

    ``ds`` is the boundary measure, usually already restricted: ``ds(LOADED)``.
    """
    t = _as_vector(t_vector)
    if t.ufl_shape != v.ufl_shape:
        raise InputError(f"t_vector has shape {t.ufl_shape}, the test function {v.ufl_shape}")
    return ufl.dot(t, v) * ds


def gravity(v, rho, dx, g=STANDARD_GRAVITY_M_S2, vertical_axis=None):
    """L(v) = ∫ −ρ g e_vertical·v dx: self-weight, ρ in kg/m³, g in m/s².

    ``rho`` may be a number, a UFL expression or a :class:`Material`; ``dx`` is the cell
    measure of the body (e.g. ``dx(BASE)``).
    """
    d, axis = _axis(v, vertical_axis)
    return -_density(rho) * g * v[axis] * dx


def hydrostatic_pressure(v, ds, level, rho_w=WATER_DENSITY_KG_M3, g=STANDARD_GRAVITY_M_S2,
                         vertical_axis=None):
    """L(v) = ∫ −p n·v ds with p = ρ_w g max(level − z, 0) in Pa.

    Water with free surface at height ``level`` (m) presses on the wetted part of the
    boundary ``ds`` (e.g. the upstream face of a dam); n is the outward unit normal, so the
    pressure pushes into the body. Points above the water level carry no load.
    """
    d, axis = _axis(v, vertical_axis)
    x = ufl.SpatialCoordinate(extract_unique_domain(v))
    n = ufl.FacetNormal(extract_unique_domain(v))
    p = rho_w * g * ufl.max_value(level - x[axis], 0.0)
    return -p * ufl.dot(n, v) * ds


def mass_form(u, v, rho, dx):
    """Mass bilinear form m(u, v) = ∫ ρ u·v dx (kg·m² for u, v in m).

    ``rho`` is a number / UFL expression (kg/m³) or ``{cell_tag: Material}``, in which case
    the sum over ``dx(tag)`` is returned (``dx`` must carry the cell tags).
    """
    if isinstance(rho, dict):
        if not rho:
            raise InputError("rho={}: need at least one cell tag -> Material")
        forms = [_density(m) * ufl.dot(u, v) * dx(tag) for tag, m in sorted(rho.items())]
        return sum(forms[1:], forms[0])
    return _density(rho) * ufl.dot(u, v) * dx
