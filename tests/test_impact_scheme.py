"""The Moreau–Jean θ-scheme away from contact, and a change of time step from Python.

θ = 1 is backward Euler on (u, v): for a mode of circular frequency ω the energy of the
mode is divided by 1 + (ωh)² every step, exactly, so the energy of a vibrating body decays
monotonically as Σ_i E_i (1 + ω_i² h²)^(−n); the references here come from the modes of
the assembled K and M (SciPy). For any θ the energy account books the numerical
dissipation (θ − ½)(‖Δv‖²_M + ‖Δu‖²_K) ≥ 0 and closes.
"""
import math

import numpy as np
import pytest
from mpi4py import MPI

E, RHO, L = 200e9, 8000.0, 1.0
C = math.sqrt(E / RHO)
DT = 0.5 * 0.1 / C   # half the wave transit time of one of the 10 elements
STRAIN = 1e-5        # initial stretch of the bar
V_AWAY = 1.0         # the bar moves away from the wall: no contact


def _bar(theta, dt=DT):
    """The bar of test_impact's bad-input cases (10 elements), stretched and moving away."""
    import dolfinx.fem
    import flexcontact as fc
    from flexcontact import compat, forms
    from flexcontact.meshes import BASE, MASTER, SLAVE, UPPER, bar_impact
    msh, cells, facets, _ = bar_impact.build(MPI.COMM_WORLD, n=10, ny=1, target="wall")
    V = compat.vector_space(msh)
    steel = forms.Material(E_Pa=E, nu=0.0, rho_kg_m3=RHO)
    u0 = dolfinx.fem.Function(V)
    u0.interpolate(lambda x: np.vstack([STRAIN * np.maximum(x[0], 0.0), 0.0 * x[1]]))
    return fc.ImpactProblem(
        V, cells, {"wall": BASE, "bar": UPPER}, {BASE: steel, UPPER: steel},
        fc.hold_body(V, cells, BASE), fc.ContactInterface(facets, SLAVE, MASTER, 0.0),
        dt_s=dt, theta=theta, initial_velocity={"bar": (V_AWAY, 0.0)},
        initial_displacement=u0)


def _dense(A, rows):
    from scipy.sparse import csr_matrix
    ai, aj, av = A.getValuesCSR()
    return csr_matrix((av, aj, ai), shape=A.getSize()).toarray()[np.ix_(rows, rows)]


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense modal reference in serial")
def test_theta_one_divides_each_modes_energy_by_one_plus_omega_h_squared():
    from scipy.linalg import eigh
    p = _bar(theta=1.0)
    free = np.flatnonzero(p.marker.array_r == 1.0)
    K, M = _dense(p.K, free), _dense(p.M, free)
    w2, phi = eigh(K, M)                      # M-orthonormal modes
    w2 = np.maximum(w2, 0.0)                  # rigid modes: round-off
    u, v = p.u_vec.array_r[free], p.v_vec.array_r[free]
    q, s = phi.T @ M @ u, phi.T @ M @ v
    e_modes = 0.5 * (s**2 + w2 * q**2)
    assert e_modes.sum() == pytest.approx(p.energy.initial, rel=1e-10)
    energies = [p.energy.initial]
    for n in range(1, 31):
        rec = p.step()
        assert rec.active == 0
        energies.append(p.energy.total)
        ref = np.sum(e_modes * (1.0 + w2 * p.dt**2) ** (-n))
        assert p.energy.total == pytest.approx(ref, rel=1e-9), n
    # Monotonic decay away from contact, all of it booked as numerical dissipation.
    assert np.all(np.diff(energies) < 0)
    assert p.energy.numerical == pytest.approx(energies[0] - energies[-1], rel=1e-9)
    assert abs(p.energy.balance_error_rel) < 1e-12
    assert p.energy.contact == 0.0 and p.energy.friction == 0.0


@pytest.mark.parametrize("theta", [0.5, 0.75])
def test_energy_account_books_the_numerical_dissipation(theta):
    p = _bar(theta=theta)
    last, prev = p.energy.initial, 0.0
    for _ in range(30):
        p.step()
        step_loss = p.energy.numerical - prev
        prev = p.energy.numerical
        assert step_loss >= 0.0
        # ΔE = −(θ − ½)(‖Δv‖²_M + ‖Δu‖²_K) step by step: no contact, loads or damping.
        assert p.energy.total - last == pytest.approx(-step_loss,
                                                      abs=1e-12 * p.energy.initial)
        last = p.energy.total
    if theta == 0.5:
        assert p.energy.numerical == 0.0
        assert p.energy.total == pytest.approx(p.energy.initial, rel=1e-12)
    else:
        assert p.energy.numerical > 1e-6 * p.energy.initial
    assert abs(p.energy.balance_error_rel) < 1e-12


def test_set_time_step_refactors_once_and_matches_a_fresh_problem():
    p = _bar(theta=0.5)
    for _ in range(5):
        p.step()
    t5 = p.t
    p.set_time_step(DT / 2)
    assert p.factorizations == 2 and p.dt == DT / 2
    fresh = _bar(theta=0.5, dt=DT / 2)
    if MPI.COMM_WORLD.rank == 0:
        W1, W2 = np.asarray(p.contact.W), np.asarray(fresh.contact.W)
        assert np.max(np.abs(W1 - W2)) <= 1e-12 * np.max(np.abs(W2))
        assert p.contact.dt_s == DT / 2
    for _ in range(4):
        p.step()
    assert p.t == pytest.approx(t5 + 4 * DT / 2, rel=1e-12)
    # θ = ½ conserves the energy away from contact whatever the step.
    assert p.energy.total == pytest.approx(p.energy.initial, rel=1e-12)
    # A step that cannot resolve the contact is refused before anything changes.
    with pytest.raises(ValueError, match=r"dt_s=0\.001 cannot resolve the contact"):
        p.set_time_step(1e-3)
    with pytest.raises(ValueError, match="dt_s=-1"):
        p.set_time_step(-1.0)
    assert p.factorizations == 2 and p.dt == DT / 2
