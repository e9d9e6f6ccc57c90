"""The energy account of the Moreau–Jean θ-scheme, step by step (docs/impact.md).

For θ = ½ the scheme satisfies exactly (multiply the discrete momentum balance by the
mid-step velocity v_m = (v⁺ + v⁻)/2, with u⁺ − u⁻ = h v_m):

    ΔE_kin + ΔE_strain = f·Δu − h v_mᵀ C v_m + Σ_k P_k·(U_k⁺ + U_k⁻)/2

The last term is the work of the contact impulses. Its tangential part at U_t⁺,
Σ P_t·U_t⁺ ≤ 0, is the friction dissipation; the rest is the scheme's own contact
dissipation: ½ P_n (1 − e) U_n⁻ ≤ 0 for a pair that closes with restitution e (zero for
e = 1), plus ½ P_t·(U_t⁻ − U_t⁺) of the tangential jump. Each term is computed here from its
own definition, so the balance E_kin + E_strain + D_friction + D_damping + D_contact − W_ext
= E_0 checks the implementation; for θ > ½ it also shows the scheme's numerical damping.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class EnergyAccount:
    """Energies [J; J/m per unit thickness in 2D], cumulative terms since the start."""

    kinetic: float = 0.0
    strain: float = 0.0
    external_work: float = 0.0     # W_ext = Σ f·Δu
    friction: float = 0.0          # D_friction = −Σ P_t·U_t⁺ ≥ 0
    damping: float = 0.0           # D_damping = Σ h v_θᵀ C v_θ ≥ 0
    contact: float = 0.0           # D_contact = −Σ P·(U⁺ + U⁻)/2 − D_friction (scheme)
    initial: float = 0.0           # E_0 = E_kin + E_strain at t = 0
    history: list = field(default_factory=list, repr=False)

    @property
    def total(self) -> float:
        """E_kin + E_strain."""
        return self.kinetic + self.strain

    @property
    def balance_error(self) -> float:
        """E + D_friction + D_damping + D_contact − W_ext − E_0 [J]."""
        return (self.total + self.friction + self.damping + self.contact
                - self.external_work - self.initial)

    @property
    def balance_error_rel(self) -> float:
        """balance_error relative to the largest energy seen (E_0 and W_ext included)."""
        scale = max([abs(self.initial), abs(self.external_work)]
                    + [abs(h["total"]) for h in self.history] + [1e-300])
        return self.balance_error / scale

    def start(self, kinetic: float, strain: float) -> None:
        self.kinetic, self.strain = kinetic, strain
        self.initial = kinetic + strain

    def add_step(self, kinetic: float, strain: float, external: float, damping: float,
                 contact_work: float, friction_work: float) -> None:
        """Book one step: the new energies and the step's works (signs as in the docstring)."""
        self.kinetic, self.strain = kinetic, strain
        self.external_work += external
        self.damping += damping
        self.friction -= friction_work
        self.contact -= contact_work - friction_work
        self.history.append(self.row())

    def row(self) -> dict:
        d = {k: getattr(self, k) for k in ("kinetic", "strain", "external_work", "friction",
                                            "damping", "contact", "initial")}
        d["total"] = self.total
        d["balance_error"] = self.balance_error
        return d
