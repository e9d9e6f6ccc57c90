"""An elastic bar with a crushable end hitting a rigid wall (docs/crushing.md §3): the model
run of the 1D solution's check, importable by the tests and runnable under mpirun.

Steel-like strip (E = 200 GPa, ν = 0, ρ = 8000 kg/m³, L = 1 m, height 0.05 m, plane
stress per unit thickness) at v = 1 m/s against a wall held by Dirichlet conditions, its
end crushable at σ_c = ratio × ρ c v; the end's nodes are the slave of a node–node
interface with the wall.

Run: ``/usr/bin/python3 tests/crush_bar_case.py RATIO N OUT.npz [dense|factor]`` (also under
mpirun): writes the step times, forces, crushing pairs, crush depth and energies.
"""
import math
import sys

import numpy as np
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import BASE, MASTER, SLAVE, UPPER, bar_impact

E, RHO, L, H, V0 = 200e9, 8000.0, 1.0, 0.05, 1.0
C = math.sqrt(E / RHO)
MASS = RHO * L * H   # per unit thickness [kg/m]
COURANT = 0.5        # h = 0.5 × element length / c


def exact(ratio):
    """The 1D solution (docs/crushing.md §3) for σ_c = ratio ρ c v: s, N, u_N, δ [m] and
    the contact duration [s]."""
    s = ratio * V0
    if s >= V0:
        return dict(s=s, N=0, u_N=V0, delta=0.0, duration=2 * L / C)
    N = math.floor((V0 - s) / (2 * s)) + 1
    u_N = V0 - 2 * N * s
    delta = (2 * L / C) * N * (V0 - N * s)
    duration = 2 * (N + 1) * L / C if u_N > 0 else 2 * N * L / C
    return dict(s=s, N=N, u_N=u_N, delta=delta, duration=duration)


def run(ratio, n, crushing=True, comm=MPI.COMM_WORLD, extra_periods=2.0, courant=COURANT,
        contact_operator="dense"):
    """Run the impact; returns a dict of arrays (same on every rank)."""
    msh, cells, facets, _ = bar_impact.build(comm, n=n, ny=1, target="wall")
    V = compat.vector_space(msh)
    steel = forms.Material(E_Pa=E, nu=0.0, rho_kg_m3=RHO)
    sigma_c = ratio * RHO * C * V0
    itf = fc.ContactInterface(facets, SLAVE, MASTER, 0.0,
                              crushing_strength_Pa=sigma_c if crushing else None)
    dt = courant * (L / n) / C
    p = fc.ImpactProblem(V, cells, {"wall": BASE, "bar": UPPER}, {BASE: steel, UPPER: steel},
                         fc.hold_body(V, cells, BASE), itf, dt_s=dt,
                         initial_velocity={"bar": (-V0, 0.0)}, kind="plane_stress",
                         contact_operator=contact_operator)
    ex = exact(ratio)
    recs = p.run(ex["duration"] + extra_periods * 2 * L / C, progress=False)
    hist = p.energy.history
    return dict(
        t=np.array([r.t_s for r in recs]), dt=dt, sigma_c=sigma_c,
        force=np.array([r.normal_force for r in recs]),
        crush=np.array([r.crush for r in recs]),
        depth=np.array([r.crush_depth_max_m for r in recs]),
        volume=np.array([r.crushed_volume_m3 for r in recs]),
        impulse=np.array([r.impulse[0] for r in recs]),
        momentum=np.array([r.momentum["bar"][0] for r in recs]),
        momentum0=np.array(p.momentum0["bar"][0]),
        crushing=np.array([h["crushing"] for h in hist]),
        contact=np.array([h["contact"] for h in hist]),
        balance=np.array([h["balance_error"] for h in hist]),
        initial=np.array(p.energy.initial),
        chatter=comm.bcast((p.crush_chatter.flips, p.crush_chatter.capped_steps)
                           if p.crush_chatter is not None else None))


if __name__ == "__main__":
    out = run(float(sys.argv[1]), int(sys.argv[2]),
              contact_operator=sys.argv[4] if len(sys.argv) > 4 else "dense")
    if MPI.COMM_WORLD.rank == 0:
        np.savez(sys.argv[3], **out)
