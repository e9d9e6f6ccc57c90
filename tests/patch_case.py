"""One contact patch test case (Taylor & Papadopoulos, matching meshes), measured against
the exact solution; importable by the tests and runnable on its own (also with mpirun).

Two stacked bodies with one footprint (meshes/patch.py): the lower body's bottom rolls
(vertical displacement 0), the upper body's top is pushed down by δ (vertical component
only), the symmetry planes x = 0 (and y = 0 in 3D) hold the normal component, the faces
x = w (y = w) are free. The exact solution is uniaxial stress σ_vv = −p in each body, the
vertical axis v being y in 2D and z in 3D:

* 3D: p = δ / (H1/E1 + H2/E2); vertical strain −p/E_i, lateral strain ν_i p/E_i;
* plane strain: p = δ / (H1(1−ν1²)/E1 + H2(1−ν2²)/E2); vertical strain
  −(1−ν_i²) p/E_i, lateral strain ν_i(1+ν_i) p/E_i.

Displacements are linear in each body, so P1 elements represent them exactly, and the
nodal contact force of a uniform pressure on P1 facets is p times the lumped tributary
measure (facet measure / vertices per facet, summed): a correct node–node method gives
pressure p, N = p·A and the exact displacements at every node up to round-off and the
contact solver's tolerance. The relative slip at the interface is the mismatch of the
bodies' lateral strains times the position, (c2 − c1)·x with c_i the lateral strain.

Run: ``/usr/bin/python3 tests/patch_case.py 2,3 stick,frictionless [--out file.json]``
(dimensions and cases, comma-separated; also under ``mpirun -n 2``): rank 0 prints one JSON
line of measurements per case and writes the full list, with the nodal pressures, to --out.
"""
import argparse
import json
import sys
from pathlib import Path

import dolfinx.fem
import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import patch, tags

DELTA_M = 1e-5  # prescribed downward displacement of the upper body's top [m]

# Case -> (lower body, upper body, μ). "stick": different materials whose lateral strains
# per unit pressure agree, so the interface sticks with zero shear (3D: ν/E equal; plane
# strain: ν(1+ν)/E equal, E2 chosen from ν2). "frictionless": steel under aluminium, whose
# lateral strains differ, so the interface slides freely.
_STEEL = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
_ALU = forms.Material(E_Pa=70e9, nu=0.33, name="aluminium")


CASES = ("stick", "frictionless", "one_material")


def materials(dim, case):
    """(lower, upper, mu) of a case."""
    if case == "frictionless":
        return _STEEL, _ALU, 0.0
    if case == "one_material":  # both bodies steel, μ = 0: no slip, p only
        return _STEEL, _STEEL, 0.0
    if case != "stick":
        raise ValueError(f"case={case!r}: one of {', '.join(CASES)}")
    lower = forms.Material(E_Pa=70e9, nu=0.15, name="lower")
    nu2 = 0.3
    if dim == 3:
        E2 = lower.E_Pa * nu2 / lower.nu  # ν/E equal: 140 GPa
    else:
        E2 = lower.E_Pa * nu2 * (1 + nu2) / (lower.nu * (1 + lower.nu))  # ν(1+ν)/E equal
    return lower, forms.Material(E_Pa=E2, nu=nu2, name="upper"), 0.3


def exact(dim, lower, upper, H1, H2, delta):
    """p [Pa] and per body (lateral strain, vertical strain) of the exact solution."""
    if dim == 3:
        c = [m.nu / m.E_Pa for m in (lower, upper)]          # lateral strain per Pa
        v = [1.0 / m.E_Pa for m in (lower, upper)]           # −vertical strain per Pa
    else:  # plane strain
        c = [m.nu * (1 + m.nu) / m.E_Pa for m in (lower, upper)]
        v = [(1 - m.nu ** 2) / m.E_Pa for m in (lower, upper)]
    p = delta / (H1 * v[0] + H2 * v[1])
    return p, [(ci * p, -vi * p) for ci, vi in zip(c, v)]


def exact_displacement(X, body_upper, strains, H1):
    """Exact u [m] at points X (n, 3); body_upper: True for nodes of the upper body."""
    d = X.shape[1]
    (c1, e1), (c2, e2) = strains
    u = np.empty_like(X)
    c = np.where(body_upper, c2, c1)
    u[:, :d - 1] = c[:, None] * X[:, :d - 1]
    zv = X[:, d - 1]
    u[:, d - 1] = np.where(body_upper, e1 * H1 + e2 * zv, e1 * (zv + H1))
    return u


