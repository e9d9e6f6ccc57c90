"""F* and the solves from MUMPS driven directly on two ranks (dolfinx_ext/src/distributed_schur.h).

With `mpirun -n 2` the default "schur" runs one MUMPS instance on the ranks' rows of K with
a Schur complement on the contact DOFs centralised on rank 0. Run under mpirun, this file
writes what the two ranks computed together with K (in the two-rank run's global numbering);
the tests then compute the references on one process from that same K: PETSc's serial MUMPS
(F*, K⁻¹b) and dense algebra (the condensed right-hand side b_c − K_ci K_ii⁻¹ b_i and the
expansion x_i = K_ii⁻¹ (b_i − K_ic u_c)). A whole 2D Hertz ContactProblem with friction,
run on two ranks, gives the serial displacement and contact pressure at every node.
"""
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from conftest import on_two_ranks
from test_ext_flexibility import contact_dofs, dense, elasticity

import flexcontact as fc
from flexcontact import _cpp, compat, forms
from flexcontact.meshes import hertz2d, tags

ROUNDOFF = 1e-10  # relative: the same factorization on one or two ranks, up to round-off
BOXES = [(2, 6), (3, 3)]


def rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(b)


def gather(vec: PETSc.Vec) -> np.ndarray:
    """The whole vector on every rank, in global numbering."""
    return np.concatenate(vec.getComm().tompi4py().allgather(vec.getArray().copy()))


# ---- under mpirun: the two ranks' results -----------------------------------------------
def _box_record(dim, n):
    comm = MPI.COMM_WORLD
    msh, V, K, tags_ = elasticity(n, dim)
    _, dofs = contact_dofs(V, tags_)
    F, factor, info = _cpp.flexibility(K, dofs, "schur")
    N = K.getSize()[0]
    b_all = np.random.default_rng(dim).standard_normal(N)
    r0, r1 = K.getOwnershipRange()
    b = K.createVecLeft()
    b.setArray(b_all[r0:r1])
    x = K.createVecRight()
    factor.solve(b, x)
    bc = factor.condense(b)
    n_c = comm.bcast(dofs.size if comm.rank == 0 else None)
    uc_all = np.random.default_rng(10 + dim).standard_normal(n_c)
    xe = K.createVecRight()
    factor.expand(uc_all if comm.rank == 0 else None, xe)
    out = {"K": dense(K), "dofs": comm.bcast(dofs), "b": b_all, "F": F, "x": gather(x),
           "condensed": bc, "u_c": uc_all, "expanded": gather(xe),
           "method": info["method"], "ordering": info["ordering"],
           "mumps_ordering": info["mumps_ordering"], "factor_type": type(factor).__name__,
           "has_condense": bool(factor.has_condense),
           "distributed_io": bool(factor.distributed_io)}
    # A second right-hand side through the solution scatter built by the first expansion
    b2_all = np.random.default_rng(20 + dim).standard_normal(N)
    uc2_all = np.random.default_rng(30 + dim).standard_normal(n_c)
    out.update({f"{k}2": v for k, v in _condense_expand(factor, K, b2_all, uc2_all).items()})
    # The same with b gathered on rank 0 and the solution scattered from it
    factor.distributed_io = False
    out.update({f"{k}_central": v for k, v in _condense_expand(factor, K, b_all, uc_all).items()})
    out["io_refusal"] = int(factor.io_refusal)
    try:  # several right-hand sides at once are served on one rank only
        factor.condense_many(np.zeros((N, 2)))
        out["many_refused"] = ""
    except RuntimeError as e:
        out["many_refused"] = str(e)
    factor.destroy()
    return out


def _condense_expand(factor, K, b_all, uc_all) -> dict:
    """condense(b), expand(u_c) and solve(b) with the factor as it is set (global arrays)."""
    comm = MPI.COMM_WORLD
    r0, r1 = K.getOwnershipRange()
    b, x, xe = K.createVecLeft(), K.createVecRight(), K.createVecRight()
    b.setArray(b_all[r0:r1])
    bc = factor.condense(b)
    factor.expand(uc_all if comm.rank == 0 else None, xe)
    factor.solve(b, x)
    out = {"b": b_all, "u_c": uc_all, "condensed": bc, "expanded": gather(xe), "x": gather(x)}
    for v in (b, x, xe):
        v.destroy()
    return out


