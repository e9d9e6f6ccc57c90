"""What an increment produced: its summary, its contact data, and the contact fields
(pressure, tangential traction, status, stress) written back into DOLFINx Functions.

Everything here reads the dict that the kernel's ``CondensedContact.step`` returned; none of
the method's algebra is redone in NumPy.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
from mpi4py import MPI

import dolfinx.fem

from . import compat
from .states import CRUSH, OPEN, SLIP, STICK, STATE_NAMES  # noqa: F401  (STATE_NAMES: re-exported)
from .writeback import set_nodal_values
from .pairing import NodePairs
from .errors import SolveError



@dataclass
class IncrementSummary:
    """What one increment produced; forces per unit thickness in 2D [N/m], in N in 3D.

    ``tangential_force`` is the total friction force on the slave surface in global axes
    (x, y in 2D; x, y, z in 3D).
    """

    increment: int
    normal_force: float
    tangential_force: list
    stick: int
    slip: int
    open: int
    max_penetration_m: float
    max_penetration_rel: float
    residual: float
    iterations: int
    state_changes: int
    solver: str
    time_s: float
    zone_edge: list = field(default_factory=list)  # interfaces whose contact reached an
    #                                                open edge of a candidate surface
    crush: int = 0                  # pairs at their force cap (crushable interfaces)
    crush_depth_max_m: float = 0.0  # deepest crush of a slave node so far
    crush_work: float = 0.0         # energy the crushing dissipated in the increment [J]

    def line(self) -> str:
        t = np.linalg.norm(self.tangential_force)
        return (f"increment {self.increment:3d}: N = {self.normal_force:11.4e}  "
                f"|T| = {t:11.4e}  stick/slip/open = {self.stick}/{self.slip}/{self.open}  "
                f"penetration = {self.max_penetration_rel:8.1e}  residual = {self.residual:8.1e}"
                f"  {self.solver} ({self.iterations} it)"
                + (f"  crush = {self.crush} (deepest {self.crush_depth_max_m:.3e} m)"
                   if self.crush_depth_max_m > 0 else ""))


@dataclass
class IncrementResult:
    """Contact data of one increment, on rank 0 (empty arrays elsewhere)."""

    summary: IncrementSummary
    lam: np.ndarray        # (m, d) λ in the local frame (λ_n ≥ 0 compression) [N or N/m]
    gap: np.ndarray        # (m, d) total gap x in the local frame [m]
    states: np.ndarray     # (m,) states.OPEN, STICK, SLIP or CRUSH
    slip_increment: np.ndarray  # (m, d-1) tangential slip in this increment [m]
    tangential: Optional[np.ndarray] = None  # (m, d) friction force per pair, global axes
    crush_depth: Optional[np.ndarray] = None  # (m,) δ of each pair's slave node [m]


def record_increment(out: Optional[dict], number: int, u, comm, dim: int,
                     elapsed: float) -> IncrementResult:
    """IncrementResult from the kernel's step dict ``out`` (rank 0; None elsewhere). The
    summary is broadcast; the penetration is also given relative to max |u|."""
    root = comm.rank == 0
    umax = comm.allreduce(float(np.max(np.abs(u.x.array), initial=0.0)), op=MPI.MAX)
    summary = None
    if root:
        rep = out["report"]
        states = out["states"].astype(int)
        pen = float(out["max_penetration"])
        summary = IncrementSummary(
            increment=number,
            normal_force=float(out["normal_force"]),
            tangential_force=out["tangential_force"].tolist(),
            stick=int((states == STICK).sum()), slip=int((states == SLIP).sum()),
            open=int((states == OPEN).sum()),
            max_penetration_m=pen,
            max_penetration_rel=pen / umax if umax > 0 else 0.0,
            residual=float(rep["residual"]), iterations=int(rep["iterations"]),
            state_changes=int(rep["state_changes"]), solver=str(rep["solver"]),
            time_s=elapsed, crush=int((states == CRUSH).sum()),
            crush_depth_max_m=float(np.max(out.get("crush_depth", np.zeros(0)), initial=0.0)),
            crush_work=float(out.get("crush_work", 0.0)))
    summary = comm.bcast(summary, root=0)
    if root:
        return IncrementResult(summary, out["lambda"], out["gap"], states, out["slip"],
                               out["pair_tangential"], out.get("crush_depth"))
    e = np.zeros((0, dim))
    return IncrementResult(summary, e, e, np.zeros(0, int), e[:, 1:], e)


def nodal_contact(inc: IncrementResult, pairs):
    """Pressure, tangential traction (global axes) and status (states.py: OPEN, STICK, SLIP,
    CRUSH) at every contact node: a slave node carries its pair's force over its tributary measure,
    a master node the equal and opposite forces Σ_k w_kj (…) of the pairs that use it."""
    m, n = pairs.m, pairs.x.shape[0]
    masters, weights = pairs.masters, pairs.weights
    force_n = np.zeros(n)
    force_t = np.zeros((n, pairs.x.shape[1]))
    state = np.full(n, float(OPEN))
    force_n[:m] += inc.lam[:, 0]
    force_t[:m] += inc.tangential
    state[:m] = inc.states
    for j in range(masters.shape[1]):
        w = weights[:, j]
        np.add.at(force_n, masters[:, j], w * inc.lam[:, 0])
        np.add.at(force_t, masters[:, j], -w[:, None] * inc.tangential)
        used = w > 0
        np.maximum.at(state, masters[used, j], inc.states[used].astype(float))
    area = np.where(pairs.node_area > 0, pairs.node_area, np.inf)
    return force_n / area, force_t / area[:, None], state


def impact_step_forces(out: dict, h: float):
    """An impact step's kernel output as :func:`nodal_contact` reads an increment: the pair
    forces as the step's mean (impulse / h), with their states."""
    from types import SimpleNamespace
    return SimpleNamespace(lam=np.asarray(out["impulse"]) / h, states=np.asarray(out["states"]),
                           tangential=np.asarray(out["pair_tangential"]) / h)


