"""A box of one or two materials under a prescribed displacement, read by the recovered
stress probe on a sphere around its centre. ``python3 stress_probe_case.py DIM FIELD OUT``
writes the probe's peak (run with mpirun to compare ranks)."""
import sys

import numpy as np
from mpi4py import MPI

import dolfinx.fem
import dolfinx.mesh

from flexcontact import compat
from flexcontact.dam.stress_probe import RecoveredStressProbe
from flexcontact.forms import Material

CONCRETE = Material(E_Pa=30e9, nu=0.2, rho_kg_m3=2400.0)
ROCK = Material(E_Pa=10e9, nu=0.3, rho_kg_m3=2600.0)
CENTRE, OFFSET_M = 1.0, 0.5
A = 1e-5 * np.array([[1.0, 2.0, -0.5], [0.3, -1.0, 0.2], [0.1, 0.4, 0.7]])


def box(dim, interface_x=None):
    """The box [0, 2]^dim in cells tagged 1, or 2 right of ``interface_x``, and its u."""
    comm = MPI.COMM_WORLD
    if dim == 2:
        msh = dolfinx.mesh.create_rectangle(comm, [np.zeros(2), np.full(2, 2.0)], [24, 24],
                                            dolfinx.mesh.CellType.triangle)
    else:
        msh = dolfinx.mesh.create_box(comm, [np.zeros(3), np.full(3, 2.0)], [12, 12, 12],
                                      dolfinx.mesh.CellType.tetrahedron)
    tdim = msh.topology.dim
    n = msh.topology.index_map(tdim).size_local + msh.topology.index_map(tdim).num_ghosts
    mid = compat.geometry_x(msh)[compat.geometry_dofmap(msh)[:n]].mean(axis=1)
    values = np.ones(n, dtype=np.int32)
    if interface_x is not None:
        values[mid[:, 0] > interface_x] = 2
    tags = dolfinx.mesh.meshtags(msh, tdim, np.arange(n, dtype=np.int32), values)
    return dolfinx.fem.Function(compat.vector_space(msh)), tags


def reach_x(dim, interface_x) -> float:
    """The largest x of the cells tagged 1 by :func:`box` (their centroid left of
    ``interface_x``): the interface runs through cells, so material 1 reaches past it."""
    u, tags = box(dim, interface_x)
    msh = u.function_space.mesh
    cells = tags.indices[tags.values == 1]
    x = compat.geometry_x(msh)[compat.geometry_dofmap(msh)[cells]][..., 0].max(initial=-np.inf)
    return MPI.COMM_WORLD.allreduce(float(x), op=MPI.MAX)


def stress(material, eps, kind):
    """The 3×3 stress (Pa) of the 3×3 strain ``eps`` (plane strain: ε_zz = 0)."""
    E, nu = material.E_Pa, material.nu
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    return lam * np.trace(eps) * np.eye(3) + 2 * mu * eps


def quadratic(x):
    """u = (x·x) a with a = 1e-5 (1, −2, 0.5): a strain, hence a stress, linear in x."""
    a = 1e-5 * np.array([1.0, -2.0, 0.5])
    r2 = (x * x).sum(axis=0)
    return np.vstack([a[i] * r2 for i in range(x.shape[0])])


def quadratic_strain(p):
    """ε of :func:`quadratic` at the points p (k, dim), as (k, 3, 3)."""
    dim = p.shape[1]
    a = 1e-5 * np.array([1.0, -2.0, 0.5])[:dim]
    grad = 2.0 * a[None, :, None] * p[:, None, :]   # ∂u_i/∂x_j = 2 a_i x_j
    eps = np.zeros((p.shape[0], 3, 3))
    eps[:, :dim, :dim] = 0.5 * (grad + grad.transpose(0, 2, 1))
    return eps


def probe(dim, field, interface_x=None):
    u, tags = box(dim, interface_x)
    if field == "linear":
        u.interpolate(lambda x: A[:dim, :dim] @ x[:dim])
    else:
        u.interpolate(lambda x: quadratic(x[:dim]))
    kind = "3d" if dim == 3 else "plane_strain"
    return RecoveredStressProbe(u, tags, {1: CONCRETE, 2: ROCK}, kind, np.full(dim, CENTRE),
                                OFFSET_M, 1)


if __name__ == "__main__":
    dim, field, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
    p = probe(dim, field, interface_x=1.3)
    value, where = p.peak()
    mean = p.mean()
    if MPI.COMM_WORLD.rank == 0:
        np.savez(out, value=value, where=where, mean=mean)


