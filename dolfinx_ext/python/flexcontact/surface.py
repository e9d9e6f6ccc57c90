"""The nodes of a tagged boundary: coordinates, DOFs, outward normals, tributary measures.

Facets are read on every rank (owned and ghost), sent to rank 0 and merged there by their
nodes' global indices, so each facet and each node counts once whatever the partition.
"""
from __future__ import annotations

import numpy as np

import dolfinx.fem

from . import compat
from .errors import InputError, InputTypeError


def surface_nodes(V, facet_tags, value: int) -> dict:
    """Nodes of the facets tagged ``value``, gathered and merged on rank 0.

    The normal of a node is the facet-measure-weighted mean of the outward unit normals of
    the tagged facets around it (outward: away from the facet's cell), normalised; its
    tributary measure is Σ (facet measure / vertices per facet) over those facets.

    Args:
        V: P1 Lagrange space (scalar or vector, not a sub-space) on the mesh of the tags.
        facet_tags: facet MeshTags of that mesh.
        value: the tag of the surface.

    Returns:
        On rank 0 a dict with "x" (n, gdim) coordinates [m], "dofs" (n, bs) global DOF
        indices (node·bs + component), "normal" (n, gdim) unit outward normals, "area" (n,)
        tributary length (2D) [m] or area (3D) [m²]; nodes sorted lexicographically by
        coordinates; "facets" (nf, nv) the rows of each facet's vertices in "x" (reference
        order of the facet: segment ends, triangle corners, or quadrilateral corners
        (0,0), (1,0), (0,1), (1,1)) and "facet_normal" (nf, gdim) their unit outward
        normals. Other ranks get arrays with no rows. Collective.

    Raises:
        ValueError: if no facet carries ``value`` (the message lists the values present),
            the tags are not facet tags of V's mesh, or V is not a whole P1 space.
    """
    if not isinstance(V, dolfinx.fem.FunctionSpace):
        raise InputTypeError(f"surface_nodes: expected a dolfinx FunctionSpace, got "
                        f"{type(V).__name__}")
    msh = V.mesh
    comm = msh.comm
    tdim = msh.topology.dim
    fdim, gdim = tdim - 1, msh.geometry.dim
    bs = V.dofmap.index_map_bs
    _check_arguments(V, facet_tags, value, tdim, gdim)

    facets = facet_tags.indices[facet_tags.values == value]
    X, nodes, cells = _facet_vertices(V, facets)     # (nf, nv, gdim), (nf, nv) global, (nf,)
    centroid = msh.geometry.x[compat.geometry_dofmap(msh)[cells]].mean(axis=1)[:, :gdim]
    normal, measure = _outward_normals(X, centroid, gdim)

    gathered = comm.gather((nodes, X, normal, measure), root=0)
    if comm.rank != 0:
        return _empty(gdim, bs, X.shape[1])
    nodes, X, normal, measure = (np.concatenate(p) for p in zip(*gathered))
    return _merge(nodes, X, normal, measure, gdim, bs)


def _check_arguments(V, facet_tags, value, tdim, gdim):
    msh = V.mesh
    if facet_tags.dim != tdim - 1:
        raise InputError(f"the tags are of entity dimension {facet_tags.dim}, facet tags "
                         f"(dimension {tdim - 1}) are needed")
    if not compat.tags_on_mesh(facet_tags, msh):
        raise InputError("the facet tags belong to another mesh than the function space")
    if gdim != tdim:
        raise InputError("surface nodes need a mesh whose geometric dimension equals its "
                         f"topological dimension (got gdim={gdim}, tdim={tdim})")
    if compat.is_subspace(V):
        raise InputError("surface nodes need a whole function space, not a sub-space")
    nv_cell = compat.geometry_dofmap(msh).shape[1]
    per_cell = compat.cell_dofs(V).shape[1]
    if per_cell != nv_cell or compat.cell_vertex_count(msh) != nv_cell:
        raise InputError(f"surface nodes need a P1 space on an affine mesh: {per_cell} nodes "
                         f"per cell, {compat.cell_vertex_count(msh)} vertices")
    local = np.unique(facet_tags.values)
    present = np.unique(np.concatenate(msh.comm.allgather(local)))
    if value not in present:
        raise InputError(f"facet tag value {value} does not occur on any facet of the mesh; "
                         f"the facet tags hold the values {present.tolist()}")


