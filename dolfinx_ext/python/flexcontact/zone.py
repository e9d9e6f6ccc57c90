"""The candidate-zone guard: which nodes of a tagged contact surface are an *open* edge.

A tagged candidate surface ends somewhere. Where it ends at a corner of the body (a block's
bottom edge), contact may well reach it. Where the body's boundary goes on smoothly past
it (a candidate strip cut out of a cylinder or a long face), a closed pair there means the
contact zone has grown past the tagged zone, and pairs that would have closed beyond it
are missing: that is what the guard reports. An edge node of the candidate surface is
*open* when an exterior facet outside the tagged surface meets it with an outward normal
within ``angle_deg`` of the node's normal.
"""
from __future__ import annotations

import numpy as np

import dolfinx.mesh

from . import compat
from .projection import boundary_nodes
from .surface import _facet_vertices, _outward_normals

OPEN_EDGE_ANGLE_DEG = 30.0


def open_edge_flags(V, facet_tags, value: int, surface: dict,
                    angle_deg: float = OPEN_EDGE_ANGLE_DEG) -> np.ndarray:
    """Flags (rank 0: one per node of ``surface``, the gathered dict of ``surface_nodes``
    for the same tag; elsewhere empty) of the surface's open edge nodes. Collective."""
    msh = V.mesh
    comm = msh.comm
    tdim, gdim = msh.topology.dim, msh.geometry.dim
    bs = V.dofmap.index_map_bs
    edge_ids = None
    if comm.rank == 0:
        flags = boundary_nodes(np.asarray(surface["facets"]), gdim, surface["x"].shape[0])
        edge_ids = np.asarray(surface["dofs"])[flags, 0] // bs
    edge_ids = comm.bcast(edge_ids, root=0)

    exterior = np.asarray(dolfinx.mesh.exterior_facet_indices(msh.topology), np.int32)
    tagged = facet_tags.indices[facet_tags.values == value]
    others = np.setdiff1d(exterior, tagged).astype(np.int32)
    X, nodes, cells = _facet_vertices(V, others)
    near = np.isin(nodes, edge_ids).any(axis=1)
    X, nodes, cells = X[near], nodes[near], cells[near]
    centroid = msh.geometry.x[compat.geometry_dofmap(msh)[cells]].mean(axis=1)[:, :gdim]
    normal, _ = _outward_normals(X, centroid, gdim) if cells.size else (np.zeros((0, gdim)),
                                                                        None)
    gathered = comm.gather((nodes, normal), root=0)
    if comm.rank != 0:
        return np.zeros(0, bool)
    nodes = np.concatenate([g[0] for g in gathered]) if gathered else np.zeros((0, 1))
    normal = np.concatenate([g[1] for g in gathered]) if gathered else np.zeros((0, gdim))
    ids = np.asarray(surface["dofs"])[:, 0] // bs
    cos = np.cos(np.radians(angle_deg))
    out = np.zeros(ids.size, bool)
    for i in np.flatnonzero(np.isin(ids, edge_ids)):
        touching = np.any(nodes == ids[i], axis=1)
        if touching.any():
            out[i] = bool(np.max(normal[touching] @ surface["normal"][i]) > cos)
    return out
