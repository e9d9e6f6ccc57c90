"""Every DOLFINx call whose spelling differs between 0.5 (Debian 12), 0.9 (Debian 13) and 0.11
(Debian unstable).

The rest of the package (and forms/, meshes/, the tests) calls these helpers only, so that a
port is a change in this file. The compiled module has no DOLFINx dependency at all: it takes
petsc4py objects and NumPy arrays (docs/architecture.md §3).
"""
from __future__ import annotations

import numpy as np

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc  # noqa: F401  (submodule must be imported explicitly in 0.5)
import dolfinx.io
import dolfinx.mesh

SUPPORTED = ((0, 5), (0, 9), (0, 11))
"""The DOLFINx generations flexcontact runs on and is tested on: Debian 12's 0.5, Debian 13's
0.9 and Debian unstable's 0.11."""

VERSION = tuple(int(p) for p in dolfinx.__version__.split(".")[:2])
if VERSION not in SUPPORTED:
    raise ImportError(
        f"flexcontact supports DOLFINx 0.5, 0.9 and 0.11; this Python sees DOLFINx "
        f"{dolfinx.__version__} ({dolfinx.__file__})")
STACK = f"DOLFINx {dolfinx.__version__}"
"""The DOLFINx in use, for messages that name the installation."""
NEW_API = VERSION >= (0, 8)
GMSH_MODULE = VERSION >= (0, 10)   # dolfinx.io.gmshio became dolfinx.io.gmsh
PETSC_LA = VERSION >= (0, 10)      # dolfinx.la's PETSc helpers moved to dolfinx.la.petsc
DIAGONAL_KEYWORD = "diag" if VERSION >= (0, 10) else "diagonal"  # of assemble_matrix


def cpp(obj):
    """The C++ object behind a DOLFINx Python object (either kind is accepted)."""
    return getattr(obj, "_cpp_object", obj)


def vector_space(msh, degree: int = 1, size: "int | None" = None):
    """Continuous Lagrange vector space of ``size`` components (default: the mesh's
    geometric dimension)."""
    size = msh.geometry.dim if size is None else int(size)
    if NEW_API:
        return dolfinx.fem.functionspace(msh, ("Lagrange", degree, (size,)))
    return dolfinx.fem.VectorFunctionSpace(msh, ("Lagrange", degree), dim=size)


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


def assemble_vector_array(form) -> np.ndarray:
    """A compiled linear form assembled into a NumPy array (owned and ghost entries, ghost
    contributions not sent to their owners): 0.5 returns the array, 0.9 on a la.Vector."""
    out = dolfinx.fem.assemble_vector(form)
    return np.asarray(out.array if hasattr(out, "array") else out)


def eval_expression(expr, msh, cells) -> np.ndarray:
    """Values of a dolfinx.fem.Expression on the given cells, (cells, points · size)."""
    if NEW_API:
        return expr.eval(msh, cells)
    return expr.eval(cells)


def geometry_x(msh):
    """Geometry node coordinates, shape (num_nodes, 3)."""
    return msh.geometry.x


def geometry_dofmap(msh) -> np.ndarray:
    """Geometry nodes of each cell, shape (num_cells, nodes per cell), local numbers."""
    if VERSION >= (0, 11):  # one dofmap per cell type; `dofmap` is deprecated
        return msh.geometry.dofmaps[0]
    g = msh.geometry.dofmap
    return g if NEW_API else g.array.reshape(-1, g.offsets[1] - g.offsets[0])


def cell_dofs(V) -> np.ndarray:
    """DOF blocks of each cell, shape (num_cells, blocks per cell), local numbers."""
    d = V.dofmap.list
    return d if NEW_API else d.array.reshape(-1, d.offsets[1] - d.offsets[0])


def connectivity(msh, d0: int, d1: int):
    """(array, offsets) of the connectivity d0 → d1, created if missing."""
    msh.topology.create_connectivity(d0, d1)
    c = msh.topology.connectivity(d0, d1)
    return np.asarray(c.array), np.asarray(c.offsets)


def entities_to_geometry(msh, dim: int, entities) -> np.ndarray:
    """Geometry nodes of each entity, shape (len(entities), nodes per entity)."""
    if NEW_API:
        msh.topology.create_connectivity(dim, msh.topology.dim)
        return dolfinx.mesh.entities_to_geometry(msh, dim, entities)
    from dolfinx.cpp.mesh import entities_to_geometry as cpp_entities_to_geometry
    cpp_mesh = getattr(msh, "_cpp_object", getattr(msh, "_mesh", msh))
    return cpp_entities_to_geometry(cpp_mesh, dim, entities, False)


def cell_vertex_count(msh) -> int:
    """Vertices of one cell (single cell type meshes)."""
    arr, off = connectivity(msh, msh.topology.dim, 0)
    return int(off[1] - off[0])


def reference_facet_vertices(msh) -> np.ndarray:
    """Cell-local vertex numbers of each facet of the reference cell, (facets, nv): the
    order DOLFINx uses for cell geometry nodes and P1 DOFs alike."""
    import basix
    cell = getattr(basix.CellType, msh.topology.cell_type.name)
    return np.array(basix.topology(cell)[msh.topology.dim - 1], dtype=np.int64)


def tags_on_mesh(tags, msh) -> bool:
    """True if the MeshTags were made on this mesh."""
    if NEW_API:
        def unwrap(t):
            return getattr(t, "_cpp_object", t)
        return unwrap(tags.topology) is unwrap(msh.topology)
    return tags.mesh.topology is msh.topology