def _singular_record():
    """Every rank's error for a K with rigid-body modes (no Dirichlet condition)."""
    msh, V, K, tags_ = elasticity(4, 2, clamped=False)
    _, dofs = contact_dofs(V, tags_)
    try:
        _cpp.flexibility(K, dofs, "schur")
        what = None
    except RuntimeError as e:
        what = f"{type(e).__name__}: {e}"
    return MPI.COMM_WORLD.gather(what)


def _write(folder):
    comm = MPI.COMM_WORLD
    out = {}
    for dim, n in BOXES:
        for k, v in _box_record(dim, n).items():
            out[f"{k}_{dim}"] = v
    singular = _singular_record()
    hertz = hertz_record()
    if comm.rank == 0:
        np.savez(Path(folder) / "boxes.npz", **out)
        (Path(folder) / "other.json").write_text(json.dumps({"singular": singular,
                                                              "hertz": hertz}))


# ---- a whole ContactProblem --------------------------------------------------------------
def hertz_record(increments=3, mu=0.3):
    """Small 2D Hertz (frictional, pushed down in increments): per increment the normal
    force, and at the end u and the contact pressure at every node sorted by position."""
    comm = MPI.COMM_WORLD
    R, a_m = 0.05, 0.005
    msh, cells, facets, _ = hertz2d.build(comm, R=R, a_expected=a_m, refine=0, zone_factor=1.25)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cells)
    steel = forms.Material(E_Pa=200e9, nu=0.3)
    a = forms.elasticity_form(u, v, {tags.BASE: steel, tags.UPPER: steel}, dx, "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    top, consts = fc.dirichlet(V, facets, tags.LOADED)
    problem = fc.ContactProblem(a, None, fixed + top,
                                fc.ContactInterface(facets, tags.SLAVE, tags.MASTER, mu))
    forces = []
    for i in range(1, increments + 1):
        consts[1].value = -a_m**2 / R * i / increments
        forces.append(problem.step().summary.normal_force)
    n_local = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:n_local, :2]
    uu = problem.u.x.array[:2 * n_local].reshape(-1, 2)
    Q = problem.pressure.function_space
    xp = Q.tabulate_dof_coordinates()[:Q.dofmap.index_map.size_local, :2]
    pp = problem.pressure.x.array[:Q.dofmap.index_map.size_local]
    x, uu, xp, pp = (np.concatenate(comm.allgather(a_)) for a_ in (x, uu, xp, pp))
    # Nodes sorted by position, rounded to 1e-9 m (the two ranks' meshes differ in the last
    # bits); where the two bodies touch at one point, then by the value
    x, xp = np.round(x, 9), np.round(xp, 9)
    ou = np.lexsort((uu[:, 1], x[:, 1], x[:, 0]))
    op = np.lexsort((pp, xp[:, 1], xp[:, 0]))
    return {"forces": forces, "u": uu[ou].tolist(), "pressure": pp[op].tolist(),
            "x_u": x[ou].tolist(), "x_p": xp[op].tolist(),
            "method": problem.flex_info["method"], "ranks": comm.size}


