"""The crushing contact law (docs/crushing.md) against exact answers.

* A block pressed into a crushable interface by a prescribed displacement (the patch-test
  bodies, ν = 0, frictionless): elastic up to δ_y = σ_c (H1 + H2)/E, then the force stays
  σ_c A while the interface crushes by δ − δ_y, uniformly; unloading is elastic from the
  crushed shape, and re-loading crushes again only past the previous depth. Round-off
  tolerances (1e-12), 2D and 3D, matching node–node and non-matching surface–surface.
* The same bodies under a pressure: below σ_c the interface carries it; above, there is no
  equilibrium, and the error says so.
* An elastic bar with a crushable end hitting a rigid wall, against its 1D solution
  (§3): crush depth, contact duration and rebound within 1 % (2 % for the rebound of the
  three-interval case) at the stated meshes; the force stays σ_c A while the end crushes;
  the energy account closes to 1e-10 with both dissipations ≥ 0 at every step; impulse
  equals the change of momentum to round-off; two ranks give the serial answer (1e-10).
"""
import math

import numpy as np
import pytest
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.errors import InputError, SolveError
from flexcontact.meshes import patch, tags

from conftest import on_two_ranks
import crush_bar_case as bar
from flexcontact.crush_watch import CHATTER_RATE

SIGMA_C = 30e6           # [Pa]
STEEL = forms.Material(E_Pa=200e9, nu=0.0, name="steel")


def _patch(dim, pairing, matching, pressure=False, contact_operator="dense"):
    """The patch-test bodies, one material, ν = 0, frictionless and crushable; the top
    pushed down by a prescribed displacement, or loaded by a pressure (upper body then held
    only by contact). Returns (problem, load setter, geometry)."""
    import dolfinx
    sizes = dict(h_lower=0.02, h_upper=0.03) if dim == 3 else dict(h_lower=0.012, h_upper=0.02)
    msh, cells, facets, geo = patch.build(MPI.COMM_WORLD, dim=dim, matching=matching, **sizes)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    kind = "3d" if dim == 3 else "plane_strain"
    a = forms.elasticity_form(u, v, {tags.BASE: STEEL, tags.UPPER: STEEL}, dx, kind)
    vert = dim - 1
    bcs, _ = fc.dirichlet(V, facets, tags.FIXED, components=[vert])
    for tag, comp in ((tags.SYMMETRY_X, 0), (tags.SYMMETRY_Y, 1))[:dim - 1]:
        bcs += fc.dirichlet(V, facets, tag, components=[comp])[0]
    itf = fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=0.0,
                              pairing=pairing, crushing_strength_Pa=SIGMA_C)
    bodies = (cells, {"lower": tags.BASE, "upper": tags.UPPER})
    if pressure:
        p = dolfinx.fem.Constant(msh, 0.0)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=facets)
        L = -p * ufl.dot(ufl.FacetNormal(msh), v) * ds(tags.LOADED)
        problem = fc.ContactProblem(a, L, bcs, itf, bodies=bodies, floating=True)

        def load(value):
            p.value = value
        return problem, load, geo
    top, (top_v,) = fc.dirichlet(V, facets, tags.LOADED, components=[vert])
    problem = fc.ContactProblem(a, None, bcs + top, itf, bodies=bodies,
                                contact_operator=contact_operator)

    def load(value):
        top_v.value = -value
    return problem, load, geo


@pytest.mark.parametrize("dim, pairing, matching, operator",
                         [(2, "node_to_node", True, "dense"),
                          (3, "node_to_node", True, "dense"),
                          (2, "surface_to_surface", False, "dense"),
                          (3, "surface_to_surface", False, "dense"),
                          (2, "node_to_node", True, "factor"),
                          (3, "surface_to_surface", False, "factor")])