def peak_pressure_Pa(inc, pairs, slave_only: bool = False) -> float:
    """The largest nodal contact pressure of :func:`nodal_contact` (Pa, 0 without contact),
    over the nodes that carry DOFs (not rigid targets' reference nodes), as
    ContactFields.write_back sets it. ``slave_only``: over the slave nodes only, whose
    pressure a crushing interface caps; a master node's, the slave forces spread over its
    own tributary measure, may exceed the cap."""
    pressure = nodal_contact(inc, pairs)[0]
    carries = pairs.dofs[:, 0] >= 0
    if slave_only:
        pressure, carries = pressure[:pairs.m], carries[:pairs.m]
    return float(pressure[carries].max(initial=0.0))


class ContactFields:
    """The output Functions: displacement, contact pressure, tangential traction, status
    (1 open, 2 stick, 3 slip, 4 crush) and, if ``stress`` is given (u -> UFL scalar), a DG0 stress."""

    def __init__(self, V, comm, stress: Optional[Callable] = None):
        msh = V.mesh
        self.V, self.comm, self.dim = V, comm, msh.geometry.dim
        self.u = dolfinx.fem.Function(V, name="displacement")
        Q = compat.scalar_space(msh, "Lagrange", 1)
        self.pressure = dolfinx.fem.Function(Q, name="contact_pressure")
        self.traction = dolfinx.fem.Function(V, name="tangential_traction")
        self.status = dolfinx.fem.Function(Q, name="contact_status")
        # Scalar fields are written at the vector space's node blocks: the numberings must agree.
        nQ = Q.dofmap.index_map.size_local
        nV = V.dofmap.index_map.size_local
        same = nQ == nV and np.allclose(Q.tabulate_dof_coordinates()[:nQ],
                                        V.tabulate_dof_coordinates()[:nV])
        if not comm.allreduce(same, op=MPI.LAND):
            raise SolveError("scalar and vector P1 spaces number their nodes differently; "
                               "contact fields cannot be written back")
        self.von_mises = None
        if stress is not None:
            self.von_mises = dolfinx.fem.Function(compat.scalar_space(msh, "DG", 0),
                                                  name="von_mises")
            # Compiled once: an Expression per write costs more than the interpolation.
            self._stress_expr = dolfinx.fem.Expression(
                stress(self.u), compat.interpolation_points(self.von_mises.function_space))

    def write_back(self, inc: IncrementResult, pairs: Optional[NodePairs]) -> None:
        """Contact fields of an increment at the slave and master nodes (collective)."""
        d = self.dim
        if self.comm.rank == 0:
            pressure, trac, status = nodal_contact(inc, pairs)
            real = pairs.dofs[:, 0] >= 0          # rigid targets' reference nodes: no DOFs
            dofs_v = pairs.dofs[real]
            blocks = dofs_v[:, :1] // d
            pressure, trac, status = pressure[real, None], trac[real], status[real, None]
        else:
            blocks = np.zeros((0, 1), np.int64)
            pressure = status = np.zeros((0, 1))
            trac = np.zeros((0, d))
            dofs_v = np.zeros((0, d), np.int64)
        set_nodal_values(self.pressure, blocks, pressure)
        set_nodal_values(self.status, blocks, status)
        set_nodal_values(self.traction, dofs_v, trac)
        if self.von_mises is not None:
            self.von_mises.interpolate(self._stress_expr)

    def all(self) -> list:
        """The Functions, in the order ResultWriter writes them."""
        f = [self.u, self.pressure, self.traction, self.status]
        return f + ([self.von_mises] if self.von_mises is not None else [])
