"""Small helpers to inspect the meshes (used by the tests; handy in demos)."""

import numpy as np


def surface_coordinates(msh, facet_tags, tag: int) -> np.ndarray:
    """Coordinates (n, 3) in m of all vertices on facets tagged ``tag``, over all ranks.

    Collective. Every rank returns the same array, one row per distinct vertex (global
    vertex number), sorted by that number. Meant for checks on small surfaces.
    """
    from flexcontact import compat
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, 0)
    f2v = msh.topology.connectivity(tdim - 1, 0)
    facets = facet_tags.indices[facet_tags.values == tag]
    verts = np.unique(np.concatenate([f2v.links(f) for f in facets])) if len(facets) else \
        np.empty(0, dtype=np.int32)
    verts = verts.astype(np.int32)
    # Vertex -> geometry node (identical for P1 meshes, but not guaranteed in general).
    nodes = compat.entities_to_geometry(msh, 0, verts).reshape(-1) if len(verts) else \
        np.empty(0, dtype=np.int32)
    x = msh.geometry.x[nodes]
    gid = msh.topology.index_map(0).local_to_global(verts) if len(verts) else np.empty(0, np.int64)
    all_gid = np.concatenate(msh.comm.allgather(np.asarray(gid, dtype=np.int64)))
    all_x = np.concatenate(msh.comm.allgather(np.asarray(x).reshape(-1, 3)))
    _, first = np.unique(all_gid, return_index=True)
    return all_x[first]
