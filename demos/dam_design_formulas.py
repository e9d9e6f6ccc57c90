# %% [markdown]
# # Computed log impact forces against published design formulas
#
# The dam scenario's impact (stage 2) over a small grid of log speeds and log lengths
# (masses), in 3D (a dam block 15 m wide and a cylindrical log: forces in N, as the
# formulas give them), against the debris-impact formulas of
# `flexcontact.dam.design_formulas`: ASCE 7 / FEMA P-55 (impulse over Δt = 0.03 s),
# Haehnel & Daly (F = v √(k m), k = 2.4 MN/m), EN 1991-1-7 Annex C with the log as an
# elastic bar (k = EA/L) and Matsutomi's driftwood fit. See docs/dam.md for why they differ.
#
# The model's columns: the log's flat end elastic (the upper bound of the force), and its
# end crushing at the wood's crushing strength (docs/crushing.md), flat and rounded (a
# spherical cap of radius D; `--crushing-ends`), on a mesh that resolves the crushed patch
# (`scenario.CRUSHED_PATCH_MESH`). All are the filtered peak force (a centred moving
# average over a tenth of the log's 2L/c, docs/impact.md).
# Elastic, the model is linear in the speed; crushing, it is not, so each speed is a run.
#
# With `--dim 2` the plane-strain section is used instead and its force per metre is
# multiplied by the log's diameter (the width a log occupies), a rough conversion stated
# in the table.
#
# Run: `/usr/bin/python3 demos/dam_design_formulas.py [--speeds 1 2 4] [--lengths 5 10]
# [--dim 3] [--no-crushing] [--crushing-ends flat rounded] [--contact-size 0.025]`; the
# whole 3D table (18 runs) takes about 10 minutes here on the resolving 12.5 mm mesh, one
# minute with `--contact-size 0.025`; `--dim 2` takes about 15 s. Results in
# `results/dam_design_formulas/` (CSV, markdown table, PNG, summary.json).

# %%
import argparse
import csv
import time

import numpy as np
from mpi4py import MPI

import flexcontact as fc
from flexcontact.dam import DamScenario
from flexcontact.dam import design_formulas as dfm
from flexcontact.dam.stage1 import solve_stage1
from flexcontact.dam.stage2 import approach_time_s, default_time_step_s, solve_stage2

parser = argparse.ArgumentParser(description="computed log impact forces vs design formulas")
parser.add_argument("--dim", type=int, default=3, choices=(2, 3))
parser.add_argument("--speeds", type=float, nargs="+", default=[1.0, 2.0, 4.0], help="m/s")
parser.add_argument("--lengths", type=float, nargs="+", default=[5.0, 10.0],
                    help="log lengths, m (the mass follows)")
parser.add_argument("--refine", type=int, default=0)
parser.add_argument("--no-crushing", action="store_true",
                    help="skip the crushing-end columns (elastic end only)")
parser.add_argument("--contact-size", type=float, default=None,
                    help="element size (m) about the first-contact point of the crushing runs "
                         "(default: CRUSHED_PATCH_MESH of the dimension)")
parser.add_argument("--crushing-ends", nargs="+", default=["flat", "rounded"],
                    choices=("flat", "chamfered", "rounded"),
                    help="end shapes of the crushing columns (the rounded cap's radius is D)")
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()
folder = fc.results_folder("dam_design_formulas")

# %% [markdown]
# ## The runs
# One stage 1 per log length (the mesh changes), one stage 2 per speed. Each run lasts the
# approach plus three times 2L/c of the log, so that the contact has ended. The approach is
# measured on the mesh: the faceted cylinder's nearest node lies a few millimetres further
# from the face than the exact cylinder's rim (7 mm at the default 3D size), which at
# 1 m/s is as long as the contact itself.

# %%
from flexcontact import compat
from flexcontact.meshes import dam_tags


def mesh_gap_m(stage1) -> float:
    """Distance from the face (x = 0) to the log's nearest node on the mesh. Collective."""
    mesh = stage1.mesh
    cells = mesh.cell_tags.indices[mesh.cell_tags.values == dam_tags.LOG]
    x = compat.geometry_x(mesh.msh)
    nodes = compat.geometry_dofmap(mesh.msh)[cells].ravel()
    front = float(x[nodes, 0].max(initial=-np.inf))
    return -comm.allreduce(front, op=MPI.MAX)


