# %% [markdown]
# # A disc hitting an elastic block obliquely, with friction
#
# A solid elastic disc (plane strain, no spin at first) hits an elastic block at normal
# speed v_n and tangential speed v_t, with Coulomb friction μ and Newton restitution e at
# the pairs (docs/impact.md). The meshes do not match: node–surface pairs, re-made before
# every step as the disc slides.
#
# Rigid-body theory (a disc of mass m, moment of inertia m R²/2, effective restitution
# e_eff, so that the normal impulse is J_n = m (1 + e_eff) v_n): stopping the contact
# point's slip takes the tangential impulse m v_t / 3 (a third of it goes into the
# translation, two thirds into the spin). So the disc slides throughout, with J_t = μ J_n,
# when v_t / v_n > 3 μ (1 + e_eff); below, it sticks at some point and J_t < μ J_n. The
# elastic disc's e_eff is not known in advance (e = 0 at the pairs, its rebound comes from
# the elastic waves): the two cases bracket the threshold for every e_eff ∈ [0, 1],
#
#     slide: v_t / v_n = 2 × 3 μ (1 + 1),    stick: v_t / v_n = ½ × 3 μ (1 + 0),
#
# and the summary reports e_eff and both thresholds 3 μ (1 + e_eff) as measured.
#
# Run: `/usr/bin/python3 demos/oblique_impact.py [--refine N] [--case slide|stick|both]`.

# %%
import argparse
import math
import time

import numpy as np
import ufl
from mpi4py import MPI

import dolfinx.fem
import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.impact_output import (contact_metrics, cost_summary, plot_history,
                                       write_history_csv)
from flexcontact.meshes import BASE, FIXED, MASTER, SLAVE, UPPER, oblique_impact

parser = argparse.ArgumentParser(description="oblique impact of a disc on a block")
parser.add_argument("--refine", type=int, default=0, help="halve the element sizes N times")
parser.add_argument("--case", choices=("slide", "stick", "both"), default="both")
parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient")
parser.add_argument("--restitution", type=float, default=0.0, help="Newton's e at the pairs")
parser.add_argument("--speed", type=float, default=5.0, help="normal speed v_n [m/s]")
parser.add_argument("--steps-per-contact", type=int, default=50)
parser.add_argument("--write-every", type=int, default=5)
parser.add_argument("--progress", action="store_true")
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Material, geometry and the expected contact duration
# Steel on steel, R = 5 cm. The time step comes from an estimate of the contact duration:
# the quasi-static line contact of a cylinder, F = π E* a² / (4R), with the approach
# δ = a²/(4R) (2 ln(4R/a) − 1) (Johnson, *Contact Mechanics*, §5.6; the 2D approach depends
# on where it is measured, so this only sets the step), integrated for the disc's mass.

# %%
steel = forms.Material(E_Pa=200e9, nu=0.3, rho_kg_m3=7850.0, name="steel")
Estar = forms.effective_modulus(steel, steel)
R = 0.05
msh, cells, facets, geo = oblique_impact.build(comm, R=R, h_contact=R / 100, refine=args.refine)
V = compat.vector_space(msh)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
mass = msh.comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(
    steel.rho_kg_m3 * dx(UPPER))), op=MPI.SUM)   # per unit thickness [kg/m]


def contact_duration_estimate(m, v):
    """t_c of the quasi-static line-contact law above for mass m [kg/m] at speed v [m/s]."""
    a = np.linspace(1e-9, 0.5 * R, 20001)
    F = math.pi * Estar * a**2 / (4 * R)
    d = a**2 / (4 * R) * (2 * np.log(4 * R / a) - 1)
    U = np.concatenate([[0.0], np.cumsum(0.5 * (F[1:] + F[:-1]) * np.diff(d))])
    k = np.searchsorted(U, 0.5 * m * v * v)
    speed = np.sqrt(np.maximum(v * v - 2 * U[:k] / m, 1e-30))
    return 2 * float(np.sum(np.diff(d[:k]) / speed[1:]))


t_est = contact_duration_estimate(mass, args.speed)
dt = t_est / args.steps_per_contact
folder = fc.results_folder("oblique_impact")
ratios = {"slide": 2 * 3 * args.mu * 2.0, "stick": 0.5 * 3 * args.mu * 1.0}


# %% [markdown]
# ## One impact
# The block is clamped at its bottom; the disc is free (no Dirichlet condition: Ŵ is
# regular through its mass).

