"""A solve with the MUMPS Schur factor split in two halves (dolfinx_ext/src/
distributed_schur.h, here on one process): condense (forward elimination onto the contact DOFs) and expand (backward
substitution from given contact values).

Checked against dense linear algebra on small elasticity problems: the condensed load is
b_c − K_ci K_ii⁻¹ b_i; condense, F* and expand give K⁻¹ b; expanding u_p,c + F* r_c after
condensing p gives K⁻¹ (p + E_c r_c) (an increment's one back-substitution); Dirichlet-held
contact DOFs; the full solve before and after; misuse as clear errors.
"""
import sys
from pathlib import Path

import numpy as np
import pytest
from petsc4py import PETSc

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_ext_flexibility import RIGHT, contact_dofs, dense, elasticity, fc, rel  # noqa: E402

TOL = 1e-12


def schur_factor(dim, n, ordering="auto", tag=None):
    msh, V, K, tags = elasticity(n, dim)
    _, dofs = contact_dofs(V, tags) if tag is None else contact_dofs(V, tags, tag)
    F, factor, info = fc.flexibility(K, dofs, "schur", ordering)
    return msh, K, dofs, np.asarray(F), factor, info


def random_vec(K, seed):
    b = K.createVecLeft()
    b.setArray(np.random.default_rng(seed).standard_normal(b.getLocalSize()))
    return b


def condensed_reference(Kd, dofs, b):
    """b_c − K_ci K_ii⁻¹ b_i by dense algebra."""
    inner = np.setdiff1d(np.arange(Kd.shape[0]), dofs)
    return b[dofs] - Kd[np.ix_(dofs, inner)] @ np.linalg.solve(Kd[np.ix_(inner, inner)],
                                                              b[inner])


@pytest.mark.parametrize("dim,n,ordering", [(2, 6, "mumps"), (2, 6, "metis"), (3, 3, "metis")])
def test_condense_expand_is_a_solve(dim, n, ordering):
    msh, K, dofs, F, factor, info = schur_factor(dim, n, ordering)
    assert info["condense"] and factor.has_condense
    Kd = dense(K)
    b = random_vec(K, 0)
    bt = factor.condense(b)
    assert bt.shape == (dofs.size,)
    assert rel(bt, condensed_reference(Kd, dofs, b.getArray())) < TOL
    x = K.createVecRight()
    factor.expand(F @ bt, x)
    x_ref = np.linalg.solve(Kd, b.getArray())
    assert rel(x.getArray(), x_ref) < TOL
    # the full solve still works after the two halves, and gives the same
    y = K.createVecRight()
    factor.solve(b, y)
    assert rel(y.getArray(), x.getArray()) < TOL
    del msh


def test_one_back_substitution_per_increment():
    """condense(p); expand(F* p̃_c + F* r_c) = K⁻¹ (p + E_c r_c): the reaction on the contact
    DOFs leaves the interior's forward elimination unchanged."""
    msh, K, dofs, F, factor, _ = schur_factor(2, 6)
    Kd = dense(K)
    p = random_vec(K, 1)
    r_c = np.random.default_rng(2).standard_normal(dofs.size)
    x = K.createVecRight()
    factor.expand(F @ factor.condense(p) + F @ r_c, x)
    rhs = p.getArray().copy()
    rhs[dofs] += r_c
    assert rel(x.getArray(), np.linalg.solve(Kd, rhs)) < TOL
    # solve, then condense and expand again: each pair stays exact
    y = K.createVecRight()
    factor.solve(p, y)
    assert rel(y.getArray(), np.linalg.solve(Kd, p.getArray())) < TOL
    q = random_vec(K, 3)
    factor.expand(F @ factor.condense(q), x)
    assert rel(x.getArray(), np.linalg.solve(Kd, q.getArray())) < TOL
    del msh


def test_held_contact_dofs_keep_their_value():
    """Contact DOFs on the clamped edge (identity rows of K): their condensed load is their
    prescribed value and F* is the identity there."""
    msh, K, dofs, F, factor, _ = schur_factor(2, 6, tag=RIGHT)
    Kd = dense(K)
    held = np.flatnonzero([np.count_nonzero(Kd[d]) == 1 for d in dofs])
    assert held.size == 2  # the bottom-right corner node
    b = random_vec(K, 4)
    bt = factor.condense(b)
    assert np.array_equal(bt[held], b.getArray()[dofs[held]])
    assert np.array_equal(F[np.ix_(held, held)], np.eye(2))
    x = K.createVecRight()
    factor.expand(F @ bt, x)
    assert rel(x.getArray(), np.linalg.solve(Kd, b.getArray())) < TOL
    del msh


def test_misuse_raises():
    msh, K, dofs, F, factor, _ = schur_factor(2, 4)
    x = K.createVecRight()
    with pytest.raises(RuntimeError, match="no condense"):
        factor.expand(np.zeros(dofs.size), x)
    b = random_vec(K, 5)
    factor.condense(b)
    with pytest.raises(ValueError, match="u_c must hold the"):
        factor.expand(np.zeros(3), x)
    factor.expand(np.zeros(dofs.size), x)
    with pytest.raises(RuntimeError, match="no condense"):  # one expansion per condensation
        factor.expand(np.zeros(dofs.size), x)
    factor.condense(b)
    factor.solve(b, x)  # a full solve replaces the kept elimination
    with pytest.raises(RuntimeError, match="no condense"):
        factor.expand(np.zeros(dofs.size), x)
    short = PETSc.Vec().createSeq(3)
    with pytest.raises(ValueError, match="b has 3 rows"):
        factor.condense(short)
    factor.destroy()
    with pytest.raises(RuntimeError, match="destroyed"):
        factor.condense(b)
    del msh


@pytest.mark.parametrize("method", ["inverse_entries", "matmatsolve"])
def test_other_methods_give_a_plain_factor(method):
    msh, V, K, tags = elasticity(4, 2)
    _, dofs = contact_dofs(V, tags)
    _, factor, info = fc.flexibility(K, dofs, method)
    assert isinstance(factor, PETSc.Mat) and not getattr(factor, "has_condense", False)
    assert info["condense"] is False
    del msh
