# %% [markdown]
# # Hertz contact of a sphere on an elastic block (3D, quarter model)
#
# A column of steel whose lower end is a sphere of radius R is pressed onto a steel block by
# lowering its flat top. Near the contact the answer is Hertz's (docs/architecture.md §6):
#
#     a = (3 P R / (4 E*))^(1/3),   p0 = 3 P / (2 π a²),   p(r) = p0 sqrt(1 − r²/a²)
#
# with P the total normal load [N], r the distance from the axis and
# E* = [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]⁻¹. Only the quarter x ≥ 0, y ≥ 0 is meshed: the planes x = 0
# and y = 0 are planes of symmetry, where the normal displacement vanishes (u_x = 0 on
# x = 0, u_y = 0 on y = 0), so P is four times the quarter's normal force.
#
# The interface nodes of the two bodies face each other (node–node pairs); the initial gap
# R − sqrt(R² − r²) enters through x0. The top is lowered in increments; each increment costs
# one back-substitution with the one MUMPS factorization (two on several MPI ranks) plus the
# dense contact solve.
#
# Run: `/usr/bin/python3 demos/hertz3d.py [--refine N]` (also with `mpirun -n 2`).

# %%
import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import analytic, compat, forms
from flexcontact.states import OPEN
from flexcontact.contact_profile import approach_to_load, hertz_fit
from flexcontact.meshes import hertz3d, tags

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--refine", type=int, default=0, help="halve the element sizes N times")
parser.add_argument("--zone-factor", type=float, default=1.6,
                    help="candidate zone radius over the target contact radius")
parser.add_argument("--elements-per-radius", type=float, default=6.0,
                    help="target contact radius over the contact element size at --refine 0")
parser.add_argument("--h-far", type=float, default=0.02, help="largest element size at --refine 0 [m]")
parser.add_argument("--increments", type=int, default=3, help="load increments")
parser.add_argument("--no-plot", action="store_true", help="skip the PNG")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Geometry, materials, form
# The mesh comes from gmsh with named physical groups: the block (master body, tag `BASE`),
# the column (`UPPER`), the block's bottom (`FIXED`), the column's flat top (`LOADED`), the
# two symmetry planes (`SYMMETRY_X`, `SYMMETRY_Y`, on both bodies) and the candidate
# contact zones (`MASTER`, `SLAVE`, quarter discs of radius 1.6 a: the contact stays inside,
# and every candidate node outside it only adds to the dense contact problem).
#
# Element sizes: a/6 on the contact zone and 20 mm far from it at `--refine 0` (about
# 12,000 DOFs, under a second); `--refine 1` halves both (a/12, about 60,000 DOFs).

# %%
R = 0.05                      # sphere radius [m]
a_target = 0.1 * R            # contact radius the load aims at [m]
t0 = time.perf_counter()
msh, cells, facets, geo = hertz3d.build(
    comm, R=R, a_expected=a_target, h_contact=a_target / args.elements_per_radius,
    h_far=args.h_far, zone_factor=args.zone_factor, refine=args.refine)
t_mesh = time.perf_counter() - t0
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
Estar = forms.effective_modulus(steel, steel)

V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "3d")

# %% [markdown]
# ## Supports, symmetry, load
# The block's bottom is clamped; the column's top is moved down by δ (and held in x and y).
# On each symmetry plane only the displacement normal to it is prescribed (zero), the
# tangential ones are free. Hertz is frictionless, so μ = 0.

# %%
fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
sym_x, _ = fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])
sym_y, _ = fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])
top, (_, _, top_z) = fc.dirichlet(V, facets, tags.LOADED)
problem = fc.ContactProblem(
    a, None, fixed + sym_x + sym_y + top,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=0.0, name="hertz3d"),
    bodies=(cells, {"block": tags.BASE, "column": tags.UPPER}),
    stress=lambda w: forms.von_mises(w, steel, "3d"))

# %% [markdown]
# The approach δ that gives the target load is not known beforehand (it includes the
# compliance of the column and of the block). The first increment is a small trial
# approach; P grows like δ^(3/2) in Hertz contact, so the remaining increments ramp δ to
# the trial value times (P_target/P_trial)^(2/3), which lands close to the target.

# %%
P_target = 4 * Estar * a_target**3 / (3 * R)   # full-sphere load for a = a_target [N]


def set_approach(d):
    top_z.value = -d


load = approach_to_load(problem, set_approach, 0.5 * a_target**2 / R, P_target, args.increments,
                        exponent=2 / 3, force_scale=4)  # quarter model: P = 4 × its force


folder = fc.results_folder("hertz3d")
with fc.ResultWriter(folder, "hertz3d", msh, tags=(cells,)) as out:
    summaries = problem.solve(max(args.increments, 2), load=load, writer=out)

# %% [markdown]
# ## Measured against Hertz
# The nodal pressure is the pair's normal force over the slave node's tributary area. On a
# symmetry plane both are cut by the same factor (a node on one plane carries half of its
# full-model force and has half its area; the node on the axis a quarter of each), so the
# ratio is the full model's pressure without correction. p0 is the pressure of the node on
# the axis (r = 0); a comes from an elliptic fit p² = p0²(1 − r²/a²) of the closed nodes
# (all nodes inside 90 % of the closed zone's radius), r = sqrt(x² + y²).

