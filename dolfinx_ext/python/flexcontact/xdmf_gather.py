"""Mesh and fields gathered on rank 0 in the mesh's input order, for the XDMF writer.

Nodes are numbered by their index in the mesh's input (``geometry.input_global_indices``) and
cells by their original cell index, so that the file written from any number of ranks holds the
same arrays as the serial one. Each value is taken from the rank that owns it, never from a
ghost copy. Checks are collective: every rank raises the same error, before anything is written.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from . import compat
from .errors import SolveError

# DOLFINx's cell-local vertex order → the XDMF/VTK order (tensor-product cells differ).
TOPOLOGY_TYPES = {
    "triangle": ("Triangle", None),
    "tetrahedron": ("Tetrahedron", None),
    "quadrilateral": ("Quadrilateral", [0, 1, 3, 2]),
    "hexahedron": ("Hexahedron", [0, 1, 3, 2, 4, 5, 7, 6]),
}


# Names DOLFINx gives tags by itself (meshtags, gmshio.model_to_mesh): written as "cell_tag".
DEFAULT_TAG_NAMES = ("mesh_tags", "Cell tags", "cell_tags", "")


def raise_on_any_rank(comm, message: Optional[str], error=ValueError) -> None:
    """Raise ``error(message)`` on every rank if any rank has a message (collective)."""
    messages = [m for m in comm.allgather(message) if m]
    if messages:
        raise error(messages[0])


@dataclass
class Field:
    """One field on rank 0: name, "Node" or "Cell", values (entities, 1 or 3 components)."""
    name: str
    center: str
    values: np.ndarray


class MeshGather:
    """The mesh in input order on rank 0 (``x``, ``cells``), and the gathering of fields."""

    def __init__(self, msh):
        self.msh, self.comm = msh, msh.comm
        name = compat.cell_type_name(msh)
        message = None
        if name not in TOPOLOGY_TYPES:
            message = f"ResultWriter: cell type '{name}' is not supported " \
                      f"(supported: {', '.join(TOPOLOGY_TYPES)})"
        self.geo = compat.geometry_dofmap(msh)
        if message is None and self.geo.shape[1] != compat.cell_vertex_count(msh):
            message = (f"ResultWriter: the mesh has {self.geo.shape[1]} geometry nodes per "
                       f"cell; only affine (degree 1) geometry is written")
        raise_on_any_rank(self.comm, message)
        self.topology_type, perm = TOPOLOGY_TYPES[name]
        self._positions = {}  # center -> (ids, positions) last placed and checked
        tdim = msh.topology.dim
        self.n_owned_cells = msh.topology.index_map(tdim).size_local
        self.node_ids = compat.input_node_indices(msh)
        self.cell_ids = compat.original_cell_indices(msh)[:self.n_owned_cells]
        x = compat.geometry_x(msh)
        parts = self.comm.gather((self.node_ids, x[:, :3].copy(), self.cell_ids,
                                  self.node_ids[self.geo[:self.n_owned_cells]]), root=0)
        if self.comm.rank == 0:
            self._order_on_root(parts, perm)

    def _order_on_root(self, parts, perm) -> None:
        ids = np.concatenate([p[0] for p in parts])
        # Ghost nodes repeat owned ones with the same coordinates: keep one of each.
        self.nodes, first = np.unique(ids, return_index=True)
        self.x = np.concatenate([p[1] for p in parts])[first]
        cell_ids = np.concatenate([p[2] for p in parts])
        self.cell_order = np.sort(cell_ids)
        if len(np.unique(cell_ids)) != len(cell_ids):
            raise SolveError("ResultWriter: a cell is owned by two ranks")
        cells = np.concatenate([p[3] for p in parts])[np.argsort(cell_ids)]
        self.cells = np.searchsorted(self.nodes, cells)
        if perm is not None:
            self.cells = self.cells[:, perm]

    def _cell_positions(self, ids) -> np.ndarray:
        return np.searchsorted(self.cell_order, ids)

    def _local(self, f):
        """(center, input ids of the owned entities, their values) or an error message."""
        name = f.name
        if not compat.same_mesh(f.function_space.mesh, self.msh):
            return f"ResultWriter: field '{name}' lives on another mesh than the writer's"
        V = f.function_space
        bs = V.dofmap.index_map_bs
        if bs not in (1, 2, 3):
            return f"ResultWriter: field '{name}' has {bs} components; scalars and vectors only"
        a = np.asarray(f.x.array)
        if np.iscomplexobj(a):
            return f"ResultWriter: field '{name}' is complex; real fields only"
        values = a.reshape(-1, bs)
        dofs = compat.cell_dofs(V)
        n_local_dofs = V.dofmap.index_map.size_local
        if dofs.shape[1] == 1:                                     # DG0: one value per cell
            return "Cell", self.cell_ids, values[dofs[:self.n_owned_cells, 0]]
        not_p1 = (f"ResultWriter: field '{name}' is neither continuous degree 1 (one value "
                  f"per vertex) nor DG0 (one value per cell)")
        if dofs.shape != self.geo.shape:
            return not_p1
        node_dof = np.full(len(self.node_ids), -1, dtype=np.int64)
        node_dof[self.geo] = dofs
        if not np.array_equal(node_dof[self.geo], dofs):                 # e.g. DG1
            return not_p1
        owned = (node_dof >= 0) & (node_dof < n_local_dofs)
        return "Node", self.node_ids[owned], values[node_dof[owned]]

    def gather(self, functions) -> list[Field]:
        """The fields in input order on rank 0 ([] elsewhere); collective."""
        local = [self._local(f) for f in functions]
        names = [f.name for f in functions]
        message = next((m for m in local if isinstance(m, str)), None)
        dup = {n for n in names if names.count(n) > 1}
        if message is None and dup:
            message = f"ResultWriter: two fields are named '{sorted(dup)[0]}'"
        raise_on_any_rank(self.comm, message)
        out = []
        for name, (center, ids, values) in zip(names, local):
            parts = self.comm.gather((ids, values), root=0)
            if self.comm.rank == 0:
                out.append(self._place(name, center, parts))
        return out

    def _place(self, name: str, center: str, parts) -> Field:
        ids = np.concatenate([p[0] for p in parts])
        values = np.concatenate([p[1] for p in parts]).astype(np.float64)
        n = len(self.cell_order) if center == "Cell" else len(self.nodes)
        # Every field of a space arrives in the same order: its positions, found and
        # checked once, serve every later write (the search costs more than the copy).
        known = self._positions.get(center)
        if known is not None and np.array_equal(known[0], ids):
            pos = known[1]
        else:
            pos = (self._cell_positions(ids) if center == "Cell"
                   else np.searchsorted(self.nodes, ids))
            if len(pos) != n or len(np.unique(pos)) != n:
                raise SolveError(f"ResultWriter: field '{name}' has {len(np.unique(pos))} "
                                   f"owned values for {n} entities")
            self._positions[center] = (ids, pos)
        full = np.empty((n, values.shape[1]))
        full[pos] = values
        if full.shape[1] == 2:  # 2D vectors as 3D ones (z = 0), as ParaView's Warp By Vector wants
            full = np.hstack([full, np.zeros((n, 1))])
        return Field(name, center, full)

    def cell_tags(self, tags) -> list[tuple[str, np.ndarray]]:
        """Cell tags as (name, one integer per cell, -1 where untagged) on rank 0; collective."""
        tdim = self.msh.topology.dim
        message = None
        for t in tags:
            if not compat.tags_on_mesh(t, self.msh):
                message = f"ResultWriter: tags '{t.name}' live on another mesh than the writer's"
            elif t.dim != tdim:
                message = (f"ResultWriter: tags '{t.name}' are of dimension {t.dim}; only cell "
                           f"tags (dimension {tdim}) are written")
        raise_on_any_rank(self.comm, message)
        out = []
        names = ["cell_tag" if t.name in DEFAULT_TAG_NAMES else t.name for t in tags]
        for i, t in enumerate(tags):
            own = t.indices < self.n_owned_cells
            parts = self.comm.gather((self.cell_ids[t.indices[own]], t.values[own]), root=0)
            if self.comm.rank == 0:
                full = np.full(len(self.cell_order), -1, dtype=np.int32)
                for ids, vals in parts:
                    full[self._cell_positions(ids)] = vals
                unique = names.count(names[i]) == 1
                out.append((names[i] if unique else f"{names[i]}_{i}", full))
        return out
