# %% [markdown]
# # Elastic bars hitting a rigid wall and an identical bar
#
# A steel-like strip of length L (ν = 0, plane stress: with ν = 0 and no lateral load the
# axial motion stays one-dimensional) moves at speed v towards
#
# * **wall**: a rigid wall — a thin body whose every node is held by a Dirichlet condition,
#   paired node–node with the bar's end (held contact DOFs get zero flexibility: exactly
#   rigid). 1D wave theory: the contact force is ρ c A v for t_c = 2L/c, c = sqrt(E/ρ), and
#   the bar leaves at −v with all its energy;
# * **bars**: an identical bar at rest and free (no Dirichlet condition at all: the
#   iteration matrix Ŵ = M + h²θ²K is regular where K is not). Force ρ c A v/2 for 2L/c;
#   afterwards the striker is at rest and the struck bar moves at v.
#
# Time stepping: Moreau–Jean θ = ½ at velocity level, restitution e = 0 (the rebound comes
# from the elastic waves), docs/impact.md. Run:
# `/usr/bin/python3 demos/bar_impact.py [--case wall|bars|both] [--n 40] [--courant 1]`.

# %%
import argparse
import math
import time

from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.impact_output import (contact_metrics, cost_summary, plot_history,
                                       write_history_csv)
from flexcontact.meshes import BASE, MASTER, SLAVE, UPPER, bar_impact

parser = argparse.ArgumentParser(description="bar impact on a wall and on a bar")
parser.add_argument("--case", choices=("wall", "bars", "both"), default="both")
parser.add_argument("--n", type=int, default=40, help="elements along a bar")
parser.add_argument("--ny", type=int, default=2, help="elements across a bar")
parser.add_argument("--courant", type=float, default=1.0, help="c dt / element length")
parser.add_argument("--mass", choices=("consistent", "lumped"), default="consistent")
parser.add_argument("--speed", type=float, default=1.0, help="impact speed v [m/s]")
parser.add_argument("--write-every", type=int, default=5, help="XDMF output interval (steps)")
parser.add_argument("--progress", action="store_true", help="progress bar on stderr")
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Material and geometry
# E = 200 GPa, ρ = 8000 kg/m³: c = 5000 m/s; L = 1 m, so 2L/c = 0.4 ms. Forces are per unit
# thickness (plane stress), A = the strip height.

# %%
steel = forms.Material(E_Pa=200e9, nu=0.0, rho_kg_m3=8000.0, name="steel")
L, H, v0 = 1.0, 0.05, args.speed
c = math.sqrt(steel.E_Pa / steel.rho_kg_m3)
folder = fc.results_folder("bar_impact")


def run(case):
    """One impact: returns the case's summary entries (rank 0) and writes its outputs."""
    target = "wall" if case == "wall" else "bar"
    msh, cells, facets, geo = bar_impact.build(comm, length=L, height=H, n=args.n,
                                               ny=args.ny, target=target)
    V = compat.vector_space(msh)
    bcs = []
    if case == "wall":
        bcs = fc.hold_body(V, cells, BASE)  # every node of the wall held: rigid
    dt = args.courant * geo["h"] / c
    problem = fc.ImpactProblem(
        V, cells, {target: BASE, "striker": UPPER}, {BASE: steel, UPPER: steel}, bcs,
        fc.ContactInterface(facets, slave=SLAVE, master=MASTER, mu=0.0, name=case),
        dt_s=dt, kind="plane_stress", initial_velocity={"striker": (-v0, 0.0)},
        mass=args.mass)
    t_end = 1.5 * 2 * L / c
    with fc.ResultWriter(folder, f"bar_impact_{case}", msh, [cells]) as out:
        records = problem.run(t_end, writer=out, write_every=args.write_every,
                              progress=args.progress or None)
    return summarise(case, target, problem, records, dt, msh.comm)


# %% [markdown]
# ## What is measured
# Contact duration (first to last step with a contact force), mean force = impulse /
# duration, impulse against the change of momentum of the striker, the bodies' final
# velocities (momentum / mass), the energy before and after, and the energy account.

# %%
def summarise(case, target, problem, records, dt, comm):
    mass = steel.rho_kg_m3 * L * H
    m = contact_metrics(records, dt)
    p0, p1 = problem.momentum0, records[-1].momentum
    e = problem.energy
    imp = sum(r.impulse[0] for r in records)
    s = {
        "case": case, "dt_s": dt, "steps": len(records), "mass": args.mass,
        "contact_duration_s": m["contact_duration_s"], "contact_duration_s_ref": 2 * L / c,
        "peak_force": m["peak_force"],
        "mean_force": m["mean_force"],
        "mean_force_ref": steel.rho_kg_m3 * c * H * v0 * (1.0 if case == "wall" else 0.5),
        "contact_episodes": m["episodes"],
        "impulse": imp, "impulse_ref": mass * v0 * (2.0 if case == "wall" else 1.0),
        "momentum_change_striker": p1["striker"][0] - p0["striker"][0],
        "rebound_velocity": p1["striker"][0] / mass,
        "rebound_velocity_ref": v0 if case == "wall" else 0.0,
        "energy_before": e.initial, "energy_after": e.total,
        "energy_after_ref": e.initial if case == "wall" else None,
        "energy_dissipated_contact": e.contact,
        "energy_balance_error_rel": e.balance_error_rel,
        "max_penetration_m": max(r.max_penetration_m for r in records),
        "cost": cost_summary(records), "expected_contact_s": problem.expected_contact_s,
        "one_back_substitution": problem.one_back_substitution,
        "timings_s": {k: v for k, v in problem.timings.items() if k != "steps_s"},
    }
    if case == "bars":
        s["struck_velocity"] = p1[target][0] / mass
        s["struck_velocity_ref"] = -v0
        s["momentum_change_struck"] = p1[target][0] - p0[target][0]
    if comm.rank == 0:
        write_history_csv(folder / f"{case}_history.csv", records, e.initial)
        if not args.no_plot:
            plot_history(folder / f"{case}.png", records, f"bar on {target}",
                         s["mean_force_ref"], 2 * L / c, m["contact_start_s"] or 0.0,
                         force_unit="N/m", energy_unit="J/m")
        print(f"{case}: duration {s['contact_duration_s']:.4e} s (2L/c {2 * L / c:.4e}), "
              f"mean force {s['mean_force']:.4e} (ref {s['mean_force_ref']:.4e}), "
              f"rebound {s['rebound_velocity']:+.4f} m/s, energy {e.initial:.4e} -> "
              f"{e.total:.4e}, balance {e.balance_error_rel:.1e}, "
              f"{s['cost']['back_substitutions_per_step']:.2f} solves/step")
    return s


# %%
cases = ["wall", "bars"] if args.case == "both" else [args.case]
results = {case: run(case) for case in cases}
fc.write_summary(folder, {"demo": "bar_impact", "units": "SI (m, s, N/m, J/m)",
                          "material": {"E_Pa": steel.E_Pa, "nu": steel.nu,
                                       "rho_kg_m3": steel.rho_kg_m3},
                          "length_m": L, "height_m": H, "speed_m_s": v0, "n": args.n,
                          "ny": args.ny, "courant": args.courant, "ranks": comm.size,
                          **results, "time_s": time.perf_counter() - t_start}, comm)
if comm.rank == 0:
    print(f"results in {folder}/")
