"""The energy account of the Moreau–Jean θ-scheme, step by step (docs/impact.md).

Multiplying the discrete momentum balance by v_θ = θv⁺ + (1 − θ)v⁻ = (u⁺ − u⁻)/h gives,
exactly and for every θ,

    ΔE_kin + ΔE_strain = f·Δu − h v_θᵀ C v_θ + Σ_k P_k·U_k^θ − (θ − ½)(‖Δv‖²_M + ‖Δu‖²_K)

with U^θ = θU⁺ + (1 − θ)U⁻ the pairs' relative velocity of the step (h U^θ is their relative
displacement). The contact term splits into the work of the tangential impulses along the
step's slip, Σ P_t·U_t^θ (minus the friction dissipation), and the work of the normal
impulses, Σ P_n U_n^θ (minus the scheme's own contact dissipation): for a closing pair with
restitution e, P_n U_n^θ = (1 − θ − θe) P_n U_n⁻, i.e. ½ (1 − e) P_n U_n⁻ ≤ 0 for θ = ½
(zero for e = 1). On a crushable interface (docs/crushing.md) the normal work of the pairs
at their cap is the crushing dissipation D_crushing = Σ P_n max(0, −U_n^θ) (the capped force
times the crush increment) and is booked apart from D_contact. The last term is the
θ-method's numerical dissipation, zero for θ = ½. Each term is computed here from its own
definition, so the balance E_kin + E_strain + D_friction + D_damping + D_contact +
D_crushing + D_numerical − W_ext = E_0 checks the implementation.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class EnergyAccount:
    """Energies [J; J/m per unit thickness in 2D], cumulative terms since the start."""

    kinetic: float = 0.0
    strain: float = 0.0
    external_work: float = 0.0     # W_ext = Σ f·Δu
    friction: float = 0.0          # D_friction = −Σ P_t·U_t^θ
    damping: float = 0.0           # D_damping = Σ h v_θᵀ C v_θ ≥ 0
    contact: float = 0.0           # D_contact = −Σ P_n U_n^θ − D_crushing (the scheme's)
    crushing: float = 0.0          # D_crushing = Σ P_n max(0, −U_n^θ) at the cap ≥ 0
    numerical: float = 0.0         # D_numerical = Σ (θ − ½)(‖Δv‖²_M + ‖Δu‖²_K) ≥ 0
    initial: float = 0.0           # E_0 = E_kin + E_strain at t = 0
    history: list = field(default_factory=list, repr=False)

    @property
    def total(self) -> float:
        """E_kin + E_strain."""
        return self.kinetic + self.strain

    @property
    def balance_error(self) -> float:
        """E + D_friction + D_damping + D_contact + D_crushing + D_numerical − W_ext − E_0
        [J]."""
        return (self.total + self.friction + self.damping + self.contact + self.crushing
                + self.numerical - self.external_work - self.initial)

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
                 contact_work: float, friction_work: float, numerical: float = 0.0,
                 crush_work: float = 0.0) -> None:
        """Book one step: the new energies and the step's works (signs as in the docstring;
        ``crush_work`` is the step's D_crushing, a part of −contact_work)."""
        self.kinetic, self.strain = kinetic, strain
        self.external_work += external
        self.damping += damping
        self.friction -= friction_work
        self.contact -= contact_work - friction_work + crush_work
        self.crushing += crush_work
        self.numerical += numerical
        self.history.append(self.row())

    def row(self) -> dict:
        d = {k: getattr(self, k) for k in ("kinetic", "strain", "external_work", "friction",
                                            "damping", "contact", "crushing", "numerical",
                                            "initial")}
        d["total"] = self.total
        d["balance_error"] = self.balance_error
        return d
