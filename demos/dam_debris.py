# %% [markdown]
# # A floating log and a concrete gravity dam — the static state and the impact
#
# The main job of flexcontact: a log carried by a flood hits the upstream face of a concrete
# gravity dam. This demo sets the scenario up and solves **stage 1**, the dam's static state
# before the impact: self-weight of the dam and its foundation, the reservoir's hydrostatic
# pressure on the upstream face (optionally tailwater and uplift); then **stage 2**, the
# log's impact on the upstream face, starting from this state (`--stage1-only` skips it).
#
# By default the dam is a 3D block between contraction joints (15 m wide, `--dam-width`) on
# its foundation, and the log a round one, pitched 10° (`--log-pitch`, `--log-yaw`), whose
# front end is rounded, not sawn (a spherical cap of radius D: drift logs arrive with root
# masses and broken tops, not saw cuts; docs/dam.md, "Scenario"), and crushes at the wood's
# crushing strength (docs/crushing.md); the log's end is
# refined about the first-contact point so that the crushed patch at the peak force spans at
# least four elements (`scenario.crushed_patch_mesh`: in 3D 12.5 mm within 0.2 m of it for
# the cap, 0.35 m for a flat end's corner, and 5 cm deep behind the end, `--contact-size`,
# `--contact-zone`, `--contact-layer`), and the rest has elements of 0.1 m on the log's
# shaft (MAIN_JOB_LOG_MESH_M, `--log-size`), 0.2 m within 1 m of the log and 3 m far from it
# (MAIN_JOB_MESH, `--impact-size`, `--far-size`: the mesh study below says why).
# `--elastic-end` keeps the end elastic (the upper bound of the force); `--log-end` shapes
# it (flat, chamfered, rounded). `--dim 2` runs the
# plane-strain section instead: per metre of dam, a raft of logs abreast along the whole
# crest, not one log.
#
# What is measured: the base section's normal force N, shear and moment M from the nodal
# forces the dam hands to the foundation, against the hand statics of the dam's free body
# (self-weight, and the hydrostatic resultant ρ_w g h²/2 acting at h/3); these are exact in
# statics, so they agree to round-off. From them, the linearised heel and toe stresses
# σ = −N/B ± 6M/B² that dam engineers use (per metre of dam in 2D).
#
# Run: `/usr/bin/python3 demos/dam_debris.py [--dim 2] [--refine N] [--water-level 27]
# [--log-end flat|chamfered|rounded] [--elastic-end] [--stage1-only] [--mesh-study]
# [--contact-operator dense|factor]`;
# results go to `results/dam_debris/`, with a short report `report.md`.

# %%
import argparse
import time

import numpy as np
from mpi4py import MPI


import flexcontact as fc
from flexcontact.dam import DamScenario
from flexcontact.dam.fields import stress_fields
from flexcontact.dam.plot import plot_groups
from flexcontact.dam.section import peak_at_offset
from flexcontact.dam.stage1 import solve_stage1, upstream_water_resultant
from flexcontact.meshes import dam_tags

parser = argparse.ArgumentParser(description="floating log and gravity dam: statics and impact")
parser.add_argument("--refine", type=int, default=0, help="halve the element sizes N times")
parser.add_argument("--dim", type=int, default=3, choices=(2, 3),
                    help="3: a dam block and a round log (default); 2: the plane-strain section")
parser.add_argument("--dam-width", type=float, default=15.0,
                    help="3D block width between contraction joints, m")
parser.add_argument("--water-level", type=float, default=27.0, help="m above the base")
parser.add_argument("--tailwater", type=float, default=0.0, help="m above the base")
parser.add_argument("--uplift", type=float, default=0.0, help="uplift factor, 0 to 1")
parser.add_argument("--log-speed", type=float, default=2.0, help="m/s (stage 2)")
parser.add_argument("--log-pitch", type=float, default=10.0, help="degrees, front end up")
parser.add_argument("--log-yaw", type=float, default=0.0, help="degrees (3D only)")
parser.add_argument("--log-length", type=float, default=10.0, help="m")
parser.add_argument("--log-diameter", type=float, default=0.8, help="m")
parser.add_argument("--westergaard", action="store_true",
                    help="stage 2: the reservoir's added mass on the upstream face (Westergaard)")
