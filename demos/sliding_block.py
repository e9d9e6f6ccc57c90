# %% [markdown]
# # A block pushed along a base: stick, partial slip, gross slip at T = μN
#
# An aluminium block sits on a steel base (plane strain). Its top is first pressed down by
# δ_n (normal load N), then moved sideways in increments. The total friction force T grows
# while the interface sticks, edges start slipping, and once every pair slips the block
# slides with T = μN: Coulomb's law, which the total tangential reaction never exceeds.
#
# Run: `/usr/bin/python3 demos/sliding_block.py [--refine N]`.

# %%
import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.states import STICK
from flexcontact.contact_profile import profile
from flexcontact.meshes import block_on_base, tags

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--refine", type=int, default=0, help="halve the element size N times")
parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient")
parser.add_argument("--normal-increments", type=int, default=2)
parser.add_argument("--tangential-increments", type=int, default=24)
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %%
msh, cells, facets, geo = block_on_base.build(comm, refine=args.refine)
aluminium = forms.Material(E_Pa=70e9, nu=0.33, name="aluminium")
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
materials = {tags.BASE: steel, tags.UPPER: aluminium}
a = forms.elasticity_form(u, v, materials, dx, "plane_strain")
# Piecewise-constant Lamé fields, so the von Mises stress uses each body's own material.
lame = forms.lame_fields(msh, cells, materials)

fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
top, (top_x, top_y) = fc.dirichlet(V, facets, tags.LOADED)
problem = fc.ContactProblem(
    a, None, fixed + top,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=args.mu,
                        name="block/base"),
    bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}),
    stress=lambda w: forms.von_mises(w, lame, "plane_strain"))

# %% [markdown]
# ## Load path
# Normal stage: the top goes down to δ_n = 1e-4 of the block's height. Tangential stage:
# the first push is a small trial; the stick response is linear, so it tells the push at
# which T would reach μN, and the remaining increments run to twice that.

# %%
n1, n2 = args.normal_increments, args.tangential_increments
delta_n = 1e-4 * geo["block_height"]
push = {"trial": None, "final": None}


def load(i, t):
    if i <= n1:
        top_y.value = -delta_n * i / n1
        return
    k = i - n1
    if k == 1:
        push["trial"] = 1e-3 * delta_n
        top_x.value = push["trial"]
        return
    if push["final"] is None:
        s = problem.increments[-1].summary
        T1 = abs(s.tangential_force[0])
        push["final"] = 2.0 * push["trial"] * args.mu * s.normal_force / T1
    top_x.value = push["trial"] + (push["final"] - push["trial"]) * (k - 1) / (n2 - 1)


folder = fc.results_folder("sliding_block")
pushes = []
with fc.ResultWriter(folder, "sliding_block", msh, tags=(cells,)) as out:
    summaries = problem.solve(n1 + n2, load=lambda i, t: (load(i, t), pushes.append(float(top_x.value))),
                              writer=out)

# %% [markdown]
# ## Slip onset
# Gross slip is the first increment at which no pair sticks. The tangential force there is
# compared with μN; every increment must satisfy |T| ≤ μN.

# %%
if comm.rank == 0:
    N = np.array([s.normal_force for s in summaries])
    T = np.array([abs(s.tangential_force[0]) for s in summaries])
    gross = [i for i, s in enumerate(summaries) if i >= n1 and s.stick == 0 and s.slip > 0]
    if not gross:
        raise RuntimeError("the block never slid: increase the push")
    i0 = gross[0]
    ratio = T / np.maximum(args.mu * N, 1e-300)
    stick_slip = []
    for inc in problem.increments:
        st = inc.states == STICK
        stick_slip.append(float(np.abs(inc.slip_increment[st]).max(initial=0.0)))
    umax = max(1e-300, float(np.abs(problem.u.x.array).max()))
    summary = {
        "demo": "sliding_block", "units": "SI (m, N/m)", "mu": args.mu,
        "normal_increments": n1, "tangential_increments": n2,
        "materials": {"base": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                      "block": {"E_Pa": aluminium.E_Pa, "nu": aluminium.nu}},
        "slip_onset_T": T[i0], "slip_onset_T_ref": args.mu * N[i0],
        "slip_onset_error_rel": T[i0] / (args.mu * N[i0]) - 1,
        "slip_onset_push_m": pushes[i0], "slip_onset_increment": i0 + 1,
        "max_T_over_muN": float(ratio[n1:].max()),
        "max_stick_slip_increment_m": max(stick_slip),
        "max_stick_slip_increment_rel": max(stick_slip) / umax,
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "contact_pairs": int(problem.m),
        "mesh": fc.output.mesh_info(V, refine=args.refine),
        "push_m": pushes, "N": N, "T": T,
        **fc.output.run_record(problem, summaries, t_start),
    }
    fc.write_summary(folder, summary)
    print(f"gross slip at increment {i0 + 1}: T = {T[i0]:.5e} N/m, muN = {args.mu * N[i0]:.5e} N/m;"
          f" max T/(muN) over the run = {ratio[n1:].max():.6f}")
    if not args.no_plot:
        plt = fc.output.pyplot()
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
        px = np.array(pushes[n1:]) * 1e6
        ax1.plot(px, T[n1:] / 1e3, "o-", label="|T| friction force")
        ax1.plot(px, args.mu * N[n1:] / 1e3, "k--", label="μN")
        ax1.axvline(pushes[i0] * 1e6, color="r", lw=0.8, label="gross slip")
        ax1.set_xlabel("top push [µm]")
        ax1.set_ylabel("force [kN/m]")
        ax1.legend()
        ax1.grid(alpha=0.3)
        x, p, q, st, _ = profile(problem, problem.increments[i0 - 1])
        ax2.plot(x * 1e3, p / 1e6, "o", ms=3, label="pressure (before gross slip)")
        ax2.plot(x * 1e3, np.abs(q[:, 0]) / 1e6, "s", ms=3, label="|shear|")
        ax2.plot(x * 1e3, args.mu * p / 1e6, "k-", lw=0.8, label="μ p")
        ax2.set_xlabel("x [mm]")
        ax2.set_ylabel("traction [MPa]")
        ax2.legend()
        ax2.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(folder / "sliding_block.png", dpi=120)
    print(f"results in {folder}/")
