"""Per-body condensation of F* against one block over all contact DOFs, in one run.

Bodies share no DOFs, so K is block-diagonal by body and so are the Schur complement K*_cc
and F* = (K*_cc)⁻¹ (dolfinx_ext/src/contact_blocks.h): each body's block is inverted on its
own. For each case (a ContactProblem of two bodies) this measures, with the same K and
contact DOFs, `_cpp.flexibility(..., per_body=False)` (one dense inverse of size n_c) and
`per_body=True` (one per body): the MUMPS factorization with the Schur complement, the
extraction of K*_cc, the dense inverse, finding the bodies, the memory the call adds to the
process's peak (VmHWM, reset before each call), and the relative difference of the two F*.
Also, per case: a plain factorization of K (no Schur complement), so that the Schur
complement's share of the factorization shows; building W = B F* Bᵀ (the kernel's
CondensedContact, from the problem's set-up); one load increment after set-up and one
back-substitution (medians). Writes bench/perbody.json.

    /usr/bin/python3 bench/perbody.py [--cases hertz2d_r2 hertz2d_r3 hertz3d_r1 block3d_r1]
"""
import argparse
import ctypes
import json
import time
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import _cpp, compat, forms
from flexcontact.info import describe
from flexcontact.meshes import block_on_base, hertz2d, hertz3d, tags
from timing import median_time  # bench/ is the script's folder, on sys.path

OUT = Path(__file__).with_name("perbody.json")
steel = forms.Material(E_Pa=200e9, nu=0.3)
aluminium = forms.Material(E_Pa=70e9, nu=0.33)


def hertz2d_case(comm, refine):
    R, a_t = 0.05, 0.005
    msh, cells, facets, _ = hertz2d.build(comm, R=R, a_expected=a_t, refine=refine)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, (_, ty) = fc.dirichlet(V, facets, tags.LOADED)
    ty.value = -a_t**2 / R
    return V, fc.ContactProblem(a, None, fixed + top,
                                fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.3))


def hertz3d_case(comm, refine):
    """The Hertz quarter model of demos/hertz3d.py (its default mesh sizes), frictionless."""
    R, a_t = 0.05, 0.005
    msh, cells, facets, _ = hertz3d.build(comm, R=R, a_expected=a_t, h_contact=a_t / 6,
                                          h_far=0.02, zone_factor=1.6, refine=refine)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "3d")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    sym_x, _ = fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])
    sym_y, _ = fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])
    top, (_, _, tz) = fc.dirichlet(V, facets, tags.LOADED)
    tz.value = -0.5 * a_t**2 / R
    return V, fc.ContactProblem(a, None, fixed + sym_x + sym_y + top,
                                fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.0))


def block3d_case(comm, refine):
    """The block on its base (meshes/block_on_base.py, 3D), the block's top fully held
    and pressed down by 1 µm, μ = 0.3."""
    msh, cells, facets, _ = block_on_base.build_3d(comm, refine=refine)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: aluminium}, dx, "3d")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, (_, _, tz) = fc.dirichlet(V, facets, tags.LOADED)
    tz.value = -1e-6
    return V, fc.ContactProblem(a, None, fixed + top,
                                fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, 0.3))


CASES = {"hertz2d_r2": (hertz2d_case, 2), "hertz2d_r3": (hertz2d_case, 3),
         "hertz3d_r1": (hertz3d_case, 1), "block3d_r1": (block3d_case, 1)}


def reset_peak():
    """Give freed heap back to the system and reset the process's peak resident size
    (VmHWM); returns the current size (MB)."""
    ctypes.CDLL("libc.so.6").malloc_trim(0)
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        pass
    return vm("VmRSS")


def vm(key):
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1]) / 1024.0
    return float("nan")



TIMES = ("factorization_s", "schur_s", "inverse_s", "blocks_s", "ordering_s", "analysis_s",
         "flexibility_s")


