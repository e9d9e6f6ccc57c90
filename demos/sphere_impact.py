# %% [markdown]
# # A sphere-ended column hitting an elastic block: Hertz impact
#
# Quarter model (symmetry planes x = 0 and y = 0) of the Hertz geometry of
# `demos/hertz3d.py`: a steel column whose end is a sphere of radius R falls at speed v on a
# steel block clamped at its bottom. Hertz impact theory (quasi-static contact, the body
# otherwise rigid: its wave round trip is short against the contact) gives, with the body's
# mass m and E* = [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]⁻¹,
#
#     t_c ≈ 2.87 (m²/(R E*² v))^(1/5),   δ_max = (15 m v²/(16 E* √R))^(2/5),
#     F_max = (4/3) E* √R δ_max^(3/2).
#
# v is chosen so that the largest contact radius sqrt(R δ_max) is the mesh's target radius.
# Time stepping: Moreau–Jean θ = ½, e = 0 (docs/impact.md); the contact duration the step
# must resolve is Hertz's, passed as `expected_contact_s`.
# Run: `/usr/bin/python3 demos/sphere_impact.py [--refine N] [--steps-per-contact 60]`.

# %%
import argparse
import math
import time

import ufl
from mpi4py import MPI

import dolfinx.fem
import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.impact_output import (contact_metrics, cost_summary, plot_history,
                                       write_history_csv)
from flexcontact.meshes import hertz3d, tags

parser = argparse.ArgumentParser(description="Hertz impact of a sphere-ended column")
parser.add_argument("--refine", type=int, default=0, help="halve the element sizes N times")
parser.add_argument("--elements-per-radius", type=float, default=4.0,
                    help="contact radius over the contact element size at --refine 0")
parser.add_argument("--h-far", type=float, default=0.02, help="largest element size [m]")
parser.add_argument("--steps-per-contact", type=int, default=60)
parser.add_argument("--progress", action="store_true")
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Geometry, material, speed

# %%
R = 0.05
a_target = 0.1 * R
msh, cells, facets, geo = hertz3d.build(
    comm, R=R, a_expected=a_target, h_contact=a_target / args.elements_per_radius,
    h_far=args.h_far, zone_factor=1.6, refine=args.refine)
steel = forms.Material(E_Pa=200e9, nu=0.3, rho_kg_m3=7850.0, name="steel")
Estar = forms.effective_modulus(steel, steel)
V = compat.vector_space(msh)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
quarter_mass = msh.comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(
    steel.rho_kg_m3 * dx(tags.UPPER))), op=MPI.SUM)
m = 4 * quarter_mass
delta_max = a_target**2 / R
v0 = math.sqrt(delta_max**2.5 * 16 * Estar * math.sqrt(R) / (15 * m))
t_hertz = 2.87 * (m**2 / (R * Estar**2 * v0)) ** 0.2
F_hertz = 4 / 3 * Estar * math.sqrt(R) * delta_max**1.5

# %%
fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
sym_x, _ = fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])
sym_y, _ = fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])
dt = t_hertz / args.steps_per_contact
problem = fc.ImpactProblem(
    V, cells, {"block": tags.BASE, "column": tags.UPPER}, {tags.BASE: steel, tags.UPPER: steel},
    fixed + sym_x + sym_y,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=0.0, name="hertz"),
    dt_s=dt, kind="3d", initial_velocity={"column": (0.0, 0.0, -v0)},
    expected_contact_s=t_hertz)
folder = fc.results_folder("sphere_impact")
with fc.ResultWriter(folder, "sphere_impact", msh, [cells]) as out:
    records = problem.run(1.4 * t_hertz, writer=out, write_every=5,
                          progress=args.progress or None)

# %% [markdown]
# ## Against Hertz
# The quarter model carries a quarter of the force and of the impulse.

# %%
met = contact_metrics(records, dt)
p0, p1 = problem.momentum0["column"][2], records[-1].momentum["column"][2]
e = problem.energy
summary = {
    "demo": "sphere_impact", "units": "SI (m, s, N, J)", "R_m": R, "speed_m_s": v0,
    "mass_kg": m, "Estar_Pa": Estar, "dt_s": dt, "steps": len(records),
    "material": {"E_Pa": steel.E_Pa, "nu": steel.nu, "rho_kg_m3": steel.rho_kg_m3},
    "contact_duration_s": met["contact_duration_s"], "contact_duration_s_ref": t_hertz,
    "peak_force": 4 * met["peak_force"], "peak_force_ref": F_hertz,
    "contact_episodes": met["episodes"],
    "impulse": 4 * met["impulse"], "momentum_change": 4 * (p1 - p0),
    "rebound_velocity": p1 / quarter_mass,
    "energy_before": 4 * e.initial, "energy_after": 4 * e.total,
    "energy_balance_error_rel": e.balance_error_rel,
    "cost": cost_summary(records), "contact_pairs": int(problem.m),
    "mesh": fc.output.mesh_info(V, refine=args.refine),
    "time_s": time.perf_counter() - t_start,
}
fc.write_summary(folder, summary, comm)
if comm.rank == 0:
    write_history_csv(folder / "history.csv", records, e.initial)
    if not args.no_plot:
        plot_history(folder / "sphere_impact.png", records, "sphere-ended column on a block "
                     "(quarter model)")
    print(f"duration {met['contact_duration_s']:.4e} s (Hertz {t_hertz:.4e}), peak force "
          f"{4 * met['peak_force']:.4e} N (Hertz {F_hertz:.4e}), v = {v0:.3f} m/s, rebound "
          f"{p1 / quarter_mass:+.3f} m/s, energy {4 * e.initial:.4e} -> {4 * e.total:.4e}, "
          f"{summary['cost']['back_substitutions_per_step']:.2f} solves/step")
