"""Friction history when pairs are re-made as slave points move onto other master facets.

An aluminium block is pressed onto a steel base (node–surface or surface–surface pairs), then its top is pushed
sideways short of gross slip: the block's edges slip, its middle sticks (partial slip, the
flat-punch analogue of Cattaneo–Mindlin). The base's candidate patch has the block's node
spacing but is shifted by EPS, so that every slave node sits EPS before a master node:
where the block slips by more than EPS, its nodes cross onto the next master facet during
the loading.

Reference: the same loading with the pairs of the reference positions kept
(``repair_pairs=False``): each slave node tied to the master point below it at the start.
For slips of a micrometre on a flat master the two descriptions differ only by the master's
strain times the slip (≈ 1e-4 · slip), so the friction forces must agree to far better than
the tolerances here (1e-4 μN for the total, 1e-3 of the largest pair force per pair;
measured 1.4e-5 μN and 2.0e-4 node–surface, 1.5e-5 μN and 1.8e-4 surface–surface, with 5
and 6 slave rows on other master facets at the end). A re-pairing that mis-measured the slip history (slip
counted from the new pair's reference gap instead of its gap at the current displacement)
would count the slip already made once more in the increment after a crossing.

The warm start: with λ and states carried over by slave node, the re-made pairs need as
many Newton iterations as the kept ones (measured 19 and 19 over the tangential stage for
either pairing; node–surface took 31 against 19 when every re-pairing restarted from λ = 0).
"""
import numpy as np
import pytest
import ufl
from mpi4py import MPI

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import block_on_base, tags

MU = 0.3
H = 0.005                # interface element size [m]
BLOCK = (0.1, 0.05)      # width, height [m]
EPS = 2e-7               # shift of the master nodes ahead of the slave nodes [m]
DELTA_N = 5e-6           # approach of the block's top [m]
DELTA_T = 3e-6           # final sideways displacement of the block's top [m]
N_NORMAL, N_TANGENT = 2, 6


def _master_sets(pairs):
    """The master nodes with a nonzero weight in each pair's row."""
    return [frozenset(m[w != 0].tolist()) for m, w in zip(pairs.masters, pairs.weights)]


def _run(repair_pairs, pairing):
    bw = BLOCK[0]
    msh, cells, facets, _ = block_on_base.build(
        MPI.COMM_WORLD, block=BLOCK, base=(0.3, 0.1), h=H, h_far=0.01,
        patch=(-bw / 2 - H + EPS, bw / 2 + H + EPS), patch_spacing=1.0)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    aluminium = forms.Material(E_Pa=70e9, nu=0.33, name="aluminium")
    steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: aluminium}, dx,
                              "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, (top_x, top_y) = fc.dirichlet(V, facets, tags.LOADED)
    problem = fc.ContactProblem(
        a, None, fixed + top,
        fc.ContactInterface(facets, slave=tags.SLAVE, master=tags.MASTER, mu=MU,
                            name="block/base", pairing=pairing),
        repair_pairs=repair_pairs)
    root = problem.comm.rank == 0
    masters0 = _master_sets(problem.pairs) if root else None

    def load(i, t):
        if i <= N_NORMAL:
            top_y.value = -DELTA_N * i / N_NORMAL
        else:
            top_x.value = DELTA_T * (i - N_NORMAL) / N_TANGENT

    summaries = problem.solve(N_NORMAL + N_TANGENT, load=load, verbose=False)
    moved = sum(a != b for a, b in zip(_master_sets(problem.pairs), masters0)) if root else 0
    lam_t = np.array([inc.lam[:, 1] for inc in problem.increments]) if root else None
    return problem, summaries, moved, lam_t


@pytest.fixture(scope="module", params=["node_to_surface", "surface_to_surface"])
def runs(request):
    return _run(True, request.param), _run(False, request.param)


def test_repaired_friction_equals_fixed_pairs(runs):
    (p1, s1, moved1, lam1), (p0, s0, moved0, lam0) = runs
    assert p1.repairing and not p0.repairing
    assert p1.pairings == len(s1) + 1 and p0.pairings == 1
    assert p1.factorizations == p0.factorizations == 1
    # Partial slip throughout the tangential stage, with slave nodes on other master facets.
    for s in s1[N_NORMAL:]:
        assert s.stick > 0 and s.slip > 0, s
    N = np.array([s.normal_force for s in s1])
    T1 = np.array([s.tangential_force[0] for s in s1])
    T0 = np.array([s.tangential_force[0] for s in s0])
    assert np.abs(T1[-1]) > 0.3 * MU * N[-1]
    assert np.abs(T1[-1]) < MU * N[-1]
    if MPI.COMM_WORLD.rank == 0:
        assert moved1 >= 2 and moved0 == 0, (moved1, moved0)
        print("friction force difference / μN:", np.max(np.abs(T1 - T0) / (MU * N)),
              "per pair / largest:", np.max(np.abs(lam1 - lam0)) / np.max(np.abs(lam0)),
              "iterations:", sum(s.iterations for s in s1[N_NORMAL:]),
              sum(s.iterations for s in s0[N_NORMAL:]), "moved:", moved1)
        assert np.max(np.abs(T1 - T0) / (MU * N)) < 1e-4
        assert np.max(np.abs(lam1 - lam0)) < 1e-3 * np.max(np.abs(lam0))
    assert [s.stick for s in s1] == [s.stick for s in s0]


def test_repairing_keeps_the_warm_start(runs):
    # The solver starts each increment from the slave nodes' last λ and states: with the
    # pairs re-made it needs no more iterations than with the pairs kept.
    (_, s1, _, _), (_, s0, _, _) = runs
    it1 = sum(s.iterations for s in s1[N_NORMAL:])
    it0 = sum(s.iterations for s in s0[N_NORMAL:])
    assert it1 <= it0, (it1, it0)


def test_repair_pairs_must_be_a_bool():
    msh, cells, facets, _ = block_on_base.build(MPI.COMM_WORLD, block=BLOCK, h=H)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    steel = forms.Material(E_Pa=200e9, nu=0.3, name="steel")
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel},
                              ufl.Measure("dx", domain=msh, subdomain_data=cells),
                              "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    with pytest.raises(ValueError, match=r"repair_pairs='no'"):
        fc.ContactProblem(a, None, fixed, fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, MU),
                          repair_pairs="no")