def flexibility_row(K, dofs, ordering, per_body, repeat):
    """One variant, `repeat` times: the least of each time (the machine is shared), the
    memory the first call added to the peak."""
    rows = []
    for _ in range(repeat):
        rss = reset_peak()
        t0 = time.perf_counter()
        F, factor, info = _cpp.flexibility(K, dofs, "schur", ordering, per_body=per_body)
        total = time.perf_counter() - t0
        peak = vm("VmHWM") - rss
        factor.destroy()
        rows.append({**{k: info[k] for k in TIMES if k in info}, "flexibility_s": total,
                     "peak_added_mb": peak})
    row = {k: min(r[k] for r in rows) for k in TIMES}
    row.update(peak_added_mb=rows[0]["peak_added_mb"], n_blocks=info["n_blocks"],
               block_sizes=info["block_sizes"], mumps_ordering=info["mumps_ordering"])
    return row, F


def run_case(comm, name, repeat):
    build, refine = CASES[name]
    V, problem = build(comm, refine)
    K, dofs = problem.K, problem.condensation.dofs
    ordering = problem.flex_info["ordering"]
    rows = {}
    F = {}
    for per_body in (False, True):
        key = "per_body" if per_body else "one_block"
        rows[key], F[key] = flexibility_row(K, dofs, ordering, per_body, repeat)
    plain, _ = flexibility_row(K, np.zeros(0, np.int64), ordering, True, repeat)
    # The analysis PETSc makes before ours with METIS: MUMPS's automatic choice before,
    # AMD now (the per-body call's analysis_s).
    auto_analysis_s = min(_cpp.factor_analysis(K, dofs, "mumps")["analysis_s"]
                          for _ in range(repeat)) if ordering == "metis" else None

    def increment():
        problem.step()
        problem.increments.pop()

    increment()
    b = problem.K.createVecLeft()
    b.set(1.0)
    x = problem.K.createVecRight()
    n = F["one_block"].shape[0]
    one, per = rows["one_block"], rows["per_body"]
    out = {
        "dofs": int(V.dofmap.index_map.size_global * V.dofmap.index_map_bs),
        "contact_dofs": int(n), "pairs": int(problem.m),
        "F_rel_diff_per_body_vs_one_block": float(np.linalg.norm(F["per_body"] - F["one_block"])
                                                  / np.linalg.norm(F["one_block"])),
        "one_block": one, "per_body": per,
        "plain_factorization_s": plain["factorization_s"],
        "plain_peak_added_mb": plain["peak_added_mb"],
        "petsc_analysis_auto_s": auto_analysis_s,
        "schur_share_of_factorization": 1.0 - plain["factorization_s"]
        / per["factorization_s"],
        "w_build_s": problem.timings.get("delassus_s"),
        "inverse_speedup": one["inverse_s"] / max(per["inverse_s"], 1e-12),
        "dense_inverse_flops_ratio": sum(s**3 for s in per["block_sizes"]) / n**3,
        "increment_s": median_time(increment, repeat),
        "backsolve_s": median_time(lambda: problem.factor.solve(b, x), repeat),
    }
    out["step_over_backsolve"] = out["increment_s"] / out["backsolve_s"]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    ap.add_argument("--repeat", type=int, default=3,
                    help="repetitions: the least F* time, the median increment")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    # a run with --cases merges into the file
    result = json.loads(OUT.read_text()) if OUT.exists() else {"bench": "perbody", "cases": {}}
    result["system"] = describe()
    for name in args.cases:
        r = run_case(comm, name, args.repeat)
        result["cases"][name] = r
        o, p = r["one_block"], r["per_body"]
        print(f"{name}: {r['dofs']} DOFs, {r['contact_dofs']} contact DOFs in blocks "
              f"{p['block_sizes']} | factorization+Schur {p['factorization_s']:.2f} s "
              f"(plain {r['plain_factorization_s']:.2f} s), K*_cc {p['schur_s']:.3f} s | "
              f"inverse one block {o['inverse_s']:.3f} s, per body {p['inverse_s']:.3f} s "
              f"(blocks found in {p['blocks_s']:.3f} s) | peak +{o['peak_added_mb']:.0f} MB vs "
              f"+{p['peak_added_mb']:.0f} MB | F* rel diff "
              f"{r['F_rel_diff_per_body_vs_one_block']:.1e} | W {r['w_build_s']:.3f} s | "
              f"increment {r['step_over_backsolve']:.2f} back-substitutions | PETSc's analysis "
              f"{p['analysis_s']:.2f} s (automatic ordering: {r['petsc_analysis_auto_s']})",
              flush=True)
        OUT.write_text(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main()
