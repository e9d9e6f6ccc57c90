"""What one load increment costs after set-up, against one back-substitution.

The method's promise (docs/architecture.md §1): all heavy sparse work happens once; an increment is
one back-substitution with the stored factor (split around the contact solve; two full ones
on several MPI ranks) plus a small dense contact solve. On the Hertz
geometry at growing sizes this measures, in one run: the factorization with F* (a), building
W (b), one increment (c, without writing output) and one back-substitution (d), and writes
bench/increment_cost.json with the ratios (b)/(a) and (c)/(d).

    /usr/bin/python3 bench/increment_cost.py [--refine 0 1 2 3]
"""
import argparse
import json
from pathlib import Path

import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.info import describe
from flexcontact.meshes import hertz2d, tags
from timing import median_time  # bench/ is the script's folder, on sys.path

ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--refine", type=int, nargs="+", default=[0, 1, 2, 3])
ap.add_argument("--repeat", type=int, default=5, help="timed repetitions (median)")
args = ap.parse_args()
comm = MPI.COMM_WORLD
steel = forms.Material(E_Pa=200e9, nu=0.3)
R, a_target = 0.05, 0.005



rows = []
for refine in args.refine:
    # refine halves both the contact and the far element size: DOFs grow about 4× a level.
    msh, cells, facets, geo = hertz2d.build(comm, R=R, a_expected=a_target, refine=refine)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, (tx, ty) = fc.dirichlet(V, facets, tags.LOADED)
    problem = fc.ContactProblem(a, None, fixed + top,
                                fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.3))
    ty.value = -a_target**2 / R

    def increment():
        problem.step()
        problem.increments.pop()  # keep the history as it was: each repetition is alike

    increment()  # first call compiles the load form
    step_s = median_time(increment, args.repeat)
    b = problem.K.createVecLeft()
    b.set(1.0)
    x = problem.K.createVecRight()
    backsolve_s = median_time(lambda: problem.factor.solve(b, x), args.repeat)
    info = problem.flex_info
    row = {
        "refine": refine,
        "dofs": int(V.dofmap.index_map.size_global * V.dofmap.index_map_bs),
        "contact_dofs": int(problem.n_contact_dofs),
        "pairs": int(problem.m),
        "ranks": comm.size,
        "factorization_s": info.get("factorization_s"),
        "flexibility_s": problem.timings["flexibility_s"],
        "w_build_s": problem.timings.get("delassus_s", 0.0),
        "increment_s": step_s,
        "backsolve_s": backsolve_s,
        "w_build_over_factorization": problem.timings.get("delassus_s", 0.0)
        / max(info.get("factorization_s", 1e-300), 1e-300),
        "step_over_backsolve": step_s / backsolve_s,
    }
    rows.append(row)
    if comm.rank == 0:
        print(f"refine {refine}: {row['dofs']:8d} DOFs, {row['contact_dofs']:4d} contact DOFs | "
              f"factorization {row['factorization_s']:.3f} s, F* total {row['flexibility_s']:.3f} s,"
              f" W {row['w_build_s']:.4f} s | increment {step_s * 1e3:.1f} ms = "
              f"{row['step_over_backsolve']:.2f} back-substitutions ({backsolve_s * 1e3:.1f} ms)",
              flush=True)

if comm.rank == 0:
    out = Path(__file__).with_name("increment_cost.json")
    out.write_text(json.dumps({"machine": describe(), "cases": rows}, indent=2))
    print(f"written {out}")
