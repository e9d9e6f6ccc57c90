"""Tests of flexcontact.forms: materials, stresses, stiffness, mass and load forms."""
import os
import sys

import numpy as np
import pytest
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc  # noqa: F401  (0.5: submodule import needed)
from dolfinx import fem, mesh

import flexcontact.forms as forms
from flexcontact import compat

Material = forms.Material
STEEL = Material(210e9, 0.3, 7850.0, name="steel")


def _cell_values(msh, expr):
    """Values of a UFL expression at the cell midpoints, (cells, ...) array."""
    tdim = msh.topology.dim
    pt = np.full((1, tdim), 1.0 / (tdim + 1))
    e = fem.Expression(expr, pt)
    ncell = msh.topology.index_map(tdim).size_local
    return compat.eval_expression(e, msh, np.arange(ncell, dtype=np.int32)).reshape(ncell, -1)


def _solve(a, L, bcs):
    problem = compat.linear_problem(a, L, bcs, {"ksp_type": "preonly", "pc_type": "lu"},
                                    "forms_test_")
    return problem.solve()


def _zero_rhs(V):
    v = ufl.TestFunction(V)
    return ufl.inner(fem.Constant(V.mesh, np.zeros(V.mesh.geometry.dim)), v) * ufl.dx


def _fix(V, comp, where, value):
    Vc, _ = V.sub(comp).collapse()
    dofs = fem.locate_dofs_geometrical((V.sub(comp), Vc), where)
    uc = fem.Function(Vc)
    uc.x.array[:] = value
    return fem.dirichletbc(uc, dofs, V.sub(comp))


# --- Material ---------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, word", [
    (dict(E_Pa=-1.0, nu=0.3), "E_Pa=-1.0"),
    (dict(E_Pa=float("inf"), nu=0.3), "E_Pa=inf"),
    (dict(E_Pa=1e9, nu=0.5), "nu=0.5"),
    (dict(E_Pa=1e9, nu=-1.0), "nu=-1.0"),
    (dict(E_Pa=1e9, nu=0.2, rho_kg_m3=-5.0), "rho_kg_m3=-5.0"),
])
def test_material_validation_names_parameter_value_and_material(kwargs, word):
    with pytest.raises(ValueError) as err:
        Material(**kwargs, name="concrete")
    assert word in str(err.value) and "concrete" in str(err.value)


def test_material_lame_constants():
    m = Material(200e9, 0.25)
    mu, lmbda = m.lame("3d")
    assert mu == pytest.approx(80e9) and lmbda == pytest.approx(80e9)
    _, lps = m.lame("plane_stress")
    assert lps == pytest.approx(2 * mu * lmbda / (lmbda + 2 * mu))
    with pytest.raises(ValueError, match="kind='2d'"):
        m.lame("2d")
    e_star = forms.effective_modulus(m, m)
    assert e_star == pytest.approx(0.5 * 200e9 / (1 - 0.25 ** 2))


# --- stress patches ------------------------------------------------------------------------

def test_uniaxial_stress_patch_plane_stress():
    """Unit square pulled in x, free lateral contraction: σ_xx = E ε, all else zero."""
    msh = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4, mesh.CellType.triangle)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    eps0 = 1e-3
    bcs = [_fix(V, 0, lambda x: np.isclose(x[0], 0.0), 0.0),
           _fix(V, 0, lambda x: np.isclose(x[0], 1.0), eps0),
           _fix(V, 1, lambda x: np.isclose(x[0], 0.0) & np.isclose(x[1], 0.0), 0.0)]
    a = forms.elasticity_form(u, v, STEEL, kind="plane_stress")
    uh = _solve(a, _zero_rhs(V), bcs)
    s = _cell_values(msh, forms.sigma(uh, STEEL, "plane_stress"))
    E = STEEL.E_Pa
    assert np.allclose(s[:, 0], E * eps0, rtol=1e-10)
    assert np.allclose(s[:, 1:], 0.0, atol=1e-10 * E * eps0)
    vm = _cell_values(msh, forms.von_mises(uh, STEEL, "plane_stress"))
    s1 = _cell_values(msh, forms.max_principal_stress(uh, STEEL, "plane_stress"))
    assert np.allclose(vm, E * eps0, rtol=1e-10) and np.allclose(s1, E * eps0, rtol=1e-10)
    # the exact field, lateral contraction −ν ε included
    exact = fem.Function(V)
    exact.interpolate(lambda x: np.vstack([eps0 * x[0], -STEEL.nu * eps0 * x[1]]))
    assert np.allclose(uh.x.array, exact.x.array, atol=1e-12)