parser.add_argument("--theta", type=float, default=0.55,
                    help="θ of stage 2's Moreau–Jean scheme, in [0.5, 1] (0.5 lets a crushing "
                         "front chatter: docs/dam.md, \"The time scheme\")")
parser.add_argument("--gap", type=float, default=0.02, help="log to face, m")
parser.add_argument("--mu", type=float, default=0.5, help="friction coefficient (stage 2)")
parser.add_argument("--log-end", default="rounded", choices=("flat", "chamfered", "rounded"),
                    help="the log's front end: a spherical cap (default), sawn flat, or "
                         "chamfered")
parser.add_argument("--end-chamfer", type=float, default=None,
                    help="chamfer c of a chamfered end, m (0 < c < D/2; default D/8)")
parser.add_argument("--end-radius", type=float, default=None,
                    help="sphere radius of a rounded end, m (>= D/2, a hemisphere; default D)")
parser.add_argument("--elastic-end", action="store_true",
                    help="the log's front end stays elastic (the upper bound of the force); "
                         "default: it crushes at the wood's crushing strength")
parser.add_argument("--contact-size", type=float, default=None,
                    help="element size (m) within --contact-zone of the first-contact point "
                         "(default: CRUSHED_PATCH_MESH of the dimension; with --elastic-end: "
                         "the impact zone's)")
parser.add_argument("--contact-zone", type=float, default=None,
                    help="radius (m) of the refined ball about the first-contact point "
                         "(default: crushed_patch_mesh of the dimension and end: in 3D 0.2 m "
                         "for a rounded end, 0.35 m otherwise)")
parser.add_argument("--contact-layer", type=float, default=None,
                    help="depth (m) behind the log's end within which the ball keeps "
                         "--contact-size; deeper, elements grow (default: CRUSHED_PATCH_MESH "
                         "of the dimension: 5 cm in 3D, the whole ball in 2D)")
parser.add_argument("--far-size", type=float, default=None,
                    help="element size far from the log, m (default: MAIN_JOB_MESH, 3 m)")
parser.add_argument("--impact-size", type=float, default=None,
                    help="element size within 1 m of the log, and on it in 2D, m (default: "
                         "MAIN_JOB_MESH, 0.2 m)")
parser.add_argument("--log-size", type=float, default=None,
                    help="element size on the log's shaft, m (default: MAIN_JOB_LOG_MESH_M, "
                         "in 3D 0.1 m: four elements across the log are too stiff in "
                         "bending; in 2D the impact size)")
parser.add_argument("--offset", type=float, default=1.0,
                    help="distance from the heel at which the peak stress is reported, m")
parser.add_argument("--stage1-only", action="store_true", help="skip the impact (stage 2)")
parser.add_argument("--dt", type=float, default=None,
                    help="impact time step, s (default: 2L/c of the log / 40)")
parser.add_argument("--impact-offset", type=float, default=0.5,
                    help="distance from the first-contact point on the face at which the "
                         "dam's peak principal stress is reported, m")
parser.add_argument("--duration", type=float, default=None,
                    help="simulated time of the impact, s (default: approach + 2L/c of the "
                         "log + half the dam's first period, for the base's response)")
parser.add_argument("--mesh-study", action="store_true",
                    help="run the impact on two finer meshes (sizes / sqrt 2 and / 2) and "
                         "extrapolate")
parser.add_argument("--mesh-study-contact", choices=("refined", "kept"), default="refined",
                    help="the mesh study's crushed-patch contact mesh: refined with the rest "
                         "(default), or kept at its size while the dam's and log's near and "
                         "far field are refined (a quicker study that leaves out the patch's "
                         "error)")