from flexcontact.dam.scenario import CRUSHED_PATCH_MESH

CRUSHING_ROUND_TRIPS = 8.0
"""A crushing end's run: the approach and 8 × 2L/c of the log (the default 3D log's contact
lasts 3.4 × 2L/c at 2 m/s); each row says whether the contact ended within it."""


def impact(s, stage1, gap, round_trips=3.0):
    """Stage 2 of ``s`` from ``stage1`` for the approach and ``round_trips`` × 2L/c of the
    log: an elastic end's contact lasts about one; a crushing end's lasts several, while the
    crushed area grows."""
    approach = approach_time_s(s) * gap / s.log_gap_m
    duration = approach + round_trips * default_time_step_s(s, steps_in_contact=1)
    r = solve_stage2(s, stage1, duration_s=duration, stress_every=10**9)
    return r, duration


rows = []
for length in args.lengths:
    base = DamScenario(dim=args.dim, refine=args.refine, log_length_m=length)
    stage1 = solve_stage1(base, comm=comm)
    gap = max(mesh_gap_m(stage1), base.log_gap_m)
    crushing = {}  # end shape -> (scenario, stage 1, mesh gap)
    for end in ([] if args.no_crushing else args.crushing_ends):
        size, zone, layer = CRUSHED_PATCH_MESH[args.dim]
        size = args.contact_size or size
        sc = base.replace(log_end_crushes=True, log_end_shape=end, mesh_size_contact_m=size,
                          contact_zone_m=zone, contact_layer_m=layer)
        st1 = solve_stage1(sc, comm=comm)
        crushing[end] = (sc, st1, max(mesh_gap_m(st1), sc.log_gap_m))
    for v in args.speeds:
        s = base.replace(log_speed_m_s=v)
        r, duration = impact(s, stage1, gap)
        m = s.log_mass_kg()
        width = 1.0 if s.dim == 3 else s.log_diameter_m
        F = r.metrics["peak_force_filtered"] * width
        row = {"length_m": length, "mass_kg": m, "speed_m_s": v,
               "computed_N": F, "computed_raw_N": r.metrics["peak_force"] * width,
               "contact_s": r.metrics["contact_duration_s"],
               "impulse_N_s": r.metrics["impulse"] * width,
               "episodes": r.metrics["episodes"], "mesh_gap_m": gap,
               "contact_ended": bool(r.metrics["contact_end_s"] is not None
                                     and r.metrics["contact_end_s"] < duration - 1e-12)}
        for end, (sc, st1, gap_c) in crushing.items():
            rc, duration_c = impact(sc.replace(log_speed_m_s=v), st1, gap_c,
                                    round_trips=CRUSHING_ROUND_TRIPS)
            Fc = rc.metrics["peak_force_filtered"] * width
            end_c = rc.metrics["contact_end_s"]
            mc = sc.log_mass_kg()
            row.update({f"computed_crushing_{end}_N": Fc,
                        f"crush_depth_{end}_m": max((x.crush_depth_max_m
                                                     for x in rc.problem.records), default=0.0),
                        f"k_effective_crushing_{end}_N_m": Fc * Fc
                        / (mc * (1 + s.added_mass_coefficient) * v * v),
                        f"contact_ended_crushing_{end}": bool(
                            end_c is not None and end_c < duration_c - 1e-12)})
        row.update({k: f for k, f in dfm.all_formulas_N(
            m, v, s.log_diameter_m, length, s.wood.E_Pa, s.wood.rho_kg_m3,
            s.wood_crushing_strength_Pa).items()})
        # What the computed force implies for the formulas' free parameter.
        row["k_effective_N_m"] = F * F / (m * (1 + s.added_mass_coefficient) * v * v)
        rows.append(row)
        if comm.rank == 0:
            crushed = "".join(f", crushing {end} end "
                              f"{row[f'computed_crushing_{end}_N'] / 1e6:.3f} MN"
                              for end in crushing)
            print(f"L = {length:g} m (m = {m:.0f} kg), v = {v:g} m/s: computed "
                  f"{F / 1e6:.3f} MN elastic{crushed}; ASCE 7 {row['asce7'] / 1e6:.3f}, Haehnel & Daly "
                  f"{row['haehnel_daly'] / 1e6:.3f}, EN 1991-1-7 bar "
                  f"{row['eurocode_bar'] / 1e6:.3f}, Matsutomi {row['matsutomi'] / 1e6:.3f} MN",
                  flush=True)

