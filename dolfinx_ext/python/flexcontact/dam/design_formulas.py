"""Published design formulas for the impact force of floating debris (logs), in SI units.

Each returns the peak (or design) force in N for a log of mass ``m_kg`` (or weight) at
``v_m_s`` and says which assumption fixes the force that the impulse m v alone cannot: a
duration Δt, a stiffness k or an empirical fit. All of them are single-degree-of-freedom
views of the collision (Haehnel & Daly 2002 show the first three are one model with
different parameters): F ≈ m v / Δt with Δt ≈ √(m/k), so F = v √(k m).

Sources (as read for this module; the standards' own texts were not at hand, so their
formulas are quoted as they are commonly reproduced — check the edition you design to):

* ASCE/SEI 7 (2005–2016), commentary on flood loads (C5.4.5), adopted by FEMA P-55
  (Coastal Construction Manual, 2011): F = π W v C_I C_O C_D C_B R_max / (2 g Δt).
* Haehnel, R. B. & Daly, S. F. (2002), *Maximum impact force of woody debris on floodplain
  structures*, ERDC/CRREL TR-02-2, US Army Corps of Engineers; J. Hydraulic Eng. 130(2)
  (2004) 112–120: F = v √(k m) with an effective contact stiffness k = 2.4 MN/m fitted to
  flume and basin tests of logs hitting structures, the largest force for a log striking
  end-on.
* EN 1991-1-7:2006 (Eurocode 1, accidental actions), Annex C, hard impact: F = v_r √(k m)
  with k the equivalent elastic stiffness of the colliding object; for an object that is an
  elastic bar, k = E A / L, i.e. F = v_r √(E A m / L) — which for a prismatic bar equals
  the one-dimensional wave result F = A √(E ρ) v.
* Matsutomi, H. (1999), *A practical formula for estimating impulsive force due to
  driftwoods and variation features of the impulsive force*, J. Hydraulic, Coastal and
  Environmental Eng., JSCE, No. 621/II-47, 111–127 (in Japanese); in English in Matsutomi,
  J. Disaster Research 4(6) (2009) 435–440: F / (γ D² L) = 1.6 C_M (v / √(g D))^1.2
  (σ_f / (γ L))^0.4, fitted to driftwood hitting a wall end-on in tsunami-like flows.
"""
from __future__ import annotations

import math
from ..errors import InputError

G_M_S2 = 9.80665
"""Standard gravity used by the formulas (m/s²)."""

HAEHNEL_DALY_STIFFNESS_N_M = 2.4e6
"""Haehnel & Daly's effective contact stiffness for logs (2.4 MN/m)."""


def _positive(**values) -> None:
    for name, v in values.items():
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise InputError(f"{name}={v!r}: must be a finite number > 0")


def asce7_force_N(weight_N: float, v_m_s: float, dt_s: float = 0.03, C_I: float = 1.0,
                  C_O: float = 0.8, C_D: float = 1.0, C_B: float = 1.0,
                  R_max: float = 1.0) -> float:
    """ASCE 7 / FEMA P-55 debris impact: F = π W v C_I C_O C_D C_B R_max / (2 g Δt), N.

    The impulse m v (m = W/g) delivered as a half-sine pulse of duration Δt, whose peak is
    π/2 times its mean. ``dt_s``: the impact duration, 0.03 s recommended by the commentary
    (from tests of logs on piles and walls); ``C_I`` importance, ``C_O`` orientation (0.8:
    most impacts are not head-on), ``C_D`` depth, ``C_B`` blockage coefficients; ``R_max``
    the dynamic response ratio of the struck element (1: the force itself, as compared here
    with a computed contact force). Assumes a rigid debris–structure pair whose stiffness is
    hidden in Δt.
    """
    _positive(weight_N=weight_N, v_m_s=v_m_s, dt_s=dt_s)
    return math.pi * weight_N * v_m_s * C_I * C_O * C_D * C_B * R_max / (2.0 * G_M_S2 * dt_s)


def contact_stiffness_force_N(m_kg: float, v_m_s: float,
                              k_N_m: float = HAEHNEL_DALY_STIFFNESS_N_M) -> float:
    """Haehnel & Daly (2002/2004): F = v √(k m), N, an undamped linear spring k between a
    rigid log of mass m and a rigid structure; contact lasts π √(m/k). Default k = 2.4 MN/m,
    their fit to flume and test-basin collisions of logs with structures (all orientations;
    the end-on strike gave the largest forces)."""
    _positive(m_kg=m_kg, v_m_s=v_m_s, k_N_m=k_N_m)
    return v_m_s * math.sqrt(k_N_m * m_kg)


