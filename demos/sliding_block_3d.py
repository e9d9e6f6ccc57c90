# %% [markdown]
# # A block pulled along a base in a turning direction (3D Coulomb friction)
#
# An aluminium block sits on a steel base. A platen presses its top down by δ_n (normal
# load N) and then travels sideways by s(t)·(cos θ(t), sin θ(t), 0), pulling the block
# through a compliant pad: the travel grows past the point of gross slip while its
# direction turns by 90° in the x–y plane. In 3D the direction of slip is an unknown of
# the problem (docs/architecture.md §1): the friction force must follow the block around
# the bend.
#
# What the demo measures:
#
# * the total friction force T on the block never exceeds μN (Coulomb's law, summed over
#   the interface), and it balances the pad's pull (the block's equilibrium);
# * gross slip starts (first increment at which no pair sticks) at |T| = μN: every pair is
#   on its Coulomb cone, and their slip directions agree, so |Σλ_t| = Σ|λ_t| = μN;
# * once the block slides, T points against the block's incremental slip (the mean of the
#   pairs' slip increments), i.e. its direction follows the block around the bend.
#
# Why a pad: a tangential *load* is a force, and a soft pad makes the platen's travel one.
# When the last sticking pair lets go, the block slides as a whole within the increment and
# all pairs slip the same way. A stiff pad instead prescribes the top's displacement:
# slipping then starts while the elastic block still deforms, the trailing corners slip
# obliquely, and |T| at the first all-slip increment is below μN although every pair is on
# its cone (it reaches μN as the block slides on). Measured at refine 0, onset |T|/μN − 1
# against the pad's stiffness per area over the block's G/h: 0.003 → −0.008 %,
# 0.01 (default) → −0.09 %, 0.03 → −0.55 %, 0.1 → −2.1 %, 1 → −2.9 %, 100 → −2.6 %.
#
# Run: `/usr/bin/python3 demos/sliding_block_3d.py [--refine N]` (also with `mpirun -n 2`).

# %%
import argparse
import time

import dolfinx.fem
import numpy as np
import ufl
from petsc4py import PETSc
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.states import STICK
from flexcontact.meshes import block_on_base, tags

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--refine", type=int, default=0, help="halve the element sizes N times")
parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient")
parser.add_argument("--turn-deg", type=float, default=90.0,
                    help="angle the platen's travel turns through over the tangential stage [°]")
parser.add_argument("--normal-increments", type=int, default=2)
parser.add_argument("--tangential-increments", type=int, default=24)
parser.add_argument("--pad-stiffness-ratio", type=float, default=0.01,
                    help="pad stiffness per area [Pa/m] over the block's shear stiffness "
                         "per area G/h [Pa/m]; small = force-like pull, large = clamped top")
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %% [markdown]
# ## Geometry, materials, supports
# Block 0.1 m × 0.1 m × 0.05 m (tag `UPPER`, slave surface its bottom) on a base
# 0.3 m × 0.3 m × 0.1 m (tag `BASE`, master surface the footprint on its top); the
# interface meshes match node for node. The base's bottom is clamped. The platen holds the
# height of the block's top; sideways the pad (springs per area k_pad [Pa/m]) joins the top
# to the platen. The pad also keeps the block from moving freely in x, y and about z, so
# K is invertible (docs/architecture.md §1).

# %%
msh, cells, facets, geo = block_on_base.build_3d(comm, refine=args.refine)
aluminium = forms.Material(E_Pa=70e9, nu=0.33, name="aluminium")
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
materials = {tags.BASE: steel, tags.UPPER: aluminium}
a = forms.elasticity_form(u, v, materials, dx, "3d")
# Piecewise-constant Lamé fields, so the von Mises stress uses each body's own material.
lame = forms.lame_fields(msh, cells, materials)

fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
# The platen holds the top's height; sideways it acts through the pad: a traction
# k_pad·(g − u) [Pa] on the top, g = s·(cos θ, sin θ) the platen's travel [m].
top, (top_z,) = fc.dirichlet(V, facets, tags.LOADED, components=[2])
ds = ufl.Measure("ds", domain=msh, subdomain_data=facets)
k_block = aluminium.mu_Pa / geo["block_height"]          # shear stiffness per area [Pa/m]
if args.pad_stiffness_ratio <= 0:
    raise SystemExit(f"--pad-stiffness-ratio must be > 0, got {args.pad_stiffness_ratio}")
k_pad = args.pad_stiffness_ratio * k_block               # [Pa/m]
g = dolfinx.fem.Constant(msh, np.zeros(3, dtype=PETSc.ScalarType))
k_pad_c = dolfinx.fem.Constant(msh, PETSc.ScalarType(k_pad))
P_t = ufl.as_matrix([[1, 0, 0], [0, 1, 0], [0, 0, 0]])  # in-plane part
a = a + k_pad_c * ufl.inner(P_t * u, v) * ds(tags.LOADED)
L = k_pad_c * ufl.inner(P_t * g, v) * ds(tags.LOADED)
problem = fc.ContactProblem(
    a, L, fixed + top,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=args.mu,
                        name="block/base"),
    bodies=(cells, {"base": tags.BASE, "block": tags.UPPER}),
    stress=lambda w: forms.von_mises(w, lame, "3d"))
pad_forms = [dolfinx.fem.form(k_pad_c * (g[c] - problem.u[c]) * ds(tags.LOADED)) for c in (0, 1)]


def pad_force_N():
    """In-plane force the pad applies to the block [N] (all ranks)."""
    return np.array([comm.allreduce(dolfinx.fem.assemble_scalar(f), op=MPI.SUM)
                     for f in pad_forms])


# %% [markdown]
# ## Load path
# Normal stage: the top goes down to δ_n = 1e-4 of the block's height [m]. Tangential
# stage: the first travel is a small trial along x; the stick response is linear, so it
# tells the travel s_μ [m] at which |T| would reach μN. The remaining increments ramp the
# travel to 2.5 s_μ while its direction turns from θ = 0 to θ = turn (90° by default): the
# block first sticks, then slips at its edges, then slides along a bend. The block slides
# about half a millimetre in all, a few per cent of the element size: small sliding, as
# node–node pairs assume.

# %%
n1, n2 = args.normal_increments, args.tangential_increments
if n2 < 4:
    raise SystemExit("--tangential-increments must be at least 4")
delta_n = 1e-4 * geo["block_height"]
turn = np.radians(args.turn_deg)
push = {"trial": None, "final": None}
path = []  # (s, θ) of the platen's travel per increment [m, rad]
pad = []   # in-plane force of the pad on the block after each increment [N]


def load(i, t):
    if i > 1:
        pad.append(pad_force_N())
    if i <= n1:
        top_z.value = -delta_n * i / n1
        s, th = 0.0, 0.0
    else:
        k = i - n1
        if k == 1:
            push["trial"] = 1e-3 * delta_n
            s, th = push["trial"], 0.0
        else:
            if push["final"] is None:
                # The trial's own force: the normal stage leaves a small tangential
                # resultant (Poisson mismatch slips) that is not the push's response.
                before, last = (problem.increments[j].summary for j in (-2, -1))
                T1 = float(np.linalg.norm(np.subtract(last.tangential_force,
                                                      before.tangential_force)))
                push["final"] = 2.5 * push["trial"] * args.mu * last.normal_force / T1
            f = (k - 1) / (n2 - 1)
            s = push["trial"] + (push["final"] - push["trial"]) * f
            th = turn * f
    g.value[:] = (s * np.cos(th), s * np.sin(th), 0.0)
    path.append((s, th))


folder = fc.results_folder("sliding_block_3d")
with fc.ResultWriter(folder, "sliding_block_3d", msh, tags=(cells,)) as out:
    summaries = problem.solve(n1 + n2, load=load, writer=out)
pad.append(pad_force_N())

# %% [markdown]
# ## Slip onset and the direction of friction
# Gross slip is the first increment at which no pair sticks. The block's incremental slip
# direction is the mean over the pairs of their tangential slip increments (turned from the
# pairs' local frames into global x, y); the friction force T on the block (summed over the
# pairs, global components) must point against it. Angles are measured from the x axis.