def test_oedometer_plane_strain_equals_3d():
    """Laterally confined compression: the plane-strain 2D solution equals the 3D one with
    ε_zz = 0 imposed, σ_zz included."""
    m = Material(30e9, 0.2, name="concrete")
    d = 1e-4
    lam, mu = m.lmbda_Pa, m.mu_Pa
    results = {}
    for kind, msh in [("plane_strain", mesh.create_unit_square(MPI.COMM_WORLD, 3, 3)),
                      ("3d", mesh.create_unit_cube(MPI.COMM_WORLD, 2, 2, 2))]:
        gdim = msh.geometry.dim
        V = compat.vector_space(msh)
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        bcs = [_fix(V, 0, lambda x: np.isclose(x[0], 0.0) | np.isclose(x[0], 1.0), 0.0),
               _fix(V, 1, lambda x: np.isclose(x[1], 0.0), 0.0),
               _fix(V, 1, lambda x: np.isclose(x[1], 1.0), -d)]
        if gdim == 3:
            bcs.append(_fix(V, 2, lambda x: np.isclose(x[2], 0.0) | np.isclose(x[2], 1.0), 0.0))
        uh = _solve(forms.elasticity_form(u, v, m, kind=kind), _zero_rhs(V), bcs)
        s3 = _cell_values(msh, forms.stress_3x3(uh, m, kind))
        results[kind] = (s3, _cell_values(msh, forms.von_mises(uh, m, kind)))
    expect = np.array([[-lam * d, 0, 0], [0, -(lam + 2 * mu) * d, 0], [0, 0, -lam * d]]).ravel()
    for kind, (s3, vm) in results.items():
        assert np.allclose(s3, expect, atol=1e-9 * abs(expect).max()), kind
    assert np.allclose(results["plane_strain"][1], results["3d"][1][0], rtol=1e-10)
    # σ_zz = ν (σ_xx + σ_yy) in plane strain
    s = results["plane_strain"][0][0]
    assert s[8] == pytest.approx(m.nu * (s[0] + s[4]), rel=1e-12)


def test_max_principal_3d_matches_eigenvalues():
    msh = mesh.create_unit_cube(MPI.COMM_WORLD, 1, 1, 1)
    V = compat.vector_space(msh)
    rng = np.random.default_rng(1)
    for grad in [rng.normal(size=(3, 3)) * 1e-3, np.eye(3) * 1e-3, np.zeros((3, 3))]:
        uh = fem.Function(V)
        uh.interpolate(lambda x: grad @ x)
        eps = 0.5 * (grad + grad.T)
        sig = 2 * STEEL.mu_Pa * eps + STEEL.lmbda_Pa * np.trace(eps) * np.eye(3)
        s1 = _cell_values(msh, forms.max_principal_stress(uh, STEEL, "3d"))
        assert np.all(np.isfinite(s1))
        assert np.allclose(s1, np.linalg.eigvalsh(sig)[-1], atol=1e-9 * max(1.0, abs(sig).max()))
        dev = sig - np.trace(sig) / 3 * np.eye(3)
        vm = _cell_values(msh, forms.von_mises(uh, STEEL, "3d"))
        assert np.allclose(vm, np.sqrt(1.5 * np.sum(dev * dev)), atol=1e-6)


def test_kind_dimension_mismatch():
    msh = mesh.create_unit_square(MPI.COMM_WORLD, 1, 1)
    V = compat.vector_space(msh)
    u = ufl.TrialFunction(V)
    with pytest.raises(ValueError, match="kind='3d'"):
        forms.sigma(u, STEEL, "3d")
    with pytest.raises(ValueError, match="kind='axisym'"):
        forms.sigma(u, STEEL, "axisym")


# --- multi-material forms -------------------------------------------------------------------

def _two_material_square():
    msh = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    tdim = msh.topology.dim
    n = msh.topology.index_map(tdim).size_local
    cells = np.arange(n, dtype=np.int32)
    mid = mesh.compute_midpoints(msh, tdim, cells)
    values = np.where(mid[:, 0] < 0.5, 1, 2).astype(np.int32)
    return msh, mesh.meshtags(msh, tdim, cells, values)