def test_block_pressed_past_yield_crushes_uniformly(dim, pairing, matching, operator):
    """The dense operator and the factor path (working set of W's columns) alike."""
    problem, push, geo = _patch(dim, pairing, matching, contact_operator=operator)
    yield_m = SIGMA_C * (geo["lower_height"] + geo["upper_height"]) / STEEL.E_Pa
    force_c = SIGMA_C * geo["area"]
    depth = 0.0
    # (displacement / δ_y): elastic, crush, unload, open, re-load short of the previous
    # depth, crush further.
    for ratio in (0.5, 2.0, 1.5, 0.2, 1.8, 3.0):
        push(ratio * yield_m)
        s = problem.solve(1, verbose=False)[-1]
        inc = problem.increments[-1]
        depth = max(depth, (ratio - 1.0) * yield_m)
        # Elastic from the crushed shape: the force of the displacement left after δ.
        expected = force_c * min(max(ratio - depth / yield_m, 0.0), 1.0)
        assert s.normal_force == pytest.approx(expected, rel=1e-12, abs=1e-12 * force_c)
        if MPI.COMM_WORLD.rank == 0:
            pr = problem.pairs
            pressure = inc.lam[:, 0] / pr.tributary
            assert np.abs(pressure - expected / geo["area"]).max() <= 1e-11 * SIGMA_C
            assert np.abs(inc.crush_depth - depth).max() <= 1e-12 * yield_m
            crushing = ratio - 1.0 >= depth / yield_m - 1e-12
            assert (inc.states == fc.states.CRUSH).all() == crushing
        assert s.crush_depth_max_m == pytest.approx(depth, rel=1e-12, abs=1e-18)


def test_pressure_above_the_crushing_strength_has_no_equilibrium():
    problem, pressure, geo = _patch(2, "node_to_node", True, pressure=True)
    pressure(0.9 * SIGMA_C)
    s = problem.solve(1, verbose=False)[-1]
    assert s.normal_force == pytest.approx(0.9 * SIGMA_C * geo["area"], rel=1e-12)
    pressure(1.01 * SIGMA_C)
    with pytest.raises(SolveError, match="no equilibrium.*crushable contact forces can carry"):
        problem.solve(1, verbose=False)
    # What was computed before stays.
    assert len(problem.increments) == 1


@pytest.mark.parametrize("value, words", [(0.0, "> 0"), (-1e6, "> 0"), (float("nan"), "> 0"),
                                          ("30 MPa", "real number"), (True, "real number")])
def test_bad_crushing_strength_is_named(value, words):
    with pytest.raises(InputError, match=f"crushing_strength_Pa=.*{words}"):
        fc.ContactInterface(None, slave=1, master=2, mu=0.0, name="log end",
                            crushing_strength_Pa=value)


# ---- the bar with a crushable end -------------------------------------------------------

def _checks(r, ex, tol_rebound):
    """The model run r against the 1D solution ex."""
    two_l_c = 2 * bar.L / bar.C
    force_c = r["sigma_c"] * bar.H
    t, F = r["t"], r["force"]
    # Crush depth and duration of contact.
    assert r["depth"][-1] == pytest.approx(ex["delta"], rel=0.01)
    touching = t[F > 0]
    assert touching[-1] - touching[0] + r["dt"] == pytest.approx(ex["duration"], rel=0.01)
    # Rebound: the bar's velocity after the contact, away from the wall.
    rebound = (r["momentum"][-1]) / bar.MASS
    assert rebound == pytest.approx(abs(ex["u_N"]), rel=tol_rebound)
    # The force is σ_c A while the end crushes at speed v − s (first interval, away from
    # the discrete wave fronts); the mean force of every crushing interval is σ_c A.
    first = (t <= 0.99 * two_l_c)
    assert np.abs(F[first] / force_c - 1.0).max() <= 1e-12
    for n in range(1, ex["N"] + 1):
        span = (t > (n - 1) * two_l_c) & (t <= n * two_l_c)
        assert F[span].mean() == pytest.approx(force_c, rel=0.01)
        # Depth at the end of interval n: (2L/c) Σ_{i ≤ n} (v − (2i − 1) s).
        at = np.searchsorted(t, n * two_l_c * (1 - 1e-9))
        expected = two_l_c * sum(bar.V0 - (2 * i - 1) * ex["s"] for i in range(1, n + 1))
        assert r["depth"][at] == pytest.approx(expected, rel=0.01)
    # Energy: the crushing dissipation is σ_c times the crushed volume (to the solver's
    # tolerance on the capped impulses), and close to ½ m (v² − u_N²).
    assert r["crushing"][-1] == pytest.approx(r["sigma_c"] * r["volume"][-1], rel=1e-8)
    assert force_c * r["depth"][-1] == pytest.approx(
        0.5 * bar.MASS * (bar.V0 ** 2 - ex["u_N"] ** 2), rel=0.01)
    assert np.abs(r["balance"]).max() <= 1e-10 * r["initial"]
    assert (np.diff(r["crushing"]) >= 0).all()
    assert (np.diff(r["contact"]) >= -1e-12 * r["initial"]).all()
    # Impulse = change of momentum (the bar's, along the bar), to the round-off that the
    # internal forces' zero sum leaves at each of the 1,000–2,400 steps (1.8e-11 measured).
    dp = r["momentum"][-1] - r["momentum0"]
    assert r["impulse"].sum() == pytest.approx(dp, rel=1e-10)


