"""The numbers a dam engineer reads off one run of the scenario (stage 1 and stage 2).

Forces per metre of dam in 2D (N/m), for the whole block in 3D (N); stresses in Pa,
tension positive. Each ``q`` that theory fixes comes with ``q_ref``.
"""
from __future__ import annotations

import math

from ..errors import InputError
from .kinematics import ROTATION_LIMIT_RAD, STRAIN_LIMIT


def engineer_numbers(s, stage1, stage2) -> dict:
    """Base-section (linearised) heel and toe stresses before and during the impact, the
    peak largest principal stress at the stated offset from the impact, the contact force,
    duration and impulse, the ratios to the strengths and the log's kinematics."""
    before = stage1.section
    ext = stage2.section_extremes()
    ft, fc = s.concrete_tensile_strength_Pa, s.wood_crushing_strength_Pa
    met = stage2.metrics
    sigma_peak = stage2.peak_tensile_stress_Pa
    halfspace = halfspace_tension_Pa(s, stage2.force_at_filtered_peak_N,
                                     stage2.static_stress_near_impact_Pa, stage2.offset_m)
    normal_only = halfspace_surface_tension_Pa(s, met["peak_force_filtered"], stage2.offset_m)
    return {
        "sigma_heel_before_Pa": before.sigma_heel_Pa,
        "sigma_heel_before_Pa_ref": stage1.reference.sigma_heel_Pa,
        "sigma_toe_before_Pa": before.sigma_toe_Pa,
        "sigma_toe_before_Pa_ref": stage1.reference.sigma_toe_Pa,
        "sigma_heel_during_max_Pa": ext["sigma_heel_max_Pa"],
        "sigma_heel_during_max_t_s": ext["sigma_heel_max_t_s"],
        "sigma_toe_during_min_Pa": ext["sigma_toe_min_Pa"],
        "sigma_toe_during_min_t_s": ext["sigma_toe_min_t_s"],
        "moment_heel_during_max_Nm": ext["moment_heel_max_Nm"],
        "sigma_heel_before_over_tensile_strength": before.sigma_heel_Pa / ft,
        "sigma_heel_during_over_tensile_strength": ext["sigma_heel_max_Pa"] / ft,
        # The impact's own change: the static part is exact on any mesh (the section's
        # statics), so it must not dilute the mesh study's error.
        "delta_sigma_heel_Pa": ext["sigma_heel_max_Pa"] - before.sigma_heel_Pa,
        "delta_sigma_toe_Pa": ext["sigma_toe_min_Pa"] - before.sigma_toe_Pa,
        "peak_force": met["peak_force"],
        "peak_force_filtered": met["peak_force_filtered"],
        "force_filter_window_s": met["filter_window_s"],
        "peak_force_t_s": stage2.peak_time_s,
        "contact_duration_s": met["contact_duration_s"],
        "contact_duration_s_ref_log_2L_c": stage2.problem.expected_contact_s,
        "impulse": met["impulse"],
        "impulse_ref": -stage2.log_momentum_change,
        "peak_max_principal_stress_near_impact_Pa": sigma_peak,
        "impact_offset_m": stage2.offset_m,
        "peak_stress_over_tensile_strength": sigma_peak / ft,
        "halfspace_tension_at_offset_Pa": halfspace,
        "halfspace_tension_over_tensile_strength": None if halfspace is None else halfspace / ft,
        "halfspace_tension_normal_force_only_Pa": normal_only,
        "force_at_filtered_peak_N": (None if stage2.force_at_filtered_peak_N is None
                                     else [float(f) for f in stage2.force_at_filtered_peak_N]),
        "peak_contact_pressure_Pa": stage2.peak_contact_pressure_Pa,
        "peak_pressure_over_wood_crushing_strength": stage2.peak_contact_pressure_Pa / fc,
        "log_max_rotation_rad": stage2.log_max_rotation_rad,
        "log_rotation_limit_rad": ROTATION_LIMIT_RAD,
        "log_max_strain": stage2.log_max_strain,
        "log_strain_limit": STRAIN_LIMIT,
        "log_end_crushes": bool(s.log_end_crushes),
        "log_crush_depth_max_m": max((r.crush_depth_max_m for r in stage2.problem.records),
                                     default=0.0),
        "log_crushed_volume_m3": max((r.crushed_volume_m3 for r in stage2.problem.records),
                                     default=0.0),
        "crushing_energy_J": stage2.problem.energy.crushing,
        "crushing_pairs_max": max((r.crush for r in stage2.problem.records), default=0),
        "contact_element_size_m": s.h_contact_m,
    }


def halfspace_tension_Pa(s, force_on_dam_N, static_stress_Pa, r_m: float):
    """The largest principal stress on the hemisphere of radius ``r_m`` around the impact
    point in 3D, from the closed-form half-space fields of the force ``force_on_dam_N`` (3,),
    global axes (Boussinesq for its normal part, Cerruti for its tangential part: friction,
    pitch, yaw), plus the dam's static stress ``static_stress_Pa`` (3, 3) there taken as
    uniform (see :mod:`~flexcontact.dam.halfspace`). The face x = 0 is the half-space's
    surface, the dam on x > 0. None in 2D (see :func:`halfspace_surface_tension_Pa`) or
    without a force."""
    if s.dim != 3 or force_on_dam_N is None:
        return None
    from .halfspace import peak_tension_Pa
    return peak_tension_Pa(force_on_dam_N, (1.0, 0.0, 0.0), s.concrete.nu, r_m,
                           static_stress_Pa)[0]