def tags_comm(tags):
    """The communicator of the mesh the MeshTags live on."""
    return tags.topology.comm if NEW_API else tags.mesh.comm


def is_subspace(V) -> bool:
    """True for a sub-space such as V.sub(0) (not collapsed)."""
    return len(V.component()) > 0


def create_connectivity(msh, d0: int, d1: int):
    msh.topology.create_connectivity(d0, d1)


def facet_dim(msh) -> int:
    return msh.topology.dim - 1


def input_node_indices(msh) -> np.ndarray:
    """Index in the mesh's input of each local geometry node: the same node has the same
    number in serial and on any number of ranks."""
    return np.asarray(cpp(msh.geometry).input_global_indices, dtype=np.int64)


def original_cell_indices(msh) -> np.ndarray:
    """Index in the mesh's input of each local cell (owned first), rank-independent."""
    return np.asarray(cpp(msh.topology).original_cell_index, dtype=np.int64)


def same_mesh(a, b) -> bool:
    """True if the two DOLFINx meshes are one and the same."""
    return cpp(a.topology) is cpp(b.topology)


def cell_type_name(msh) -> str:
    """"triangle", "tetrahedron", "quadrilateral", ... (single cell type meshes)."""
    return msh.topology.cell_type.name


def locate_component_dofs(V, component: int, facet_indices):
    """Dofs of one vector component on the given facets, as DOLFINx's dirichletbc wants them."""
    fdim = V.mesh.topology.dim - 1
    return dolfinx.fem.locate_dofs_topological(V.sub(component), fdim, facet_indices)


def set_bc(b, bcs, scale: float = 1.0):
    """b[dof] = scale · g[dof] at the Dirichlet DOFs (``scale`` is ``alpha`` from 0.8 on)."""
    if NEW_API:
        dolfinx.fem.petsc.set_bc(b, bcs, alpha=scale)
    else:
        dolfinx.fem.petsc.set_bc(b, bcs, scale=scale)


def bc_is_homogeneous(bc) -> bool:
    """True if the DirichletBC prescribes zero through a Constant as set now (``bc.g`` is
    the C++ Constant or Function on 0.5 and 0.9); a Function value counts as non-zero
    without being read."""
    g = bc.g
    return not hasattr(g, "x") and hasattr(g, "value") and not np.any(np.asarray(g.value))


def create_petsc_vector(V):
    """A ghosted PETSc vector laid out like the Function space's DOFs."""
    if PETSC_LA:
        import dolfinx.la.petsc
        vec = dolfinx.la.petsc.create_vector([(V.dofmap.index_map, V.dofmap.index_map_bs)])
        vec.zeroEntries()  # documented as not initialised from 0.10 on
        return vec
    import dolfinx.la
    return dolfinx.la.create_petsc_vector(V.dofmap.index_map, V.dofmap.index_map_bs)


def linear_problem(a, L, bcs, petsc_options: dict, prefix: str):
    """DOLFINx's LinearProblem of ``a == L``; from 0.10 on it needs an options prefix of its
    own (``prefix``, e.g. ``"forms_test_"``)."""
    import dolfinx.fem.petsc
    extra = {"petsc_options_prefix": prefix} if VERSION >= (0, 10) else {}
    return dolfinx.fem.petsc.LinearProblem(a, L, bcs=list(bcs), petsc_options=petsc_options,
                                           **extra)


def assemble_matrix(form, bcs, diagonal: float = 1.0):
    """The assembled PETSc matrix of a bilinear form, with ``diagonal`` on the rows and
    columns of the Dirichlet DOFs (the keyword is ``diag`` from 0.10 on)."""
    A = dolfinx.fem.petsc.assemble_matrix(form, bcs=list(bcs), **{DIAGONAL_KEYWORD: diagonal})
    A.assemble()
    return A


def gmsh_model_to_mesh(model, comm, rank: int, gdim: int):
    """(mesh, cell_tags, facet_tags) of a gmsh model living on ``rank``, distributed over
    ``comm``; only elements in physical groups are kept."""
    if GMSH_MODULE:
        import dolfinx.io.gmsh as reader
    else:
        import dolfinx.io.gmshio as reader  # the submodule must be imported explicitly
    out = reader.model_to_mesh(model, comm, rank, gdim=gdim)
    return out[0], out[1], out[2]


def points_in_cells(msh, points) -> tuple[np.ndarray, np.ndarray]:
    """Which of ``points`` (n, 3) lie in this rank's cells: (point indices, one cell each).

    A point on a cell boundary is given one of its cells; points outside every local cell
    (owned or ghost) are left out."""
    import dolfinx.geometry as geometry
    tdim = msh.topology.dim
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    if NEW_API:
        tree = geometry.bb_tree(msh, tdim)
        candidates = geometry.compute_collisions_points(tree, points)
    else:
        tree = geometry.BoundingBoxTree(msh, tdim)
        candidates = geometry.compute_collisions(tree, points)
    colliding = geometry.compute_colliding_cells(msh, candidates, points)
    found, cells = [], []
    for i in range(points.shape[0]):
        links = colliding.links(i)
        if len(links):
            found.append(i)
            cells.append(links[0])
    return np.array(found, dtype=np.int64), np.array(cells, dtype=np.int32)
