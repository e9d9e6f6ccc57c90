"""Every DOLFINx call whose spelling differs between 0.5 (Debian 12) and 0.9 (Debian 13).

The rest of the package calls these helpers only, so that a port is a change in this file
(and in ``dolfinx_ext/src/compat.h`` on the C++ side).
"""
from __future__ import annotations

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc  # noqa: F401  (submodule must be imported explicitly in 0.5)
import dolfinx.io

_VERSION = tuple(int(p) for p in dolfinx.__version__.split(".")[:2])
NEW_API = _VERSION >= (0, 8)


def cpp(obj):
    """The C++ object behind a DOLFINx Python object (either kind is accepted)."""
    return getattr(obj, "_cpp_object", obj)


def vector_space(msh, degree: int = 1):
    """Continuous Lagrange vector space of the mesh's geometric dimension."""
    if NEW_API:
        gdim = msh.geometry.dim
        return dolfinx.fem.functionspace(msh, ("Lagrange", degree, (gdim,)))
    return dolfinx.fem.VectorFunctionSpace(msh, ("Lagrange", degree))


def scalar_space(msh, family: str = "Lagrange", degree: int = 1):
    """Scalar space, e.g. ("Lagrange", 1) for nodal contact fields, ("DG", 0) for stresses."""
    if NEW_API:
        return dolfinx.fem.functionspace(msh, (family, degree))
    return dolfinx.fem.FunctionSpace(msh, (family, degree))


def petsc_vec(u):
    """The PETSc vector holding a Function's values (owned + ghosts)."""
    return u.x.petsc_vec if NEW_API else u.vector


def interpolation_points(V):
    pts = V.element.interpolation_points
    return pts() if callable(pts) else pts


def interpolate_expression(target, expr):
    """Interpolate a UFL expression into the Function ``target``."""
    e = dolfinx.fem.Expression(expr, interpolation_points(target.function_space))
    target.interpolate(e)


def geometry_x(msh):
    """Geometry node coordinates, shape (num_nodes, 3)."""
    return msh.geometry.x


def create_connectivity(msh, d0: int, d1: int):
    msh.topology.create_connectivity(d0, d1)


def facet_dim(msh) -> int:
    return msh.topology.dim - 1


def write_mesh_and_tags(xdmf, msh, tags=()):
    xdmf.write_mesh(msh)
    for t in tags:
        if NEW_API:
            xdmf.write_meshtags(t, msh.geometry)
        else:
            xdmf.write_meshtags(t)


def locate_component_dofs(V, component: int, facet_indices):
    """Dofs of one vector component on the given facets, as DOLFINx's dirichletbc wants them."""
    fdim = V.mesh.topology.dim - 1
    return dolfinx.fem.locate_dofs_topological(V.sub(component), fdim, facet_indices)


def create_petsc_vector(V):
    """A ghosted PETSc vector laid out like the Function space's DOFs."""
    import dolfinx.la
    return dolfinx.la.create_petsc_vector(V.dofmap.index_map, V.dofmap.index_map_bs)