# %%
def angle_deg(vx, vy):
    return float(np.degrees(np.arctan2(vy, vx)))


def between_deg(a, b):
    """Unsigned angle between two plane vectors [°]."""
    c = (a[0] * b[0] + a[1] * b[1]) / max(np.hypot(*a) * np.hypot(*b), 1e-300)
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


if comm.rank == 0:
    frames = problem.frames
    N = np.array([s.normal_force for s in summaries])
    Tvec = np.array([s.tangential_force for s in summaries])
    T = np.linalg.norm(Tvec[:, :2], axis=1)
    muN = args.mu * N
    gross = [i for i, s in enumerate(summaries) if i >= n1 and s.stick == 0 and s.slip > 0]
    if not gross:
        raise RuntimeError("the block never slid: increase the platen travel")
    i0 = gross[0]
    ratio = T / np.maximum(muN, 1e-300)

    # Mean slip increment of the block over the pairs, global x, y [m]; and per increment the
    # angle between −T and it (friction opposes slip), and between −T and the push increment.
    slip_mean, slip_vs_T, push_vs_T, stick_slip = [], [], [], []
    top_xy = np.array([(s * np.cos(th), s * np.sin(th)) for s, th in path])
    for i, inc in enumerate(problem.increments):
        g = np.einsum("kij,ki->kj", frames[:, 1:, :], inc.slip_increment)  # (m, 3) [m]
        mean = g[:, :2].mean(axis=0)
        slip_mean.append(mean)
        st = inc.states == STICK
        stick_slip.append(float(np.linalg.norm(inc.slip_increment[st], axis=1).max(initial=0.0)))
        minus_T = -Tvec[i, :2]
        slip_vs_T.append(between_deg(minus_T, mean) if i in gross else np.nan)
        d_push = top_xy[i] - (top_xy[i - 1] if i > 0 else 0.0)
        push_vs_T.append(between_deg(minus_T, d_push) if i in gross else np.nan)
    slip_mean = np.array(slip_mean)
    # Coulomb per pair at onset: every pair slips, so Σ|λ_t| = μN exactly; |T| = |Σ λ_t| is
    # smaller by the spread of the pairs' slip directions.
    lam0 = problem.increments[i0].lam
    onset_sum_abs = float(np.linalg.norm(lam0[:, 1:], axis=1).sum() / (args.mu * lam0[:, 0].sum()))
    # Total slip of the block (mean over pairs) from the onset to the end [m].
    slid = float(np.hypot(*slip_mean[i0:].sum(axis=0)))
    slip_vs_T, push_vs_T = np.array(slip_vs_T), np.array(push_vs_T)
    # The block's in-plane equilibrium: the pad's pull balances the friction on the block.
    pad_vs_friction = float(np.abs(np.array(pad) + Tvec[:, :2]).max() / max(T.max(), 1e-300))
    umax = max(1e-300, float(np.abs(problem.u.x.array).max()))
    theta_T = [angle_deg(-t[0], -t[1]) if np.hypot(t[0], t[1]) > 0 else np.nan for t in Tvec]
    theta_slip = [angle_deg(*m) if np.hypot(*m) > 0 else np.nan for m in slip_mean]
    theta_push = [np.degrees(th) for _, th in path]
    d_xy = np.diff(np.vstack([[0.0, 0.0], top_xy]), axis=0)
    theta_dpush = [angle_deg(*d) if np.hypot(*d) > 0 else np.nan for d in d_xy]
    summary = {
        "demo": "sliding_block_3d", "units": "SI (m, N, degrees)", "mu": args.mu,
        "turn_deg": args.turn_deg,
        "normal_increments": n1, "tangential_increments": n2,
        "materials": {"base": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                      "block": {"E_Pa": aluminium.E_Pa, "nu": aluminium.nu}},
        "q": T[i0], "q_ref": muN[i0],
        "pad_stiffness_ratio": args.pad_stiffness_ratio, "pad_stiffness_Pa_per_m": k_pad,
        "pad_force_N": np.array(pad), "pad_vs_friction_rel": pad_vs_friction,
        "slip_onset_T": T[i0], "slip_onset_T_ref": muN[i0],
        "slip_onset_error_rel": T[i0] / muN[i0] - 1,
        "slip_onset_increment": i0 + 1,
        "slip_onset_push_m": path[i0][0], "slip_onset_push_angle_deg": np.degrees(path[i0][1]),
        "onset_sum_abs_lambda_t_over_muN": onset_sum_abs,
        "sliding_T": T[-1], "sliding_T_ref": muN[-1],
        "sliding_error_rel": T[-1] / muN[-1] - 1,
        "slid_since_onset_m": slid,
        "gross_slip_increments": [i + 1 for i in gross],
        "max_T_over_muN": float(ratio[n1:].max()),
        "min_T_over_muN_gross_slip": float(ratio[gross].min()),
        "max_angle_T_vs_slip_deg": float(np.nanmax(slip_vs_T)),
        "max_angle_T_vs_push_increment_deg": float(np.nanmax(push_vs_T)),
        "final_angle_T_deg": theta_T[-1], "final_push_angle_deg": theta_push[-1],
        "max_stick_slip_increment_m": max(stick_slip),
        "max_stick_slip_increment_rel": max(stick_slip) / umax,
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "contact_pairs": int(problem.m),
        "mesh": {"cells": int(msh.topology.index_map(3).size_global),
                 "dofs": int(V.dofmap.index_map.size_global * V.dofmap.index_map_bs),
                 "h_m": geo["h"], "refine": args.refine, "ranks": comm.size},
        **fc.output.run_record(problem, summaries, t_start),
        "push_m": [p[0] for p in path], "push_angle_deg": theta_push,
        "push_increment_angle_deg": theta_dpush,
        "N": N, "T": T, "T_vector": Tvec, "friction_angle_deg": theta_T,
        "slip_angle_deg": theta_slip, "angle_T_vs_slip_deg": slip_vs_T,
    }
    fc.write_summary(folder, summary)
    print(f"gross slip at increment {i0 + 1} (travel {np.degrees(path[i0][1]):.1f}° from x): "
          f"|T| = {T[i0]:.5e} N, muN = {muN[i0]:.5e} N ({100 * (T[i0] / muN[i0] - 1):+.3f}%); "
          f"max |T|/(muN) = {ratio[n1:].max():.8f}; "
          f"largest angle between -T and the slip while sliding = {np.nanmax(slip_vs_T):.3f}°")
    if not args.no_plot:
        plt = fc.output.pyplot()
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
        k = np.arange(1, len(summaries) + 1)
        ax1.plot(k[n1:], T[n1:] / 1e3, "o-", label="|T| friction force")
        ax1.plot(k[n1:], muN[n1:] / 1e3, "k--", label="μN")
        ax1.plot(k[n1:], np.linalg.norm(np.array(pad), axis=1)[n1:] / 1e3, "x", ms=4,
                 label="pad pull")
        ax1.axvline(i0 + 1, color="r", lw=0.8, label="gross slip")
        ax1.set_xlabel("increment")
        ax1.set_ylabel("force [kN]")
        ax1.legend()
        ax1.grid(alpha=0.3)
        ax2.plot(k[n1:], theta_push[n1:], "k--", label="platen travel θ")
        ax2.plot(k[n1:], theta_dpush[n1:], "k:", label="travel increment")
        ax2.plot(k[n1:], theta_slip[n1:], "s", ms=4, mfc="none", label="mean slip increment")
        ax2.plot(k[n1:], theta_T[n1:], "o", ms=3, label="−T (friction reversed)")
        ax2.axvline(i0 + 1, color="r", lw=0.8)
        ax2.set_xlabel("increment")
        ax2.set_ylabel("direction from x [°]")
        ax2.legend(fontsize=8)
        ax2.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(folder / "sliding_block_3d.png", dpi=120)
    print(f"results in {folder}/")
