# %% [markdown]
# # A block held only by contact, pressed by N and pushed by a growing force Q
#
# An aluminium block rests on a clamped steel base (plane strain). No Dirichlet condition
# touches the block: only contact holds it, so its stiffness alone is singular (three rigid
# modes). `floating=True` makes the problem solvable the FETI way: the block's rigid modes R
# come from its geometry, a few fixing DOFs far from the contact make the factor a
# generalized inverse K⁺, and the block's equilibrium Rᵀ(p + Bᵀλ) = 0 joins the condensed
# problem as extra equations (docs/architecture.md §1).
#
# Its top carries a uniform traction: N downwards, then a tangential Q growing in force
# control. The block is low (μh < b/2), so it slides before it tips. Below μN the interface
# is in partial slip (the edges slip, the centre sticks) and the contact forces balance the
# loads exactly: Σλ_n = N, Σλ_t = Q. Once Q passes μN no contact force can hold the block:
# the solver reports that no static equilibrium exists and names the body. Small increments
# close to μN find that threshold to within 1 %.
#
# Run: `/usr/bin/python3 demos/pushed_block.py [--refine N] [--mu 0.3]`.

# %%
import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI

import dolfinx.fem

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import block_on_base, tags

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--refine", type=int, default=0, help="halve the element size N times")
parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient")
parser.add_argument("--N", type=float, default=1e5, help="normal force N [N/m]")
parser.add_argument("--pairing", default="auto", help="pairing model of the interface")
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %%
msh, cells, facets, geo = block_on_base.build(comm, refine=args.refine)
b, h = geo["block_width"], geo["block_height"]
if not args.mu * h < b / 2:
    raise SystemExit(f"--mu {args.mu}: μh = {args.mu * h:.4g} m must stay below b/2 = "
                     f"{b / 2:.4g} m, or the block tips before it slides")
aluminium = forms.Material(E_Pa=70e9, nu=0.33, name="aluminium")
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
ds = ufl.Measure("ds", domain=msh, subdomain_data=facets)
a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: aluminium}, dx, "plane_strain")
# The traction on the top [Pa]: (Q/b, −N/b), so that it sums to (Q, −N) per metre of depth.
traction = dolfinx.fem.Constant(msh, np.zeros(2))
L = ufl.inner(traction, v) * ds(tags.LOADED)

fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
problem = fc.ContactProblem(
    a, L, fixed,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=args.mu,
                        name="block/base", pairing=args.pairing),
    bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}), floating=True)

# %% [markdown]
# ## Load path
# N first (one increment, Q = 0), then Q as fractions of μN, in smaller steps close to it;
# the last one, 1.005 μN, has no static equilibrium.

# %%
N = args.N
fractions = [0.0, 0.2, 0.4, 0.6, 0.8, 0.9, 0.95, 0.98, 0.99, 0.995, 1.005]
Q_ref = args.mu * N
summaries, Q_done, failure = [], [], None
for f in fractions:
    Q = f * Q_ref
    traction.value = np.array([Q / b, -N / b])
    try:
        inc = problem.step()
    except fc.NoEquilibriumError as e:
        failure = {"Q": Q, "fraction": f, "message": str(e)}
        break
    summaries.append(inc.summary)
    Q_done.append(Q)
    if comm.rank == 0:
        print(f"Q/(μN) = {f:.3f}: {inc.summary.line()}", flush=True)

# %% [markdown]
# ## Checks
# Each converged increment: the normal total equals N and the friction total equals Q (the
# block's equilibrium, to rounding). Partial slip: stick and slip pairs at once. The
# threshold: the last converged Q and the first refused one bracket μN within 1 %.

# %%
if comm.rank == 0:
    Nt = np.array([s.normal_force for s in summaries])
    Tt = np.array([-s.tangential_force[0] for s in summaries])  # friction opposes the push
    Qd = np.array(Q_done)
    partial = [float(Q / Q_ref) for Q, s in zip(Q_done, summaries) if s.stick > 0 and s.slip > 0]
    last_ok = Q_done[-1] if Q_done else 0.0
    critical = 0.5 * (last_ok + failure["Q"]) if failure else float("nan")
    summary = {
        "demo": "pushed_block", "units": "SI (m, N/m)", "mu": args.mu,
        "block_width_m": b, "block_height_m": h,
        "materials": {"base": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                      "block": {"E_Pa": aluminium.E_Pa, "nu": aluminium.nu}},
        "pairing": problem.interfaces[0].pairing_used,
        "Q_over_muN": [float(Q / Q_ref) for Q in Q_done],
        "normal_total": Nt, "normal_total_ref": np.full(Nt.size, N),
        "normal_total_error_rel": float(np.abs(Nt / N - 1).max()),
        "tangential_total": Tt, "tangential_total_ref": Qd,
        "tangential_total_error_rel": float(np.abs(Tt - Qd).max() / N),
        "stick": [s.stick for s in summaries], "slip": [s.slip for s in summaries],
        "partial_slip_at_Q_over_muN": partial,
        "no_equilibrium": failure,
        "critical_Q": critical, "critical_Q_ref": Q_ref,
        "critical_Q_bracket_rel": ((failure["Q"] - last_ok) / Q_ref) if failure else None,
        "mesh": fc.output.mesh_info(V, refine=args.refine),
        **fc.output.run_record(problem, summaries, t_start),
    }
    folder = fc.results_folder("pushed_block")
    fc.write_summary(folder, summary)
    print(f"normal total error {summary['normal_total_error_rel']:.2e}, tangential "
          f"{summary['tangential_total_error_rel']:.2e} (relative to N); partial slip at "
          f"Q/(μN) = {partial}")
    if failure:
        print(f"no static equilibrium at Q = {failure['fraction']} μN: {failure['message']}")
    if not args.no_plot:
        plt = fc.output.pyplot()
        fig, ax = plt.subplots(figsize=(5, 4))
        ax.plot(Qd / Q_ref, Tt / Q_ref, "o-", label="friction total / μN")
        ax.plot(Qd / Q_ref, np.array(summary["slip"]) / problem.m, "s-", label="slipping pairs")
        if failure:
            ax.axvline(failure["fraction"], color="r", lw=0.8, label="no equilibrium")
        ax.set_xlabel("Q / (μN)")
        ax.legend()
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(folder / "pushed_block.png", dpi=120)
    print(f"results in {folder}/")