def flamant(cells_per_m: int, diagonal: str = "right"):
    """A tangential line load Q on a half-plane (Flamant): the box [−2, 2] × [−2, 0] m with
    Q = 1 MN/m along +x at the origin, the exact traction σ·n on its sides and bottom, and
    two corners pinned against the (zero) rigid motion. The exact stress is radial,
    σ_rr = −2Q cos φ / (π r) with φ from +x, and σ_zz = ν σ_rr in plane strain: behind the
    load the surface is in tension, the largest principal stress at distance r being
    2Q/(π r). Returns (the RecoveredStressProbe at r = OFFSET_M on the solution, that exact
    peak in Pa)."""
    import ufl
    from flexcontact.forms import sigma
    q = 1e6
    n = 2 * cells_per_m
    msh = dolfinx.mesh.create_rectangle(
        MPI.COMM_WORLD, [np.array([-2.0, -2.0]), np.array([2.0, 0.0])], [2 * n, n],
        dolfinx.mesh.CellType.triangle, diagonal=getattr(dolfinx.mesh.DiagonalType, diagonal))
    tdim = msh.topology.dim
    nc = msh.topology.index_map(tdim).size_local + msh.topology.index_map(tdim).num_ghosts
    tags = dolfinx.mesh.meshtags(msh, tdim, np.arange(nc, dtype=np.int32),
                                 np.ones(nc, np.int32))
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    x = ufl.SpatialCoordinate(msh)
    r = ufl.sqrt(ufl.dot(x, x))
    exact = -2.0 * q * x[0] / (np.pi * r * r) * ufl.outer(x / r, x / r)
    outer = dolfinx.mesh.locate_entities_boundary(
        msh, tdim - 1, lambda X: (X[1] < -2 + 1e-9) | (np.abs(X[0]) > 2 - 1e-9))
    facets = dolfinx.mesh.meshtags(msh, tdim - 1, np.sort(outer).astype(np.int32),
                                   np.ones(outer.size, np.int32))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=facets,
                     metadata={"quadrature_degree": 8})
    a = dolfinx.fem.form(ufl.inner(sigma(u, CONCRETE, "plane_strain"), ufl.sym(ufl.grad(v)))
                         * ufl.dx)
    L = dolfinx.fem.form(ufl.inner(ufl.dot(exact, ufl.FacetNormal(msh)), v) * ds(1))
    corner = dolfinx.fem.locate_dofs_geometrical(
        V, lambda X: np.isclose(X[0], -2.0) & np.isclose(X[1], -2.0))
    V1, _ = V.sub(1).collapse()
    roller = dolfinx.fem.locate_dofs_geometrical(
        (V.sub(1), V1), lambda X: np.isclose(X[0], 2.0) & np.isclose(X[1], -2.0))
    bcs = [dolfinx.fem.dirichletbc(np.zeros(2), corner, V),
           dolfinx.fem.dirichletbc(dolfinx.fem.Function(V1), roller, V.sub(1))]
    uh = _solve_with_point_force(V, a, L, bcs, 0, q)
    probe = RecoveredStressProbe(uh, tags, {1: CONCRETE}, "plane_strain", np.zeros(2),
                                 OFFSET_M, 1)
    return probe, 2.0 * q / (np.pi * OFFSET_M)


def boussinesq_principal(p, force_N: float, nu: float) -> np.ndarray:
    """Largest principal stress (Pa) of :func:`boussinesq_stress`."""
    return np.linalg.eigvalsh(boussinesq_stress(p, force_N, nu))[:, -1]


def boussinesq_stress(p, force_N: float, nu: float) -> np.ndarray:
    """Stress (k, 3, 3) in Pa of Boussinesq's solution at the points p (k, 3) of the
    half-space z ≤ 0 under a normal force ``force_N`` pushing down at the origin: the
    library's closed form (flexcontact.dam.halfspace, depth along +z) mirrored in z."""
    from flexcontact.dam.halfspace import point_force_stress
    mirror = np.diag([1.0, 1.0, -1.0])
    return mirror @ point_force_stress(p @ mirror, (0.0, 0.0, force_N), nu) @ mirror


