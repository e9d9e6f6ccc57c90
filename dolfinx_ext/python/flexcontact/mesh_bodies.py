"""Which body a node belongs to: the connected components of the mesh, across ranks.

Bodies in contact never share nodes (meshes/__init__.py), so two surfaces lie on the same
body exactly when the mesh connects their nodes. A contact interface whose master surface
sits on the slave's own body is almost always a tag mixed up (a boundary tag given as the
master); ``pair_interfaces`` uses this to say so.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from . import compat


def body_labels(V, blocks: Optional[np.ndarray]) -> Optional[np.ndarray]:
    """The body of each node in ``blocks`` (global DOF-block indices of the P1 space V,
    given on rank 0): one integer per connected component of the mesh, the same on every
    partition. Returned on rank 0, None elsewhere. Collective."""
    comm = V.mesh.comm
    imap = V.dofmap.index_map
    n_owned, ghosts = imap.size_local, np.asarray(imap.ghosts, dtype=np.int64)
    n = n_owned + ghosts.size
    cells = compat.cell_dofs(V)
    # Each cell joins its first node to the others: the components of that graph.
    rows = np.repeat(cells[:, 0], cells.shape[1] - 1)
    graph = coo_matrix((np.ones(rows.size), (rows, cells[:, 1:].reshape(-1))), shape=(n, n))
    _, comp = connected_components(graph, directed=False)
    glob = np.asarray(imap.local_to_global(np.arange(n, dtype=np.int32)), dtype=np.int64)
    label = np.full(comp.max(initial=-1) + 1, np.iinfo(np.int64).max)
    np.minimum.at(label, comp, glob)     # a local component is named by its least node
    node_label = label[comp]

    # Components cut by the partition meet at ghost nodes: rank 0 joins the names.
    shared = np.unique(np.concatenate(comm.allgather(ghosts)))
    owned_shared = np.isin(glob[:n_owned], shared)
    links = comm.gather((glob[:n_owned][owned_shared], node_label[:n_owned][owned_shared],
                         ghosts, node_label[n_owned:]), root=0)
    join = None
    if comm.rank == 0:
        owner = {}
        for g, lab, _, _ in links:
            owner.update(zip(g.tolist(), lab.tolist()))
        parent: dict[int, int] = {}

        def root(a: int) -> int:
            while parent.get(a, a) != a:
                a = parent[a]
            return a

        for _, _, gh, lab in links:
            for g, here in zip(gh.tolist(), lab.tolist()):
                a, b = root(here), root(owner[g])
                if a != b:
                    parent[max(a, b)] = min(a, b)
        join = {a: root(a) for a in parent}
    join = comm.bcast(join, root=0)

    wanted = comm.bcast(np.asarray(blocks, dtype=np.int64) if comm.rank == 0 else None,
                        root=0)
    start = int(glob[0]) if n_owned else 0      # a rank owns a contiguous range of nodes
    here = np.flatnonzero((wanted >= start) & (wanted < start + n_owned))
    labels = [join.get(lab, lab) for lab in node_label[wanted[here] - start].tolist()]
    found = comm.gather((here, labels), root=0)
    if comm.rank != 0:
        return None
    out = np.full(wanted.size, -1, dtype=np.int64)
    for k, lab in found:
        out[k] = lab
    return out
