# %% [markdown]
# # A block sliding far along a longer block, with friction (plane strain)
#
# An aluminium block is pressed onto a steel base by lowering its top, then dragged
# sideways by its top over several element lengths. The base's candidate surface (its top
# along the whole slide path) is meshed at another spacing than the block's bottom, so the
# pairs are node–surface: before every increment each node of the block's bottom is paired
# again with its closest point on the base's facets. F* was computed once, on all nodes of
# both candidate surfaces: the pairs change, the factorization does not (the summary counts
# both). While the block slides, Coulomb's law gives the total friction force
#
#     |T| = μ N,
#
# and the contact stays closed without penetration.
#
# Run: `/usr/bin/python3 demos/long_slide.py [--refine N] [--elements 6]` (also with
# `mpirun -n 2`).

# %%
import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import block_on_base, tags

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--refine", type=int, default=0, help="halve the element size N times")
parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient")
parser.add_argument("--elements", type=float, default=6.0,
                    help="slide distance in element lengths of the block's bottom")
parser.add_argument("--increments-per-element", type=int, default=2,
                    help="tangential increments per element length of slide")
parser.add_argument("--no-plot", action="store_true", help="skip the PNG")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Geometry, materials, supports
# Block 100 × 50 mm on a 400 × 100 mm base, element size h = 5 mm on the block's bottom,
# 0.7 h on the base's candidate patch, which runs from 10 mm left of the block to 10 mm past
# where its right edge ends up.

# %%
h = 0.005 / 2 ** args.refine
slide = args.elements * h
msh, cells, facets, geo = block_on_base.build(
    comm, block=(0.1, 0.05), base=(0.4, 0.1), h=0.005, h_far=0.01, refine=args.refine,
    patch=(-0.06, 0.06 + slide), patch_spacing=0.7)
aluminium = forms.Material(E_Pa=70e9, nu=0.33, name="aluminium")
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: aluminium}, dx,
                          "plane_strain")

fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
top, (top_x, top_y) = fc.dirichlet(V, facets, tags.LOADED)
problem = fc.ContactProblem(
    a, None, fixed + top,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=args.mu,
                        name="block/base", pairing="node_to_surface"),
    bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}))

# %% [markdown]
# ## Load path
# Two increments lower the top by δ_n = 1e-4 of the block's height; then the top moves
# right by `slide` in equal steps (`--increments-per-element` per element length).

# %%
n1 = 2
n2 = int(np.ceil(args.elements * args.increments_per_element))
delta_n = 1e-4 * geo["block_height"]


def load(i, t):
    if i <= n1:
        top_y.value = -delta_n * i / n1
    else:
        top_x.value = slide * (i - n1) / n2


folder = fc.results_folder("long_slide")
with fc.ResultWriter(folder, "long_slide", msh) as out:
    summaries = problem.solve(n1 + n2, load=load, writer=out)

# %% [markdown]
# ## Friction during the slide, penetration, factorizations
# An increment is in gross slip when no pair sticks; there |T| must equal μN. The slide
# distance is the mean horizontal displacement of the block's bottom nodes.

# %%
pr = problem.pairs
uc = problem.condensation.gather(compat.petsc_vec(problem.u))
if comm.rank == 0:
    N = np.array([s.normal_force for s in summaries])
    T = np.array([abs(s.tangential_force[0]) for s in summaries])
    gross = [i for i, s in enumerate(summaries) if i >= n1 and s.stick == 0 and s.slip > 0]
    ratio = T[gross] / (args.mu * N[gross])
    bottom_ux = uc.reshape(-1, 2)[:pr.m, 0]
    pen = max(s.max_penetration_m for s in summaries)
    summary = {
        "demo": "long_slide", "units": "SI (m, N/m)", "mu": args.mu,
        "materials": {"base": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                      "block": {"E_Pa": aluminium.E_Pa, "nu": aluminium.nu}},
        "h_m": geo["h"], "h_patch_m": geo["h_patch"], "slide_m": slide,
        "slid_m": float(bottom_ux.mean()), "slid_elements": float(bottom_ux.mean() / geo["h"]),
        "normal_increments": n1, "tangential_increments": n2,
        "gross_slip_increments": [i + 1 for i in gross],
        "T_over_muN_gross_slip": ratio,
        "max_penetration_m": pen, "max_penetration_rel_h": pen / geo["h"],
        "N": N, "T": T,
        "mesh": fc.output.mesh_info(V, refine=args.refine),
        **fc.output.run_record(problem, summaries, t_start),
    }
    fc.write_summary(folder, summary)
    print(f"slid {summary['slid_elements']:.2f} element lengths; in gross slip T/(muN) = "
          f"{ratio.min():.6f} … {ratio.max():.6f} over {len(gross)} increments; penetration "
          f"{pen / geo['h']:.1e} h; factorizations {summary['factorizations']}, pairings "
          f"{summary['pairings']}")
    if not args.no_plot:
        plt = fc.output.pyplot()
        fig, ax = plt.subplots(figsize=(7, 4))
        k = np.arange(1, len(N) + 1)
        ax.plot(k, T / 1e3, "o-", label="|T| friction force")
        ax.plot(k, args.mu * N / 1e3, "k--", label="μN")
        ax.set_xlabel("increment")
        ax.set_ylabel("force [kN/m]")
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(folder / "long_slide.png", dpi=120)
    print(f"results in {folder}/")
