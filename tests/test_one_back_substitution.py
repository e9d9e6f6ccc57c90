"""An increment with the serial Schur factor is one back-substitution: p condensed onto the
contact DOFs before the contact solve, u expanded from u_p,c + F* r_c after it
(ContactProblem.step with DistributedSchur.condense/expand). The reference is the same problem
solved with the factor's two full solves (u_p = K⁻¹ p, then u = K⁻¹ (p + Bᵀ λ)), through
the same factor as a plain petsc4py Mat: a rigid target (virtual DOFs, re-pairing), a body
held only by contact (K⁺ and its rigid modes) and two deformable bodies pressed by a
prescribed displacement.
"""
import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent))
from demo_runner import A_TARGET, R_HERTZ  # noqa: E402
from test_node_surface import _hertz2d_problem, _rigid_block  # noqa: E402
from test_pushed_block import MU, N, _block  # noqa: E402

from flexcontact.meshes import hertz2d, tags  # noqa: E402

TOL = 1e-10
serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="a serial comparison (two ranks: test_mpi_schur.py)")


class _FullSolves:
    """The factor seen through its full solve only: two solves per increment."""

    def __init__(self, factor):
        self._factor = factor

    def solve(self, b, x):
        self._factor.solve(b, x)


def _pair(build):
    """The problem twice: once splitting its increments, once with two full solves."""
    split, ref = build(), build()
    assert getattr(split[0].factor, "has_condense", False)
    ref[0].factor = _FullSolves(ref[0].factor)
    assert not getattr(ref[0].factor, "has_condense", False)
    return split, ref


def _same(a, b):
    ua, ub = a.u.x.array, b.u.x.array
    assert np.linalg.norm(ua - ub) <= TOL * np.linalg.norm(ub)


def _same_increment(ia, ib):
    assert np.allclose(ia.lam, ib.lam, rtol=0, atol=TOL * np.abs(ib.lam).max())
    assert np.array_equal(ia.states, ib.states)


@serial
def test_rigid_target():
    (a, circle_a, geo), (b, circle_b, _) = _pair(lambda: _rigid_block(3.0, "ignore"))
    w = geo["w"]
    for depth in (0.3, 1.0):   # the second increment re-pairs at the first's displacement
        for c in (circle_a, circle_b):
            c.displacement_m = np.array([0.0, -depth * w**2 / R_HERTZ])
        _same_increment(a.step(), b.step())
        _same(a, b)
    assert a.increments[-1].summary.normal_force > 0


@serial
def test_body_held_only_by_contact():
    (a, traction_a, width), (b, traction_b, _) = _pair(_block)
    for f in (0.3, 0.6):       # partial slip under Q = f μN
        for t in (traction_a, traction_b):
            t.value = np.array([f * MU * N / width, -N / width])
        _same_increment(a.step(), b.step())
        _same(a, b)
        assert np.allclose(a.increments[-1].alpha, b.increments[-1].alpha,
                           rtol=0, atol=TOL * np.abs(b.increments[-1].alpha).max())


@serial
def test_two_bodies_pressed_by_a_displacement():
    def build():
        msh, cells, facets, _ = hertz2d.build(MPI.COMM_WORLD, R=R_HERTZ, a_expected=A_TARGET)
        return _hertz2d_problem(msh, cells, facets, slave=tags.SLAVE, master=tags.MASTER,
                                pairing="node_to_surface")
    (a, top_a), (b, top_b) = _pair(build)
    for d in (-0.5, -1.0):
        for top in (top_a, top_b):
            top.value = d * A_TARGET**2 / R_HERTZ
        _same_increment(a.step(), b.step())
        _same(a, b)
    assert a.increments[-1].summary.normal_force > 0
