"""One case of the bench command (bench/run.py), run in its own process.

On one Hertz mesh (2D plane strain or the 3D quarter model, meshes/hertz2d.py,
meshes/hertz3d.py) this measures, one phase after the other in the same process:

* ``linear``: one plain linear-elastic solve with the same Dirichlet data, no contact:
  assembly of K, one MUMPS factorization of K without Schur complement (a) with the
  ordering flexcontact uses (``_cpp.flexibility`` with no contact DOFs, ordering "auto"),
  the load vector, one back-substitution (d, also as the median of ``repeat``);
* ``contact``: ``ContactProblem`` set-up (assembly, pairing, F* from the factorization
  with the Schur complement and W: (b) is F* + W), then ``increments`` load increments
  ramping the approach to a²/R (c: the median of increments 2.. after set-up), the kernel's
  local contact solve of each, and one back-substitution with the stored factor (d: the
  median of one before each increment and ``repeat`` after them).

Each phase's peak memory is the process's peak resident set from the start of that phase
(the high-water mark is reset through /proc/self/clear_refs after meshing and between the
phases), so gmsh's peak and the other phase do not count. Prints one line
``RESULT {json}`` on stdout.

    /usr/bin/python3 bench/case.py --spec '{"name": "t", "mesh": "hertz2d", "build": {}}'
"""
from __future__ import annotations

import argparse
import ctypes
import gc
import json
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import _cpp, compat, forms
from flexcontact.assembly import assemble_load, assemble_stiffness
from flexcontact.info import describe
from flexcontact.meshes import hertz2d, hertz3d, tags
from timing import median_time  # bench/ is the script's folder, on sys.path

R_M, A_M = 0.05, 0.005  # sphere/cylinder radius and the aimed contact half-width (m)
STEEL = forms.Material(E_Pa=200e9, nu=0.3)


def _status_kb(key: str) -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1])
    return 0


def _release_heap() -> None:
    """Hand the heap freed by the previous phase (MUMPS's factor, PETSc matrices) back to
    the system: glibc keeps it otherwise, and the next phase would start from the last one's
    peak."""
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


@contextmanager
def memory_phase(out: dict):
    """Peak resident memory (MB) of the enclosed phase, from a high-water mark reset at its
    start; ``rss_before_mb`` is what the process held then (Python, DOLFINx, the mesh)."""
    gc.collect()
    _release_heap()
    try:
        Path("/proc/self/clear_refs").write_text("5")
        out["peak_reset"] = True
    except OSError:
        out["peak_reset"] = False  # peak then includes everything before
    out["rss_before_mb"] = _status_kb("VmRSS") / 1024
    yield
    out["peak_mb"] = _status_kb("VmHWM") / 1024


def model(spec: dict, comm=MPI.COMM_SELF) -> dict:
    """Mesh, form, Dirichlet conditions and the contact interface of a Hertz case."""
    dim = 2 if spec["mesh"] == "hertz2d" else 3
    builder = hertz2d if dim == 2 else hertz3d
    t0 = time.perf_counter()
    msh, cells, facets, geo = builder.build(comm, R=R_M, a_expected=A_M, **spec.get("build", {}))
    mesh_s = time.perf_counter() - t0
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: STEEL, tags.UPPER: STEEL}, dx,
                              "plane_strain" if dim == 2 else "3d")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, consts = fc.dirichlet(V, facets, tags.LOADED)
    bcs = fixed + top
    if dim == 3:  # quarter model: the normal displacement held on both symmetry planes
        bcs += fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])[0]
        bcs += fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])[0]
    mu = spec.get("mu", 0.3)

    def approach(d_m):
        consts[dim - 1].value = -d_m

    return {"dim": dim, "V": V, "a": a, "bcs": bcs, "approach": approach,
            "interface": fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, mu),
            "delta_m": A_M**2 / R_M, "mesh_s": mesh_s, "mu": mu,
            "dofs": int(V.dofmap.index_map.size_global * V.dofmap.index_map_bs),
            "contact_nodes_per_surface": int(geo.get("n_contact_nodes", 0))}



def compiled_form(a):
    import dolfinx.fem
    return dolfinx.fem.form(a)


