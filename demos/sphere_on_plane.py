# %% [markdown]
# # An elastic sphere pressed on a rigid plane (3D, quarter model)
#
# The sphere-ended column of `hertz3d.py` alone, pressed onto the rigid analytic plane
# z = 0 (`fc.RigidTarget("plane", ...)`: no DOFs, no mesh). Its pairs join each node of the
# column's candidate zone to a point of the plane along the plane's normal. The column's
# top is lowered by δ. The reference is Hertz's point contact with a rigid body,
# 1/E* = (1 − ν²)/E (docs/architecture.md §6):
#
#     a = (3 P R / (4 E*))^(1/3),   p0 = 3 P / (2 π a²)
#
# with P the load on the whole sphere (4× the quarter model's).
#
# Run: `/usr/bin/python3 demos/sphere_on_plane.py [--refine N]` (also with `mpirun -n 2`).

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
parser.add_argument("--elements-per-radius", type=float, default=6.0,
                    help="target contact radius over the contact element size at --refine 0")
parser.add_argument("--h-far", type=float, default=0.02, help="largest element size at --refine 0 [m]")
parser.add_argument("--increments", type=int, default=3, help="load increments")
parser.add_argument("--no-plot", action="store_true", help="skip the PNG")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %%
R = 0.05                      # sphere radius [m]
a_target = 0.1 * R            # contact radius the load aims at [m]
msh, cells, facets, geo = hertz3d.build(
    comm, R=R, a_expected=a_target, h_contact=a_target / args.elements_per_radius,
    h_far=args.h_far, zone_factor=1.6, refine=args.refine, with_block=False)
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
Estar = steel.E_Pa / (1 - steel.nu**2)

V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.UPPER: steel}, dx, "3d")

# %% [markdown]
# ## Supports, symmetry, the rigid plane
# The column's top is moved down by δ (held in x and y); on each symmetry plane the normal
# displacement is zero. Frictionless.

# %%
sym_x, _ = fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])
sym_y, _ = fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])
top, (_, _, top_z) = fc.dirichlet(V, facets, tags.LOADED)
plane = fc.RigidTarget("plane", point_m=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0),
                       name="rigid plane")
problem = fc.ContactProblem(
    a, None, sym_x + sym_y + top,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=plane, mu=0.0, name="sphere on plane"),
    bodies=(cells, {"column": tags.UPPER}))

# %% [markdown]
# A trial approach, then δ ramped to the trial value times (P_target/P_trial)^(2/3).

# %%
P_target = 4 * Estar * a_target**3 / (3 * R)


def set_approach(d):
    top_z.value = -d


load = approach_to_load(problem, set_approach, 0.5 * a_target**2 / R, P_target, args.increments,
                        exponent=2 / 3, force_scale=4)  # quarter model: P = 4 × its force


folder = fc.results_folder("sphere_on_plane")
with fc.ResultWriter(folder, "sphere_on_plane", msh) as out:
    summaries = problem.solve(max(args.increments, 2), load=load, writer=out)

# %% [markdown]
# ## Measured against Hertz
# Nodal pressure = pair force over the slave node's tributary area (on the symmetry planes
# both are cut by the same factor); p0 at the node on the axis, a from an elliptic fit.

# %%
if comm.rank == 0:
    pr = problem.pairs
    inc = problem.increments[-1]
    r = np.hypot(pr.x[:pr.m, 0], pr.x[:pr.m, 1])
    p = inc.lam[:, 0] / pr.area
    order = np.argsort(r)
    r, p, states = r[order], p[order], inc.states[order]
    P = 4 * summaries[-1].normal_force
    a_ref, p0_ref = analytic.hertz_sphere(P, R, Estar)
    a_fit, p_max, a_extent = hertz_fit(r, p)
    p0 = float(p[0])
    summary = {
        "demo": "sphere_on_plane", "units": "SI (m, Pa, N)",
        "P": P, "P_target": P_target, "R_m": R, "a_target_m": a_target,
        "materials": {"column": {"E_Pa": steel.E_Pa, "nu": steel.nu}},
        "a": a_fit, "a_ref": a_ref, "a_error_rel": a_fit / a_ref - 1, "a_extent": a_extent,
        "p0": p0, "p0_ref": p0_ref, "p0_error_rel": p0 / p0_ref - 1,
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "contact_pairs": int(problem.m), "closed_pairs": int((states > OPEN).sum()),
        "candidate_zone_radius_m": geo["w"],
        "mesh": fc.output.mesh_info(V, h_contact_m=geo["h_contact"], refine=args.refine),
        **fc.output.run_record(problem, summaries, t_start),
        "profile": {"r": r, "pressure": p, "state": states},
    }
    fc.write_summary(folder, summary)
    print(f"sphere on rigid plane, P = {P:.4e} N: a = {a_fit:.5e} m (ref {a_ref:.5e}, "
          f"{100 * (a_fit / a_ref - 1):+.2f}%), p0 = {p0:.5e} Pa (ref {p0_ref:.5e}, "
          f"{100 * (p0 / p0_ref - 1):+.2f}%)")
    if not args.no_plot:
        plt = fc.output.pyplot()
        rs = np.linspace(0, 1.6 * a_ref, 400)
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(rs * 1e3, [analytic.hertz_pressure(t, a_ref, p0_ref) / 1e6 for t in rs],
                "k-", label="Hertz (rigid plane)")
        ax.plot(r * 1e3, p / 1e6, "o", ms=3, label="flexcontact")
        ax.set_xlim(0, 1.6 * a_ref * 1e3)
        ax.set_xlabel("r [mm]")
        ax.set_ylabel("contact pressure [MPa]")
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(folder / "sphere_on_plane.png", dpi=120)
    print(f"results in {folder}/")
