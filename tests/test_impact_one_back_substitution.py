"""An impact time step with MUMPS's Schur factor of Ŵ is one back-substitution: the step's
right-hand side condensed onto the contact DOFs, the kernel's step from it
(ImpactContact.step_condensed), the velocity expanded from the contact values it returns
(ImpactProblem.step with factor.condense/expand; dynamics.py).

The reference is the same problem stepped with full solves through the same factor (v_free,
then v⁺ = v_free + Ŵ⁻¹ Bᵀ P in steps with contact): the velocities, impulses and energy
accounts of the two agree to round-off (1e-10 relative) over a whole impact, on one rank
and on two (the DistributedSchur), and the split step costs one
back-substitution in every step, with and without contact. Cases: the 10-element bar of
tests/test_impact.py hitting the held wall obliquely with friction, Rayleigh damping, a
body load and θ = 0.6 (held contact DOFs); two free bars (no Dirichlet condition at all);
the bar re-paired node-to-surface before every step.
"""
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conftest import on_two_ranks  # noqa: E402

E, RHO, L, V0 = 200e9, 8000.0, 1.0, 1.0
C = math.sqrt(E / RHO)
DT = 0.5 * 0.1 / C     # half the wave transit time of one of the 10 elements
ROUNDOFF = 1e-10       # relative: one factor, its solve split or whole
CASES = ("wall_friction_damped_loaded", "two_free_bars", "repaired_node_to_surface")


class _TwoSolves:
    """The same factor without condense/expand: ImpactProblem falls back to full solves."""

    def __init__(self, factor):
        self._factor = factor
        self.solve = factor.solve


def _problem(case):
    import ufl

    import flexcontact as fc
    from flexcontact import compat, forms
    from flexcontact.meshes import BASE, MASTER, SLAVE, UPPER, bar_impact
    comm = MPI.COMM_WORLD
    target = "bar" if case == "two_free_bars" else "wall"
    msh, cells, facets, _ = bar_impact.build(comm, n=10, ny=1, target=target)
    V = compat.vector_space(msh)
    steel = forms.Material(E_Pa=E, nu=0.0, rho_kg_m3=RHO)
    kw = dict(dt_s=DT, initial_velocity={"bar": (-V0, 0.0)})
    mu, pairing, bcs = 0.0, "auto", fc.hold_body(V, cells, BASE)
    if case == "wall_friction_damped_loaded":
        mu = 0.3
        kw.update(initial_velocity={"bar": (-V0, 2.0 * V0)}, theta=0.6,
                  rayleigh=(200.0, 2e-7),
                  loads=forms.gravity(ufl.TestFunction(V), RHO, ufl.dx(domain=msh), g=1e3,
                                      vertical_axis=0))
    elif case == "two_free_bars":
        bcs = []
    else:
        pairing = "node_to_surface"
    return fc.ImpactProblem(V, cells, {"target": BASE, "bar": UPPER},
                            {BASE: steel, UPPER: steel},
                            bcs, fc.ContactInterface(facets, SLAVE, MASTER, mu, pairing=pairing),
                            **kw)


def _rel_diff(a, b) -> float:
    """‖a − b‖ / ‖b‖ of two distributed vectors (collective)."""
    d = a.copy()
    d.axpy(-1.0, b)
    out = d.norm() / max(b.norm(), 1e-300)
    d.destroy()
    return out


def compare(case) -> dict:
    """Steps the case split and with two solves over 1.5 × 2L/c; what differs (collective;
    the same dict on every rank)."""
    split, ref = _problem(case), _problem(case)
    ref.factor = _TwoSolves(ref.factor)
    out = {"split_used": split.one_back_substitution,
           "reference_splits": ref.one_back_substitution,
           "velocity": 0.0, "displacement": 0.0, "impulse": 0.0, "energy": 0.0,
           "split_solves": [], "reference_solves": [], "contact": [], "states_equal": True,
           "repairs": split.pairings}
    n = int(round(1.5 * 2 * L / C / DT))
    peak = 0.0
    for _ in range(n):
        ra, rb = split.step(), ref.step()
        out["velocity"] = max(out["velocity"], _rel_diff(split.v_vec, ref.v_vec))
        out["displacement"] = max(out["displacement"], _rel_diff(split.u_vec, ref.u_vec))
        if MPI.COMM_WORLD.rank == 0:
            pa, pb = (np.asarray(p._last_out["impulse"]) for p in (split, ref))
            peak = max(peak, float(np.abs(pb).max()))
            out["impulse"] = max(out["impulse"], float(np.abs(pa - pb).max()))
            out["states_equal"] &= bool(np.array_equal(split._last_out["states"],
                                                       ref._last_out["states"]))
        ea, eb = ra.energy, rb.energy
        scale = max(abs(v) for v in eb.values() if isinstance(v, float)) or 1.0
        out["energy"] = max(out["energy"], max(abs(ea[k] - eb[k]) / scale for k in eb
                                               if isinstance(eb[k], float)))
        out["split_solves"].append(ra.back_substitutions)
        out["reference_solves"].append(rb.back_substitutions)
        out["contact"].append(rb.active > 0 and rb.normal_force != 0.0)
    out["impulse"] = out["impulse"] / peak if peak > 0 else float("inf")
    out["peak_impulse"] = peak
    out["repairs"] = split.pairings
    out["energy_balance_error_rel"] = split.energy.balance_error_rel
    return MPI.COMM_WORLD.bcast(out, root=0)


def check(out: dict, case: str) -> None:
    assert out["split_used"] and not out["reference_splits"]
    contact = np.array(out["contact"])
    assert contact.sum() >= 5, "the case must have steps with an impulse"
    assert (~contact).sum() >= 5, "and steps without one"
    # One back-substitution in every step; the reference's two in steps with an impulse.
    assert set(out["split_solves"]) == {1}
    ref = np.array(out["reference_solves"])
    assert np.all(ref[contact] == 2) and np.all(ref[~contact] == 1)
    assert out["velocity"] <= ROUNDOFF, out
    assert out["displacement"] <= ROUNDOFF, out
    assert out["impulse"] <= ROUNDOFF, out
    assert out["states_equal"]
    assert out["energy"] <= ROUNDOFF, out
    assert abs(out["energy_balance_error_rel"]) <= 1e-8, out
    if case == "repaired_node_to_surface":
        assert out["repairs"] == len(contact)  # the first step's pairs, then one per step


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="the two-rank case runs its own mpirun")
@pytest.mark.parametrize("case", CASES)
def test_split_step_gives_the_two_solve_step_serial(case):
    check(compare(case), case)


@pytest.fixture(scope="module")
def two_ranks(tmp_path_factory):
    folder = tmp_path_factory.mktemp("impact_split")
    on_two_ranks(__file__, folder, timeout=600)
    return json.loads((folder / "compare.json").read_text())


@pytest.mark.mpi
@pytest.mark.parametrize("case", CASES)
def test_split_step_gives_the_two_solve_step_on_two_ranks(two_ranks, case):
    assert two_ranks["ranks"] == 2
    check(two_ranks[case], case)


if __name__ == "__main__":
    results = {case: compare(case) for case in CASES}
    if MPI.COMM_WORLD.rank == 0:
        results["ranks"] = MPI.COMM_WORLD.size
        (Path(sys.argv[1]) / "compare.json").write_text(json.dumps(results))
