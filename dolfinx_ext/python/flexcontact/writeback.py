"""Values computed on rank 0 (contact forces, gaps, states …) written into distributed
DOLFINx Functions."""
from __future__ import annotations

import numpy as np

from .mpi import raise_on_every_rank


def set_nodal_values(u, dofs, values) -> None:
    """Set the listed DOFs of ``u`` to ``values``; every other DOF keeps its value.

    Args:
        u: a DOLFINx Function.
        dofs: global DOF indices as in PETSc vectors of u's space (node·bs + component; for a
            scalar space the global node index), any shape, given on rank 0 (empty
            elsewhere).
        values: as many float64 values, on rank 0.

    Each rank sets the entries it owns, then the ghosts are updated. Collective.

    Raises:
        ValueError: on every rank, if the sizes differ or an index is out of range.
    """
    V = u.function_space
    imap, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    comm = V.mesh.comm
    n_global = imap.size_global * bs
    error, payload = None, None
    if comm.rank == 0:
        g = np.asarray(dofs, dtype=np.int64).reshape(-1)
        v = np.asarray(values, dtype=np.float64).reshape(-1)
        if g.size != v.size:
            error = f"set_nodal_values: {g.size} DOF indices but {v.size} values"
        elif g.size and (g.min() < 0 or g.max() >= n_global):
            bad = int(g.min() if g.min() < 0 else g.max())
            error = f"set_nodal_values: DOF index {bad} out of range [0, {n_global})"
        payload = (g, v)
    raise_on_every_rank(comm, error)
    g, v = comm.bcast(payload, root=0)   # surface-sized: every rank keeps what it owns
    start, end = imap.local_range
    block = g // bs
    mine = (block >= start) & (block < end)
    u.x.array[(block[mine] - start) * bs + g[mine] % bs] = v[mine]
    u.x.scatter_forward()
