# %% [markdown]
# # The contact patch test on matching and non-matching meshes, every pairing
#
# Two stacked blocks of one material (steel), frictionless (Taylor & Papadopoulos): the
# lower block's bottom on rollers, the symmetry plane x = 0 (and y = 0 in 3D) on rollers,
# the upper block's top pushed down by δ. The exact solution is uniaxial stress σ_vv = −p,
# the same in both blocks, so the interface must carry the *uniform* pressure
#
#     plane strain: p = δ E / ((H1 + H2)(1 − ν²)),     3D: p = δ E / (H1 + H2).
#
# The load is a prescribed displacement δ of the top (default), or with `--load pressure`
# the uniform pressure p itself on the top: the upper block's vertical motion is then held
# by contact alone (`floating=True`: its equilibrium joins the condensed problem, see
# floating.py); the interface must carry the same uniform pressure either way.
#
# The interface is meshed twice: *matching* (both sides the same, non-uniformly spaced
# nodes) and *non-matching* (2D: the upper side has 1.5 times as many segments, graded the
# other way; meshes/patch.py). In 3D the bodies are tetrahedra (`--cell tetrahedron`, the
# default; non-matching: the upper face structured, the lower unstructured) or hexahedra
# (`--cell hexahedron`: quadrilateral interface facets, rectangles graded along x and y,
# the upper face 1.5 times finer and graded the other way when non-matching). Each pairing
# (ContactInterface.pairing) is run on each mesh:
#
# * node_to_node — matching meshes only;
# * node_to_surface — closest-point projection of the slave nodes (single pass): exact on
#   matching meshes, not on non-matching ones (its error is reported, not hidden);
# * surface_to_surface — integrated mortar rows with the dual basis (mortar.py): passes the
#   patch test on both;
# * auto (the default) — node_to_node where the nodes match, surface_to_surface otherwise.
#
# Measured: the nodal pressure at every slave node (row force / tributary measure) and at
# every master node (the forces passed on through the weights / tributary measure), the
# total force N against p·A, and the displacements against the exact linear field.
#
# Run: `/usr/bin/python3 demos/patch_test.py [--dim 2|3] [--cell hexahedron] [--pairing
# all|NAME] [--load displacement|pressure]` (also with `mpirun -n 2`); writes
# results/patch_test/<dim>d/summary.json (hexahedra: 3d_hexahedron; `--load pressure`:
# a `_pressure` suffix).

# %%
import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import patch, tags

PAIRINGS = ("node_to_node", "node_to_surface", "surface_to_surface", "auto")
parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--dim", type=int, choices=(2, 3), default=2)
parser.add_argument("--pairing", choices=("all",) + PAIRINGS, default="all")
parser.add_argument("--mesh", choices=("both", "matching", "nonmatching"), default="both")
parser.add_argument("--refine", type=int, default=0, help="halve the element sizes N times")
parser.add_argument("--cell", choices=("tetrahedron", "hexahedron"), default="tetrahedron",
                    help="3D cells (2D: triangles)")
parser.add_argument("--load", choices=("displacement", "pressure"), default="displacement",
                    help="the top pushed down by δ, or pressed by the uniform pressure p")
args = parser.parse_args()
if args.dim == 2 and args.cell != "tetrahedron":
    parser.error(f"--cell {args.cell} needs --dim 3 (2D meshes are triangles)")
cell = args.cell if args.dim == 3 else "triangle"
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Material, load and the exact solution

# %%
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
delta_m = 1e-5                               # downward displacement of the top [m]
sizes = dict(h_lower=0.02, h_upper=0.03) if args.dim == 3 else dict(h_lower=0.012,
                                                                     h_upper=0.02)


def exact(geo):
    """p [Pa], lateral strain c and vertical strain e of the exact uniaxial-stress field."""
    H = geo["lower_height"] + geo["upper_height"]
    E, nu = steel.E_Pa, steel.nu
    if args.dim == 3:
        p = delta_m * E / H
        return p, nu * p / E, -p / E
    p = delta_m * E / (H * (1 - nu**2))
    return p, nu * (1 + nu) * p / E, -(1 - nu**2) * p / E


# %% [markdown]
# ## One run: mesh, supports, contact, solve, measure