parser.add_argument("--contact-operator", choices=("dense", "factor"), default=None,
                    help="how the impact holds the log/dam contact: dense F-hat and W_eff, or "
                         "through the factor of the iteration matrix, for contact zones too "
                         "large for the dense operators (the same answer to rounding; "
                         "docs/impact.md). Default: dense, and factor for the 3D mesh "
                         "study's meshes with a refined crushed patch")
parser.add_argument("--no-paraview", action="store_true", help="skip the ParaView picture")
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## The scenario
# Every parameter lives in one checked object: a bad value (water above the crest, a log
# denser than water, a negative speed, ...) raises here, naming it, before anything is
# meshed. The log's elevation is not an input: it floats at its draft.

# %%
from flexcontact.dam.scenario import MAIN_JOB_LOG_MESH_M, MAIN_JOB_MESH, crushed_patch_mesh
crushes = not args.elastic_end
size, zone, layer = crushed_patch_mesh(args.dim, args.log_end) if crushes else (None, 0.1, None)
far_size, impact_size = MAIN_JOB_MESH[args.dim]
scenario = DamScenario(
    dim=args.dim, dam_width_m=args.dam_width, refine=args.refine,
    water_level_m=args.water_level,
    tailwater_level_m=args.tailwater, uplift_factor=args.uplift,
    log_speed_m_s=args.log_speed, log_pitch_deg=args.log_pitch, log_yaw_deg=args.log_yaw,
    log_length_m=args.log_length, log_diameter_m=args.log_diameter, log_gap_m=args.gap,
    friction_mu=args.mu, westergaard=args.westergaard, log_end_crushes=crushes,
    time_scheme_theta=args.theta,
    log_end_shape=args.log_end, log_end_chamfer_m=args.end_chamfer,
    log_end_radius_m=args.end_radius,
    mesh_size_contact_m=args.contact_size or size, contact_zone_m=args.contact_zone or zone,
    contact_layer_m=args.contact_layer or layer,
    mesh_size_far_m=args.far_size or far_size,
    mesh_size_impact_m=args.impact_size or impact_size,
    mesh_size_log_m=args.log_size or MAIN_JOB_LOG_MESH_M[args.dim])
folder = fc.results_folder("dam_debris")

# %% [markdown]
# ## Stage 1: statics
# One linear solve (MUMPS); the log is held, the foundation clamped at its bottom and on
# rollers at its ends. The base section is read from the dam's nodal forces at the base
# nodes, and once more from the foundation's side as a check of the solve.

# %%
stage1 = solve_stage1(scenario, comm=comm)
msh, cells, facets, info = stage1.mesh
s = scenario
width = 1.0 if s.dim == 2 else s.dam_width_m
fields = stress_fields(stage1.V, stage1.u, cells, stage1.materials(), stage1.kind)
water_force, water_height = upstream_water_resultant(stage1)
heel = np.zeros(s.dim)
peak_heel, peak_where = peak_at_offset(fields[1], heel, args.offset, cells, dam_tags.DAM)
u_max = comm.allreduce(float(np.abs(stage1.u.x.array).max(initial=0.0)), op=MPI.MAX)

with fc.ResultWriter(folder, "stage1", msh, tags=(cells,)) as xdmf:
    xdmf.write([stage1.u, *fields], 0.0)
if s.dim == 2 and not args.no_plot:
    plot_groups(stage1.mesh, folder / "geometry.png", s)

# %% [markdown]
# The heel is a re-entrant corner (the upstream face meets the reservoir bed): the stress
# there grows without bound under refinement, which is why engineers read the linearised
# heel stress. The largest principal stress at `--offset` from the heel converges instead,
# slowly: at the default size the offset lies inside the first element, so compare
# `--refine 1` and `--refine 2` before trusting it.
#
# ## Summary
# Forces per metre of dam in 2D (N/m, N·m/m), for the whole block in 3D (N, N·m); stresses
# in Pa, tension positive. Each `q` has its hand-statics reference `q_ref`.

