# %% [markdown]
# # Hertz contact of a cylinder on an elastic block (plane strain)
#
# A half-cylinder of radius R is pressed onto an elastic block by lowering its flat top.
# Both bodies are steel. Near the contact the answer is Hertz's (docs/architecture.md §6):
#
#     a = sqrt(4 P R / (π E*)),   p0 = 2 P / (π a),   p(x) = p0 sqrt(1 − x²/a²)
#
# with P the load per unit length and E* = [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]⁻¹. The interface nodes
# of the two bodies face each other (node–node pairs); the initial gap R − sqrt(R² − x²)
# enters through x0. The top is lowered in increments; each increment costs one
# back-substitution with the one MUMPS factorization (two on several MPI ranks) plus the
# small dense contact solve.
#
# Run: `/usr/bin/python3 demos/hertz2d.py [--refine N]` (also with `mpirun -n 2`).

# %%
import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import analytic, compat, forms
from flexcontact.states import OPEN
from flexcontact.contact_profile import approach_to_load, hertz_fit, profile
from flexcontact.meshes import hertz2d, tags

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--refine", type=int, default=0, help="halve the contact element size N times")
parser.add_argument("--increments", type=int, default=4, help="load increments")
parser.add_argument("--no-plot", action="store_true", help="skip the PNG")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Geometry, materials, form
# The mesh comes from gmsh with named physical groups: the block (master body, tag
# `BASE`), the cylinder (`UPPER`), the block's bottom (`FIXED`), the cylinder's flat top
# (`LOADED`) and the two candidate contact zones (`MASTER`, `SLAVE`).

# %%
R = 0.05                      # cylinder radius [m]
a_target = 0.1 * R            # contact half-width the load aims at [m]
msh, cells, facets, geo = hertz2d.build(comm, R=R, a_expected=a_target, refine=args.refine)
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
Estar = forms.effective_modulus(steel, steel)

V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")

# %% [markdown]
# ## Supports and load
# The block's bottom is held; the cylinder's top is moved down by δ (and held
# horizontally). Hertz is frictionless, so μ = 0.

# %%
fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
top, (top_x, top_y) = fc.dirichlet(V, facets, tags.LOADED)
problem = fc.ContactProblem(
    a, None, fixed + top,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=0.0, name="hertz"),
    bodies=(cells, {"block": tags.BASE, "cylinder": tags.UPPER}),
    stress=lambda w: forms.von_mises(w, steel, "plane_strain"))

# %% [markdown]
# The approach δ that gives the target load is not known beforehand (in 2D it depends on
# the bodies' size). The first increment is a small trial approach; since P grows almost
# linearly with δ, the remaining increments ramp δ to the value that aims at a_target.

# %%
P_target = np.pi * Estar * a_target**2 / (4 * R)


def set_approach(d):
    top_y.value = -d


load = approach_to_load(problem, set_approach, a_target**2 / (2 * R), P_target, args.increments)


folder = fc.results_folder("hertz2d")
with fc.ResultWriter(folder, "hertz2d", msh, tags=(cells,)) as out:
    summaries = problem.solve(max(args.increments, 2), load=load, writer=out)

# %% [markdown]
# ## Measured against Hertz
# p0 is the largest nodal pressure (nodal force over the node's tributary length); a is
# the half-width of the closed zone from an elliptic fit of the inner nodes (and, as a
# check, the midpoint between the last closed and first open node).

# %%
if comm.rank == 0:
    x, p, q, states, _ = profile(problem)
    P = summaries[-1].normal_force
    a_ref, p0_ref = analytic.hertz_cylinder(P, R, Estar)
    a_fit, p0, a_extent = hertz_fit(x, p)
    inside = np.abs(x) < a_ref
    p_ref = np.array([analytic.hertz_pressure(xi, a_ref, p0_ref) for xi in x])
    rms = float(np.sqrt(np.mean((p[inside] - p_ref[inside]) ** 2)) / p0_ref)
    last = summaries[-1]
    summary = {
        "demo": "hertz2d",
        "units": "SI (m, Pa, N/m)",
        "P": P, "P_target": P_target,
        # The inputs of the references, so that a test can recompute them.
        "R_m": R, "a_target_m": a_target,
        "materials": {"block": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                      "cylinder": {"E_Pa": steel.E_Pa, "nu": steel.nu}},
        "a": a_fit, "a_ref": a_ref, "a_error_rel": a_fit / a_ref - 1,
        "a_extent": a_extent,
        "p0": p0, "p0_ref": p0_ref, "p0_error_rel": p0 / p0_ref - 1,
        "pressure_rms_error_rel_p0": rms,
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "contact_pairs": int(problem.m),
        "closed_pairs": int((states > OPEN).sum()),
        "contact_dofs": int(problem.n_contact_dofs),
        "mesh": fc.output.mesh_info(V, h_contact_m=geo["h_contact"], refine=args.refine),
        **fc.output.run_record(problem, summaries, t_start),
        "profile": {"x": x, "pressure": p, "traction": q[:, 0], "state": states},
    }
    fc.write_summary(folder, summary)
    print(f"Hertz: a = {a_fit:.5e} m (ref {a_ref:.5e}, {100 * (a_fit / a_ref - 1):+.2f}%), "
          f"p0 = {p0:.5e} Pa (ref {p0_ref:.5e}, {100 * (p0 / p0_ref - 1):+.2f}%)")

    if not args.no_plot:
        fc.output.plot_hertz_profile(
            folder / "hertz2d.png", x, p, a_ref, p0_ref, label="flexcontact: pressure",
            ylabel="traction [MPa]",
            extra=[(x, q[:, 0], "s", "flexcontact: tangential traction")],
            title=f"Hertz cylinder, P = {P / 1e6:.2f} MN/m: a {100 * (a_fit / a_ref - 1):+.1f}%,"
                  f" p0 {100 * (p0 / p0_ref - 1):+.1f}%")
    print(f"results in {folder}/")
