# %% [markdown]
# # Two cylinders of different radii pressed together (plane strain, non-matching meshes)
#
# Cylinder 1 (radius R1, below) and cylinder 2 (radius R2, above), each half a disc, touch
# at one line; cylinder 1's flat bottom is held and cylinder 2's flat top is lowered. Near
# the contact the pair acts as one cylinder of radius R = (1/R1 + 1/R2)⁻¹ pressed on a
# plane by the combined modulus E* = [(1 − ν1²)/E1 + (1 − ν2²)/E2]⁻¹, so Hertz's answer
# (docs/architecture.md §6) is the reference:
#
#     a = sqrt(4 P R / (π E*)),   p0 = 2 P / (π a)
#
# Both contact arcs are faceted chains whose nodes sit on the circles at different
# spacings: no node faces another. `--slave 1|2` picks the body whose nodes (or, for
# surface–surface pairing, whose facets) carry the contact rows; the master is then the
# other, curved, faceted arc. `--pairing auto` (default) takes surface–surface pairing
# (integrated mortar rows, mortar.py) on these non-matching meshes; `--pairing
# node_to_surface` pairs each slave node with its closest point on the master facets.
#
# Run: `/usr/bin/python3 demos/two_cylinders.py [--slave 1|2] [--refine N]
# [--pairing auto|surface_to_surface|node_to_surface]` (also with `mpirun -n 2`).

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
from flexcontact.meshes import tags, two_cylinders

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--slave", type=int, choices=(1, 2), default=2,
                    help="the cylinder whose surface carries the contact rows")
parser.add_argument("--refine", type=int, default=0, help="halve the contact element size N times")
parser.add_argument("--pairing", choices=("auto", "surface_to_surface", "node_to_surface"),
                    default="auto", help="ContactInterface.pairing")
parser.add_argument("--R1", type=float, default=0.05, help="radius of cylinder 1 [m]")
parser.add_argument("--R2", type=float, default=0.03, help="radius of cylinder 2 [m]")
parser.add_argument("--E1", type=float, default=200e9, help="Young's modulus of cylinder 1 [Pa]")
parser.add_argument("--nu1", type=float, default=0.3, help="Poisson's ratio of cylinder 1")
parser.add_argument("--E2", type=float, default=70e9, help="Young's modulus of cylinder 2 [Pa]")
parser.add_argument("--nu2", type=float, default=0.33, help="Poisson's ratio of cylinder 2")
parser.add_argument("--spacing-ratio", type=float, default=0.7,
                    help="cylinder 1's zone spacing relative to cylinder 2's")
parser.add_argument("--increments", type=int, default=4, help="load increments")
parser.add_argument("--no-plot", action="store_true", help="skip the PNG")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Geometry, materials, form
# The builder tags cylinder 1's candidate arc `MASTER` and cylinder 2's `SLAVE` (the names
# of the shared convention); here they are just the two zones. The load aims at a half-width
# of a tenth of R, small against both radii as Hertz assumes.

# %%
body1 = forms.Material(E_Pa=args.E1, nu=args.nu1, name="cylinder 1")
body2 = forms.Material(E_Pa=args.E2, nu=args.nu2, name="cylinder 2")
R = two_cylinders.effective_radius(args.R1, args.R2)
a_target = 0.1 * R
msh, cells, facets, geo = two_cylinders.build(comm, R1=args.R1, R2=args.R2,
                                              a_expected=a_target, refine=args.refine,
                                              spacing_ratio=args.spacing_ratio)
Estar = forms.effective_modulus(body1, body2)

V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.BASE: body1, tags.UPPER: body2}, dx, "plane_strain")

# %% [markdown]
# ## Supports, contact and load
# Cylinder 1's flat bottom is held; cylinder 2's flat top is moved down by δ (and held
# horizontally); frictionless.

# %%
zone = {1: tags.MASTER, 2: tags.SLAVE}
slave, master = zone[args.slave], zone[3 - args.slave]
fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
top, (top_x, top_y) = fc.dirichlet(V, facets, tags.LOADED)
interface = fc.ContactInterface(facets, slave=slave, master=master, mu=0.0,
                                name=f"two cylinders, cylinder {args.slave} as slave",
                                pairing=args.pairing)