def mesh_sizes(dim):
    """Small unstructured meshes, different sizes in the two bodies away from the interface."""
    return dict(h_lower=0.02, h_upper=0.03) if dim == 3 else dict(h_lower=0.012, h_upper=0.02)


def run(dim, case, comm=MPI.COMM_WORLD, increments=1, chain=("active_set",), tolerance=1e-10,
        pairing="node_to_node", matching=True, cell=None):
    """Solve the case and return its measurements (the same dict on every rank).

    ``chain``: the kernel's solvers, in order (SolverOptions.chain; empty: the default chain,
    which starts with projection sweeps); ``tolerance``: SolverOptions.tolerance, the
    relative natural-map residual at which an answer is accepted. The active-set method
    (the seed's) is exact once its states settle, so its answer is exact up to round-off.
    ``pairing``: the ContactInterface's; ``matching``: False for non-matching interface
    meshes (meshes/patch.py); ``cell``: its cell kind (None: triangles in 2D, tetrahedra in
    3D; "hexahedron" in 3D).
    """
    cell = cell or ("tetrahedron" if dim == 3 else "triangle")
    msh, cells, facets, geo = patch.build(comm, dim=dim, matching=matching, cell=cell,
                                          **mesh_sizes(dim))
    H1, H2, A = geo["lower_height"], geo["upper_height"], geo["area"]
    lower, upper, mu = materials(dim, case)
    kind = "3d" if dim == 3 else "plane_strain"
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    a = forms.elasticity_form(u, v, {tags.BASE: lower, tags.UPPER: upper}, dx, kind)
    vert = dim - 1
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED, components=[vert])
    top, (top_v,) = fc.dirichlet(V, facets, tags.LOADED, components=[vert])
    sym, _ = fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])
    if dim == 3:
        sym_y, _ = fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])
        sym += sym_y
    options = fc.SolverOptions()
    options.chain = list(chain)
    options.tolerance = tolerance
    problem = fc.ContactProblem(
        a, None, fixed + top + sym,
        fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=mu, name="patch",
                            pairing=pairing),
        bodies=(cells, {"lower": tags.BASE, "upper": tags.UPPER}), solver=options)

    def load(i, t):
        top_v.value = -DELTA_M * t

    summaries = problem.solve(increments, load=load, verbose=False)
    p, strains = exact(dim, lower, upper, H1, H2, DELTA_M)

    # Displacements at every node, against the exact field of the node's own body (the two
    # bodies have distinct nodes on the interface).
    n_own = V.dofmap.index_map.size_local
    upper_node = np.zeros(n_own + V.dofmap.index_map.num_ghosts, dtype=bool)
    for c in cells.indices[cells.values == tags.UPPER]:
        upper_node[V.dofmap.cell_dofs(c)] = True
    X = V.tabulate_dof_coordinates()[:n_own, :dim]
    u_h = problem.u.x.array.reshape(-1, dim)[:n_own]
    u_ex = exact_displacement(X, upper_node[:n_own], strains, H1)
    u_err = comm.allreduce(float(np.abs(u_h - u_ex).max(initial=0.0)), op=MPI.MAX)
    u_scale = comm.allreduce(float(np.abs(u_ex).max(initial=0.0)), op=MPI.MAX)

    # The written-back pressure Function at every interface node (slave and master), owned
    # DOFs only.
    Q = problem.pressure.function_space
    fdim = dim - 1
    iface = np.concatenate([facets.indices[facets.values == t] for t in (tags.SLAVE, tags.MASTER)])
    qdofs = dolfinx.fem.locate_dofs_topological(Q, fdim, iface)
    qdofs = qdofs[qdofs < Q.dofmap.index_map.size_local]
    p_fun = problem.pressure.x.array[qdofs]
    p_fun_dev = comm.allreduce(float(np.abs(p_fun / p - 1).max(initial=0.0)), op=MPI.MAX)
    p_fun_count = comm.allreduce(int(qdofs.size), op=MPI.SUM)

    out = None
    if comm.rank == 0:
        inc = problem.increments[-1]
        pr = problem.pairs
        m = pr.m
        lam = inc.lam
        pressure = lam[:, 0] / pr.area                      # λ_n / tributary measure [Pa]
        xs = pr.x[:m]
        shear = np.linalg.norm(lam[:, 1:], axis=1) / pr.area  # |λ_t| / tributary measure [Pa]
        # Global shear components (x, y) that the symmetry conditions hold on both sides of a
        # pair (x component on x = 0, y component on y = 0): a force there moves nothing, so
        # no equation fixes it.
        t_glob = np.einsum("kij,ki->kj", problem.frames[:, 1:, :], lam[:, 1:])[:, :dim - 1]
        held = np.abs(pr.x[:m, :dim - 1]) <= 1e-12 * geo["width"]
        shear_free = np.abs(np.where(held, 0.0, t_glob)).max(axis=1) / pr.area
        # Relative tangential displacement slave − master, global components [m]: the total
        # tangential gap (the initial one is zero) turned into x, y by the local frames.
        slip = np.einsum("kij,ki->kj", problem.frames[:, 1:, :], inc.gap[:, 1:])
        slip_ex = np.zeros_like(xs)
        slip_ex[:, :dim - 1] = (strains[1][0] - strains[0][0]) * xs[:, :dim - 1]
        slip_scale = float(np.abs(slip_ex).max())
        s = summaries[-1]
        order = np.lexsort(xs.T[::-1])
        out = {
            "dim": dim, "cell": cell, "case": case, "mu": mu, "ranks": comm.size,
            "pairs": int(m),
            "pairing": pairing, "matching": matching,
            "increments": increments, "flexibility": problem.flex_info.get("method"),
            "p_exact_Pa": p, "A": A, "N": s.normal_force, "N_exact": p * A,
            "N_error_rel": abs(s.normal_force / (p * A) - 1),
            "pressure_dev_rel": float(np.abs(pressure / p - 1).max()),
            "pressure_function_dev_rel": p_fun_dev, "pressure_function_nodes": p_fun_count,
            "shear_rel": float(shear.max() / p),
            "shear_rel_not_held": float(shear_free.max() / p),
            "held_shear_components": int(held.sum()),
            "area_ratio": float(pr.area.max() / pr.area.min()),
            "tangential_force_rel": float(np.linalg.norm(s.tangential_force) / (p * A)),
            "u_error_rel": u_err / u_scale,
            "slip_exact_max_m": slip_scale,
            "slip_error_rel": (float(np.abs(slip - slip_ex).max() / slip_scale)
                               if slip_scale > 0 else float(np.abs(slip).max() / u_scale)),
            "stick": s.stick, "slip": s.slip, "open": s.open,
            "residual": s.residual, "solver": s.solver, "iterations": s.iterations,
            "max_penetration_rel": s.max_penetration_rel,
            # Per slave node, sorted by position: for the comparison between rank counts.
            "x": xs[order].tolist(), "pressure": pressure[order].tolist(),
        }
    return comm.bcast(out, root=0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dims", help="comma-separated dimensions: 2, 3 or 2,3")
    ap.add_argument("cases", help="comma-separated cases: stick, frictionless")
    ap.add_argument("--increments", type=int, default=1)
    ap.add_argument("--chain", default="active_set",
                    help="comma-separated solver chain; 'default' for the kernel's default")
    ap.add_argument("--tolerance", type=float, default=1e-10)
    ap.add_argument("--out", type=Path, help="also write the results (a JSON list) here")
    ap.add_argument("--pairing", default="node_to_node",
                    help="comma-separated pairings (ContactInterface.pairing)")
    ap.add_argument("--nonmatching", action="store_true", help="non-matching interface meshes")
    ap.add_argument("--cell", choices=("tetrahedron", "hexahedron"), default=None,
                    help="3D cells (default tetrahedra)")
    args = ap.parse_args(argv)
    chain = [] if args.chain == "default" else args.chain.split(",")
    results = [run(int(d), c, increments=args.increments, chain=chain, tolerance=args.tolerance,
                   pairing=pg, matching=not args.nonmatching,
                   cell=args.cell if int(d) == 3 else None)
               for d in args.dims.split(",") for c in args.cases.split(",")
               for pg in args.pairing.split(",")]
    if MPI.COMM_WORLD.rank == 0:
        if args.out:
            args.out.write_text(json.dumps(results))
        for r in results:
            print(json.dumps({k: v for k, v in r.items() if k not in ("x", "pressure")}))


if __name__ == "__main__":
    sys.exit(main())
