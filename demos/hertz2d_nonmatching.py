# %% [markdown]
# # Hertz line contact on non-matching meshes, either body as slave (plane strain)
#
# The set-up of `hertz2d.py` — a steel half-cylinder of radius R pressed onto a steel block
# by lowering its flat top — with the block's contact zone meshed at a different spacing
# from the cylinder's, so that no node faces another. Pairs are node–surface by default: each
# slave node against its closest point on the master facets, with the facet's shape weights;
# `--pairing surface_to_surface` uses integrated mortar rows (dual basis, exact integration
# over the segment overlaps, mortar.py) instead.
# `--slave cylinder` pairs the cylinder's nodes with the flat block; `--slave block` pairs
# the block's nodes with the faceted arc of the cylinder. Either way Hertz's answer
# (docs/architecture.md §6) is the reference:
#
#     a = sqrt(4 P R / (π E*)),   p0 = 2 P / (π a)
#
# Pairs are re-made before each increment from the current positions; F* was computed
# once, on all nodes of both tagged zones, and the summary counts the factorizations.
#
# Run: `/usr/bin/python3 demos/hertz2d_nonmatching.py [--slave block] [--refine N]
# [--pairing surface_to_surface]`
# (also with `mpirun -n 2`).

# %%
import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import analytic, compat, forms
from flexcontact.states import OPEN
from flexcontact.contact_profile import approach_to_load, elliptic_fit, hertz_fit, profile
from flexcontact.meshes import hertz2d, tags

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--slave", choices=("cylinder", "block"), default="cylinder",
                    help="the body whose nodes are paired")
parser.add_argument("--refine", type=int, default=0, help="halve the contact element size N times")
parser.add_argument("--pairing", choices=("node_to_surface", "surface_to_surface"),
                    default="node_to_surface", help="ContactInterface.pairing")
parser.add_argument("--block-spacing", type=float, default=0.7,
                    help="the block's zone spacing relative to the cylinder's")
parser.add_argument("--increments", type=int, default=4, help="load increments")
parser.add_argument("--no-plot", action="store_true", help="skip the PNG")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Geometry, materials, form
# The gmsh builder tags the cylinder's candidate zone `SLAVE` and the block's `MASTER`
# (names from the matching set-up); here they are simply the two zones.

# %%
R = 0.05                      # cylinder radius [m]
a_target = 0.1 * R            # contact half-width the load aims at [m]
msh, cells, facets, geo = hertz2d.build(comm, R=R, a_expected=a_target, refine=args.refine,
                                        block_spacing=args.block_spacing)
cylinder_zone, block_zone = tags.SLAVE, tags.MASTER
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
Estar = forms.effective_modulus(steel, steel)

V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")

# %% [markdown]
# ## Supports, contact and load
# The block's bottom is held; the cylinder's top is moved down by δ (and held
# horizontally); frictionless.

# %%
slave, master = ((cylinder_zone, block_zone) if args.slave == "cylinder"
                 else (block_zone, cylinder_zone))
fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
top, (top_x, top_y) = fc.dirichlet(V, facets, tags.LOADED)
problem = fc.ContactProblem(
    a, None, fixed + top,
    fc.ContactInterface(facets, slave=slave, master=master, mu=0.0,
                        name=f"hertz, {args.slave} as slave", pairing=args.pairing),
    bodies=(cells, {"block": tags.BASE, "cylinder": tags.UPPER}))

# %% [markdown]
# As in `hertz2d.py`, a small trial approach first, then δ ramped to the value that aims at
# a_target (P grows almost linearly with δ).

# %%
P_target = np.pi * Estar * a_target**2 / (4 * R)


def set_approach(d):
    top_y.value = -d


load = approach_to_load(problem, set_approach, a_target**2 / (2 * R), P_target, args.increments)


# Node–surface results keep their folder; other pairings get their own beside it.
suffix = "" if args.pairing == "node_to_surface" else f"_{args.pairing}"
name = f"hertz2d_nonmatching_{args.slave}{suffix}"
folder = fc.results_folder(f"hertz2d_nonmatching/{args.slave}{suffix}")
with fc.ResultWriter(folder, name, msh) as out:
    summaries = problem.solve(max(args.increments, 2), load=load, writer=out)

# %% [markdown]
# ## Measured against Hertz
# Nodal pressures at the slave nodes (force over tributary length); a and p0 from a
# least-squares elliptic fit p² = p0²(1 − x²/a²) of the inner nodes. Single-pass
# node–surface pairs on non-matching meshes make the nodal pressure oscillate from node
# to node (a slave node above a master node meets a softer surface than one above the
# middle of a master facet; the oscillation does not shrink under refinement, the known
# weakness that integrated surface–surface pairing removes): the largest nodal pressure
# is reported as `p_nodal_max`, with the RMS deviation of the nodes from Hertz's curve.

# %%
if comm.rank == 0:
    x, p, q, states, _ = profile(problem)
    P = summaries[-1].normal_force
    a_ref, p0_ref = analytic.hertz_cylinder(P, R, Estar)
    _, p_nodal_max, a_extent = hertz_fit(x, p)
    a_fit, p0 = elliptic_fit(x, p)
    inside = np.abs(x) < a_ref
    p_ref = np.array([analytic.hertz_pressure(xi, a_ref, p0_ref) for xi in x])
    rms = float(np.sqrt(np.mean((p[inside] - p_ref[inside]) ** 2)) / p0_ref)
    summary = {
        "demo": "hertz2d_nonmatching", "slave": args.slave, "pairing": args.pairing,
        "units": "SI (m, Pa, N/m)",
        "P": P, "P_target": P_target, "R_m": R, "a_target_m": a_target,
        "materials": {"block": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                      "cylinder": {"E_Pa": steel.E_Pa, "nu": steel.nu}},
        "a": a_fit, "a_ref": a_ref, "a_error_rel": a_fit / a_ref - 1, "a_extent": a_extent,
        "p0": p0, "p0_ref": p0_ref, "p0_error_rel": p0 / p0_ref - 1,
        "p_nodal_max": p_nodal_max, "p_nodal_max_error_rel": p_nodal_max / p0_ref - 1,
        "pressure_rms_error_rel_p0": rms,
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "contact_pairs": int(problem.m), "closed_pairs": int((states > OPEN).sum()),
        "contact_dofs": int(problem.n_contact_dofs),
        "mesh": fc.output.mesh_info(V, h_cylinder_m=geo["h_contact"],
                                    h_block_m=geo["h_block"], refine=args.refine),
        **fc.output.run_record(problem, summaries, t_start),
        "profile": {"x": x, "pressure": p, "state": states},
    }
    fc.write_summary(folder, summary)
    print(f"Hertz ({args.slave} as slave, {args.pairing}): a = {a_fit:.5e} m (ref {a_ref:.5e}, "
          f"{100 * (a_fit / a_ref - 1):+.2f}%), p0 = {p0:.5e} Pa (ref {p0_ref:.5e}, "
          f"{100 * (p0 / p0_ref - 1):+.2f}%); largest nodal pressure "
          f"{100 * (p_nodal_max / p0_ref - 1):+.2f}%, RMS deviation {100 * rms:.1f}% of p0; "
          f"factorizations {summary['factorizations']}")

    if not args.no_plot:
        fc.output.plot_hertz_profile(
            folder / f"{name}.png", x, p, a_ref, p0_ref,
            label=f"flexcontact, {args.slave} as slave",
            title=f"Non-matching Hertz: a {100 * (a_fit / a_ref - 1):+.1f}%, "
                  f"p0 {100 * (p0 / p0_ref - 1):+.1f}%")
    print(f"results in {folder}/")