@pytest.mark.parametrize("ratio, n, tol_rebound", [(0.37, 100, 0.01), (0.18, 200, 0.02)])
def test_bar_with_crushable_end_matches_the_1d_solution(ratio, n, tol_rebound):
    """s/v = 0.37: one crushing interval, then elastic contact and rebound at v − 2s;
    s/v = 0.18: three intervals, then separation at 6L/c (v/s away from the integers where
    the duration jumps)."""
    ex = bar.exact(ratio)
    assert ex["N"] == (1 if ratio == 0.37 else 3)
    r = bar.run(ratio, n)
    _checks(r, ex, tol_rebound)
    # The end crushes as one at θ = ½: the chatter watch stays quiet (crush_watch.py).
    # Measured: no flip in 803 capped pair-steps (s/v = 0.37), 14 in 4,777 (0.18).
    flips, capped = r["chatter"]
    assert flips < CHATTER_RATE * capped


def test_bar_below_the_threshold_is_the_uncapped_history():
    """ρ c v ≤ 0.9 σ_c: the cap never binds, and every step equals the uncapped run. At
    Courant number 1 the discrete wave front's first step overshoots ρ c A v by 8 % (by 28 %
    at 0.5, which would reach the cap), so this runs at 1."""
    capped = bar.run(1.0 / 0.9, 50, extra_periods=0.5, courant=1.0)
    plain = bar.run(1.0 / 0.9, 50, crushing=False, extra_periods=0.5, courant=1.0)
    assert capped["crush"].max() == 0 and capped["depth"].max() == 0.0
    scale = np.abs(plain["force"]).max()
    assert np.abs(capped["force"] - plain["force"]).max() <= 1e-12 * scale
    assert np.abs(capped["momentum"] - plain["momentum"]).max() <= 1e-12 * bar.MASS * bar.V0


@pytest.mark.mpi
def test_crushing_bar_two_ranks_equal_serial(tmp_path):
    serial = bar.run(0.37, 40)
    on_two_ranks(bar.__file__, 0.37, 40, tmp_path / "two.npz")
    two = np.load(tmp_path / "two.npz")
    scale = np.abs(serial["force"]).max()
    assert two["force"].shape == serial["force"].shape
    assert np.abs(two["force"] - serial["force"]).max() <= 1e-10 * scale
    assert two["depth"][-1] == pytest.approx(serial["depth"][-1], rel=1e-10)


def test_crushing_at_the_zone_edge_warns():
    """A rigid circle pressed into a block whose candidate zone is narrower than the
    crushed patch: the pairs at the zone's open edge crush (state crush), and the interface
    warns as contact there does (ContactZoneWarning, the increment kept)."""
    import warnings

    from demo_runner import R_HERTZ
    from flexcontact.states import CRUSH
    from rigid_block_case import rigid_block
    # σ_c far below the Hertz pressure: the whole zone crushes at a modest approach.
    problem, circle, geo = rigid_block(1.0, "crushable", crushing_strength_Pa=1e6)
    w = geo["w"]
    circle.displacement_m = np.array([0.0, -(1.5 * w) ** 2 / R_HERTZ])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", fc.ContactZoneWarning)
        inc = problem.step()
    assert inc.summary.zone_edge == ["crushable"]
    assert (inc.states == CRUSH).sum() == len(inc.states)
    if MPI.COMM_WORLD.rank == 0:
        assert any(issubclass(c.category, fc.ContactZoneWarning)
                   and "crushable: increment 1" in str(c.message) for c in caught)
