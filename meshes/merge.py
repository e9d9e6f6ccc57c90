"""Several meshed bodies as one mesh, node for node: the reference that checks a method
condensing the bodies apart against the monolithic run on identical meshes.

Each part is a serial DOLFINx mesh of P1 simplices with its cell and facet tags, and a map
placing its nodes (a body meshed in its own frame is rotated and moved here). The parts'
cells and tagged facets are written into one gmsh model as discrete entities and read back
as a DOLFINx mesh, so the union has exactly the parts' nodes and cells (renumbered); no
node is shared between parts.
"""
from __future__ import annotations

import numpy as np

from . import _gmsh

_GMSH_TYPE = {(2, 2): 2, (2, 1): 1, (3, 3): 4, (3, 2): 2}
"""gmsh element type by (mesh dimension, entity dimension): triangle, line, tetrahedron."""


def merge(comm, parts, name: str = "merged"):
    """One mesh of ``parts``: a list of (msh, cell_tags, facet_tags, place), ``place`` a
    function taking node coordinates (n, gdim) to their position in the union (None: as
    they are). Cell and facet tags keep their values (a value used by several parts tags
    the cells of all of them). Collective over ``comm`` (the union lives on rank 0, then is
    distributed). Returns (mesh, cell_tags, facet_tags, info)."""
    from flexcontact import compat
    gdim = parts[0][0].geometry.dim
    for msh, *_ in parts:
        if msh.comm.size != 1:
            raise ValueError("merge: each part must be a serial mesh")
        if msh.geometry.dim != gdim:
            raise ValueError("merge: the parts have different dimensions")
    data = []
    for msh, ct, ft, place in parts:
        x = np.asarray(compat.geometry_x(msh))[:, :gdim]
        x = place(x) if place is not None else x
        cells = np.asarray(compat.geometry_dofmap(msh)).reshape(-1, gdim + 1)
        cell_values = np.full(cells.shape[0], -1, np.int64)
        cell_values[ct.indices] = ct.values
        facets = {}
        for v in np.unique(ft.values):
            ents = np.sort(ft.indices[ft.values == v]).astype(np.int32)
            facets[int(v)] = np.asarray(compat.entities_to_geometry(msh, gdim - 1, ents))
        data.append((x, cells, cell_values, facets))
    return _gmsh.generate(comm, name, lambda: _model(data, gdim), gdim=gdim)


def _model(data, gdim):
    import gmsh
    offset, entity = 0, 0
    cells_by_tag: dict = {}
    facets_by_tag: dict = {}
    node_entity = None
    for x, cells, cell_values, facets in data:
        xyz = np.zeros((x.shape[0], 3))
        xyz[:, :gdim] = x
        entity += 1
        gmsh.model.addDiscreteEntity(gdim, entity)
        node_entity = node_entity or entity
        gmsh.model.mesh.addNodes(gdim, entity, offset + 1 + np.arange(x.shape[0]),
                                 xyz.reshape(-1))
        for v in np.unique(cell_values):
            cells_by_tag.setdefault(int(v), []).append(cells[cell_values == v] + offset + 1)
        for v, f in facets.items():
            facets_by_tag.setdefault(v, []).append(f + offset + 1)
        offset += x.shape[0]
    element = offset  # element numbers after the node numbers, never reused
    for dim, groups in ((gdim, cells_by_tag), (gdim - 1, facets_by_tag)):
        for v, blocks in sorted(groups.items()):
            if v < 0:
                continue  # untagged cells are not kept, as gmsh's reader keeps groups only
            nodes = np.vstack(blocks)
            entity += 1
            gmsh.model.addDiscreteEntity(dim, entity)
            tags = element + 1 + np.arange(nodes.shape[0])
            element += nodes.shape[0]
            gmsh.model.mesh.addElementsByType(entity, _GMSH_TYPE[(gdim, dim)], tags,
                                              nodes.reshape(-1))
            gmsh.model.addPhysicalGroup(dim, [entity], v)
    return {"dim": gdim, "nodes": int(offset)}
