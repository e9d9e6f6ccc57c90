"""ImpactProblem(contact_operator="factor"): one plain factorization of Ŵ, W_eff's columns of
the index set fetched through it (docs/impact.md, "The factor path"), against the dense path
on cases small enough for both: the same forces, impulses and crush depths to 1e-10 of the
peak, on one rank and on two."""
import math

import numpy as np
import pytest
from mpi4py import MPI

import crush_bar_case as bar
import flexcontact as fc
from conftest import mpirun
from flexcontact import compat, forms
from flexcontact.meshes import BASE, MASTER, SLAVE, UPPER, bar_impact

TOL = 1e-10


def _close(a, b, scale):
    assert np.asarray(a).shape == np.asarray(b).shape
    assert np.max(np.abs(np.asarray(a) - np.asarray(b)), initial=0.0) <= TOL * scale


@pytest.fixture(scope="module")
def crushing():
    """The crushable bar (docs/crushing.md §3) at σ_c = 0.3 ρcv: the end crushes twice."""
    return {op: bar.run(0.3, 20, contact_operator=op) for op in ("dense", "factor")}


def test_crushing_bar_is_the_dense_answer(crushing):
    d, f = crushing["dense"], crushing["factor"]
    assert d["crush"].max() > 0 and d["depth"].max() > 0
    _close(f["force"], d["force"], np.abs(d["force"]).max())
    _close(f["impulse"], d["impulse"], np.abs(d["impulse"]).max())
    _close(f["depth"], d["depth"], d["depth"].max())
    _close(f["momentum"], d["momentum"], abs(float(d["momentum0"])))
    # The account closes on the factor path as on the dense one.
    assert np.abs(f["balance"]).max() <= 1e-9 * float(f["initial"])


def _sliding(op, **kw):
    msh, cells, facets, _ = bar_impact.build(MPI.COMM_WORLD, n=10, ny=2, target="wall")
    V = compat.vector_space(msh)
    steel = forms.Material(E_Pa=bar.E, nu=0.3, rho_kg_m3=bar.RHO)
    p = fc.ImpactProblem(V, cells, {"wall": BASE, "bar": UPPER}, {BASE: steel, UPPER: steel},
                         fc.hold_body(V, cells, BASE),
                         fc.ContactInterface(facets, SLAVE, MASTER, 0.3),
                         dt_s=0.05 / bar.C, initial_velocity={"bar": (-1.0, 5.0)},
                         kind="plane_strain", contact_operator=op, **kw)
    return p


def test_sliding_impact_and_a_new_time_step_are_the_dense_answer():
    """Friction (every pair slipping) and a change of time step half way (a new factor of
    Ŵ, the held columns dropped) give the dense path's impulses."""
    t_half = 2 * bar.L / bar.C
    runs = {}
    for op in ("dense", "factor"):
        p = _sliding(op)
        recs = p.run(0.6 * t_half, progress=False)
        p.set_time_step(0.5 * p.dt)
        recs += p.run(1.2 * t_half, progress=False)
        runs[op] = (np.array([r.impulse for r in recs]), p)
    (Pd, dense), (Pf, factor) = runs["dense"], runs["factor"]
    assert np.abs(Pd[:, 1]).max() > 0  # friction acted
    _close(Pf, Pd, np.abs(Pd).max())
    assert factor.factorizations == dense.factorizations == 2
    assert factor.W_eff is None
    assert not factor.one_back_substitution


def test_two_solve_dense_path_survives_a_new_time_step():
    """The dense path with a factor that does not split (two solves a step) builds its
    reaction vectors on Ŵ's layout: after set_time_step destroyed the old Ŵ they must come
    from the new one (this crashed). Its impulses are the split path's."""
    t_end = 1.2 * 2 * bar.L / bar.C
    runs = []
    for flexibility in ("schur", "inverse_entries"):
        p = _sliding("dense", flexibility=flexibility)
        recs = p.run(0.3 * t_end, progress=False)
        p.set_time_step(0.5 * p.dt)
        recs += p.run(t_end, progress=False)
        runs.append(np.array([r.impulse for r in recs]))
    _close(runs[1], runs[0], np.abs(runs[0]).max())


def test_two_ranks_give_the_serial_answer(crushing, tmp_path):
    out = tmp_path / "factor2.npz"
    mpirun(2, bar.__file__, 0.3, 20, out, "factor")
    two = np.load(out)
    d = crushing["dense"]
    _close(two["force"], d["force"], np.abs(d["force"]).max())
    _close(two["depth"], d["depth"], d["depth"].max())


def test_unknown_contact_operator_is_named():
    with pytest.raises(ValueError, match="contact_operator"):
        _sliding("sparse")