def halfspace_surface_tension_Pa(s, force_N: float, r_m: float):
    """Boussinesq's surface tension (1 − 2ν) F / (2π r²) at distance ``r_m`` from a normal
    force ``force_N`` on an elastic half-space (ν of the concrete): in 3D the largest
    principal stress near the impact is this radial tension, in a surface layer about
    0.1 r deep (docs/dam.md) that the impact zone's elements do not resolve. None in 2D,
    where a normal line load leaves the half-plane in compression (Flamant)."""
    if s.dim != 3:
        return None
    return (1.0 - 2.0 * s.concrete.nu) * force_N / (2.0 * math.pi * r_m ** 2)


MESH_STUDY_COLUMNS = (
    ("sigma_heel_before_Pa", "heel σ before [MPa]", 1e-6),
    ("sigma_heel_during_max_Pa", "heel σ max during [MPa]", 1e-6),
    ("sigma_toe_during_min_Pa", "toe σ min during [MPa]", 1e-6),
    ("peak_max_principal_stress_near_impact_Pa", "peak σ₁ at offset [MPa]", 1e-6),
    ("peak_force", "peak force [MN/m or MN]", 1e-6),
    ("peak_force_filtered", "filtered peak force [MN/m or MN]", 1e-6),
    ("contact_duration_s", "duration [ms]", 1e3),
    ("impulse", "impulse [kN·s/m or kN·s]", 1e-3),
    ("peak_contact_pressure_Pa", "peak pressure [MPa]", 1e-6),
)
"""(key, heading, scale) of the mesh-study table."""

CONVERGENCE_QUANTITIES = (
    ("delta_sigma_heel_Pa", "Δσ heel (impact) [MPa]", 1e-6),
    ("delta_sigma_toe_Pa", "Δσ toe (impact) [MPa]", 1e-6),
    ("peak_max_principal_stress_near_impact_Pa", "peak σ₁ at offset [MPa]", 1e-6),
    ("peak_force_filtered", "filtered peak force [MN/m or MN]", 1e-6),
    ("impulse", "impulse [kN·s/m or kN·s]", 1e-3),
)
"""(key, heading, scale) of the quantities whose convergence the study estimates."""


STUDY_CONTACT = ("refined", "kept")
"""What the mesh study does to the crushed patch's contact mesh (mesh_size_contact_m):
refined with the rest, or kept as it is while the dam's near and far field are refined."""


def study_scenarios(s, ratio: float, contact: str = "refined") -> list:
    """The mesh study's three scenarios: ``s`` (the default mesh) and s with every element
    size divided by ratio and by ratio², near field and far field together. With
    ``contact="kept"`` the contact zone's element size (a crushing end's patch,
    ``mesh_size_contact_m``) stays the default's: it is set by resolving the crushed patch,
    and refining it too multiplies the contact DOFs (in 3D beyond this machine's memory)."""
    if contact not in STUDY_CONTACT:
        raise InputError(f"contact={contact!r}: one of {STUDY_CONTACT}")
    has_zone = s.mesh_size_contact_m is not None

    def h_contact(k):
        if not has_zone:
            return None
        return s.h_contact_m / ratio ** k if contact == "refined" else s.h_contact_m
    return [s] + [s.replace(refine=0, mesh_size_far_m=s.h_far_m / ratio ** k,
                            mesh_size_impact_m=s.h_impact_m / ratio ** k,
                            mesh_size_log_m=(None if s.mesh_size_log_m is None
                                             else s.h_log_m / ratio ** k),
                            mesh_size_contact_m=h_contact(k))
                  for k in (1, 2)]


def mesh_study_row(s, impact_offset_m: float, duration_s=None, comm=None,
                   contact_operator: str = "dense") -> dict:
    """Stage 1 and stage 2 of ``s`` without output files; the engineer's numbers with the
    mesh's size. Collective."""
    from mpi4py import MPI

    from .stage1 import solve_stage1
    from .stage2 import solve_stage2
    comm = comm or MPI.COMM_WORLD
    stage1 = solve_stage1(s, comm=comm)
    stage2 = solve_stage2(s, stage1, offset_m=impact_offset_m, duration_s=duration_s,
                          contact_operator=contact_operator)
    from ..output import mesh_info
    row = engineer_numbers(s, stage1, stage2)
    size = mesh_info(stage1.V)
    row.update(refine=s.refine, h_impact_m=s.h_impact_m, h_far_m=s.h_far_m,
               h_contact_m=s.h_contact_m, cells=size["cells"], dofs=size["dofs"],
               time_s=stage1.timings_s["total"] + stage2.timings_s["setup"]
               + stage2.timings_s["steps"])
    return row
