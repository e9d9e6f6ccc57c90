"""Node–node pairing of two contact surfaces (the seed's first contact model).

``match_nodes`` runs on rank 0 with the gathered surface data of ``surface_nodes``;
``pair_interfaces`` does it for every interface of a problem. Each slave node is
paired with the master node at the same tangential position (the mesh must have matching
interface nodes); the local frame comes from the master's outward normal, so the normal gap
of a pair is n · (X_s − X_m) ≥ 0 when the bodies are apart.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from . import compat
from .surface import surface_nodes
from .mpi import raise_on_every_rank


@dataclass
class NodePairs:
    """Pairs of one contact interface, in the node-major contact numbering.

    Contact node k < m is the slave of pair k, node m + k its master. ``dofs`` holds the
    global PETSc DOF indices of all 2m contact nodes (2m × d).
    """

    x: np.ndarray          # (2m, d) node coordinates [m]
    dofs: np.ndarray       # (2m, d) global DOF indices
    normal: np.ndarray     # (m, d) master outward unit normal per pair
    area: np.ndarray       # (m,) slave tributary length [m] (2D) or area [m²] (3D)
    area_master: np.ndarray  # (m,) master tributary measure

    @property
    def m(self) -> int:
        return self.normal.shape[0]

    @property
    def dim(self) -> int:
        return self.normal.shape[1]


def match_nodes(slave: dict, master: dict, tolerance: float, label: str = "") -> NodePairs:
    """Pair every slave node with the master node opposite it.

    ``tolerance`` is the largest tangential offset accepted, in metres. Raises ValueError
    when the counts differ, a slave node has no master within the tolerance, or two slave
    nodes claim the same master node.
    """
    xs, xm = np.asarray(slave["x"]), np.asarray(master["x"])
    ns, nm = xs.shape[0], xm.shape[0]
    where = f" ({label})" if label else ""
    if ns != nm:
        raise ValueError(
            f"node–node contact{where}: the slave surface has {ns} nodes and the master "
            f"surface {nm}; node–node pairing needs matching interface nodes")
    if ns == 0:
        raise ValueError(f"node–node contact{where}: the contact surfaces have no nodes")
    normals = np.asarray(master["normal"])
    partner = np.empty(ns, dtype=np.int64)
    offset = np.empty(ns)
    chunk = max(1, 4_000_000 // max(nm, 1))
    for start in range(0, ns, chunk):
        d = xs[start:start + chunk, None, :] - xm[None, :, :]          # (c, nm, dim)
        dn = np.einsum("cmk,mk->cm", d, normals)
        dt = np.sqrt(np.maximum(np.einsum("cmk,cmk->cm", d, d) - dn**2, 0.0))
        best = np.argmin(dt, axis=1)
        partner[start:start + chunk] = best
        offset[start:start + chunk] = dt[np.arange(best.size), best]
    worst = int(np.argmax(offset))
    if offset[worst] > tolerance:
        raise ValueError(
            f"node–node contact{where}: slave node at {xs[worst].tolist()} has no master node "
            f"within the tangential tolerance {tolerance:g} m (nearest is {offset[worst]:.3g} m "
            f"away); the contact surfaces have no matching nodes")
    taken, counts = np.unique(partner, return_counts=True)
    if np.any(counts > 1):
        dup = int(taken[np.argmax(counts)])
        raise ValueError(
            f"node–node contact{where}: {int(counts.max())} slave nodes match the same master "
            f"node at {xm[dup].tolist()}; the surfaces' nodes do not match one to one")
    return NodePairs(
        x=np.vstack([xs, xm[partner]]),
        dofs=np.vstack([np.asarray(slave["dofs"]), np.asarray(master["dofs"])[partner]]),
        normal=normals[partner],
        area=np.asarray(slave["area"], dtype=float),
        area_master=np.asarray(master["area"], dtype=float)[partner],
    )


def pair_interfaces(V, interfaces: Sequence, comm) -> tuple[Optional[NodePairs], np.ndarray, int]:
    """Pairs of all contact interfaces in one node-major numbering.

    Each interface gives ``facet_tags``, ``slave``, ``master``, ``mu``, ``tolerance_m`` (None:
    1e-6 of the surfaces' extent) and ``label``. Returns (pairs, μ per pair) on rank 0,
    (None, empty) elsewhere, and the pair count m on every rank. A pairing error is raised
    as ValueError on every rank.
    """
    msh = V.mesh
    compat.create_connectivity(msh, msh.topology.dim - 1, msh.topology.dim)
    root = comm.rank == 0
    parts, mus, error = [], [], None
    for itf in interfaces:
        # Collective: every rank takes part even after an error on rank 0.
        s = surface_nodes(V, itf.facet_tags, itf.slave)
        m = surface_nodes(V, itf.facet_tags, itf.master)
        if root and error is None:
            try:
                tol = itf.tolerance_m
                if tol is None:
                    pts = np.vstack([s["x"], m["x"]])
                    tol = 1e-6 * max(float(np.ptp(pts, axis=0).max()), 1e-300)
                parts.append(match_nodes(s, m, tol, itf.label))
                mus.append(np.full(parts[-1].m, float(itf.mu)))
            except ValueError as e:
                error = str(e)
    raise_on_every_rank(comm, error)
    pairs = concat(parts) if root else None
    mu = np.concatenate(mus) if root else np.zeros(0)
    return pairs, mu, comm.bcast(pairs.m if root else None, root=0)


def concat(parts: list[NodePairs]) -> NodePairs:
    """Pairs of several interfaces in one node-major numbering: all slaves, then all
    masters in the same order."""
    if len(parts) == 1:
        return parts[0]
    return NodePairs(
        x=np.vstack([p.x[:p.m] for p in parts] + [p.x[p.m:] for p in parts]),
        dofs=np.vstack([p.dofs[:p.m] for p in parts] + [p.dofs[p.m:] for p in parts]),
        normal=np.vstack([p.normal for p in parts]),
        area=np.concatenate([p.area for p in parts]),
        area_master=np.concatenate([p.area_master for p in parts]),
    )