# %% [markdown]
# ## The table and the plot

# %%
ENDS = [] if args.no_crushing else list(args.crushing_ends)
KEYS = (("computed_N",) + tuple(f"computed_crushing_{e}_N" for e in ENDS)
        + ("asce7", "haehnel_daly", "eurocode_bar", "matsutomi"))
NAMES = {"computed_N": "model, elastic flat end",
         **{f"computed_crushing_{e}_N": f"model, {e} end crushing" for e in ENDS},
         "asce7": "ASCE 7 / FEMA P-55",
         "haehnel_daly": "Haehnel & Daly", "eurocode_bar": "EN 1991-1-7 bar (EA/L)",
         "matsutomi": "Matsutomi"}
if comm.rank == 0:
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / "comparison.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    unit = "N" if args.dim == 3 else "N (2D per metre × log diameter)"
    k_heads = " | k_eff elastic [MN/m]" + "".join(f" | k_eff {e} crushing [MN/m]"
                                                  for e in ENDS)
    contact_mm = 1e3 * (args.contact_size or CRUSHED_PATCH_MESH[args.dim][0])
    crushing_mesh = (f" Crushing runs: elements of {contact_mm:g} mm about the first contact."
                     if ENDS else "")
    lines = [f"Peak impact force [MN]; {args.dim}D model, forces in {unit}; the model's "
             "columns are filtered peaks (moving average over a tenth of the log's 2L/c)."
             + crushing_mesh,
             "", "| L [m] | m [kg] | v [m/s] | " + " | ".join(NAMES[k] for k in KEYS)
             + " | contact [ms]" + k_heads + " |",
             "|---" * (5 + len(KEYS) + len(ENDS)) + "|"]
    for r in rows:
        k_vals = f" | {r['k_effective_N_m'] / 1e6:.1f}" + "".join(
            f" | {r[f'k_effective_crushing_{e}_N_m'] / 1e6:.1f}" for e in ENDS)
        lines.append(f"| {r['length_m']:g} | {r['mass_kg']:.0f} | {r['speed_m_s']:g} | "
                     + " | ".join(f"{r[k] / 1e6:.3f}" for k in KEYS)
                     + f" | {r['contact_s'] * 1e3:.2f}{k_vals} |")
    (folder / "comparison.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    if not args.no_plot:
        from flexcontact.output import pyplot
        plt = pyplot()
        fig, axes = plt.subplots(1, len(args.lengths), figsize=(5 * len(args.lengths), 4),
                                 squeeze=False)
        for ax, length in zip(axes[0], args.lengths):
            sel = [r for r in rows if r["length_m"] == length]
            v = [r["speed_m_s"] for r in sel]
            for k in KEYS:
                model = k.startswith("computed")
                ax.plot(v, [r[k] / 1e6 for r in sel], "o-" if model else ".--",
                        label=NAMES[k], lw=2 if model else 1)
            ax.set_yscale("log")
            ax.set_xlabel("log speed [m/s]")
            ax.set_ylabel("peak force [MN]")
            ax.set_title(f"log {length:g} m × Ø{base.log_diameter_m:g} m "
                         f"({sel[0]['mass_kg']:.0f} kg)")
            ax.grid(True, which="both", lw=0.3)
        axes[0][0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(folder / "comparison.png", dpi=120)
        plt.close(fig)
fc.write_summary(folder, {"demo": "dam_design_formulas", "dim": args.dim, "rows": rows,
                          "contact_size_m": args.contact_size or CRUSHED_PATCH_MESH[args.dim][0],
                          "timings_s_total": time.perf_counter() - t_start}, comm)
