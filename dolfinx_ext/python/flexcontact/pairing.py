"""Node–node pairing of two contact surfaces (the seed's first contact model).

``match_nodes`` runs on rank 0 with the gathered surface data of ``surface_nodes``;
``pair_interfaces`` does it for every interface of a problem. Each slave node is
paired with the master node at the same tangential position (the mesh must have matching
interface nodes); the local frame comes from the master's outward normal, so the normal gap
of a pair is n · (X_s − X_m) ≥ 0 when the bodies are apart.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from . import compat
from .surface import surface_nodes
from .surface_pairs import build_surface_pairs, slave_edge_flags
from . import names
from .mesh_bodies import body_labels
from .mpi import raise_on_every_rank
from .zone import open_edge_flags
from .errors import InputError


class NonMatchingError(InputError):
    """The two contact surfaces have no matching nodes (counts differ, or nodes do not face
    each other one to one in any direction): a mesh property, not a set-up error."""


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
    at_edge: Optional[np.ndarray] = None  # (m,) slave node on an open edge (zone.py)
    interface: Optional[np.ndarray] = None  # (m,) index of each pair's interface

    @property
    def m(self) -> int:
        return self.normal.shape[0]

    @property
    def dim(self) -> int:
        return self.normal.shape[1]

    # The SurfacePairs view of node–node pairs (master of pair k is contact node m + k).
    @property
    def masters(self) -> np.ndarray:
        return np.arange(self.m, 2 * self.m)[:, None]

    @property
    def weights(self) -> np.ndarray:
        return np.ones((self.m, 1))

    @property
    def offset(self) -> np.ndarray:
        return np.zeros(self.m)

    @property
    def node_area(self) -> np.ndarray:
        return np.concatenate([self.area, self.area_master])

    @property
    def tributary(self) -> np.ndarray:
        """The measure each pair's normal force acts on: the slave's tributary measure."""
        return self.area

    crushing_strength: Optional[np.ndarray] = None  # (m,) σ_c per pair [Pa], inf: none

    n_virtual = 0


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
        raise NonMatchingError(
            f"node–node contact{where}: the slave surface has {ns} nodes and the master "
            f"surface {nm}; node–node pairing needs matching interface nodes; use "
            f"pairing='surface_to_surface' or 'node_to_surface' for non-matching meshes")
    if ns == 0:
        raise InputError(f"node–node contact{where}: the contact surfaces have no nodes")
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
        text, facing = _unmatched_message(xs, np.asarray(slave["normal"]), xm, offset, worst,
                                          tolerance, where)
        raise (ValueError if facing else NonMatchingError)(text)
    taken, counts = np.unique(partner, return_counts=True)
    if np.any(counts > 1):
        dup = int(taken[np.argmax(counts)])
        raise NonMatchingError(
            f"node–node contact{where}: {int(counts.max())} slave nodes match the same master "
            f"node at {xm[dup].tolist()}; the surfaces' nodes do not match one to one")
    return NodePairs(
        x=np.vstack([xs, xm[partner]]),
        dofs=np.vstack([np.asarray(slave["dofs"]), np.asarray(master["dofs"])[partner]]),
        normal=normals[partner],
        area=np.asarray(slave["area"], dtype=float),
        area_master=np.asarray(master["area"], dtype=float)[partner],
        at_edge=slave_edge_flags(slave, xs.shape[1]) if "facets" in slave else None,
    )


def _unmatched_message(xs, ns, xm, offset, worst, tolerance, where) -> tuple[str, bool]:
    """Why node–node pairing failed, and whether the nodes face each other one to one along
    the slave's normals but not along the master's (a curved or tilted master: True) or do
    not match at all (False)."""
    partner, off = [], []
    for x, n in zip(xs, ns):
        d = xm - x
        t = np.sqrt(np.maximum(np.einsum("mk,mk->m", d, d) - (d @ n) ** 2, 0.0))
        partner.append(int(np.argmin(t)))
        off.append(float(t[partner[-1]]))
    facing = (xs.shape[0] == xm.shape[0] and max(off) <= tolerance
              and np.unique(partner).size == len(partner))
    head = (f"node–node contact{where}: slave node at {xs[worst].tolist()} has no master "
            f"node along the master surface's normal within the tangential tolerance "
            f"{tolerance:g} m (the nearest is {offset[worst]:.3g} m off that line)")
    if facing:
        return (head + "; the two surfaces' nodes do face each other one to one, but along "
                "the slave's normals, not the master's, as on a curved master surface. Use "
                "pairing='node_to_surface' or 'surface_to_surface' (any choice of slave and "
                "master), or make the flat surface the master"), True
    return (head + "; the contact surfaces have no matching nodes. Use "
            "pairing='surface_to_surface' or 'node_to_surface' for non-matching "
            "meshes"), False


# "auto": node–node where the surfaces' nodes match, surface–surface (the pairing that passes
# the patch test on non-matching meshes) where they do not.
PAIRINGS = names.PAIRINGS


def pair_interfaces(V, interfaces: Sequence, comm):
    """Pairs of all contact interfaces in one node-major numbering.

    Each interface gives ``facet_tags``, ``slave``, ``master`` (a tag, or a RigidTarget),
    ``mu``, ``tolerance_m`` (None: 1e-6 of the surfaces' extent), ``label`` and optionally
    ``pairing`` ("node_to_node", the default, or "node_to_surface"). Returns (pairs, μ per
    pair) on rank 0, (None, empty) elsewhere, and the pair count m on every rank. The pairs
    are NodePairs when every interface is node–node between tagged surfaces, SurfacePairs
    (surface_pairs.py) otherwise. A pairing error is raised as ValueError on every rank.
    """
    msh = V.mesh
    compat.create_connectivity(msh, msh.topology.dim - 1, msh.topology.dim)
    root = comm.rank == 0
    parts, mus, sigmas, error, surfaces = [], [], [], None, []
    for itf in interfaces:
        rigid = not isinstance(itf.master, (int, np.integer))
        kind = "rigid" if rigid else getattr(itf, "pairing", "node_to_node")
        # Collective: every rank takes part even after an error on rank 0.
        s = _candidate_surface(V, itf.facet_tags, itf.slave)
        m = itf.master if rigid else _candidate_surface(V, itf.facet_tags, itf.master)
        surfaces.append((s, None if rigid else m))
        if root and error is None:
            try:
                kind, other = _resolve(kind, s, m, itf, V.mesh.geometry.dim)
                parts.append((kind, s, other))
                mus.append(np.full(np.asarray(s["x"]).shape[0], float(itf.mu)))
                sigma = getattr(itf, "crushing_strength_Pa", None)
                sigmas.append(np.full(np.asarray(s["x"]).shape[0],
                                      np.inf if sigma is None else float(sigma)))
            except ValueError as e:
                error = str(e)
    if root and error is None and any(k != "node_to_node" for k, _, _ in parts):
        try:
            pairs = build_surface_pairs(parts, V.mesh.geometry.dim,
                                        [itf.label for itf in interfaces])
        except ValueError as e:
            error = str(e)
    elif root and error is None:
        pairs = concat([p for _, _, p in parts])
        pairs.interface = np.concatenate([np.full(p.m, i) for i, (_, _, p) in
                                          enumerate(parts)])
    raise_on_every_rank(comm, error)
    _check_bodies(V, interfaces, surfaces, comm)
    kinds = comm.bcast([k for k, _, _ in parts] if root else None, root=0)
    for itf, kind in zip(interfaces, kinds):
        itf.pairing_used = kind   # what "auto" chose (and "rigid" for rigid targets)
    pairs = pairs if root else None
    if root:
        pairs.crushing_strength = np.concatenate(sigmas)
    mu = np.concatenate(mus) if root else np.zeros(0)
    return pairs, mu, comm.bcast(pairs.m if root else None, root=0)


def pair_caps(pairs) -> Optional[np.ndarray]:
    """The caps of the pairs' normal forces, σ_c × the measure each acts on [N; N/m in 2D]
    (inf where the interface does not crush), or None when no interface crushes (rank 0).
    A mortar row's measure is its D_jj of the current pairing, so its cap follows the
    overlap, while the slave node's crush depth carries over (docs/crushing.md)."""
    sigma = getattr(pairs, "crushing_strength", None)
    if sigma is None or not np.isfinite(sigma).any():
        return None
    finite = np.isfinite(sigma)
    caps = np.full(sigma.shape, np.inf)
    caps[finite] = sigma[finite] * np.asarray(pairs.tributary, float)[finite]
    # A slave node with no measure (nothing covered) gets no force at all: a tiny cap
    # rather than zero, which the kernel refuses.
    return np.where(caps > 0.0, caps, np.finfo(float).tiny)


class SelfContactWarning(UserWarning):
    """A contact interface's master surface lies on the slave's own body, as asked
    (``ContactInterface(self_contact=True)``)."""


def _check_bodies(V, interfaces: Sequence, surfaces: list, comm) -> None:
    """ValueError naming both tags when an interface's master surface lies on the slave's
    own body (a boundary tag mixed up with the master tag), or a SelfContactWarning where
    the interface says a self-contact is meant. Collective."""
    if all(getattr(itf, "rigid", False) for itf in interfaces):
        return  # a rigid target is no body of the mesh
    bs = V.dofmap.index_map_bs
    root = comm.rank == 0
    blocks, spans = [], []
    if root:
        for s, m in surfaces:
            if m is None:
                spans.append(None)
                continue
            a = np.asarray(s["dofs"])[:, 0] // bs
            b = np.asarray(m["dofs"])[:, 0] // bs
            spans.append((len(blocks), a.size, b.size))
            blocks.extend(a.tolist())
            blocks.extend(b.tolist())
    labels = body_labels(V, np.asarray(blocks, dtype=np.int64) if root else None)
    error, same = None, []
    if root:
        for itf, span in zip(interfaces, spans):
            if span is None:
                continue
            start, ns, nm = span
            shared = np.intersect1d(labels[start:start + ns], labels[start + ns:start + ns + nm])
            if shared.size == 0:
                continue
            if getattr(itf, "self_contact", False):
                same.append(itf.label)
                continue
            error = (f"contact interface {itf.label}: the master surface (facet tag "
                     f"{itf.master}) lies on the same body as the slave surface (facet tag "
                     f"{itf.slave}): the mesh connects their nodes. A boundary tag may have "
                     "been given as the master; contact needs the tag of the other body's "
                     "surface. For a body touching itself, pass self_contact=True")
            break
    raise_on_every_rank(comm, error)
    for label in same:
        warnings.warn(f"contact interface {label}: self-contact: the master surface lies on "
                      "the slave's own body", SelfContactWarning, stacklevel=4)


def _candidate_surface(V, facet_tags, value: int) -> dict:
    """surface_nodes with the open-edge flags of the candidate-zone guard. Collective."""
    s = surface_nodes(V, facet_tags, value)
    flags = open_edge_flags(V, facet_tags, value, s)
    if V.mesh.comm.rank == 0:
        s["open_edge"] = flags
    return s


def _resolve(kind: str, s: dict, m, itf, dim: int):
    """The pairing of one interface and what build_surface_pairs needs of the master:
    NodePairs for node–node, the master surface (or the rigid target) otherwise. "auto" is
    node–node where the nodes match, else surface–surface (rank 0)."""
    if kind == "auto":
        try:
            return "node_to_node", _node_pairs(s, m, itf)
        except ValueError:
            # Any surfaces node–node cannot pair (counts differ, nodes off the master's
            # normals as when slave and master are swapped on a curved surface):
            # surface–surface pairs them, or says itself why it cannot.
            return "surface_to_surface", m
    if kind == "node_to_node":
        return kind, _node_pairs(s, m, itf)
    return kind, m


def _node_pairs(s: dict, m: dict, itf) -> NodePairs:
    tol = itf.tolerance_m
    if tol is None:
        pts = np.vstack([s["x"], m["x"]])
        tol = 1e-6 * max(float(np.ptp(pts, axis=0).max()), 1e-300)
    return match_nodes(s, m, tol, itf.label)


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
        at_edge=(np.concatenate([p.at_edge for p in parts])
                 if all(p.at_edge is not None for p in parts) else None),
    )