# %%
fe, ref = stage1.section.as_dict(), stage1.reference.as_dict()
section = {}
for key, value in fe.items():
    section[key] = value
    section[f"{key}_ref"] = ref[key]
    section[f"{key}_error_rel"] = abs(value - ref[key]) / max(abs(ref[key]), 1e-300)
summary = {
    "demo": "dam_debris", "stage": "1 (statics)",
    "units": "SI; 2D: forces per metre of dam (N/m, N·m/m); stresses in Pa, tension positive",
    "scenario": s.as_dict(),
    "mesh": fc.output.mesh_info(stage1.V, refine=s.refine, h_far_m=s.h_far_m,
                                h_impact_m=s.h_impact_m),
    "log": {"draft_m": s.log_draft_m, "axis_elevation_m": s.log_axis_elevation_m,
            "centre_m": s.log_centre, "front_point_m": s.log_front_point,
            "mass_kg": s.log_mass_kg(), "mass_2d_kg_per_m": s.log_mass_2d_kg_per_m(),
            "added_mass_kg": s.log_added_mass_kg()},
    "stage1": {
        "hydrostatic_resultant_N": water_force,
        "hydrostatic_resultant_N_ref": s.hydrostatic_resultant_N_per_m() * width,
        "hydrostatic_height_m": water_height,
        "hydrostatic_height_m_ref": s.water_level_m / 3.0,
        "base_section": section,
        "base_section_from_foundation": stage1.section_foundation.as_dict(),
        "peak_max_principal_stress_near_heel_Pa": peak_heel,
        "peak_offset_from_heel_m": args.offset, "peak_point_m": peak_where,
        "concrete_tensile_strength_Pa": s.concrete_tensile_strength_Pa,
        "max_displacement_m": u_max,
        "timings_s": {**stage1.timings_s, "total": time.perf_counter() - t_start},
    },
}
if comm.rank == 0:
    print(f"base section: N = {fe['normal_force_N']:.6e} (ref {ref['normal_force_N']:.6e}), "
          f"M_heel = {fe['moment_heel_Nm']:.6e} (ref {ref['moment_heel_Nm']:.6e})")
    print(f"linearised stresses: heel {fe['sigma_heel_Pa'] / 1e6:.4f} MPa, "
          f"toe {fe['sigma_toe_Pa'] / 1e6:.4f} MPa; peak principal stress "
          f"{args.offset} m from the heel {peak_heel / 1e6:.4f} MPa")
    print(f"results in {folder}/")

# %% [markdown]
# ## Stage 2: the impact
# The log, free now, moves along its axis at `--log-speed` and hits the upstream face;
# the dam and foundation start from stage 1's displacement under the same constant loads,
# so they are at rest until the log arrives. The log's density is raised by the added-mass
# coefficient, ρ_wood (1 + C_a), and its weight and buoyancy cancel. Contact: the log's
# front end (the point of its cap nearest the face touches first; of a flat end, the lower
# front corner) against the face, node–surface with
# Coulomb friction μ; the pairs are made once at the initial positions (the log slides
# along the face by much less than an element). Time integration:
# Moreau–Jean on the condensed system, `dt` = 2L/c of the log / 40 by default, with
# θ = 0.55: a little damping of the mesh's highest frequencies, without which the crushing
# front chatters and its force comes out about 15 % low (docs/dam.md, "The time scheme").
#
# What is measured: the contact force per metre of dam against time, its peak, the
# contact duration and the impulse, checked against the log's change of momentum
# m_eff Δv from the velocities of its nodes before and after (no other force acts on the
# log, so they agree to round-off); the largest principal stress in the dam at
# `--impact-offset` from the first-contact point (the contact's own stress grows with
# refinement), read from the recovered (nodal-average) stress, with Boussinesq's
# half-space value beside it in 3D, where the face's tension lies in a layer thinner
# than the elements; and the peak contact pressure (mean over a step and a node's tributary
# length: mesh-dependent where a corner touches) against the wood's crushing strength.
#
# What engineers use: the base section's force and moment at every step, from the dam's
# displacement (the same nodal residual as in stage 1), and from them the linearised heel
# and toe stresses during the impact. The base feels the impact only after the stress
# wave has crossed the dam (H/c ≈ 10 ms) and its moment peaks about a quarter to a half
# of the dam's first period later, so the run lasts the approach, the contact and half
# that period (Fenves & Chopra's T₁ = 1.4 H/√E in ft and psi, ≈ 0.07 s here).
# The log's rigid rotation and largest strain are watched too: a Python warning names
# them if they leave the small range of the linear model.

