"""UFL forms for flexcontact: materials, elasticity, stress measures, mass and loads.

Everything is in SI units: lengths in m, stresses and moduli in Pa, densities in kg/m³,
accelerations in m/s². The package depends on UFL and, for the piecewise-constant material
fields only, on DOLFINx.

``kind`` selects the elasticity model everywhere:

* ``"plane_strain"`` — 2D, ε_zz = 0, σ_zz = λ tr ε = ν (σ_xx + σ_yy);
* ``"plane_stress"`` — 2D, σ_zz = 0 (the 3D Lamé λ is replaced by 2μλ/(λ + 2μ));
* ``"3d"`` — full 3D.
"""

from .material import KINDS, Material, check_kind, effective_modulus
from .elasticity import (elasticity_form, epsilon, lame_fields, max_principal_stress,
                         sigma, stress_3x3, von_mises)
from .loads import gravity, hydrostatic_pressure, mass_form, surface_traction

__all__ = ["KINDS", "Material", "check_kind", "effective_modulus", "elasticity_form", "epsilon",
           "lame_fields",
           "max_principal_stress", "sigma", "stress_3x3", "von_mises", "gravity",
           "hydrostatic_pressure", "mass_form", "surface_traction"]