# %%
if comm.rank == 0:
    pr = problem.pairs
    inc = problem.increments[-1]
    xy = pr.x[:pr.m, :2]
    r = np.hypot(xy[:, 0], xy[:, 1])
    p = inc.lam[:, 0] / pr.area
    order = np.argsort(r)
    r, p, xy, states = r[order], p[order], xy[order], inc.states[order]
    P = 4 * summaries[-1].normal_force
    a_ref, p0_ref = analytic.hertz_sphere(P, R, Estar)
    a_fit, p_max, a_extent = hertz_fit(r, p)
    if r[0] > 1e-9 * R:
        raise RuntimeError(f"no slave node on the axis (nearest at r = {r[0]:.3e} m)")
    p0 = float(p[0])
    p_ref = np.array([analytic.hertz_pressure(ri, a_ref, p0_ref) for ri in r])
    inside = r < a_ref
    rms = float(np.sqrt(np.mean((p[inside] - p_ref[inside]) ** 2)) / p0_ref)
    # The symmetry planes: the pressure there must follow the same curve as inside the quarter
    # (same tributary-area factor on force and area).
    planar = np.minimum(xy[:, 0], xy[:, 1]) < 1e-9 * R
    on_plane = planar & inside & (r > 0)
    off_plane = ~planar & inside & (r > 0)
    plane_dev = float(np.sqrt(np.mean((p[on_plane] - p_ref[on_plane]) ** 2)) / p0_ref)
    off_dev = float(np.sqrt(np.mean((p[off_plane] - p_ref[off_plane]) ** 2)) / p0_ref)
    summary = {
        "demo": "hertz3d",
        "units": "SI (m, Pa, N)",
        "P": P, "P_target": P_target, "P_quarter": summaries[-1].normal_force,
        # The inputs of the references, so that a test can recompute them.
        "R_m": R, "a_target_m": a_target,
        "materials": {"block": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                      "column": {"E_Pa": steel.E_Pa, "nu": steel.nu}},
        "a": a_fit, "a_ref": a_ref, "a_error_rel": a_fit / a_ref - 1,
        "a_extent": a_extent,
        "p0": p0, "p0_ref": p0_ref, "p0_error_rel": p0 / p0_ref - 1,
        "p_max": p_max,
        "pressure_rms_error_rel_p0": rms,
        "pressure_rms_error_rel_p0_symmetry_planes": plane_dev,
        "pressure_rms_error_rel_p0_interior": off_dev,
        "approach_m": float(-top_z.value),
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "contact_pairs": int(problem.m),
        "closed_pairs": int((states > OPEN).sum()),
        "contact_dofs": int(problem.n_contact_dofs),
        "candidate_zone_radius_m": geo["w"],
        "outermost_closed_r_m": float(r[states > OPEN].max()),
        "mesh": {"cells": int(msh.topology.index_map(3).size_global),
                 "dofs": int(V.dofmap.index_map.size_global * V.dofmap.index_map_bs),
                 "h_contact_m": geo["h_contact"], "h_far_m": geo["h_far"],
                 "refine": args.refine, "ranks": comm.size},
        **fc.output.run_record(problem, summaries, t_start, mesh=t_mesh),
        "profile": {"r": r, "x": xy[:, 0], "y": xy[:, 1], "pressure": p, "state": states},
    }
    fc.write_summary(folder, summary)
    print(f"Hertz sphere, P = {P:.4e} N: a = {a_fit:.5e} m (ref {a_ref:.5e}, "
          f"{100 * (a_fit / a_ref - 1):+.2f}%), p0 = {p0:.5e} Pa (ref {p0_ref:.5e}, "
          f"{100 * (p0 / p0_ref - 1):+.2f}%)")

    if not args.no_plot:
        plt = fc.output.pyplot()
        rs = np.linspace(0, 1.6 * a_ref, 400)
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(rs * 1e3, [analytic.hertz_pressure(t, a_ref, p0_ref) / 1e6 for t in rs],
                "k-", label="Hertz")
        ax.plot(r[~planar] * 1e3, p[~planar] / 1e6, "o", ms=3, alpha=0.7,
                label="flexcontact: slave nodes")
        ax.plot(r[planar] * 1e3, p[planar] / 1e6, "s", ms=3, mfc="none",
                label="flexcontact: nodes on a symmetry plane")
        ax.set_xlim(0, 1.6 * a_ref * 1e3)
        ax.set_xlabel("r [mm]")
        ax.set_ylabel("contact pressure [MPa]")
        ax.set_title(f"Hertz sphere, P = {P / 1e3:.1f} kN: a {100 * (a_fit / a_ref - 1):+.1f}%,"
                     f" p0 {100 * (p0 / p0_ref - 1):+.1f}%")
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(folder / "hertz3d.png", dpi=120)
    print(f"results in {folder}/")
