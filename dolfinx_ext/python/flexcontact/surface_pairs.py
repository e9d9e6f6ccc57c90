"""Node–surface pairs and rigid-target pairs, re-made as the bodies move (rank 0).

Contact nodes are numbered: the slave nodes of every interface first (contact node k is the
slave of pair k), then the master-surface nodes of each interface (all nodes of the tagged
master candidate surface for node–surface pairing, the matched master nodes for node–node),
then one reference node per rigid target, which has no DOFs. The candidate set is fixed, so
F* on it is computed once; re-pairing only changes each pair's master nodes, weights, frame
and offset, and the kernel rebuilds B, x0 and W from the stored F*.

Node–surface (docs/architecture.md §4, "Pairing models"): each slave node is paired with its closest point on the master
facets, with the facet's shape-function weights there. The frame's normal at that point is
the *smoothed* normal Σ w_j n_j (normalised), n_j the measure-weighted mean of the outward
normals of the master facets around node j: it is continuous as a slave node passes from
one facet to the next, and equals the facet normal on flat surfaces. On a curved, faceted
master it differs from the facet normal by at most half the angle between neighbouring facets.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from .mortar import mortar_rows_2d, mortar_rows_3d
from .mortar_3d import full_measures
from .projection import (boundary_nodes, closest_points, facet_measures, facet_normals,
                         nodal_normals)
from .errors import InputError


@dataclass
class SurfacePairs:
    """Pairs of all interfaces with master points inside facets or on rigid targets.

    Same attribute names as NodePairs where they mean the same: ``x`` (n_nodes, d) reference
    coordinates of the contact nodes [m], ``dofs`` (n_nodes, d) their global DOFs (−1 for a
    rigid target's reference node), ``normal`` (m, d), ``area`` (m,) the slave tributary
    measures; and ``masters``/``weights`` (m, j) each pair's master nodes and weights
    (padded with weight 0), ``offset`` (m,) [m], ``node_area`` (n_nodes,) the tributary
    measure of every contact node, ``at_edge`` (m,) pairs whose slave node is on the
    boundary of its candidate surface or whose master point is on the master candidate
    surface's boundary, ``interface`` (m,) the interface index of each pair.
    """

    x: np.ndarray
    dofs: np.ndarray
    normal: np.ndarray
    area: np.ndarray
    masters: np.ndarray
    weights: np.ndarray
    offset: np.ndarray
    node_area: np.ndarray
    at_edge: np.ndarray
    interface: np.ndarray
    pairers: list = field(default_factory=list)
    targets: list = field(default_factory=list)   # RigidTarget per reference node
    # (m,) the measure each pair's normal force acts on: a mortar row's D_jj (it changes
    # with the overlap on re-pairing), else the slave node's tributary measure ``area``
    tributary: Optional[np.ndarray] = None
    crushing_strength: Optional[np.ndarray] = None  # (m,) σ_c per pair [Pa], inf: none

    @property
    def m(self) -> int:
        return self.normal.shape[0]

    @property
    def dim(self) -> int:
        return self.x.shape[1]

    @property
    def n_virtual(self) -> int:
        return len(self.targets)

    def virtual_displacement(self) -> np.ndarray:
        """The rigid targets' prescribed translations, node-major (n_virtual·d,)."""
        if not self.targets:
            return np.zeros(0)
        return np.concatenate([t.current_displacement() for t in self.targets])

    def repair(self, u_c: Optional[np.ndarray] = None) -> None:
        """Re-make every pair at the current positions x + u_c (u_c: the displacement of
        every contact node, node-major, rigid reference nodes included; None: zero)."""
        xcur = self.x if u_c is None else self.x + np.asarray(u_c).reshape(self.x.shape)
        for p in self.pairers:
            masters, weights, normal, offset, edge = p.pair(xcur)
            rows = p.slave_rows
            width = self.masters.shape[1]
            if masters.shape[1] > width:  # mortar rows may reach more master nodes
                more = masters.shape[1] - width
                self.masters = np.hstack([self.masters,
                                          np.repeat(self.masters[:, :1], more, axis=1)])
                self.weights = np.hstack([self.weights, np.zeros((self.m, more))])
                width = masters.shape[1]
            pad = width - masters.shape[1]
            self.masters[rows] = np.hstack([masters, np.repeat(masters[:, :1], pad, axis=1)])
            self.weights[rows] = np.hstack([weights, np.zeros((rows.size, pad))])
            self.normal[rows], self.offset[rows], self.at_edge[rows] = normal, offset, edge
            if self.tributary is None:
                self.tributary = np.asarray(self.area, float).copy()
            measure = getattr(p, "tributary", None)
            if measure is not None:
                self.tributary[rows] = measure


@dataclass
class FixedPairer:
    """Node–node pairs of one interface: they never change."""

    slave_rows: np.ndarray
    master_rows: np.ndarray
    normal: np.ndarray
    slave_edge: np.ndarray
    width: int = 1

    def pair(self, xcur):
        n = self.slave_rows.size
        return (self.master_rows[:, None], np.ones((n, 1)), self.normal, np.zeros(n),
                self.slave_edge)


@dataclass
class NodeToSurfacePairer:
    """Closest-point projection of the slave nodes on the master facets (contact rows)."""

    slave_rows: np.ndarray
    facets: np.ndarray          # (nf, nv) contact-node rows of the master facets
    facet_normal: np.ndarray    # (nf, d) reference outward normals (orientation)
    slave_edge: np.ndarray      # (ns,) slave nodes on the slave surface's boundary
    master_edge: np.ndarray     # (n_nodes,) flags of master-boundary contact nodes
    label: str = ""

    @property
    def width(self) -> int:
        return self.facets.shape[1]

    def pair(self, xcur):
        nodes = np.unique(self.facets)
        local = np.searchsorted(nodes, self.facets)
        X = xcur[nodes]
        fn = facet_normals(X, local, self.facet_normal)
        nn = nodal_normals(X, local, fn)
        best, w, border = closest_points(xcur[self.slave_rows], X, local)
        corners = local[best]                                  # (ns, nv) local rows
        normal = np.einsum("sj,sjk->sk", w, nn[corners])
        normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
        masters = nodes[corners]
        on_master_edge = border & np.all(self.master_edge[masters] | (w <= 1e-12), axis=1)
        return (masters, w, normal, np.zeros(best.size),
                self.slave_edge | on_master_edge)


@dataclass
class SurfaceToSurfacePairer:
    """Mortar rows of the slave nodes with the dual basis (mortar.py; 2D segments, 3D
    triangles and quadrilaterals): slave node j with
    weight 1, master nodes k with weights M_jk / D_jj, along the slave node's normal
    (pointing towards the slave body, as the master's outward normal does). A slave node
    that the master surface does not cover at all gets its closest-point row instead (the
    fallback pairer), so that every row has a gap.
    """

    slave_rows: np.ndarray
    slave_facets: np.ndarray    # (nfs, nv) contact-node rows of the slave facets
    slave_normal: np.ndarray    # (nfs, d) their reference outward normals (orientation)
    fallback: NodeToSurfacePairer
    cutoff_m: float             # largest slave–master distance of an overlap
    width: int = 4
    covered: int = 0            # slave nodes with mortar rows at the last pairing
    tributary: Optional[np.ndarray] = None  # D_jj of the last pairing (∫N_j uncovered)

    def pair(self, xcur):
        fb = self.fallback
        masters, weights, normal, offset, edge = fb.pair(xcur)
        snodes = self.slave_rows
        local_s = np.searchsorted(snodes, self.slave_facets)
        mnodes = np.unique(fb.facets)
        local_m = np.searchsorted(mnodes, fb.facets)
        Xs, Xm = xcur[snodes], xcur[mnodes]
        rows_of = mortar_rows_2d if xcur.shape[1] == 2 else mortar_rows_3d
        D, rows, cols, vals = rows_of(Xs, local_s, self.slave_normal, Xm, local_m,
                                      fb.facet_normal, self.cutoff_m)
        full = self._full_measure(Xs, local_s, self.slave_normal)
        covered = D > 1e-12 * np.maximum(full, 1e-300)
        keep = covered[rows] & (vals != 0.0)
        rows, cols, vals = rows[keep], cols[keep], vals[keep]
        # Sum the couples of each (row, master node), then one row of weights per slave.
        key = rows * mnodes.size + cols
        uniq, inv = np.unique(key, return_inverse=True)
        summed = np.zeros(uniq.size)
        np.add.at(summed, inv.reshape(-1), vals)
        r, c = uniq // mnodes.size, uniq % mnodes.size
        count = np.bincount(r, minlength=snodes.size)
        covered &= count > 0
        self.covered = int(covered.sum())
        width = max(int(count.max(initial=0)), masters.shape[1])
        self.width = max(self.width, width)
        m_out = np.repeat(masters[:, :1], width, axis=1)
        w_out = np.zeros((snodes.size, width))
        m_out[:, :masters.shape[1]] = masters
        w_out[:, :masters.shape[1]] = weights
        rows_c = np.flatnonzero(covered)
        starts = np.concatenate([[0], np.cumsum(count)])
        # Padding of a mortar row: its first master node with weight 0.
        m_out[rows_c] = mnodes[c[starts[rows_c]]][:, None]
        w_out[rows_c] = 0.0
        slot = np.arange(r.size) - starts[r]
        m_out[r, slot] = mnodes[c]
        w_out[r, slot] = summed / D[r]
        fs = facet_normals(Xs, local_s, self.slave_normal)
        ns = nodal_normals(Xs, local_s, fs)
        normal[rows_c] = -ns[rows_c]
        # The cap of a crushable interface acts on the row's own measure (docs/crushing.md).
        self.tributary = np.where(covered, D, full)
        partial = covered & (D < (1 - 1e-9) * full)
        on_master_edge = partial & np.any(fb.master_edge[m_out] & (w_out != 0), axis=1)
        edge = np.where(covered, self.fallback.slave_edge | on_master_edge, edge)
        return m_out, w_out, normal, np.zeros(snodes.size), edge

    @staticmethod
    def _full_measure(X, facets, reference):
        """∫ N_j over the whole slave surface (the lumped tributary measure of each node on
        segments, triangles and parallelograms), as the mortar rows integrate it."""
        nv = facets.shape[1]
        out = np.zeros(X.shape[0])
        if X.shape[1] == 3:
            np.add.at(out, facets.reshape(-1), full_measures(X, facets, reference).reshape(-1))
        else:
            np.add.at(out, facets.reshape(-1), np.repeat(facet_measures(X, facets) / nv, nv))
        return out


@dataclass
class RigidPairer:
    """Slave nodes against a rigid analytic target (one reference node, no DOFs)."""

    slave_rows: np.ndarray
    reference_row: int
    target: object
    slave_edge: np.ndarray
    width: int = 1

    def pair(self, xcur):
        normal, offset = self.target.normals_and_offsets(xcur[self.slave_rows])
        n = self.slave_rows.size
        return (np.full((n, 1), self.reference_row), np.ones((n, 1)), normal, offset,
                self.slave_edge)


def slave_edge_flags(slave: dict, dim: int) -> np.ndarray:
    """Flags of a gathered surface's open edge nodes (zone.py), where the candidate zone
    ends while the body's boundary goes on; without that information, all edge nodes."""
    if "open_edge" in slave:
        return np.asarray(slave["open_edge"], bool)
    facets = np.asarray(slave.get("facets", np.zeros((0, dim), np.int64)))
    return boundary_nodes(facets, dim, np.asarray(slave["x"]).shape[0])


def build_surface_pairs(parts: list, dim: int, labels=None) -> SurfacePairs:
    """SurfacePairs of several interfaces from their gathered surfaces (rank 0).

    ``parts`` holds one tuple per interface: ("node_to_node", slave, NodePairs),
    ("node_to_surface" or "surface_to_surface", slave, master) or ("rigid", slave,
    RigidTarget), ``slave`` and ``master`` the dicts of ``surface_nodes``; ``labels`` name
    the interfaces in errors. Pairs are made in the reference configuration (rigid targets
    at their current displacement).

    Raises ValueError when a surface–surface interface has no slave node that a facing
    master facet covers: the tags name surfaces that do not face each other.
    """
    n_slave = [np.asarray(s["x"]).shape[0] for _, s, _ in parts]
    m = int(sum(n_slave))
    start = np.concatenate([[0], np.cumsum(n_slave)]).astype(np.int64)
    xs, dofs, area_nodes = [], [], []
    for _, s, _ in parts:
        xs.append(np.asarray(s["x"])); dofs.append(np.asarray(s["dofs"]))
        area_nodes.append(np.asarray(s["area"], float))
    next_row = m
    layouts, targets = [], []
    for i, (kind, s, other) in enumerate(parts):
        rows = np.arange(start[i], start[i + 1])
        edge = slave_edge_flags(s, dim)
        if kind == "node_to_node":
            k = other.m
            xs.append(other.x[k:]); dofs.append(other.dofs[k:])
            area_nodes.append(other.area_master)
            layouts.append(FixedPairer(rows, np.arange(next_row, next_row + k), other.normal,
                                       edge))
            next_row += k
        elif kind in ("node_to_surface", "surface_to_surface"):
            nm = np.asarray(other["x"]).shape[0]
            xs.append(np.asarray(other["x"])); dofs.append(np.asarray(other["dofs"]))
            area_nodes.append(np.asarray(other["area"], float))
            layouts.append((rows, np.asarray(other["facets"]) + next_row,
                            np.asarray(other["facet_normal"]), edge, other, next_row))
            next_row += nm
        else:
            layouts.append((rows, other, edge))
            targets.append(other)
    # Rigid reference nodes come last: their DOFs are not PETSc DOFs.
    for t in targets:
        xs.append(t.point_m[None, :]); dofs.append(np.full((1, dim), -1, np.int64))
        area_nodes.append(np.zeros(1))
    n_nodes = next_row + len(targets)
    master_edge = np.zeros(n_nodes, bool)
    pairers, ref_row = [], next_row
    for (kind, s, other), lay in zip(parts, layouts):
        if kind == "node_to_node":
            pairers.append(lay)
        elif kind in ("node_to_surface", "surface_to_surface"):
            rows, facets, fnormal, edge, master, first = lay
            nm = np.asarray(master["x"]).shape[0]
            master_edge[first:first + nm] = slave_edge_flags(master, dim)
            pairer = NodeToSurfacePairer(rows, facets, fnormal, edge, master_edge)
            if kind == "surface_to_surface":
                pairer = _mortar_pairer(pairer, s, master, rows[0], dim)
            pairers.append(pairer)
        else:
            rows, target, edge = lay
            pairers.append(RigidPairer(rows, ref_row, target, edge))
            ref_row += 1
    width = max(p.width for p in pairers)
    interface = np.concatenate([np.full(n, i) for i, n in enumerate(n_slave)])
    pairs = SurfacePairs(
        x=np.vstack(xs), dofs=np.vstack(dofs).astype(np.int64), normal=np.zeros((m, dim)),
        area=np.concatenate(area_nodes[:len(parts)]),
        masters=np.zeros((m, width), np.int64), weights=np.zeros((m, width)),
        offset=np.zeros(m), node_area=np.concatenate(area_nodes),
        at_edge=np.zeros(m, bool), interface=interface, pairers=pairers, targets=targets)
    u0 = np.zeros(pairs.x.shape)
    if targets:
        u0[n_nodes - len(targets):] = pairs.virtual_displacement().reshape(-1, dim)
    pairs.repair(u0.reshape(-1))
    for i, p in enumerate(pairers):
        if isinstance(p, SurfaceToSurfacePairer) and p.covered == 0:
            label = labels[i] if labels else f"interface {i}"
            raise InputError(
                f"surface–surface contact ({label}): none of the {p.slave_rows.size} slave "
                "nodes is covered by a master facet facing it (outward normals opposite, "
                f"within {p.cutoff_m:.3g} m): the slave and master tags name surfaces that "
                "do not face each other")
    return pairs


def _mortar_pairer(fallback: NodeToSurfacePairer, slave: dict, master: dict, first_row: int,
                   dim: int) -> SurfaceToSurfacePairer:
    """The surface–surface pairer of one interface; its overlaps count up to half the
    diagonal of the two candidate surfaces' bounding box away from the slave surface (the
    facing test already excludes the far side of a closed surface)."""
    pts = np.vstack([np.asarray(slave["x"]), np.asarray(master["x"])])
    cutoff = 0.5 * float(np.linalg.norm(np.ptp(pts, axis=0)))
    return SurfaceToSurfacePairer(
        fallback.slave_rows, np.asarray(slave["facets"]) + first_row,
        np.asarray(slave["facet_normal"]), fallback, cutoff)
