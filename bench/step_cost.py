"""What one impact time step costs, in back-substitutions with the stored factor of Ŵ.

The method's promise in time (docs/impact.md): Ŵ = M + hθC + h²θ²K is factored once per
time-step size; a step is one back-substitution, split around the contact solve
(condensation of the step's right-hand side, the kernel's step, expansion) with MUMPS's
Schur factor, else one for the free velocity plus, only when a contact impulse acts, a
second one for the correction. This runs the bar-on-wall impact
(and then some free flight) at growing sizes and reports, measured in the same run, the
back-substitutions per step (mean, and the medians of steps with and without contact), the
time of one step against one back-substitution, and the set-up (assembly, factorization
with W_eff). Writes bench/step_cost.json.

    /usr/bin/python3 bench/step_cost.py [--n 40 80 160]
"""
import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.impact_output import cost_summary
from flexcontact.info import describe
from flexcontact.meshes import BASE, MASTER, SLAVE, UPPER, bar_impact

ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--n", type=int, nargs="+", default=[40, 80, 160])
ap.add_argument("--ny", type=int, default=4)
ap.add_argument("--mass", choices=("consistent", "lumped"), default="consistent")
args = ap.parse_args()
comm = MPI.COMM_WORLD
steel = forms.Material(E_Pa=200e9, nu=0.0, rho_kg_m3=8000.0)
c = math.sqrt(steel.E_Pa / steel.rho_kg_m3)
L = 1.0

rows = []
for n in args.n:
    msh, cells, facets, geo = bar_impact.build(comm, length=L, n=n, ny=args.ny, target="wall")
    V = compat.vector_space(msh)
    bcs = fc.hold_body(V, cells, BASE)
    dt = geo["h"] / c
    t0 = time.perf_counter()
    p = fc.ImpactProblem(V, cells, {"wall": BASE, "bar": UPPER}, {BASE: steel, UPPER: steel},
                         bcs, fc.ContactInterface(facets, SLAVE, MASTER, 0.0), dt_s=dt,
                         initial_velocity={"bar": (-1.0, 0.0)}, mass=args.mass)
    setup_s = time.perf_counter() - t0
    records = p.run(3 * 2 * L / c, progress=False)  # contact for a third of the run
    steps = np.array(p.timings["steps_s"])
    b = p.K.createVecLeft()
    b.setRandom()
    x = b.duplicate()
    ts = []
    for _ in range(10):
        t1 = time.perf_counter()
        p.factor.solve(b, x)
        ts.append(time.perf_counter() - t1)
    solve_s = float(np.median(ts))
    on = np.array([r.active > 0 for r in records])
    row = {"n": n, "dofs": int(V.dofmap.index_map.size_global * 2), "pairs": int(p.m),
           **cost_summary(records), "setup_s": setup_s,
           "factorization_s": p.timings.get("flexibility_s"),
           "back_substitution_s": solve_s,
           "step_s_median_with_contact": float(np.median(steps[on])),
           "step_s_median_without_contact": float(np.median(steps[~on])),
           "step_over_back_substitution_with_contact": float(np.median(steps[on])) / solve_s,
           "step_over_back_substitution_without_contact":
               float(np.median(steps[~on])) / solve_s}
    rows.append(row)
    if comm.rank == 0:
        print(f"n={n:4d} dofs={row['dofs']:6d}: {row['back_substitutions_per_step']:.3f} "
              f"back-substitutions/step (median {row['median_with_contact']:.0f} with contact, "
              f"{row['median_without_contact']:.0f} without); step/solve = "
              f"{row['step_over_back_substitution_with_contact']:.1f} with contact, "
              f"{row['step_over_back_substitution_without_contact']:.1f} without", flush=True)

if comm.rank == 0:
    out = {"bench": "step_cost", "mass": args.mass, "ranks": comm.size, "system": describe(),
           "rows": rows}
    Path(__file__).with_name("step_cost.json").write_text(json.dumps(out, indent=2))
