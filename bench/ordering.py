"""The fill-reducing ordering of the MUMPS factorization of K, compared on P1 elasticity.

Debian 12's MUMPS has no METIS or SCOTCH of its own (asking for them gives AMF or PORD);
flexcontact hands it a METIS nested dissection of the mesh nodes instead (ordering="metis",
dolfinx_ext/src/ordering.h). For 3D tetrahedral boxes of about 30k, 90k and 300k DOFs and a
2D triangle square of about 200k DOFs, with a contact set of 300 DOFs on the top face, this
reports per ordering, both for the plain factor and for the factor with the Schur complement
on the contact DOFs (what ContactProblem does, flexibility="schur"):

* from MUMPS's analysis (deterministic): entries in the factor (INFOG(20)), flops of the
  elimination (RINFOG(1)), estimated memory (INFOG(17), MB);
* from the factorization itself, for the orderings given by --factor and where the
  estimated memory fits --memory-mb: the time of the whole flexibility F* (analysis,
  factorization, Schur complement, its inverse), entries (INFOG(29)), flops (RINFOG(3)) and
  memory (INFOG(22), MB).

Times are of one run on a shared machine; choose by flops and entries. Writes
bench/ordering.json (a run with --cases merges into it).

    /usr/bin/python3 bench/ordering.py [--cases 3d_30k 3d_90k 3d_300k 2d_200k]
        [--factor metis mumps] [--memory-mb 3000]
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
import dolfinx.mesh
from flexcontact import _cpp, compat
from flexcontact.info import describe
from flexcontact.names import ORDERINGS

CASES = {"3d_30k": (3, 20), "3d_90k": (3, 30), "3d_300k": (3, 45), "2d_200k": (2, 315)}
CONTACT_NODES = 100  # 300 contact DOFs in 3D, 200 in 2D
OUT = Path(__file__).with_name("ordering.json")


def stiffness(dim: int, n: int):
    """Unit box (n³ tetrahedra ×6) or square (n² triangles ×2), P1 elasticity, bottom held;
    K and the DOFs of the CONTACT_NODES top nodes nearest the top centre."""
    comm = MPI.COMM_SELF
    if dim == 3:
        msh = dolfinx.mesh.create_box(comm, [np.zeros(3), np.ones(3)], [n] * 3,
                                      dolfinx.mesh.CellType.tetrahedron)
    else:
        msh = dolfinx.mesh.create_rectangle(comm, [np.zeros(2), np.ones(2)], [n] * 2,
                                            dolfinx.mesh.CellType.triangle)
    V = compat.vector_space(msh)
    E, nu = 200e9, 0.3
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    a = dolfinx.fem.form(ufl.inner(2 * mu * eps(u) + lmbda * ufl.tr(eps(u)) * ufl.Identity(dim),
                                   eps(v)) * ufl.dx)
    fdim = dim - 1
    bottom = dolfinx.mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[dim - 1], 0))
    held = dolfinx.fem.locate_dofs_topological(V, fdim, bottom)
    bc = dolfinx.fem.dirichletbc(np.zeros(dim, dtype=PETSc.ScalarType), held, V)
    K = dolfinx.fem.petsc.assemble_matrix(a, bcs=[bc])
    K.assemble()
    x = V.tabulate_dof_coordinates()[:, :dim]  # one row per DOF block (node)
    top = np.flatnonzero(np.isclose(x[:, dim - 1], 1.0))
    centre = np.full(dim - 1, 0.5)
    near = top[np.argsort(np.linalg.norm(x[top, :dim - 1] - centre, axis=1), kind="stable")]
    nodes = np.sort(near[:CONTACT_NODES])
    dofs = (nodes[:, None] * dim + np.arange(dim)).reshape(-1).astype(np.int64)
    return K, dofs


def analysis_rows(K, dofs):
    rows = {}
    for schur, c in (("plain", np.zeros(0, np.int64)), ("schur", dofs)):
        for o in ORDERINGS:
            a = _cpp.factor_analysis(K, c, o)
            rows[f"{schur}/{o}"] = {k: a[k] for k in ("mumps_ordering", "estimated_entries",
                                                     "estimated_flops", "estimated_memory_mb",
                                                     "analysis_s", "ordering_s")}
    return rows


def factor_rows(K, dofs, orderings, analysis, memory_mb):
    rows = {}
    for o in orderings:
        est = analysis[f"schur/{o}"]["estimated_memory_mb"]
        if est > memory_mb:
            rows[o] = {"skipped": f"estimated {est} MB > --memory-mb {memory_mb}"}
            continue
        t0 = time.perf_counter()
        F, factor, info = _cpp.flexibility(K, dofs, "schur", o)
        total = time.perf_counter() - t0
        factor.destroy()
        rows[o] = {"flexibility_s": total, **{k: info[k] for k in (
            "mumps_ordering", "factorization_s", "ordering_s", "schur_s", "inverse_s",
            "factor_entries", "factor_flops", "factor_memory_mb")}, "F": F}
    # F* must not depend on the ordering
    ref = next((r["F"] for r in rows.values() if "F" in r), None)
    for r in rows.values():
        if "F" in r:
            r["F_rel_diff_to_first"] = float(np.linalg.norm(r.pop("F") - ref) / np.linalg.norm(ref))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    ap.add_argument("--factor", nargs="*", choices=ORDERINGS, default=["metis", "mumps"])
    ap.add_argument("--memory-mb", type=int, default=3000,
                    help="skip a factorization whose estimated memory is larger (MB)")
    args = ap.parse_args()
    out = json.loads(OUT.read_text()) if OUT.exists() else {"bench": "ordering", "cases": {}}
    out["system"] = describe()
    for name in args.cases:
        dim, n = CASES[name]
        K, dofs = stiffness(dim, n)
        N = K.getSize()[0]
        print(f"{name}: {N} DOFs, {dofs.size} contact DOFs", flush=True)
        analysis = analysis_rows(K, dofs)
        for key, r in analysis.items():
            print(f"  analysis {key:14s} -> {r['mumps_ordering']:6s} entries "
                  f"{r['estimated_entries'] / 1e6:8.2f}M flops {r['estimated_flops']:.3e} "
                  f"memory {r['estimated_memory_mb']} MB", flush=True)
        factor = factor_rows(K, dofs, args.factor, analysis, args.memory_mb)
        for o, r in factor.items():
            print(f"  factor {o}: {r}", flush=True)
        out["cases"][name] = {"dim": dim, "n": n, "dofs": N, "contact_dofs": int(dofs.size),
                              "analysis": analysis, "factorization": factor}
        K.destroy()
        OUT.write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