# ---- the tests (one process) -------------------------------------------------------------
@pytest.fixture(scope="module")
def two_ranks(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mpi_schur")
    on_two_ranks(__file__, folder, timeout=600)
    return np.load(folder / "boxes.npz"), json.loads((folder / "other.json").read_text())


def _serial(K_dense, bs):
    """K on one process as a PETSc AIJ matrix of block size bs (the two-rank run's
    numbering)."""
    n = K_dense.shape[0]
    rows, cols = np.nonzero(K_dense)
    indptr = np.searchsorted(rows, np.arange(n + 1)).astype(PETSc.IntType)
    K = PETSc.Mat().createAIJ([n, n], bsize=bs, csr=(indptr, cols.astype(PETSc.IntType),
                                                       K_dense[rows, cols]),
                              comm=PETSc.COMM_SELF)
    K.assemble()
    return K


@pytest.mark.mpi
@pytest.mark.parametrize("dim", [d for d, _ in BOXES])
def test_two_ranks_refuse_several_right_hand_sides_at_once_by_name(two_ranks, dim):
    assert str(two_ranks[0][f"many_refused_{dim}"]) == (
        "condense_many: the factor is distributed over 2 processes; several right-hand "
        "sides at once are served on one")


@pytest.mark.mpi
@pytest.mark.parametrize("dim", [d for d, _ in BOXES])
def test_two_ranks_schur_flexibility_equals_petsc_serial(two_ranks, dim):
    par = two_ranks[0]
    assert str(par[f"method_{dim}"]) == "schur"
    assert str(par[f"factor_type_{dim}"]) == "DistributedSchur" and par[f"has_condense_{dim}"]
    # "auto": METIS for 3D elasticity (gathered on rank 0), MUMPS's choice in 2D, as serial
    assert str(par[f"ordering_{dim}"]) == ("metis" if dim == 3 else "mumps")
    if dim == 3:
        assert str(par[f"mumps_ordering_{dim}"]) == "metis"
    K = _serial(par[f"K_{dim}"], dim)
    F, factor, info = _cpp.flexibility(K, par[f"dofs_{dim}"], "schur")
    assert info["method"] == "schur"
    assert rel(par[f"F_{dim}"], F) < ROUNDOFF
    b, x = K.createVecLeft(), K.createVecRight()
    b.setArray(par[f"b_{dim}"])
    factor.solve(b, x)
    assert rel(par[f"x_{dim}"], x.getArray()) < ROUNDOFF


def _dense_condense_expand(Kd, dofs, b, uc):
    """b̃_c = b_c − K_ci K_ii⁻¹ b_i (in the order of the contact DOFs given) and the
    expansion of u_c: x_c = u_c, x_i = K_ii⁻¹ (b_i − K_ic u_c), by dense algebra."""
    inner = np.setdiff1d(np.arange(Kd.shape[0]), dofs)
    Kii, Kic = Kd[np.ix_(inner, inner)], Kd[np.ix_(inner, dofs)]
    condensed = b[dofs] - Kic.T @ np.linalg.solve(Kii, b[inner])
    x = np.empty(Kd.shape[0])
    x[dofs] = uc
    x[inner] = np.linalg.solve(Kii, b[inner] - Kic @ uc)
    return condensed, x


@pytest.mark.mpi
@pytest.mark.parametrize("suffix", ["", "2", "_central"])
@pytest.mark.parametrize("dim", [d for d, _ in BOXES])
def test_two_ranks_condense_and_expand(two_ranks, dim, suffix):
    """Distributed right-hand side and solution (the default; "2": a second right-hand side
    through the same solution scatter) and centralised ones ("_central")."""
    par = two_ranks[0]
    assert par[f"distributed_io_{dim}"] and par[f"io_refusal_{dim}"] == 0
    Kd, dofs = par[f"K_{dim}"], par[f"dofs_{dim}"]
    b, uc = par[f"b{suffix}_{dim}"], par[f"u_c{suffix}_{dim}"]
    condensed, x = _dense_condense_expand(Kd, dofs, b, uc)
    assert rel(par[f"condensed{suffix}_{dim}"], condensed) < ROUNDOFF
    assert rel(par[f"expanded{suffix}_{dim}"], x) < ROUNDOFF
    assert rel(par[f"x{suffix}_{dim}"], np.linalg.solve(Kd, b)) < ROUNDOFF


@pytest.mark.mpi
@pytest.mark.parametrize("dim", [d for d, _ in BOXES])
def test_two_ranks_distributed_io_equals_centralised(two_ranks, dim):
    """The same factor gives the same numbers whether b and the solution pass through rank 0
    or stay on their ranks: only the order of a few sums may differ."""
    par = two_ranks[0]
    for k in ("condensed", "expanded", "x"):
        assert rel(par[f"{k}_{dim}"], par[f"{k}_central_{dim}"]) < 1e-12, k


@pytest.mark.mpi
def test_two_ranks_singular_stiffness_raises_on_every_rank(two_ranks):
    errors = two_ranks[1]["singular"]
    assert len(errors) == 2
    for e in errors:
        assert e is not None and e.startswith("SingularStiffnessError: stiffness matrix is "
                                              "singular"), e


@pytest.mark.mpi
def test_two_ranks_hertz_contact_problem_equals_serial(two_ranks):
    par = two_ranks[1]["hertz"]
    assert par["ranks"] == 2 and par["method"] == "schur"
    serial = hertz_record()
    assert serial["method"] == "schur"
    np.testing.assert_allclose(par["forces"], serial["forces"], rtol=ROUNDOFF)
    assert np.array_equal(par["x_u"], serial["x_u"]) and np.array_equal(par["x_p"], serial["x_p"])
    u, us = np.array(par["u"]), np.array(serial["u"])
    assert u.shape == us.shape and rel(u, us) < ROUNDOFF
    p, ps = np.array(par["pressure"]), np.array(serial["pressure"])
    assert np.max(ps) > 0 and rel(p, ps) < ROUNDOFF


if __name__ == "__main__":
    _write(sys.argv[1])
