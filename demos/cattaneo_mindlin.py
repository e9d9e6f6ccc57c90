# %% [markdown]
# # Cattaneo–Mindlin partial slip: normal load P, then tangential load Q < μP
#
# A steel half-cylinder on a steel block — elastically similar bodies, so the normal and
# tangential problems decouple (docs/architecture.md §6). After the normal load P (Hertz: half-width
# a) a tangential load Q < μP is applied. The centre of the contact sticks, the edges slip:
#
#     c = a sqrt(1 − Q/(μP)),
#     q(x) = μ p0 sqrt(1 − x²/a²) − μ p0 (c/a) sqrt(1 − x²/c²)   for |x| < c.
#
# Friction is path dependent: the normal load goes first, then the tangential push, in
# increments, each solved with the stick/slip/open states of the previous one as a start.
#
# Run: `/usr/bin/python3 demos/cattaneo_mindlin.py [--refine N]`.

# %%
import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import analytic, compat, forms
from flexcontact.states import SLIP, STICK
from flexcontact.contact_profile import hertz_fit, profile, zone_halfwidth
from flexcontact.meshes import hertz2d, tags

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--refine", type=int, default=0, help="halve the contact element size N times")
parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient")
parser.add_argument("--q-ratio", type=float, default=0.5, help="target Q/(μP), below 1")
parser.add_argument("--normal-increments", type=int, default=3)
parser.add_argument("--tangential-increments", type=int, default=6)
parser.add_argument("--no-plot", action="store_true")
args = parser.parse_args()
if not 0 < args.q_ratio < 1:
    raise SystemExit(f"--q-ratio={args.q_ratio}: must lie strictly between 0 and 1")
comm = MPI.COMM_WORLD
t_start = time.perf_counter()

# %%
R = 0.05
a_target = 0.1 * R
msh, cells, facets, geo = hertz2d.build(comm, R=R, a_expected=a_target, refine=args.refine)
steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
Estar = forms.effective_modulus(steel, steel)
V = compat.vector_space(msh)
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")
fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
top, (top_x, top_y) = fc.dirichlet(V, facets, tags.LOADED)
problem = fc.ContactProblem(
    a, None, fixed + top,
    fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=args.mu,
                        name="cylinder/block"),
    bodies=(cells, {"block": tags.BASE, "cylinder": tags.UPPER}),
    stress=lambda w: forms.von_mises(w, steel, "plane_strain"))

# %% [markdown]
# ## Load path
# Normal stage as in the Hertz demo (a trial approach, then a ramp to the target load).
# Tangential stage: a trial push measures the stick stiffness; the ramp aims at
# Q = q_ratio · μP. Partial slip softens the response, so Q ends somewhat below the aim;
# the reference uses the Q actually reached.

# %%
n1, n2 = args.normal_increments, args.tangential_increments
P_target = np.pi * Estar * a_target**2 / (4 * R)
ctl = {"d_trial": a_target**2 / (2 * R), "d_final": None, "s_trial": None, "s_final": None}


def load(i, t):
    if i <= n1:
        if i == 1:
            top_y.value = -ctl["d_trial"]
            return
        if ctl["d_final"] is None:
            ctl["d_final"] = ctl["d_trial"] * P_target / problem.increments[-1].summary.normal_force
        top_y.value = -(ctl["d_trial"] + (ctl["d_final"] - ctl["d_trial"]) * (i - 1) / (n1 - 1))
        return
    k = i - n1
    if k == 1:
        ctl["s_trial"] = 1e-3 * ctl["d_trial"]
        top_x.value = ctl["s_trial"]
        return
    if ctl["s_final"] is None:
        s = problem.increments[-1].summary
        ctl["s_final"] = ctl["s_trial"] * args.q_ratio * args.mu * s.normal_force / abs(s.tangential_force[0])
    top_x.value = ctl["s_trial"] + (ctl["s_final"] - ctl["s_trial"]) * (k - 1) / (n2 - 1)


folder = fc.results_folder("cattaneo_mindlin")
with fc.ResultWriter(folder, "cattaneo_mindlin", msh, tags=(cells,)) as out:
    summaries = problem.solve(n1 + n2, load=load, writer=out)

# %% [markdown]
# ## Stick zone against Cattaneo–Mindlin
# c is the half-width of the run of stick pairs (to the midpoints towards their slipping
# neighbours); a comes from Hertz with the final P.

