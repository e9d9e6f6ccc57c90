"""The fill-reducing ordering of the MUMPS factorization (dolfinx_ext/src/ordering.h).

F* and the factor's solves must not depend on the ordering: each ordering's F* is checked
against the old default (MUMPS's automatic choice) and against the dense inverse of K, and
MUMPS must report (INFOG(7)) the ordering asked for. Which ordering is cheapest is measured
by bench/ordering.py, not here.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_ext_flexibility import contact_dofs, dense, elasticity, fc, rel  # noqa: E402

from flexcontact.names import ORDERINGS, check_ordering  # noqa: E402

ORDERED = ["metis", "amd", "amf", "pord", "qamd"]


@pytest.fixture(scope="module")
def box3d():
    """A small 3D box (6³ cells, 1,029 DOFs) and its top-face contact DOFs. The mesh stays
    alive until the module's tests end: on DOLFINx 0.9, K's communicator is the mesh's and
    is freed with it, so PETSc could create no object on it afterwards."""
    msh, V, K, tags = elasticity(6, 3)
    _, dofs = contact_dofs(V, tags)
    yield K, dofs
    del msh


@pytest.mark.parametrize("method", ["schur", "inverse_entries", "matmatsolve"])
def test_metis_flexibility_equals_mumps_ordering(box3d, method):
    """F* with the METIS ordering equals F* with MUMPS's own choice (the former default)
    to 1e-10 relative, and the dense inverse of K likewise."""
    K, dofs = box3d
    F_metis, _, info = fc.flexibility(K, dofs, method, "metis")
    F_mumps, _, info_mumps = fc.flexibility(K, dofs, method, "mumps")
    assert info["ordering"] == "metis" and info["mumps_ordering"] == "metis"
    assert info_mumps["ordering"] == "mumps" and info_mumps["mumps_ordering"] != "metis"
    assert rel(F_metis, F_mumps) < 1e-10
    Fd = np.linalg.inv(dense(K))[np.ix_(dofs, dofs)]
    assert rel(F_metis, Fd) < 1e-10


@pytest.mark.parametrize("ordering", ORDERED)
def test_each_ordering_is_used_and_exact(box3d, ordering):
    """The plain factor uses the ordering asked for; with a Schur complement MUMPS replaces
    AMF, PORD and QAMD by AMD; F* is the same whatever the order."""
    K, dofs = box3d
    F_ref, _, _ = fc.flexibility(K, dofs, "matmatsolve", "mumps")
    F, _, info = fc.flexibility(K, dofs, "inverse_entries", ordering)
    assert info["mumps_ordering"] == ordering
    assert rel(F, F_ref) < 1e-10
    F_schur, _, info_schur = fc.flexibility(K, dofs, "schur", ordering)
    assert info_schur["mumps_ordering"] == ("metis" if ordering == "metis" else "amd")
    assert rel(F_schur, F_ref) < 1e-10
    # the statistics MUMPS reports: a factor at least as large as K's lower triangle
    n = K.getSize()[0]
    nnz_lower = (K.getInfo()["nz_used"] + n) / 2
    assert info["factor_entries"] >= nnz_lower
    assert info["factor_flops"] > 0 and info["factor_memory_mb"] > 0
    assert 0 <= info["ordering_s"] <= info["factorization_s"]


@pytest.mark.parametrize("dim,n", [(2, 8), (3, 4)])
def test_metis_factor_solves_with_K(dim, n):
    """The Schur-enabled factor with the METIS order (Schur variables last) solves K x = b."""
    msh, V, K, tags = elasticity(n, dim)
    _, dofs = contact_dofs(V, tags)
    _, factor, info = fc.flexibility(K, dofs, "schur", "metis")
    assert info["mumps_ordering"] == "metis"
    Kd = dense(K)
    b = K.createVecLeft()
    b.setArray(np.random.default_rng(3).standard_normal(b.getLocalSize()))
    x = K.createVecRight()
    factor.solve(b, x)
    assert rel(x.getArray(), np.linalg.solve(Kd, b.getArray())) < 1e-10


def test_no_contact_dofs_with_metis():
    msh, V, K, tags = elasticity(4, 3)
    F, factor, info = fc.flexibility(K, np.zeros(0, np.int64), "schur", "metis")
    assert F.shape == (0, 0) and info["mumps_ordering"] == "metis"


def test_unknown_ordering_raises():
    msh, V, K, tags = elasticity(3, 2)
    with pytest.raises(ValueError, match="unknown ordering 'nd'"):
        fc.flexibility(K, np.array([0], np.int64), "schur", "nd")
    with pytest.raises(ValueError, match="unknown ordering 'scotch'"):
        check_ordering("scotch")
    assert set(ORDERINGS) == {"auto", "mumps", *ORDERED}


@pytest.mark.parametrize("dim,n,schur,expected", [(3, 3, True, "metis"), (3, 3, False, "metis"),
                                                   (2, 6, True, "mumps"), (2, 6, False, "mumps"),
                                                   (2, 230, True, "metis")])
def test_auto_is_metis_in_3d_and_for_large_schur_factors(dim, n, schur, expected):
    """The default "auto" orders 3D elasticity (block size 3) with METIS, and a 2D factor
    with a Schur complement from 100,000 DOFs on (230² squares: 106,722 DOFs); smaller or
    plain 2D factors with MUMPS's choice."""
    msh, V, K, tags = elasticity(n, dim)
    _, dofs = contact_dofs(V, tags)
    _, _, info = fc.flexibility(K, dofs if schur else dofs[:0])
    assert info["ordering"] == expected
    assert (info["mumps_ordering"] == "metis") == (expected == "metis")
    # Every supported PETSc generation takes our ordering: no fallback to MUMPS's own.
    assert info["ordering_fallback"] == ""