# %%
if not args.stage1_only:
    from flexcontact.dam.key_numbers import engineer_numbers, mesh_study_row
    from flexcontact.dam.plot import plot_stress_histories
    from flexcontact.dam.section import write_section_csv
    from flexcontact.dam.stage2 import approach_time_s, response_duration_s, solve_stage2
    from flexcontact.impact_output import plot_history, write_history_csv
    duration = args.duration or response_duration_s(s)
    with fc.ResultWriter(folder, "impact", msh, tags=(cells,)) as xdmf:
        stage2 = solve_stage2(s, stage1, dt_s=args.dt, offset_m=args.impact_offset,
                              duration_s=duration, writer=xdmf,
                              contact_operator=args.contact_operator or "dense")
    p2, met = stage2.problem, stage2.metrics
    records = p2.records
    peak_u = stage2.peak_state
    with fc.ResultWriter(folder, "impact_peak", msh, tags=(cells,)) as xdmf:
        xdmf.write([peak_u, *stress_fields(stage1.V, peak_u, cells, stage1.materials(),
                                           stage1.kind)], stage2.peak_time_s)
    if comm.rank == 0:
        write_history_csv(folder / "impact_force.csv", records, p2.energy.initial)
        write_section_csv(folder / "base_section.csv", stage2.section_history)
        if not args.no_plot:
            unit = "N/m" if s.dim == 2 else "N"
            plot_history(folder / "impact_force.png", records, "log on the dam's face",
                         force_unit=unit, energy_unit="J/m" if s.dim == 2 else "J")
            plot_stress_histories(folder / "impact_stresses.png", stage2, s)
    numbers = engineer_numbers(s, stage1, stage2)
    summary["stage2"] = {
        "dt_s": stage2.timings_s["dt_s"], "steps": len(records),
        "duration_simulated_s": stage2.timings_s["duration_s"],
        "log_mass_effective_kg": stage2.log_mass_effective,
        "log_velocity_before_m_s": stage2.log_velocity_before,
        "log_velocity_after_m_s": stage2.log_velocity_after,
        "force_unit": "N/m" if s.dim == 2 else "N",
        "peak_force_N_per_m" if s.dim == 2 else "peak_force_N": met["peak_force"],
        "contact_start_s": met["contact_start_s"],
        "contact_start_s_ref": approach_time_s(s),
        "contact_episodes": met["episodes"],
        "impulse_N_s_per_m" if s.dim == 2 else "impulse_N_s": met["impulse"],
        "impact_point_m": stage2.impact_point_m,
        **numbers,
        "energy_before": p2.energy.initial, "energy_after": p2.energy.total,
        "energy_dissipated_contact": p2.energy.contact,
        "energy_balance_error_rel": p2.energy.balance_error_rel,
        "max_penetration_m": max(r.max_penetration_m for r in records),
        "timings_s": stage2.timings_s,
    }
    if comm.rank == 0:
        print(f"impact: peak force {met['peak_force']:.4e}, contact "
              f"{met['contact_duration_s'] * 1e3:.3f} ms, impulse {met['impulse']:.6e} "
              f"(log m_eff dv {-stage2.log_momentum_change:.6e}); peak principal stress "
              f"{args.impact_offset} m from the impact "
              f"{stage2.peak_tensile_stress_Pa / 1e6:.3f} MPa"
              + ("" if numbers["halfspace_tension_at_offset_Pa"] is None else
                 f" (half-space value with the tangential force and the static stress "
                 f"{numbers['halfspace_tension_at_offset_Pa'] / 1e6:.3f} MPa, normal force "
                 f"alone {numbers['halfspace_tension_normal_force_only_Pa'] / 1e6:.3f} MPa)"))
        print(f"linearised heel stress {numbers['sigma_heel_before_Pa'] / 1e6:.4f} MPa before, "
              f"up to {numbers['sigma_heel_during_max_Pa'] / 1e6:.4f} MPa during the impact")