def eurocode_bar_force_N(m_kg: float, v_m_s: float, E_Pa: float, area_m2: float,
                         length_m: float) -> float:
    """EN 1991-1-7 Annex C hard impact with the object as an elastic bar: k = E A / L and
    F = v √(k m), N (the structure rigid, the object elastic). For a uniform bar of density
    ρ (m = ρ A L) this is A √(E ρ) v, the force of the bar's first compression wave."""
    _positive(m_kg=m_kg, v_m_s=v_m_s, E_Pa=E_Pa, area_m2=area_m2, length_m=length_m)
    return v_m_s * math.sqrt(E_Pa * area_m2 / length_m * m_kg)


def matsutomi_force_N(diameter_m: float, length_m: float, v_m_s: float,
                      unit_weight_N_m3: float, yield_stress_Pa: float = 20e6,
                      C_M: float = 1.7) -> float:
    """Matsutomi (1999): F = 1.6 C_M (v/√(g D))^1.2 (σ_f/(γ L))^0.4 γ D² L, N.

    An empirical fit for driftwood (a log of diameter D and length L, unit weight γ) hitting
    a wall end-on; ``C_M`` the apparent-mass coefficient (about 1.7 for a bore or surge,
    1.9 in steady flow), ``yield_stress_Pa`` σ_f the wood's yield stress along the grain
    (about 20 MPa: the formula's force is limited by local crushing of the log's end)."""
    _positive(diameter_m=diameter_m, length_m=length_m, v_m_s=v_m_s,
              unit_weight_N_m3=unit_weight_N_m3, yield_stress_Pa=yield_stress_Pa, C_M=C_M)
    D, L, gamma = diameter_m, length_m, unit_weight_N_m3
    froude = v_m_s / math.sqrt(G_M_S2 * D)
    return 1.6 * C_M * froude ** 1.2 * (yield_stress_Pa / (gamma * L)) ** 0.4 * gamma * D * D * L


def all_formulas_N(m_kg: float, v_m_s: float, diameter_m: float, length_m: float,
                   E_Pa: float, density_kg_m3: float, yield_stress_Pa: float = 20e6) -> dict:
    """Every formula for a cylindrical log (defaults of each source), N."""
    area = math.pi * diameter_m ** 2 / 4.0
    return {
        "asce7": asce7_force_N(m_kg * G_M_S2, v_m_s),
        "haehnel_daly": contact_stiffness_force_N(m_kg, v_m_s),
        "eurocode_bar": eurocode_bar_force_N(m_kg, v_m_s, E_Pa, area, length_m),
        "matsutomi": matsutomi_force_N(diameter_m, length_m, v_m_s,
                                       density_kg_m3 * G_M_S2, yield_stress_Pa),
    }


FORMULA_NAMES = {"asce7": "ASCE 7 / FEMA P-55 (impulse over Δt = 0.03 s)",
                 "haehnel_daly": "Haehnel & Daly (spring k = 2.4 MN/m)",
                 "eurocode_bar": "EN 1991-1-7 Annex C (log as an elastic bar, k = EA/L)",
                 "matsutomi": "Matsutomi (1999), driftwood fit"}


def effective_stiffness_N_m(force_N: float, m_kg: float, v_m_s: float) -> float:
    """k_eff = F²/(m v²): the linear spring that gives the peak force F for a mass m striking
    at v (F = v √(k m)), the common measure of the formulas and the model."""
    return force_N * force_N / (m_kg * v_m_s * v_m_s)


def comparison(scenario: dict, mass_kg: float, peak_force_filtered: float) -> dict:
    """The model's filtered peak force of one impact beside every formula for the same log
    and speed, with k_eff for each: {"model_N", "width_m", "mass_kg", "speed_m_s",
    "formulas_N": {...}, "k_eff_N_m": {"model": …, formula: …}}. ``scenario`` is
    DamScenario.as_dict() and ``mass_kg`` the log's mass (its end's shape included); in 2D
    the force per metre is multiplied by the log's diameter (the width one log occupies: a
    rough conversion). The model's k_eff uses the mass with the added mass, as the model's
    log moves it; a formula's, the log's own mass, as its source does (Haehnel & Daly's is
    then its 2.4 MN/m)."""
    s = scenario
    D, L, v = s["log_diameter_m"], s["log_length_m"], s["log_speed_m_s"]
    rho, m = s["wood"]["rho_kg_m3"], float(mass_kg)
    m_eff = m * (1.0 + s["added_mass_coefficient"])
    width = 1.0 if s["dim"] == 3 else D
    model = peak_force_filtered * width
    formulas = all_formulas_N(m, v, D, L, s["wood"]["E_Pa"], rho,
                              s["wood_crushing_strength_Pa"])
    k = {"model": effective_stiffness_N_m(model, m_eff, v)}
    k.update({name: effective_stiffness_N_m(f, m, v) for name, f in formulas.items()})
    return {"model_N": model, "width_m": width, "mass_kg": m, "mass_with_added_kg": m_eff,
            "speed_m_s": v, "formulas_N": formulas, "k_eff_N_m": k}