# %%
def run(matching, pairing):
    msh, cells, facets, geo = patch.build(comm, dim=args.dim, matching=matching,
                                          refine=args.refine, cell=cell, **sizes)
    d = args.dim
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    kind = "3d" if d == 3 else "plane_strain"
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, kind)
    bcs, _ = fc.dirichlet(V, facets, tags.FIXED, components=[d - 1])
    sym, _ = fc.dirichlet(V, facets, tags.SYMMETRY_X, components=[0])
    bcs += sym
    if d == 3:
        bcs += fc.dirichlet(V, facets, tags.SYMMETRY_Y, components=[1])[0]
    p, c, e = exact(geo)
    L = None
    if args.load == "pressure":
        ds = ufl.Measure("ds", domain=msh, subdomain_data=facets)
        L = -p * v[d - 1] * ds(tags.LOADED)
    else:
        top, (top_v,) = fc.dirichlet(V, facets, tags.LOADED, components=[d - 1])
        bcs += top
        top_v.value = -delta_m
    problem = fc.ContactProblem(
        a, L, bcs,
        fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=0.0,
                            name="patch", pairing=pairing),
        bodies=(cells, {"lower": tags.BASE, "upper": tags.UPPER}),
        floating=args.load == "pressure")
    s = problem.solve(1, verbose=False)[-1]
    # Displacement error at every node against u = (c x, [c y,] e (v + H1)).
    n_own = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:n_own, :d]
    u_ex = np.empty_like(X)
    u_ex[:, :d - 1] = c * X[:, :d - 1]
    u_ex[:, d - 1] = e * (X[:, d - 1] + geo["lower_height"])
    u_h = problem.u.x.array.reshape(-1, d)[:n_own]
    u_err = comm.allreduce(float(np.abs(u_h - u_ex).max(initial=0)), op=MPI.MAX)
    u_scale = comm.allreduce(float(np.abs(u_ex).max(initial=0)), op=MPI.MAX)
    out = None
    if comm.rank == 0:
        pr, inc = problem.pairs, problem.increments[-1]
        m = pr.m
        p_slave = inc.lam[:, 0] / pr.area
        force = np.zeros(pr.x.shape[0])
        for j in range(pr.masters.shape[1]):
            np.add.at(force, pr.masters[:, j], pr.weights[:, j] * inc.lam[:, 0])
        p_master = force[m:] / pr.node_area[m:]
        both = np.concatenate([p_slave, p_master])
        order = np.lexsort(pr.x[:m].T[::-1])
        out = {"matching": matching, "pairing": pairing,
               "pairing_used": problem.interfaces[0].pairing_used,
               "slave_nodes": int(m), "master_nodes": int(pr.x.shape[0] - m),
               "p_min": float(both.min()), "p_max": float(both.max()), "p_ref": p,
               "pressure_error_rel": float(np.abs(both / p - 1).max()),
               "pressure_error_rel_slave": float(np.abs(p_slave / p - 1).max()),
               "pressure_error_rel_master": float(np.abs(p_master / p - 1).max()),
               "N": s.normal_force, "N_ref": p * geo["area"],
               "u_error_rel": u_err / u_scale, "open": s.open,
               "max_penetration_rel": s.max_penetration_rel,
               "factorizations": problem.factorizations,
               "x": pr.x[:m][order], "p_slave": p_slave[order]}
    return comm.bcast(out, root=0), geo


# %% [markdown]
# ## Every pairing on every mesh
# Node–node pairing on the non-matching mesh is not a method that can run (its nodes do not
# face each other): it is recorded as refused, with the library's message.

# %%
meshes = {"both": (True, False), "matching": (True,), "nonmatching": (False,)}[args.mesh]
pairings = PAIRINGS if args.pairing == "all" else (args.pairing,)
runs = []
for matching in meshes:
    for pairing in pairings:
        try:
            r, geo = run(matching, pairing)
        except ValueError as err:
            if matching or pairing != "node_to_node":
                raise
            r = {"matching": False, "pairing": pairing, "refused": str(err)}
        runs.append(r)
        if comm.rank == 0:
            mesh_name = "matching" if matching else "non-matching"
            text = (f"refused: {r['refused'][:80]}..." if "refused" in r else
                    f"pressure error {r['pressure_error_rel_slave']:.2e} (slave), "
                    f"{r['pressure_error_rel_master']:.2e} (master), N {r['N']:.6e} "
                    f"(ref {r['N_ref']:.6e}), u error {r['u_error_rel']:.2e}")
            print(f"{args.dim}D {cell} {mesh_name:13s} {pairing:19s} {text}")

# %% [markdown]
# ## Summary
# Each run's q/q_ref pairs: `N`/`N_ref`, and the extreme nodal pressures `p_min`, `p_max`
# against `p_ref`; `pressure_error_rel` is max |p_node/p − 1| over slave and master nodes.

# %%
suffix = ("_hexahedron" if cell == "hexahedron" else "") + \
    ("_pressure" if args.load == "pressure" else "")
folder = fc.results_folder(f"patch_test/{args.dim}d{suffix}")
fc.write_summary(folder, {
    "demo": "patch_test", "dim": args.dim, "cell": cell, "units": "SI (m, Pa; N/m in 2D)",
    "materials": {"lower": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                  "upper": {"E_Pa": steel.E_Pa, "nu": steel.nu}},
    "mu": 0.0, "delta_m": delta_m, "refine": args.refine, "load": args.load,
    "geometry": {k: geo[k] for k in ("width", "lower_height", "upper_height", "area")},
    "runs": runs, "ranks": comm.size, "time_s": time.perf_counter() - t_start,
})
if comm.rank == 0:
    print(f"results in {folder}/")