# %% [markdown]
# ## ParaView picture
# The dam and the log at the step of the peak contact force, as they are (displacements
# true to scale: the log touches the face), coloured by the largest principal stress (red:
# tension; the log is in compression) on ±2 × the concrete's tensile strength (saturated
# beyond). Rendered by `pvbatch` under `xvfb-run` if ParaView is installed; otherwise the
# report says so.

# %%
paraview = (False, "skipped (--no-paraview)") if args.no_paraview else None
if not args.stage1_only and not args.no_paraview:
    from flexcontact.dam.picture import render_stress_picture
    paraview = (False, "not rendered")
    if comm.rank == 0:
        # Saturated at twice the concrete's tensile strength: the contact point's singular
        # peak would otherwise wash out the dam's stress field. Not warped: an exaggerated
        # dam would move its face through the log.
        paraview = render_stress_picture(folder / "impact_peak.xdmf",
                                         folder / "stress_paraview.png", 1.0,
                                         body_tag=(dam_tags.DAM, dam_tags.LOG),
                                         bound=2.0 * s.concrete_tensile_strength_Pa)
        print(("ParaView picture: " if paraview[0] else "no ParaView picture: ") + paraview[1])
    paraview = comm.bcast(paraview, root=0)

# %% [markdown]
# ## Mesh study
# With `--mesh-study`, the same impact on two finer meshes, every element size divided by
# √2 and by 2, near field and far field together (no output files). The report tabulates
# the three, extrapolates each quantity (Richardson), and gives the observed order and the
# default mesh's grid convergence index, or says where the meshes are not asymptotic.
# The crushed patch's contact mesh is refined with the rest; in 3D its contact zone then
# outgrows the dense operators, and the finer meshes hold it through the factor of the
# iteration matrix (`--contact-operator factor`, the same answer to rounding). In 3D the
# study took 25 minutes and 4.8 GB here, beside other jobs (its finest mesh has 229,000
# DOFs, the log's shaft at 5 cm); `--mesh-study-contact kept` keeps the patch
# at its size and refines the rest, leaving out the patch's error.

# %%
rows = None
if args.mesh_study and not args.stage1_only:
    from flexcontact.dam.convergence import RATIO
    from flexcontact.dam.key_numbers import study_scenarios
    rows = [{**numbers, "refine": s.refine, "h_impact_m": s.h_impact_m, "h_far_m": s.h_far_m,
             "h_contact_m": s.h_contact_m, "cells": summary["mesh"]["cells"],
             "dofs": summary["mesh"]["dofs"]}]
    study_contact = args.mesh_study_contact
    study_operator = args.contact_operator or (
        "factor" if s.dim == 3 and study_contact == "refined" else "dense")
    for finer in study_scenarios(s, RATIO, study_contact)[1:]:
        if comm.rank == 0:
            print(f"mesh study: h impact {finer.h_impact_m:.3g} m, far {finer.h_far_m:.3g} m, "
                  f"contact {finer.h_contact_m:.3g} m", flush=True)
        rows.append(mesh_study_row(finer, args.impact_offset, duration_s=duration, comm=comm,
                                   contact_operator=study_operator))
    summary["mesh_study"] = rows

summary["timings_s_total"] = time.perf_counter() - t_start
fc.write_summary(folder, summary, comm)
if comm.rank == 0:
    import json
    from flexcontact.dam.impact_report import write_report
    plain = json.loads((folder / "summary.json").read_text())
    print(f"report: {write_report(folder, plain, plain.get('mesh_study'), paraview)}")