# %%
def run(case):
    v_n, v_t = args.speed, ratios[case] * args.speed
    fixed, _ = fc.dirichlet(V, facets, FIXED)
    problem = fc.ImpactProblem(
        V, cells, {"block": BASE, "disc": UPPER}, {BASE: steel, UPPER: steel}, fixed,
        fc.ContactInterface(facets, slave=SLAVE, master=MASTER, mu=args.mu, name="disc/block",
                            pairing="node_to_surface"),
        dt_s=dt, kind="plane_strain", initial_velocity={"disc": (v_t, -v_n)},
        restitution=args.restitution, expected_contact_s=t_est)
    with fc.ResultWriter(folder, f"oblique_impact_{case}", msh, [cells]) as out:
        records = problem.run(1.6 * t_est, writer=out, write_every=args.write_every,
                              progress=args.progress or None)
    return summarise(case, problem, records, v_n, v_t)


# %% [markdown]
# ## What is measured
# The impulses J_n, J_t on the disc (sums over the steps), the disc's momentum change
# (they agree: the disc is free), its effective restitution e_eff = v_n⁺ / v_n, the ratio
# J_t / J_n against μ (slide) or the rigid sticking impulse m v_t / 3 (stick), the energy
# account with each dissipation, and the pairs' states.

# %%
def summarise(case, problem, records, v_n, v_t):
    met = contact_metrics(records, dt)
    J = np.sum([r.impulse for r in records], axis=0)      # on the disc, global axes
    p0, p1 = np.array(problem.momentum0["disc"]), np.array(records[-1].momentum["disc"])
    e = problem.energy
    e_eff = p1[1] / mass / v_n
    in_contact = [r for r in records if r.active > 0]
    s = {
        "case": case, "v_n_m_s": v_n, "v_t_m_s": v_t, "v_t_over_v_n": v_t / v_n,
        "dt_s": dt, "steps": len(records), "contact_duration_s": met["contact_duration_s"],
        "contact_duration_s_estimate": t_est, "contact_episodes": met["episodes"],
        "peak_force": met["peak_force"],
        "normal_impulse": J[1], "tangential_impulse": -J[0],
        "momentum_change": (p1 - p0).tolist(), "impulse": J.tolist(),
        "effective_restitution": e_eff,
        "threshold_ratio": 3 * args.mu * (1 + e_eff),
        "tangential_ratio": -J[0] / J[1], "tangential_ratio_ref": args.mu,
        "tangential_impulse_rigid_stick": mass * v_t / 3,
        "slip_steps": sum(1 for r in in_contact if r.stick == 0),
        "stick_steps": sum(1 for r in in_contact if r.stick > 0),
        "pairings": problem.pairings, "factorizations": problem.factorizations,
        "energy_before": e.initial, "energy_after": e.total,
        "energy_friction": e.friction, "energy_contact": e.contact,
        "energy_numerical": e.numerical, "energy_damping": e.damping,
        "energy_balance_error_rel": e.balance_error_rel,
        "max_penetration_m": max(r.max_penetration_m for r in records),
        "cost": cost_summary(records),
    }
    if comm.rank == 0:
        write_history_csv(folder / f"{case}_history.csv", records, e.initial)
        if not args.no_plot:
            plot_history(folder / f"{case}.png", records, f"disc on block ({case})",
                         force_unit="N/m", energy_unit="J/m")
        print(f"{case}: v_t/v_n {v_t / v_n:.2f} (threshold {s['threshold_ratio']:.2f}), "
              f"J_t/J_n {s['tangential_ratio']:.4f} (mu {args.mu}), J_t "
              f"{s['tangential_impulse']:.4g} (rigid stick {mass * v_t / 3:.4g}), e_eff "
              f"{e_eff:.3f}, energy {e.initial:.4g} -> {e.total:.4g} (friction "
              f"{e.friction:.3g}, contact {e.contact:.3g}), balance "
              f"{e.balance_error_rel:.1e}, {s['pairings']} pairings")
    return s


# %%
cases = ["slide", "stick"] if args.case == "both" else [args.case]
results = {case: run(case) for case in cases}
fc.write_summary(folder, {
    "demo": "oblique_impact", "units": "SI (m, s, N/m, J/m)",
    "material": {"E_Pa": steel.E_Pa, "nu": steel.nu, "rho_kg_m3": steel.rho_kg_m3},
    "R_m": R, "mass_kg_m": mass, "mu": args.mu, "restitution": args.restitution,
    "speed_m_s": args.speed, "ranks": comm.size,
    "mesh": fc.output.mesh_info(V, refine=args.refine), **results,
    "time_s": time.perf_counter() - t_start}, comm)
if comm.rank == 0:
    print(f"results in {folder}/")