def test_elasticity_form_two_materials_energy():
    msh, ct = _two_material_square()
    V = compat.vector_space(msh)
    mats = {1: Material(1e9, 0.25, name="soft"), 2: Material(3e9, 0.1, name="stiff")}
    grad = np.array([[1e-3, 2e-4], [-1e-4, 5e-4]])
    uh = fem.Function(V)
    uh.interpolate(lambda x: grad @ x[:2])
    eps = 0.5 * (grad + grad.T)

    def energy(m, kind):
        mu, lam = m.lame(kind)
        sig = 2 * mu * eps + lam * np.trace(eps) * np.eye(2)
        return 0.5 * np.sum(sig * eps)  # half of the two halves' unit area

    for kind in ("plane_strain", "plane_stress"):
        expect = sum(energy(m, kind) for m in mats.values())
        a1 = forms.elasticity_form(uh, uh, mats, kind=kind, cell_tags=ct)
        e1 = fem.assemble_scalar(fem.form(a1))
        mu, lam = forms.lame_fields(msh, ct, mats)
        e2 = fem.assemble_scalar(fem.form(forms.elasticity_form(uh, uh, (mu, lam), kind=kind)))
        assert msh.comm.allreduce(e1) == pytest.approx(expect, rel=1e-12)
        assert msh.comm.allreduce(e2) == pytest.approx(expect, rel=1e-12)


def test_elasticity_form_missing_material():
    msh, ct = _two_material_square()
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    with pytest.raises(ValueError, match=r"cell tags \[2\]"):
        forms.elasticity_form(u, v, {1: STEEL}, kind="plane_strain", cell_tags=ct)
    with pytest.raises(ValueError, match=r"cell tags \[2\]"):
        forms.lame_fields(msh, ct, {1: STEEL})


# --- loads and mass ---------------------------------------------------------------------------

def _resultant(L, V):
    """Σ of the assembled load vector per component (N, per m of thickness in 2D)."""
    b = fem.petsc.assemble_vector(fem.form(L))
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    n = V.dofmap.index_map.size_local * 2
    local = b.array[:n].reshape(-1, 2).sum(axis=0)
    return V.mesh.comm.allreduce(local)


def test_loads_resultants():
    msh = mesh.create_rectangle(MPI.COMM_WORLD, [[0, 0], [2, 1]], [8, 4])
    V = compat.vector_space(msh)
    v = ufl.TestFunction(V)
    concrete = Material(30e9, 0.2, 2400.0, name="concrete")
    fy = _resultant(forms.gravity(v, concrete, ufl.dx), V)
    assert fy == pytest.approx([0.0, -2400.0 * 9.81 * 2.0])
    fdim = msh.topology.dim - 1
    left = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[0], 0.0))
    ft = mesh.meshtags(msh, fdim, left, np.full(len(left), 5, dtype=np.int32))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=ft)
    # water up to y = 0.5 against the left face pushes in +x: ρ g h²/2 (exact for P1: the
    # pressure is linear and the kink at the water level sits on a node)
    fh = _resultant(forms.hydrostatic_pressure(v, ds(5), level=0.5), V)
    assert fh == pytest.approx([1000 * 9.81 * 0.5 ** 2 / 2, 0.0])
    ft_ = _resultant(forms.surface_traction(v, (0.0, -1e5), ds(5)), V)
    assert ft_ == pytest.approx([0.0, -1e5 * 1.0])


def test_mass_form_total_mass():
    msh, ct = _two_material_square()
    V = compat.vector_space(msh)
    one = fem.Function(V)
    one.interpolate(lambda x: np.vstack([np.ones(x.shape[1]), np.zeros(x.shape[1])]))
    mats = {1: Material(1e9, 0.2, 1000.0), 2: Material(1e9, 0.2, 3000.0)}
    dx = ufl.Measure("dx", domain=msh, subdomain_data=ct)
    m = fem.assemble_scalar(fem.form(forms.mass_form(one, one, mats, dx)))
    assert msh.comm.allreduce(m) == pytest.approx(0.5 * 1000 + 0.5 * 3000)
    m1 = fem.assemble_scalar(fem.form(forms.mass_form(one, one, 7.0, ufl.dx(domain=msh))))
    assert msh.comm.allreduce(m1) == pytest.approx(7.0)