problem = fc.ContactProblem(
    a, None, fixed + top, interface,
    bodies=(cells, {"cylinder 1": tags.BASE, "cylinder 2": tags.UPPER}))

# %% [markdown]
# A small trial approach first, then δ ramped to the value that aims at a_target (P grows
# almost linearly with δ).

# %%
P_target = np.pi * Estar * a_target**2 / (4 * R)


def set_approach(d):
    top_y.value = -d


load = approach_to_load(problem, set_approach, a_target**2 / (2 * R), P_target, args.increments)
pairing = interface.pairing_used
folder = fc.results_folder(f"two_cylinders/slave{args.slave}_{pairing}")
name = f"two_cylinders_slave{args.slave}_{pairing}"
with fc.ResultWriter(folder, name, msh) as out:
    summaries = problem.solve(max(args.increments, 2), load=load, writer=out)

# %% [markdown]
# ## Measured against Hertz
# The summary holds each measured quantity beside its reference (`a`/`a_ref`, `p0`/`p0_ref`).
# Nodal pressures at the slave nodes (force over tributary length); a and p0 from a
# least-squares elliptic fit p² = p0²(1 − x²/a²) of the inner nodes of the closed zone.
# The x of a slave node on a faceted arc differs from its arc length by O(a³/R²), far
# below the element size.

# %%
if comm.rank == 0:
    x, p, _, states, _ = profile(problem)
    P = summaries[-1].normal_force
    a_ref, p0_ref = analytic.hertz_cylinder(P, R, Estar)
    _, p_nodal_max, a_extent = hertz_fit(x, p)
    a_fit, p0 = elliptic_fit(x, p)
    summary = {
        "demo": "two_cylinders", "slave": args.slave, "pairing": pairing,
        "pairing_requested": args.pairing, "units": "SI (m, Pa, N/m)",
        "R1_m": args.R1, "R2_m": args.R2, "R_m": R, "Estar_Pa": Estar,
        "P": P, "P_target": P_target, "a_target_m": a_target,
        "materials": {"cylinder 1": {"E_Pa": body1.E_Pa, "nu": body1.nu},
                      "cylinder 2": {"E_Pa": body2.E_Pa, "nu": body2.nu}},
        "a": a_fit, "a_ref": a_ref, "a_error_rel": a_fit / a_ref - 1, "a_extent": a_extent,
        "p0": p0, "p0_ref": p0_ref, "p0_error_rel": p0 / p0_ref - 1,
        "p_nodal_max": p_nodal_max, "p_nodal_max_error_rel": p_nodal_max / p0_ref - 1,
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "contact_pairs": int(problem.m), "closed_pairs": int((states > OPEN).sum()),
        "contact_dofs": int(problem.n_contact_dofs),
        "mesh": fc.output.mesh_info(V, h_cylinder2_m=geo["h_contact"],
                                    h_cylinder1_m=geo["h_cylinder1"], refine=args.refine),
        **fc.output.run_record(problem, summaries, t_start),
        "profile": {"x": x, "pressure": p, "state": states},
    }
    fc.write_summary(folder, summary)
    print(f"Two cylinders (cylinder {args.slave} as slave, {pairing}): a = {a_fit:.5e} m "
          f"(ref {a_ref:.5e}, {100 * (a_fit / a_ref - 1):+.2f}%), p0 = {p0:.5e} Pa "
          f"(ref {p0_ref:.5e}, {100 * (p0 / p0_ref - 1):+.2f}%); largest nodal pressure "
          f"{100 * (p_nodal_max / p0_ref - 1):+.2f}%; factorizations {summary['factorizations']}")

    if not args.no_plot:
        fc.output.plot_hertz_profile(
            folder / f"{name}.png", x, p, a_ref, p0_ref, ref_label="Hertz, 1/R = 1/R1 + 1/R2",
            label=f"flexcontact, cylinder {args.slave} as slave",
            title=f"Two cylinders: a {100 * (a_fit / a_ref - 1):+.1f}%, "
                  f"p0 {100 * (p0 / p0_ref - 1):+.1f}%")
    print(f"results in {folder}/")