def boussinesq_box(cells_per_m: int, force_N: float = 1e6):
    """Boussinesq's problem on the box [−2, 2]² × [−2, 0] m: the normal force at the origin
    node, the exact traction σ·n on the other faces, three corners pinned against the (zero)
    rigid motion. Returns (the displacement, the cell tags)."""
    import ufl
    from flexcontact.forms import sigma
    nu = CONCRETE.nu
    n = 2 * cells_per_m
    msh = dolfinx.mesh.create_box(MPI.COMM_WORLD, [np.full(3, -2.0), np.array([2.0, 2.0, 0.0])],
                                  [2 * n, 2 * n, n], dolfinx.mesh.CellType.tetrahedron)
    nc = msh.topology.index_map(3).size_local + msh.topology.index_map(3).num_ghosts
    tags = dolfinx.mesh.meshtags(msh, 3, np.arange(nc, dtype=np.int32), np.ones(nc, np.int32))
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    x = ufl.SpatialCoordinate(msh)
    zeta, rho, R = -x[2], ufl.sqrt(x[0] ** 2 + x[1] ** 2), ufl.sqrt(ufl.dot(x, x))
    c = force_N / (2.0 * np.pi)
    e_r = ufl.as_vector([x[0] / rho, x[1] / rho, 0.0])
    e_t = ufl.as_vector([-x[1] / rho, x[0] / rho, 0.0])
    e_z = ufl.as_vector([0.0, 0.0, 1.0])
    exact = (c * ((1 - 2 * nu) / rho ** 2 * (1 - zeta / R) - 3 * rho ** 2 * zeta / R ** 5)
             * ufl.outer(e_r, e_r)
             + c * (1 - 2 * nu) * (zeta / R ** 3 - (1 - zeta / R) / rho ** 2) * ufl.outer(e_t, e_t)
             - 3 * c * zeta ** 3 / R ** 5 * ufl.outer(e_z, e_z)
             + 3 * c * rho * zeta ** 2 / R ** 5 * (ufl.outer(e_r, e_z) + ufl.outer(e_z, e_r)))
    outer = dolfinx.mesh.locate_entities_boundary(
        msh, 2, lambda X: (X[2] < -2 + 1e-9) | (np.abs(X[0]) > 2 - 1e-9)
        | (np.abs(X[1]) > 2 - 1e-9))
    facets = dolfinx.mesh.meshtags(msh, 2, np.sort(outer).astype(np.int32),
                                   np.ones(outer.size, np.int32))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=facets,
                     metadata={"quadrature_degree": 6})
    a = dolfinx.fem.form(ufl.inner(sigma(u, CONCRETE, "3d"), ufl.sym(ufl.grad(v))) * ufl.dx)
    L = dolfinx.fem.form(ufl.inner(ufl.dot(exact, ufl.FacetNormal(msh)), v) * ds(1))
    bcs = []
    for corner, comps in (((-2, -2, -2), (0, 1, 2)), ((2, -2, -2), (1, 2)), ((-2, 2, -2), (2,))):
        for k in comps:
            Vk, _ = V.sub(k).collapse()
            dofs = dolfinx.fem.locate_dofs_geometrical(
                (V.sub(k), Vk), lambda X, p=corner: np.isclose(X[0], p[0])
                & np.isclose(X[1], p[1]) & np.isclose(X[2], p[2]))
            bcs.append(dolfinx.fem.dirichletbc(dolfinx.fem.Function(Vk), dofs, V.sub(k)))
    uh = _solve_with_point_force(V, a, L, bcs, 2, -force_N)
    return uh, tags


def _solve_with_point_force(V, a, L, bcs, component: int, force_N: float):
    """The displacement of a(u, v) = L(v) plus a point force (N, along ``component``) at the
    origin's node, by MUMPS."""
    from petsc4py import PETSc
    import dolfinx.fem.petsc
    A = compat.assemble_matrix(a, bcs)
    b = dolfinx.fem.petsc.assemble_vector(L)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    origin = np.flatnonzero(np.linalg.norm(V.tabulate_dof_coordinates(), axis=1) < 1e-12)
    with b.localForm() as loc:   # on whichever ranks hold the node; only owners count
        loc.array[V.dofmap.index_map_bs * origin + component] += force_N
    dolfinx.fem.petsc.set_bc(b, bcs)
    ksp = PETSc.KSP().create(V.mesh.comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    uh = dolfinx.fem.Function(V)
    ksp.solve(b, compat.petsc_vec(uh))
    uh.x.scatter_forward()
    for obj in (ksp, A, b):
        obj.destroy()
    return uh
