"""Linear elastic isotropic material (SI units)."""

import math
import numbers
from dataclasses import dataclass

from flexcontact.errors import InputError
from flexcontact.names import ELASTICITY_KINDS, check_option

KINDS = ELASTICITY_KINDS


def _real(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool)


def check_kind(kind: str) -> str:
    """Return ``kind`` if it is one of :data:`KINDS` (names.ElasticityKind), else raise
    InputError."""
    return check_option(kind, KINDS, "kind")


@dataclass(frozen=True)
class Material:
    """Isotropic linear elastic material.

    Attributes:
        E_Pa: Young's modulus E in Pa (finite, > 0).
        nu: Poisson's ratio ν (dimensionless, −1 < ν < 0.5).
        rho_kg_m3: mass density ρ in kg/m³ (≥ 0; 0 means massless, statics only).
        name: label used in error messages and reports.
    """

    E_Pa: float
    nu: float
    rho_kg_m3: float = 0.0
    name: str = ""

    def __post_init__(self):
        label = f" (material {self.name!r})" if self.name else ""
        if not (_real(self.E_Pa) and math.isfinite(self.E_Pa) and self.E_Pa > 0):
            raise InputError(
                f"E_Pa={self.E_Pa!r}{label}: Young's modulus must be finite and > 0 Pa")
        if not (_real(self.nu) and -1.0 < self.nu < 0.5):
            raise InputError(f"nu={self.nu!r}{label}: Poisson's ratio must satisfy -1 < nu < 0.5")
        if not (_real(self.rho_kg_m3) and math.isfinite(self.rho_kg_m3)
                and self.rho_kg_m3 >= 0):
            raise InputError(
                f"rho_kg_m3={self.rho_kg_m3!r}{label}: density must be finite and >= 0 kg/m³")

    @property
    def mu_Pa(self) -> float:
        """Shear modulus μ = E / (2(1 + ν)) in Pa."""
        return self.E_Pa / (2.0 * (1.0 + self.nu))

    @property
    def lmbda_Pa(self) -> float:
        """3D Lamé constant λ = E ν / ((1 + ν)(1 − 2ν)) in Pa."""
        return self.E_Pa * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    def lame(self, kind: str = "3d"):
        """(μ, λ) in Pa for ``kind``; plane stress gives the effective λ* = 2μλ/(λ + 2μ)."""
        check_kind(kind)
        mu, lmbda = self.mu_Pa, self.lmbda_Pa
        if kind == "plane_stress":
            lmbda = 2.0 * mu * lmbda / (lmbda + 2.0 * mu)
        return mu, lmbda

    @property
    def E_plane_strain_Pa(self) -> float:
        """Plane-strain modulus E/(1 − ν²) in Pa (Hertz: 1/E* = Σ 1/E_plane_strain)."""
        return self.E_Pa / (1.0 - self.nu ** 2)


def effective_modulus(m1: Material, m2: Material) -> float:
    """Hertz contact modulus E* = [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]⁻¹ in Pa."""
    return 1.0 / (1.0 / m1.E_plane_strain_Pa + 1.0 / m2.E_plane_strain_Pa)
