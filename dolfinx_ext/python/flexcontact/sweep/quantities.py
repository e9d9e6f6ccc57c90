"""The sweep's columns as an engineer reads them: a name in words, what it is, and the unit
it is shown in (MN, MPa, ms, ...). The table (results.csv, summary.json) keeps SI values at
full precision; only the report and the figures use these.

A column not listed here is shown by the unit its name ends with (``_Pa`` in MPa, ``_N`` in
MN, ``_m`` in m, ``_deg`` in degrees, ``_s`` in ms), its name in words from the rest.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Quantity:
    """How one column is shown: ``words`` (a short name), ``definition`` (one sentence:
    where, which component, linearised or not), ``unit`` and ``scale`` (shown value =
    SI value × scale), ``stress`` (compared with the concrete's tensile strength)."""

    words: str
    definition: str = ""
    unit: str = ""
    scale: float = 1.0
    stress: bool = False

    def label(self) -> str:
        """An axis label: the words and the unit in parentheses."""
        return f"{self.words} ({self.unit})" if self.unit else self.words

    def show(self, si_value) -> str:
        """The value in this unit to three significant figures ("—" if not finite)."""
        return three_figures(si_value, self.scale)


def three_figures(value, scale: float = 1.0) -> str:
    """A number to three significant figures, without an exponent between 10⁻³ and 10⁶
    (names are shown as they are; None, NaN and ±inf as "—")."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return str(value)
    if value is None or not math.isfinite(float(value)):
        return "—"
    v = float(value) * scale
    if v == 0.0:
        return "0"
    if isinstance(value, int) and scale == 1.0:
        return str(value)
    exponent = math.floor(math.log10(abs(v)))
    if not -3 <= exponent < 6:
        return f"{v:.2e}"
    return f"{v:.{max(0, 2 - exponent)}f}"


def _per(dim: int) -> str:
    return "/m" if dim == 2 else ""


def _of(dim: int) -> str:
    return " per metre of dam (the 2D section)" if dim == 2 else " on the 3D block"


def outputs(dim: int) -> dict:
    """The evaluators' outputs (flexcontact.dam.coupled_step, sweep.monolithic) in words.
    Forces and impulses are per metre of dam in 2D and totals in 3D, whatever their column
    names say."""
    per, of = _per(dim), _of(dim)
    return {
        "peak_force_filtered_N_per_m": Quantity(
            "Peak impact force, filtered",
            f"Largest contact force of the log on the dam{of}, after a moving average over "
            "a tenth of the log's wave period 2L/c: a discrete wave front overshoots, the "
            "average keeps the bar pulse's plateau.", f"MN{per}", 1e-6),
        "peak_force_N_per_m": Quantity(
            "Peak impact force, raw",
            f"Largest contact force of the log on the dam{of}, step by step (overshoots the "
            "physical plateau by a few per cent at a discrete wave front).", f"MN{per}", 1e-6),
        "impulse_N_s_per_m": Quantity(
            "Impulse", f"Time integral of the contact force{of}: the log's loss of momentum.",
            f"kN·s{per}", 1e-3),
        "heel_stress_impact_Pa": Quantity(
            "Heel stress during impact",
            "Largest vertical stress at the upstream heel of the base section during the "
            "run, linearised over the section from its normal force and moment (tension "
            "positive; static load included; never below the static value).", "MPa", 1e-6,
            stress=True),
        "toe_stress_impact_Pa": Quantity(
            "Toe stress during impact",
            "Most compressive vertical stress at the downstream toe of the base section "
            "during the run, linearised over the section (tension positive; static load "
            "included; never above the static value).", "MPa", 1e-6),
        "base_normal_force_change_N_per_m": Quantity(
            "Base normal force change", f"Largest change of the base section's normal "
            f"force{of} during the run.", f"MN{per}", 1e-6),
        "base_moment_change_Nm_per_m": Quantity(
            "Base moment change", f"Largest change of the base section's moment about its "
            f"centre{of} during the run.", f"MN·m{per}", 1e-6),
        "heel_stress_static_Pa": Quantity(
            "Static heel stress",
            "Linearised vertical stress at the upstream heel under self-weight and water "
            "(tension positive).", "MPa", 1e-6),
        "peak_tensile_stress_Pa": Quantity(
            "Peak principal stress near the impact",
            "Largest principal stress of the concrete (tension positive, not linearised) at "
            "the stated distance from the first contact point, peak over the contact.",
            "MPa", 1e-6, stress=True),
        "halfspace_tension_Pa": Quantity(
            "Half-space tension near the impact (Boussinesq + Cerruti)",
            "Largest principal stress on the hemisphere of the stated radius r around the "
            "first contact point, from the closed-form half-space fields of the force at "
            "the filtered peak (Boussinesq for its normal part, Cerruti for its tangential "
            "part) plus the static stress there: in 3D the face's tension lies in a layer "
            "thinner than the elements, so the principal stress read from the mesh is low "
            "(docs/dam.md). Assumes the face flat and the crest and block sides far.",
            "MPa", 1e-6, stress=True),
        "peak_contact_pressure_Pa": Quantity(
            "Peak contact pressure", "Largest nodal-average contact pressure on the log's "
            "end.", "MPa", 1e-6),
        "contact_duration_s": Quantity(
            "Contact duration", "From the first to the last step in contact.", "ms", 1e3),
        "contact_start_s": Quantity("Contact start", "Time of the first contact.", "ms", 1e3),
        "log_momentum_change_N_s_per_m": Quantity(
            "Log momentum change along the flow", "", f"kN·s{per}", 1e-3),
        "log_momentum_change_vertical_N_s_per_m": Quantity(
            "Log momentum change, vertical", "", f"kN·s{per}", 1e-3),
        "log_mass_kg_per_m": Quantity("Log mass (with added mass)", "", f"t{per}", 1e-3),
        "log_velocity_after_m_s": Quantity("Log speed after impact", "", "m/s"),
        "log_rotation_rad": Quantity("Log rotation at the end", "", "°", 180 / math.pi),
        "stress_offset_m": Quantity("Stress read at", "", "m"),
        "crush_depth_m": Quantity("Crush depth of the log's end", "", "mm", 1e3),
    }


INPUTS = {
    "log_speed_m_s": Quantity("Log speed", unit="m/s"),
    "log_pitch_deg": Quantity("Log pitch", unit="°"),
    "log_yaw_deg": Quantity("Log yaw", unit="°"),
    "log_across_m": Quantity("Log's place across the block (y of its centre)", unit="m"),
    "log_length_m": Quantity("Log length", unit="m"),
    "log_diameter_m": Quantity("Log diameter", unit="m"),
    "wood_density_kg_m3": Quantity("Wood density", unit="kg/m³"),
    "friction_mu": Quantity("Friction coefficient μ"),
    "water_level_m": Quantity("Reservoir level", unit="m"),
    "wood_crushing_strength_Pa": Quantity("Wood crushing strength", unit="MPa", scale=1e-6),
    "log_end_shape": Quantity("Log end shape"),
    "log_end_radius_m": Quantity("End cap radius", unit="m"),
    "log_end_chamfer_m": Quantity("End chamfer", unit="m"),
    "added_mass_coefficient": Quantity("Added-mass coefficient"),
    "concrete_tensile_strength_Pa": Quantity("Concrete tensile strength", unit="MPa",
                                             scale=1e-6),
}
"""Names in words of the inputs a sweep usually varies (any DamScenario parameter may be
swept; the others are shown by their suffix)."""

_SUFFIXES = (("_N_s_per_m", "kN·s", 1e-3), ("_N_per_m", "MN", 1e-6), ("_kg_m3", "kg/m³", 1),
             ("_m_s", "m/s", 1), ("_Pa", "MPa", 1e-6), ("_N", "MN", 1e-6),
             ("_deg", "°", 1), ("_mm", "mm", 1), ("_m", "m", 1), ("_s", "ms", 1e3))


def quantity(name: str, dim: int = 2) -> Quantity:
    """How the column ``name`` is shown: its entry among the outputs or inputs, otherwise
    from its name's unit suffix."""
    known = outputs(dim).get(name) or INPUTS.get(name)
    if known is not None:
        return known
    for suffix, unit, scale in _SUFFIXES:
        if name.endswith(suffix):
            words = name[: -len(suffix)].replace("_", " ")
            return Quantity(words[:1].upper() + words[1:], unit=unit, scale=scale)
    words = name.replace("_", " ")
    return Quantity(words[:1].upper() + words[1:])