def _facet_vertices(V, facets):
    """Coordinates (nf, nv, gdim) and global node numbers (nf, nv) of each facet's vertices,
    in the reference order of the facet within its first cell, and that cell (nf,)."""
    msh = V.mesh
    tdim = msh.topology.dim
    gdim = msh.geometry.dim
    f2c = compat.connectivity(msh, tdim - 1, tdim)
    c2f = compat.connectivity(msh, tdim, tdim - 1)
    cells = f2c[0][f2c[1][facets]]
    per_cell = c2f[1][1] - c2f[1][0]
    local_facet = np.argmax(c2f[0].reshape(-1, per_cell)[cells] == facets[:, None], axis=1)
    ref = compat.reference_facet_vertices(msh)              # (facets per cell, nv)
    verts = ref[local_facet]                                 # cell-local vertex numbers
    rows = cells[:, None]
    X = msh.geometry.x[compat.geometry_dofmap(msh)[rows, verts]][:, :, :gdim]
    local = compat.cell_dofs(V)[rows, verts]
    nodes = V.dofmap.index_map.local_to_global(local.reshape(-1).astype(np.int32))
    return np.asarray(X, float), np.asarray(nodes, np.int64).reshape(local.shape), cells


def _outward_normals(X, centroid, gdim):
    """Unit normals pointing away from the cell, and facet measures (length or area)."""
    nv = X.shape[1]
    if gdim == 2:
        d = X[:, 1] - X[:, 0]
        n = np.stack([d[:, 1], -d[:, 0]], axis=1)
        length = np.linalg.norm(n, axis=1)
        measure = length
    else:
        # Triangle: (x1 − x0) × (x2 − x0); quadrilateral (reference order 0,1,2,3 with
        # diagonals 0–3 and 1–2): (x3 − x0) × (x2 − x1). Both are twice the area.
        a = X[:, 1] - X[:, 0] if nv == 3 else X[:, 3] - X[:, 0]
        b = X[:, 2] - X[:, 0] if nv == 3 else X[:, 2] - X[:, 1]
        n = np.cross(a, b)
        length = np.linalg.norm(n, axis=1)
        measure = 0.5 * length
    n = n / np.where(length > 0, length, 1.0)[:, None]
    side = np.einsum("fk,fk->f", n, X.mean(axis=1) - centroid)
    n[side < 0] *= -1
    return n, measure


def _empty(gdim, bs, nv):
    return {"x": np.zeros((0, gdim)), "dofs": np.zeros((0, bs), np.int64),
            "normal": np.zeros((0, gdim)), "area": np.zeros(0),
            "facets": np.zeros((0, nv), np.int64), "facet_normal": np.zeros((0, gdim))}


def _merge(nodes, X, normal, measure, gdim, bs):
    """Each facet once (key: its sorted node numbers), then sums per node, sorted."""
    nv = nodes.shape[1]
    if nodes.shape[0] == 0:
        return _empty(gdim, bs, nv)
    _, first = np.unique(np.sort(nodes, axis=1), axis=0, return_index=True)
    nodes, X, normal, measure = nodes[first], X[first], normal[first], measure[first]
    ids, inverse = np.unique(nodes.reshape(-1), return_inverse=True)
    inverse = inverse.reshape(-1)
    x = np.zeros((ids.size, gdim))
    x[inverse] = X.reshape(-1, gdim)
    n = np.zeros((ids.size, gdim))
    np.add.at(n, inverse, np.repeat(measure[:, None] * normal, nv, axis=0))
    area = np.zeros(ids.size)
    np.add.at(area, inverse, np.repeat(measure / nv, nv))
    length = np.linalg.norm(n, axis=1)
    n = n / np.where(length > 0, length, 1.0)[:, None]
    # Lexicographic by coordinates, then by global number (np.lexsort: last key first).
    order = np.lexsort((ids,) + tuple(x[:, k] for k in reversed(range(gdim))))
    dofs = ids[order, None] * bs + np.arange(bs)[None, :]
    row = np.empty(ids.size, np.int64)
    row[order] = np.arange(ids.size)
    return {"x": x[order], "dofs": dofs.astype(np.int64), "normal": n[order],
            "area": area[order], "facets": row[inverse].reshape(-1, nv),
            "facet_normal": normal}