# %%
if comm.rank == 0:
    x, p, q, states, _ = profile(problem)
    P = summaries[-1].normal_force
    Q = abs(summaries[-1].tangential_force[0])
    a_ref, p0_ref = analytic.hertz_cylinder(P, R, Estar)
    a_fit, p0, _ = hertz_fit(x, p)
    c = zone_halfwidth(x, states == STICK)
    c_ref = analytic.cattaneo_mindlin_stick_halfwidth(a_ref, Q, args.mu, P)
    q_ref = np.array([analytic.cattaneo_mindlin_shear(xi, a_ref, c_ref, args.mu, p0_ref) for xi in x])
    inside = np.abs(x) < a_ref
    shear_rms = float(np.sqrt(np.mean((np.abs(q[inside, 0]) - q_ref[inside]) ** 2)) / (args.mu * p0_ref))
    # Stick means no slip in the increment: the largest incremental slip of any stick pair
    # over the whole load path, relative to the largest displacement.
    stick_slip = max(float(np.abs(inc.slip_increment[inc.states == STICK]).max(initial=0.0))
                     for inc in problem.increments)
    umax = max(1e-300, float(np.abs(problem.u.x.array).max()))
    summary = {
        "demo": "cattaneo_mindlin", "units": "SI (m, Pa, N/m)", "mu": args.mu,
        "P": P, "Q": Q, "Q_over_muP": Q / (args.mu * P),
        # The inputs of the references, so that a test can recompute them.
        "R_m": R, "a_target_m": a_target,
        "materials": {"block": {"E_Pa": steel.E_Pa, "nu": steel.nu},
                      "cylinder": {"E_Pa": steel.E_Pa, "nu": steel.nu}},
        "c": c, "c_ref": c_ref, "c_error_rel": c / c_ref - 1,
        "a": a_fit, "a_ref": a_ref, "p0": p0, "p0_ref": p0_ref,
        "shear_rms_error_rel_mu_p0": shear_rms,
        "max_stick_slip_increment_rel": stick_slip / umax,
        "max_penetration_rel": max(s.max_penetration_rel for s in summaries),
        "stick_pairs": int((states == STICK).sum()), "slip_pairs": int((states == SLIP).sum()),
        "h_contact_m": geo["h_contact"],
        "mesh": fc.output.mesh_info(V, refine=args.refine),
        **fc.output.run_record(problem, summaries, t_start),
        "profile": {"x": x, "pressure": p, "traction": q[:, 0], "state": states},
    }
    fc.write_summary(folder, summary)
    print(f"Cattaneo–Mindlin: Q/(muP) = {Q / (args.mu * P):.3f}, c = {c:.4e} m "
          f"(ref {c_ref:.4e}, {100 * (c / c_ref - 1):+.1f}%)")
    if not args.no_plot:
        plt = fc.output.pyplot()
        xs = np.linspace(-1.3 * a_ref, 1.3 * a_ref, 600)
        fig, ax = plt.subplots(figsize=(9, 4))
        ax.plot(xs * 1e3, [analytic.hertz_pressure(t, a_ref, p0_ref) / 1e6 for t in xs], "k-",
                label="Hertz p(x)")
        ax.plot(xs * 1e3, [analytic.cattaneo_mindlin_shear(t, a_ref, c_ref, args.mu, p0_ref) / 1e6
                           for t in xs], "b-", label="Cattaneo–Mindlin q(x)")
        ax.plot(x * 1e3, p / 1e6, "ko", ms=3, label="pressure")
        for st, mk, name in ((STICK, "bs", "shear, stick"), (SLIP, "r^", "shear, slip")):
            sel = states == st
            ax.plot(x[sel] * 1e3, np.abs(q[sel, 0]) / 1e6, mk, ms=4, label=name)
        ax.axvspan(-c_ref * 1e3, c_ref * 1e3, color="b", alpha=0.07, label="stick zone (theory)")
        ax.set_xlim(-1.3 * a_ref * 1e3, 1.3 * a_ref * 1e3)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("traction [MPa]")
        ax.set_title(f"Q/(μP) = {Q / (args.mu * P):.2f}: c {100 * (c / c_ref - 1):+.1f}% of theory")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5))
        fig.tight_layout()
        fig.savefig(folder / "cattaneo_mindlin.png", dpi=120)
    print(f"results in {folder}/")