def linear_phase(m: dict, repeat: int) -> dict:
    """One plain linear-elastic solve: assembly, factorization (a), back-substitution (d)."""
    out = {}
    comm = m["V"].mesh.comm
    a_form = compiled_form(m["a"])
    with memory_phase(out):
        t0 = time.perf_counter()
        K = assemble_stiffness(a_form, m["bcs"])
        out["assembly_s"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        _, factor, info = _cpp.flexibility(K, np.zeros(0, np.int64), "schur", "auto")
        out["factorization_call_s"] = time.perf_counter() - t0
        m["approach"](m["delta_m"])
        t0 = time.perf_counter()
        p = assemble_load(m["V"], a_form, None, m["bcs"], comm)
        out["load_s"] = time.perf_counter() - t0
        x = K.createVecRight()
        t0 = time.perf_counter()
        factor.solve(p, x)
        out["first_backsolve_s"] = time.perf_counter() - t0
        out["backsolve_s"] = median_time(lambda: factor.solve(p, x), repeat)
    out["factorization_s"] = info["factorization_s"]
    out.update({k: info[k] for k in ("ordering", "mumps_ordering", "ordering_s",
                                     "factor_entries", "factor_flops", "factor_memory_mb")})
    out["solve_s"] = (out["assembly_s"] + out["factorization_call_s"] + out["load_s"]
                      + out["first_backsolve_s"])
    for obj in (p, x, factor, K):
        obj.destroy()
    return out


def contact_phase(m: dict, increments: int, repeat: int) -> dict:
    """Set-up (F* and W: b), ``increments`` load increments (c), back-substitution (d)."""
    out = {}
    with memory_phase(out):
        t0 = time.perf_counter()
        problem = fc.ContactProblem(m["a"], None, m["bcs"], m["interface"])
        out["setup_s"] = time.perf_counter() - t0
        b = problem.K.createVecLeft()
        b.set(1.0)
        x = problem.K.createVecRight()
        rows, solves = [], []
        for i in range(1, increments + 1):
            m["approach"](m["delta_m"] * i / increments)
            # a back-substitution next to each increment: the machine's load drifts
            solves.append(median_time(lambda: problem.factor.solve(b, x), 1))
            t0 = time.perf_counter()
            inc = problem.step()
            s = inc.summary
            rows.append({"increment_s": time.perf_counter() - t0,
                         "contact_solve_s": problem.timings.get("last_contact_step_s", 0.0),
                         "solver": s.solver, "iterations": s.iterations,
                         "residual": s.residual, "closed_pairs": s.stick + s.slip,
                         "normal_force": s.normal_force})
        solves += [median_time(lambda: problem.factor.solve(b, x), 1) for _ in range(repeat)]
        out["backsolve_s"] = float(np.median(solves))
        out["backsolve_samples_s"] = solves
    t, info = problem.timings, problem.flex_info
    out.update({k: t.get(k, 0.0) for k in ("assemble_K_s", "pairing_s", "flexibility_s",
                                          "delassus_s")})
    out.update({k: info[k] for k in ("method", "ordering", "mumps_ordering", "factorization_s",
                                     "schur_s", "inverse_s", "ordering_s", "factor_entries",
                                     "factor_flops", "factor_memory_mb")})
    out["fstar_w_s"] = out["flexibility_s"] + out["delassus_s"]
    out["delassus_routes"] = list(info.get("delassus_routes", []))
    # an increment is one back-substitution split around the contact solve when the factor
    # condenses and expands (serial Schur factor), two full ones otherwise
    out["split_increment"] = bool(info.get("condense", False))
    out["contact_dofs"] = int(problem.n_contact_dofs)
    out["pairs"] = int(problem.m)
    out["dense_mb"] = 8 * (out["contact_dofs"] ** 2 + (problem.m * m["dim"]) ** 2) / 2**20
    out["increments"] = rows
    later = rows[1:] if len(rows) > 1 else rows
    out["increment_s"] = float(np.median([r["increment_s"] for r in later]))
    out["contact_solve_s"] = float(np.median([r["contact_solve_s"] for r in later]))
    out["first_increment_s"] = rows[0]["increment_s"]
    if m.get("answer_file"):
        write_answer(problem, rows, m["answer_file"])
    for v in (b, x):
        v.destroy()
    return out


def write_answer(problem, rows: list, path: str) -> None:
    """The answer, to compare runs on different numbers of ranks (bench/run.py --mpi): the
    normal force of each increment, u and the contact pressure at every node, nodes sorted
    by position (the bodies' touching node: then by value), gathered on rank 0."""
    comm, dim = problem.comm, problem.dim
    V, Q = problem.u.function_space, problem.pressure.function_space
    nu, nq = V.dofmap.index_map.size_local, Q.dofmap.index_map.size_local
    parts = comm.gather((V.tabulate_dof_coordinates()[:nu, :dim],
                         problem.u.x.array[:dim * nu].reshape(-1, dim),
                         Q.tabulate_dof_coordinates()[:nq, :dim],
                         problem.pressure.x.array[:nq]))
    if comm.rank != 0:
        return
    xu, u, xp, p = (np.concatenate([q[k] for q in parts]) for k in range(4))
    xu, xp = np.round(xu, 9), np.round(xp, 9)  # [m]: meshes on 1 or 2 ranks differ in the last bits
    ou = np.lexsort((u[:, -1], *xu.T[::-1]))
    op = np.lexsort((p, *xp.T[::-1]))
    np.savez(path, u=u[ou], pressure=p[op],
             normal_force=[r["normal_force"] for r in rows])


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spec", required=True, help="the case as JSON (bench/run.py's CASES)")
    args = ap.parse_args()
    spec = json.loads(args.spec)
    comm = MPI.COMM_WORLD  # one process, or the ranks of bench/run.py --mpi
    m = model(spec, comm)
    m["answer_file"] = spec.get("answer_file")
    compiled_form(m["a"])  # the form compiler runs before any timing
    increments, repeat = spec.get("increments", 4), spec.get("repeat", 5)
    result = {"name": spec["name"], "spec": spec, "dim": m["dim"], "dofs": m["dofs"],
              "ranks": comm.size,
              "mu": m["mu"], "mesh_s": m["mesh_s"],
              "contact_nodes_per_surface": m["contact_nodes_per_surface"]}
    result["linear"] = linear_phase(m, repeat)
    result["contact"] = contact_phase(m, increments, repeat)
    result["system"] = describe()  # the libraries this process actually loaded
    result["loaded_libraries"] = loaded_libraries()
    if comm.rank == 0:
        print("RESULT " + json.dumps(result), flush=True)


def loaded_libraries() -> list[str]:
    """The MUMPS, PETSc, METIS and BLAS/LAPACK shared libraries mapped into this process."""
    keys = ("mumps", "petsc", "metis", "blas", "lapack", "scalapack", "mkl")
    found = set()
    for line in Path("/proc/self/maps").read_text().splitlines():
        path = line.split()[-1] if "/" in line else ""
        name = Path(path).name
        if any(k in name for k in keys) and ".so" in name and "-packages" not in path:
            found.add(str(Path(path).resolve()))
    return sorted(found)


if __name__ == "__main__":
    main()
