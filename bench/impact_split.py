"""An impact time step split around the contact solve (one back-substitution) against the
same step with full solves (v_free, then a second solve in steps with contact).

The dam demo's stage 2 (demos/dam_debris.py at its default size, and refined) and the
bar-on-wall impact of bench/step_cost.py: for each case two ImpactProblems of the same
factor class are built, one stepping through ``factor.condense``/``expand``
(dynamics.py), one through ``factor.solve`` only, and stepped in turn (so that the shared
machine's load falls on both alike) over the run. Reported per case: the medians of the
step's wall time with and without contact for both, their ratio, the back-substitutions per
step, one full back-substitution's time (median of 10), the largest relative difference of
the two velocities (round-off) and the load average. Writes bench/impact_split.json.

    /usr/bin/python3 bench/impact_split.py [--dam-refine 0 1] [--bar-n 400] [--steps N] [--out F]
"""
import argparse
import json
import math
import os
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.info import describe
from flexcontact.meshes import BASE, MASTER, SLAVE, UPPER, bar_impact

ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--dam-refine", type=int, nargs="*", default=[0, 1])
ap.add_argument("--bar-n", type=int, nargs="*", default=[400])
ap.add_argument("--steps", type=int, default=None,
                help="steps per case (default: the dam demo's duration; 3 round trips)")
ap.add_argument("--out", default=str(Path(__file__).with_name("impact_split.json")))
args = ap.parse_args()
comm = MPI.COMM_WORLD


class TwoSolves:
    """The same factor without condense/expand: ImpactProblem steps with full solves."""

    def __init__(self, factor):
        self._factor = factor
        self.solve = factor.solve


def dam_pair(refine):
    from flexcontact.dam import DamScenario
    from flexcontact.dam.stage1 import solve_stage1
    from flexcontact.dam.stage2 import (MARGIN, approach_time_s, default_time_step_s,
                                        make_problem)
    s = DamScenario(refine=refine)
    stage1 = solve_stage1(s, comm=comm)
    dt = default_time_step_s(s)
    split, ref = make_problem(s, stage1, dt), make_problem(s, stage1, dt)
    steps = int(round((approach_time_s(s) + MARGIN * split.expected_contact_s) / dt))
    return split, ref, steps


def bar_pair(n):
    steel = forms.Material(E_Pa=200e9, nu=0.0, rho_kg_m3=8000.0)
    c = math.sqrt(steel.E_Pa / steel.rho_kg_m3)

    def one():
        msh, cells, facets, geo = bar_impact.build(comm, length=1.0, n=n, ny=4, target="wall")
        V = compat.vector_space(msh)
        return fc.ImpactProblem(V, cells, {"wall": BASE, "bar": UPPER},
                                {BASE: steel, UPPER: steel}, fc.hold_body(V, cells, BASE),
                                fc.ContactInterface(facets, SLAVE, MASTER, 0.0),
                                dt_s=geo["h"] / c, initial_velocity={"bar": (-1.0, 0.0)})
    split, ref = one(), one()
    return split, ref, int(round(3 * 2.0 / c / split.dt))


def rel_diff(a, b) -> float:
    d = a.copy()
    d.axpy(-1.0, b)
    out = d.norm() / max(b.norm(), 1e-300)
    d.destroy()
    return out


def measure(name, split, ref, steps):
    assert split.one_back_substitution, split.flex_info.get("method")
    ref.factor = TwoSolves(ref.factor)
    load0 = os.getloadavg()
    worst = 0.0
    for _ in range(steps):
        split.step()
        ref.step()
        worst = max(worst, rel_diff(split.v_vec, ref.v_vec))
    b = split.K.createVecLeft()
    b.setRandom()
    x = b.duplicate()
    ts = []
    for _ in range(10):
        t0 = time.perf_counter()
        split.factor.solve(b, x)
        ts.append(time.perf_counter() - t0)
    row = {"case": name, "dofs": int(split.K.getSize()[0]), "pairs": int(split.m or 0),
           "contact_dofs": int(split.condensation.n_contact_dofs), "steps": steps,
           "back_substitution_s": float(np.median(ts)), "velocity_rel_diff_max": worst,
           "loadavg_before": list(load0), "loadavg_after": list(os.getloadavg())}
    for key, p in (("split", split), ("two_solves", ref)):
        t = np.array(p.timings["steps_s"])
        on = np.array([r.active > 0 and r.normal_force != 0.0 for r in p.records])
        solves = np.array([r.back_substitutions for r in p.records])
        row[key] = {"step_s_median_with_contact": float(np.median(t[on])) if on.any() else None,
                    "step_s_median_without_contact":
                        float(np.median(t[~on])) if (~on).any() else None,
                    "step_s_mean": float(t.mean()), "steps_with_contact": int(on.sum()),
                    "back_substitutions_per_step": float(solves.mean()),
                    "back_substitutions_with_contact":
                        float(np.median(solves[on])) if on.any() else None}
    w = row["split"]["step_s_median_with_contact"], row["two_solves"]["step_s_median_with_contact"]
    row["with_contact_split_over_two_solves"] = w[0] / w[1] if None not in w else None
    row["mean_split_over_two_solves"] = row["split"]["step_s_mean"] / row["two_solves"]["step_s_mean"]
    if comm.rank == 0:
        print(f"{name}: {row['dofs']} DOFs, {row['contact_dofs']} contact DOFs, {steps} steps "
              f"({row['split']['steps_with_contact']} with contact); step with contact "
              f"{w[0] * 1e3:.2f} ms split / {w[1] * 1e3:.2f} ms two solves "
              f"(ratio {row['with_contact_split_over_two_solves']:.2f}); mean ratio "
              f"{row['mean_split_over_two_solves']:.2f}; one back-substitution "
              f"{row['back_substitution_s'] * 1e3:.2f} ms; velocities differ by {worst:.1e}; "
              f"load {load0[0]:.2f}", flush=True)
    for o in (b, x):
        o.destroy()
    return row


rows = []
for r in args.dam_refine:
    split, ref, steps = dam_pair(r)
    rows.append(measure(f"dam 2D refine {r}", split, ref, args.steps or steps))
    del split, ref
for n in args.bar_n:
    split, ref, steps = bar_pair(n)
    rows.append(measure(f"bar on wall n={n}", split, ref, args.steps or steps))
    del split, ref

if comm.rank == 0:
    out = {"bench": "impact_split", "ranks": comm.size, "system": describe(), "rows": rows}
    Path(args.out).write_text(json.dumps(out, indent=1))
