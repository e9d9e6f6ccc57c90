# %% [markdown]
# # A rigid cylinder pressed on an elastic block (plane strain)
#
# The target is a rigid analytic circle of radius R (`fc.RigidTarget("circle", ...)`): it
# has no DOFs, its pairs join each node of the block's candidate zone to the circle's
# centre with an offset R, so that the normal gap is |x_s − c| − R along the radial normal.
# The circle is lowered by a prescribed displacement per increment; pairs are re-made
# before each increment from the current positions (no new factorization). The reference
# is Hertz's line contact with a rigid body, 1/E* = (1 − ν²)/E (docs/architecture.md §6):
#
#     a = sqrt(4 P R / (π E*)),   p0 = 2 P / (π a)
#
# Run: `/usr/bin/python3 demos/rigid_cylinder.py [--refine N]` (also with `mpirun -n 2`).

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
# ## The block and the rigid circle
# The block of `hertz2d.py` alone (its candidate zone tagged `MASTER` by the builder, here
# the slave surface); the circle touches the block's top at the origin.

# %%
R = 0.05                      # circle radius [m]
a_target = 0.1 * R            # contact half-width the load aims at [m]
msh, cells, facets, geo = hertz2d.build(comm, R=R, a_expected=a_target, refine=args.refine,
                                        with_cylinder=False)
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
Estar = steel.E_Pa / (1 - steel.nu**2)

V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.BASE: steel}, dx, "plane_strain")

circle = fc.RigidTarget("circle", point_m=(0.0, R), radius_m=R, name="rigid cylinder")
fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
problem = fc.ContactProblem(
    a, None, fixed,
    fc.ContactInterface(facets, slave=tags.MASTER, master=circle, mu=0.0, name="rigid cylinder"),
    bodies=(cells, {"block": tags.BASE}))

# %% [markdown]
# A trial approach first; then δ ramped to the value that aims at a_target (P grows almost
# linearly with δ in 2D).

# %%
P_target = np.pi * Estar * a_target**2 / (4 * R)


def set_approach(d):
    circle.displacement_m = np.array([0.0, -d])


load = approach_to_load(problem, set_approach, a_target**2 / (2 * R), P_target, args.increments)


folder = fc.results_folder("rigid_cylinder")
with fc.ResultWriter(folder, "rigid_cylinder", msh) as out:
    summaries = problem.solve(max(args.increments, 2), load=load, writer=out)

# %% [markdown]
# ## Measured against Hertz

# %%
if comm.rank == 0:
    x, p, q, states, _ = profile(problem)
    P = summaries[-1].normal_force
    a_ref, p0_ref = analytic.hertz_cylinder(P, R, Estar)
    a_fit, p0, a_extent = hertz_fit(x, p)
    summary = {
        "demo": "rigid_cylinder", "units": "SI (m, Pa, N/m)",
        "P": P, "P_target": P_target, "R_m": R, "a_target_m": a_target,
        "materials": {"block": {"E_Pa": steel.E_Pa, "nu": steel.nu}},
        "a": a_fit, "a_ref": a_ref, "a_error_rel": a_fit / a_ref - 1, "a_extent": a_extent,
        "p0": p0, "p0_ref": p0_ref, "p0_error_rel": p0 / p0_ref - 1,
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "contact_pairs": int(problem.m), "closed_pairs": int((states > OPEN).sum()),
        "mesh": fc.output.mesh_info(V, h_contact_m=geo["h_contact"], refine=args.refine),
        **fc.output.run_record(problem, summaries, t_start),
        "profile": {"x": x, "pressure": p, "state": states},
    }
    fc.write_summary(folder, summary)
    print(f"rigid cylinder: a = {a_fit:.5e} m (ref {a_ref:.5e}, {100 * (a_fit / a_ref - 1):+.2f}%),"
          f" p0 = {p0:.5e} Pa (ref {p0_ref:.5e}, {100 * (p0 / p0_ref - 1):+.2f}%)")
    if not args.no_plot:
        fc.output.plot_hertz_profile(folder / "rigid_cylinder.png", x, p, a_ref, p0_ref,
                                     ref_label="Hertz (rigid cylinder)")
    print(f"results in {folder}/")
