"""Static frictional contact between deformable bodies, loaded in increments.

The flow is one-directional (DESIGN.md §3): DOLFINx assembles K and p; one MUMPS
factorization gives the flexibility F* = (K⁻¹)_cc on the contact DOFs; the kernel solves the
condensed stick/slip/open problem x = W λ + q per increment (W = B F* Bᵀ, q = B K⁻¹ p + x0);
u = K⁻¹ (p + Bᵀ λ) comes from the same factor; results go back into DOLFINx Functions.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import numpy as np
import scipy.sparse as sp
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc

from . import _cpp, compat
from .pairing import NodePairs, match_nodes
from .rigid_modes import check_bodies
from .surface import surface_nodes
from .writeback import set_nodal_values

STATE_NAMES = {0: "open", 1: "stick", 2: "slip"}


@dataclass
class ContactInterface:
    """Two tagged contact surfaces and their Coulomb friction coefficient.

    ``slave`` is the contact surface (the softer body's, in the seed's words) and ``master``
    the target; the master's outward normal defines the local frame. ``tolerance_m`` is the
    largest tangential offset between paired nodes (default: 1e-6 of the surfaces' extent).
    """

    facet_tags: object
    slave: int
    master: int
    mu: float
    tolerance_m: Optional[float] = None
    name: str = ""

    def __post_init__(self):
        mu = self.mu
        if not isinstance(mu, (int, float, np.floating)) or not math.isfinite(mu) or mu < 0:
            raise ValueError(f"contact interface {self.label}: friction coefficient mu={mu!r}; "
                             "it must be a finite number ≥ 0")
        if self.slave == self.master:
            raise ValueError(f"contact interface {self.label}: slave and master are the same "
                             f"tag ({self.slave})")

    @property
    def label(self) -> str:
        return self.name or f"slave tag {self.slave} / master tag {self.master}"


@dataclass
class IncrementSummary:
    """What one increment produced; forces per unit thickness in 2D [N/m], in N in 3D."""

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

    def line(self) -> str:
        t = np.linalg.norm(self.tangential_force)
        return (f"increment {self.increment:3d}: N = {self.normal_force:11.4e}  "
                f"|T| = {t:11.4e}  stick/slip/open = {self.stick}/{self.slip}/{self.open}  "
                f"penetration = {self.max_penetration_rel:8.1e}  residual = {self.residual:8.1e}"
                f"  {self.solver} ({self.iterations} it)")


@dataclass
class IncrementResult:
    """Contact data of one increment, on rank 0 (empty arrays elsewhere)."""

    summary: IncrementSummary
    lam: np.ndarray        # (m, d) λ in the local frame (λ_n ≥ 0 compression) [N or N/m]
    gap: np.ndarray        # (m, d) total gap x in the local frame [m]
    states: np.ndarray     # (m,) 0 open, 1 stick, 2 slip
    slip_increment: np.ndarray  # (m, d-1) tangential slip in this increment [m]


class ContactProblem:
    """Static contact of deformable bodies with Coulomb friction, by condensation.

    Parameters
    ----------
    a : UFL bilinear form of linear elasticity (K); must not change between increments.
    L : UFL linear form of the loads (p), or None. Loads change between increments through
        the dolfinx Constants/Functions it contains, set by ``solve``'s ``load`` callback.
    bcs : Dirichlet conditions (values may also change per increment).
    contact : one ContactInterface or a list of them.
    bodies : optional ``(cell_tags, {name: value})``; each body's rigid modes are checked
        so that a singular K is reported with the body's name.
    stress : optional callable u -> UFL scalar (e.g. von Mises) written as a DG0 field.
    solver : kernel SolverOptions (tolerance, max_iterations, chain).
    flexibility : "schur" (MUMPS Schur complement; on several ranks PETSc cannot solve with
        that factor, so MUMPS selected inverse entries are used: "inverse_entries"),
        "inverse_entries", or "matmatsolve" (a multi-right-hand-side solve, the reference).
        Each makes one sparse factorization, which then serves every solve.
    """

    def __init__(self, a, L, bcs: Sequence, contact, *, bodies=None,
                 stress: Optional[Callable] = None, solver=None, flexibility: str = "schur"):
        self.interfaces = list(contact) if isinstance(contact, (list, tuple)) else [contact]
        if not self.interfaces:
            raise ValueError("no contact interface given")
        self.bcs = list(bcs)
        self.a_form = dolfinx.fem.form(a)
        self.L_form = dolfinx.fem.form(L) if L is not None else None
        self.V = a.arguments()[0].ufl_function_space()
        self.msh = self.V.mesh
        self.comm = self.msh.comm  # the mesh's: it may live on a sub-communicator
        self.dim = self.msh.geometry.dim
        self.stress = stress
        self.options = solver if solver is not None else _cpp.SolverOptions()
        self.flexibility_method = flexibility
        self.timings = {}
        self.increments: list[IncrementResult] = []
        self.local_problem = None  # rank 0: the last increment's {dim, W, q, mu}

        t0 = time.perf_counter()
        self.K = dolfinx.fem.petsc.assemble_matrix(self.a_form, bcs=self.bcs)
        self.K.assemble()
        self.timings["assemble_K_s"] = time.perf_counter() - t0
        if bodies is not None:
            cell_tags, names = bodies
            check_bodies(self.K, self.V, cell_tags, names, self.comm)
        self._pair()
        self._condense()
        self._make_outputs()

    # ---- set-up -------------------------------------------------------------------
    def _pair(self):
        fdim = self.msh.topology.dim - 1
        compat.create_connectivity(self.msh, fdim, self.msh.topology.dim)
        root = self.comm.rank == 0
        parts, error = [], None
        mus = []
        for itf in self.interfaces:
            s = surface_nodes(self.V, itf.facet_tags, itf.slave)
            m = surface_nodes(self.V, itf.facet_tags, itf.master)
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
        error = self.comm.bcast(error, root=0)
        if error:
            raise ValueError(error)
        if root:
            self.pairs = _concat(parts)
            self.mu = np.concatenate(mus)
        else:
            self.pairs = None
            self.mu = np.zeros(0)
        self.m = self.comm.bcast(self.pairs.m if root else None, root=0)

    def _constrained_mask(self):
        """True for the contact DOFs that a Dirichlet condition fixes (rank 0)."""
        marker = self.K.createVecLeft()
        marker.set(1.0)
        dolfinx.fem.petsc.set_bc(marker, self.bcs, scale=0.0)
        vals = self._gather(marker)
        marker.destroy()
        return vals == 0.0 if vals is not None else None

    def _condense(self):
        root = self.comm.rank == 0
        d = self.dim
        dofs = self.pairs.dofs.reshape(-1).astype(np.int64) if root else np.zeros(0, np.int64)
        self._contact_dofs = dofs
        is_from = PETSc.IS().createGeneral(dofs.astype(PETSc.IntType), comm=self.comm)
        self._seq = PETSc.Vec().createSeq(dofs.size, comm=PETSc.COMM_SELF)
        is_to = PETSc.IS().createStride(dofs.size, 0, 1, comm=PETSc.COMM_SELF)
        self._scatter = PETSc.Scatter().create(self.K.createVecLeft(), is_from, self._seq, is_to)
        constrained = self._constrained_mask()

        t0 = time.perf_counter()
        F, self.factor, info = _cpp.flexibility(self.K, dofs, self.flexibility_method)
        self.timings["flexibility_s"] = time.perf_counter() - t0
        self.flex_info = dict(info)
        self.n_contact_dofs = self.comm.bcast(dofs.size if root else None, root=0)

        if root:
            F = np.array(F, dtype=float)
            # A contact DOF held by a Dirichlet condition does not move under contact forces:
            # its flexibility is zero (K's identity row would otherwise make it 1 m/N).
            F[constrained, :] = 0.0
            F[:, constrained] = 0.0
            self._constrained = constrained
            kpairs = []
            m = self.pairs.m
            for k in range(m):
                p = _cpp.ContactPair()
                p.slave = k
                p.masters = [m + k]
                p.weights = [1.0]
                p.frame = _cpp.frame_from_normal(self.pairs.normal[k])
                kpairs.append(p)
            self._kpairs = kpairs
            rows, cols, vals, shape = _cpp.gap_operator(d, 2 * m, kpairs)
            self.B = sp.csr_matrix((vals, (rows, cols)), shape=tuple(shape))
            self.frames = np.array([p.frame for p in kpairs])
            self.x0 = np.asarray(_cpp.initial_gap(kpairs, self.pairs.x))
            t0 = time.perf_counter()
            W = np.asarray(self.B @ (self.B @ F).T)
            W = 0.5 * (W + W.T)
            self.timings["delassus_s"] = time.perf_counter() - t0
            self.W = W
            self.solver = _cpp.IncrementalSolver(d, W, self.mu, self.options)
            self.solver.set_initial_gap(self.x0)

    def _make_outputs(self):
        msh = self.msh
        self.u = dolfinx.fem.Function(self.V, name="displacement")
        Q = compat.scalar_space(msh, "Lagrange", 1)
        self.pressure = dolfinx.fem.Function(Q, name="contact_pressure")
        self.traction = dolfinx.fem.Function(self.V, name="tangential_traction")
        self.status = dolfinx.fem.Function(Q, name="contact_status")
        nQ = Q.dofmap.index_map.size_local
        nV = self.V.dofmap.index_map.size_local
        same = nQ == nV and np.allclose(Q.tabulate_dof_coordinates()[:nQ],
                                        self.V.tabulate_dof_coordinates()[:nV])
        if not self.comm.allreduce(same, op=MPI.LAND):
            raise RuntimeError("scalar and vector P1 spaces number their nodes differently; "
                               "contact fields cannot be written back")
        self.von_mises = None
        if self.stress is not None:
            self.von_mises = dolfinx.fem.Function(compat.scalar_space(msh, "DG", 0),
                                                  name="von_mises")
            self._stress_expr = self.stress(self.u)

    # ---- one increment ---------------------------------------------------------------
    def _gather(self, vec):
        self._scatter.scatter(vec, self._seq, addv=PETSc.InsertMode.INSERT,
                              mode=PETSc.ScatterMode.FORWARD)
        return self._seq.array.copy() if self.comm.rank == 0 else None

    def _assemble_load(self):
        # Ghosted, as DOLFINx's lifting and ghost accumulation need.
        p = compat.create_petsc_vector(self.V)
        p.zeroEntries()
        if self.L_form is not None:
            dolfinx.fem.petsc.assemble_vector(p, self.L_form)
        dolfinx.fem.petsc.apply_lifting(p, [self.a_form], bcs=[self.bcs])
        p.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        dolfinx.fem.petsc.set_bc(p, self.bcs)
        arr = p.array_r
        if not self.comm.allreduce(bool(np.all(np.isfinite(arr))), op=MPI.LAND):
            p.destroy()
            raise ValueError("the load vector is not finite (check the loads and Dirichlet "
                             "values of this increment)")
        return p

    def step(self) -> IncrementResult:
        """Solve one increment with the loads and Dirichlet values as they are set now."""
        t0 = time.perf_counter()
        root = self.comm.rank == 0
        d = self.dim
        p = self._assemble_load()
        up = self.K.createVecRight()
        self.factor.solve(p, up)
        upc = self._gather(up)
        error, result = None, None
        if root:
            q = self.B @ upc + self.x0
            # The increment's local problem u = W λ + q' (slip measured from the last gap),
            # kept for inspection and for cross-checks with other solvers.
            self.local_problem = {"dim": d, "W": self.W, "q": np.asarray(self.solver.local_q(q)),
                                  "mu": self.mu}
            error = self._held_and_penetrating(q)
            try:
                if error:
                    raise _cpp.ConvergenceError(error)
                rep = self.solver.step(q)
                lam = np.asarray(rep.lambda_)
                r_c = self.B.T @ lam
                r_c[self._constrained] = 0.0
                result = (rep, lam, r_c)
            except _cpp.ConvergenceError as e:
                error = f"increment {len(self.increments) + 1}: {e}"
        error = self.comm.bcast(error, root=0)
        if error:
            for v in (p, up):
                v.destroy()
            raise _cpp.ConvergenceError(error)
        r = self.K.createVecLeft()
        r.zeroEntries()
        if root:
            r.setValues(self._contact_dofs.astype(PETSc.IntType), result[2],
                        addv=PETSc.InsertMode.ADD_VALUES)
        r.assemble()
        r.axpy(1.0, p)
        uvec = compat.petsc_vec(self.u)
        self.factor.solve(r, uvec)
        self.u.x.scatter_forward()
        for v in (p, up, r):
            v.destroy()
        inc = self._record(result, time.perf_counter() - t0)
        self._write_back(inc)
        return inc

    def _held_and_penetrating(self, q):
        """Message naming the pairs that cannot be separated, or None (rank 0).

        A pair whose nodes are all held by Dirichlet conditions has no normal flexibility;
        if the prescribed motion makes it penetrate, no contact force can open it and the
        problem has no solution (iterations would only make λ grow).
        """
        d = self.dim
        wn = np.diag(self.W)[::d]
        rigid = wn <= 1e-12 * max(float(wn.max(initial=0.0)), 1e-300)
        scale = max(float(np.abs(q).max(initial=0.0)), 1e-300)
        bad = np.flatnonzero(rigid & (q[::d] < -1e-12 * scale))
        if bad.size == 0:
            return None
        k = int(bad[0])
        return (f"{bad.size} contact pair(s) are held by "
                f"Dirichlet conditions on both sides and pushed into each other, so no contact "
                f"force can separate them; e.g. the slave node at {self.pairs.x[k].tolist()} "
                f"penetrates by {-q[k * d]:.3e} m. Release one side or change the prescribed "
                f"displacements")

    def _record(self, result, elapsed) -> IncrementResult:
        root = self.comm.rank == 0
        d, m = self.dim, self.m
        umax = self.comm.allreduce(float(np.max(np.abs(self.u.x.array), initial=0.0)),
                                   op=MPI.MAX)
        if root:
            rep, lam, _ = result
            lam = lam.reshape(m, d)
            gap = np.asarray(self.solver.gap()).reshape(m, d)
            states = np.asarray(rep.states, dtype=int)
            prev = self.increments[-1].gap if self.increments else self.x0.reshape(m, d)
            slip = gap[:, 1:] - prev[:, 1:]
            tang_global = np.einsum("kij,ki->j", self.frames[:, 1:, :], lam[:, 1:])
            pen = float(max(0.0, -gap[:, 0].min()))
            summary = IncrementSummary(
                increment=len(self.increments) + 1,
                normal_force=float(lam[:, 0].sum()),
                tangential_force=(lam[:, 1:].sum(axis=0).tolist() if d == 2
                                  else tang_global.tolist()),
                stick=int((states == 1).sum()), slip=int((states == 2).sum()),
                open=int((states == 0).sum()),
                max_penetration_m=pen,
                max_penetration_rel=pen / umax if umax > 0 else 0.0,
                residual=float(rep.residual), iterations=int(rep.iterations),
                state_changes=int(rep.state_changes), solver=str(rep.solver), time_s=elapsed)
            inc = IncrementResult(summary, lam, gap, states, slip)
        else:
            inc = None
        summary = self.comm.bcast(inc.summary if root else None, root=0)
        if not root:
            e = np.zeros((0, d))
            inc = IncrementResult(summary, e, e, np.zeros(0, int), e[:, 1:])
        self.increments.append(inc)
        return inc

    def _write_back(self, inc: IncrementResult):
        root = self.comm.rank == 0
        d = self.dim
        if root:
            pr = self.pairs
            blocks = pr.dofs[:, :1] // d
            area = np.concatenate([pr.area, pr.area_master])
            lam_n = np.concatenate([inc.lam[:, 0], inc.lam[:, 0]])
            pressure = (lam_n / area)[:, None]
            t_glob = np.einsum("kij,ki->kj", self.frames[:, 1:, :], inc.lam[:, 1:])
            # Master nodes carry the reaction: equal and opposite traction.
            trac = np.vstack([t_glob / pr.area[:, None], -t_glob / pr.area_master[:, None]])
            status = np.concatenate([inc.states, inc.states])[:, None] + 1.0
            dofs_v = pr.dofs
        else:
            blocks = np.zeros((0, 1), np.int64)
            pressure = status = np.zeros((0, 1))
            trac = np.zeros((0, d))
            dofs_v = np.zeros((0, d), np.int64)
        set_nodal_values(self.pressure, blocks, pressure)
        set_nodal_values(self.status, blocks, status)
        set_nodal_values(self.traction, dofs_v, trac)
        if self.von_mises is not None:
            compat.interpolate_expression(self.von_mises, self._stress_expr)

    # ---- driver -------------------------------------------------------------------
    def solve(self, increments: int, load: Optional[Callable[[int, float], None]] = None,
              writer=None, verbose: bool = True) -> list[IncrementSummary]:
        """Run ``increments`` load increments.

        ``load(i, t)`` is called before increment i (1-based), t = i/increments, to set the
        loads and Dirichlet values of that increment (dolfinx Constants). ``writer`` (a
        ResultWriter) receives the fields after each increment. If an increment fails, the
        increments already done stay written and the error is raised.
        """
        if not isinstance(increments, (int, np.integer)) or increments < 1:
            raise ValueError(f"increments={increments!r}; it must be a positive integer")
        out = []
        for i in range(1, increments + 1):
            if load is not None:
                load(i, i / increments)
            inc = self.step()
            out.append(inc.summary)
            if writer is not None:
                writer.write(self, float(i))
            if verbose and self.comm.rank == 0:
                print(inc.summary.line(), flush=True)
        return out

    def fields(self):
        f = [self.u, self.pressure, self.traction, self.status]
        return f + ([self.von_mises] if self.von_mises is not None else [])


def _concat(parts: list[NodePairs]) -> NodePairs:
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
