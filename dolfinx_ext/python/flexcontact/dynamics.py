"""Impact: dynamic contact on the condensed system by the Moreau–Jean θ-scheme at velocity
level, with Newton restitution and Coulomb friction on impulses (docs/impact.md).

One time step of size h, with r = h [f − C v⁻ − K (u⁻ + hθ v⁻)], is one back-substitution
with the stored factor of Ŵ = M + hθC + h²θ²K (factored once per time-step size) when the
factor splits its solves (``factor.has_condense``: MUMPS's Schur factor, serial or
distributed):

1. r condensed onto the contact DOFs, r̃_c = r_c − Ŵ_ci Ŵ_ii⁻¹ r_i (forward elimination);
2. in the kernel (``_cpp.ImpactContact.step_condensed``; one crossing of the binding): the
   free velocity v_free,c = v⁻_c + F̂ r̃_c, the contact impulses P from
   U⁺ = W_eff P + B v_free, W_eff = B F̂ Bᵀ, and Δv_c = F̂ (r̃_c + Bᵀ P);
3. the expansion from Δv_c (backward substitution): Δv = Ŵ⁻¹ (r + Bᵀ P), v⁺ = v⁻ + Δv,
   with or without contact;
4. u⁺ = u⁻ + h (θ v⁺ + (1 − θ) v⁻).

With a factor that cannot split (another flexibility method), v_free = v⁻ + Ŵ⁻¹ r is a full
solve, the kernel's ``step`` takes it, and steps with contact add v⁺ = v_free + Ŵ⁻¹ Bᵀ P,
a second solve.

A body with no Dirichlet condition at all is fine: Ŵ is regular where K is not. Rank 0 holds
the condensed problem, as in the static ContactProblem.
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable, Optional, Sequence, Union

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem

from . import _cpp, impact_setup as setup
from ._cpp import SolverOptions
from .condensation import Condensation
from .crush_watch import CrushChatterWatch
from .energy import EnergyAccount
from .factor_path import FactorImpactCondensation
from .names import (CONTACT_OPERATORS, ContactOperator, check_chain, check_flexibility_method,
                    check_option, check_ordering)
from .pairing import pair_interfaces
from .postprocess import ContactFields, impact_step_forces, peak_pressure_Pa
from .states import CRUSH, OPEN, SLIP, STICK
from .stepper import Stepper, StepperViews
from .errors import InputError

if TYPE_CHECKING:
    from dolfinx.fem import DirichletBC, FunctionSpace
    from dolfinx.mesh import MeshTags

    from .output import ResultWriter

    from .problem import ContactInterface


@dataclass
class ImpactStepRecord:
    """What one time step produced (every rank). Forces are impulses / h: the mean force
    over the step [N; N/m per unit thickness in 2D]."""

    step: int
    t_s: float
    normal_force: float
    slave_force: list          # global axes, on the slave side
    impulse: list              # Σ_k T_kᵀ P_k of the step [N·s]
    active: int
    stick: int
    slip: int
    open: int
    back_substitutions: int
    solver: str
    iterations: int
    max_penetration_m: float
    crush: int = 0               # pairs at their force cap (crushable interfaces)
    crush_depth_max_m: float = 0.0  # deepest crush of a slave node so far
    # Σ_k a_k δ_k: the crushed volume so far [m³; m² per unit thickness in 2D], a_k the
    # measure each pair's force acts on
    crushed_volume_m3: float = 0.0
    energy: dict = field(default_factory=dict)
    momentum: dict = field(default_factory=dict)  # body -> d components [N·s]


class ImpactProblem(StepperViews):
    """Dynamic frictional contact of elastic bodies by condensation (Moreau–Jean, θ = ½).

    Parameters
    ----------
    V : vector P1 function space.
    cell_tags : MeshTags of the cells; ``bodies`` maps body names to their tags.
    materials : ``{cell_tag: forms.Material}``; every body needs E and a density > 0.
    bcs : Dirichlet conditions (zero values: fixed supports). A body whose nodes are all
        held is rigid: contact DOFs held by a condition get no flexibility.
    contact : one ContactInterface or a list of them (node–node or node–surface pairs; no
        rigid targets).
    dt_s : time step h [s], checked against the expected contact duration (at least
        ``setup.MIN_STEPS_IN_CONTACT`` steps), estimated as the shortest 2L/c of the
        bodies along the contact normal unless ``expected_contact_s`` is given.
    kind : "plane_stress", "plane_strain" or "3d".
    initial_velocity : ``{body name: (v_x, v_y[, v_z])}`` in m/s.
    restitution : Newton's e in [0, 1] (default 0: for deformable bodies the rebound comes
        from the elastic waves).
    theta : θ in [½, 1]; ½ conserves energy away from contact.
    mass : "consistent" or "lumped" (row sum).
    rayleigh : (α, β) of C = αM + βK.
    loads : UFL linear form of constant external loads, or None.
    added_mass : optional callable ``(u, v) -> UFL bilinear form`` (kg·m² for u, v in m)
        added to the mass form, e.g. the water moving with a face (Westergaard); its kinetic
        energy is part of the account's kinetic energy.
    initial_displacement : a Function on V (m) to start from, e.g. a static state under
        ``loads`` (zeroed at held DOFs); None: zero. Its strain energy is the initial one.
    solver, flexibility, ordering : as for ContactProblem.
    contact_operator : "dense" (default): F̂ = (Ŵ⁻¹)_cc and W_eff formed once, a step about
        one back-substitution; "factor": one plain factorization of Ŵ, W_eff's columns of
        the pairs that come into contact fetched through it and held (docs/impact.md,
        "The factor path"), two solves per step while an impulse acts. For contact zones
        too large for the dense path's 8·n_c² bytes.

    Node–surface pairs are re-made before every step but the first (``repair``: B, x0 and
    W_eff from the stored F̂, no factorization; ``pairings`` counts them), unless
    ``repair_pairs`` is False: then the pairs of the initial positions are kept, and the
    problem stays linear in the initial velocities (an impact of fixed contact geometry).
    ``set_time_step`` changes h (one new factorization; ``factorizations`` counts them).
    ``energy`` is the step-by-step energy account (energy.py), ``records`` one
    ImpactStepRecord per step.
    """

    def __init__(self, V: FunctionSpace, cell_tags: MeshTags, bodies: dict[str, int], materials: dict,
                 bcs: Sequence[DirichletBC],
                 contact: Union[ContactInterface, Sequence[ContactInterface]], *,
                 dt_s: float, kind: str = "plane_stress",
                 initial_velocity: Optional[dict] = None, restitution: float = 0.0,
                 theta: float = 0.5, mass: str = "consistent",
                 rayleigh: tuple[float, float] = (0.0, 0.0), loads: Optional[ufl.Form] = None,
                 solver: Optional[SolverOptions] = None, flexibility: str = "schur",
                 ordering: str = "auto", expected_contact_s: Optional[float] = None,
                 initial_displacement: Optional[dolfinx.fem.Function] = None,
                 repair_pairs: bool = True,
                 added_mass: Optional[Callable[[ufl.Argument, ufl.Argument], ufl.Form]] = None,
                 contact_operator: ContactOperator = "dense"):
        from . import forms
        setup.check_scheme(dt_s, restitution, theta, mass, rayleigh)
        check_flexibility_method(flexibility)
        check_option(contact_operator, CONTACT_OPERATORS, "contact_operator")
        self.contact_operator = contact_operator
        check_ordering(ordering)
        self.ordering = ordering
        if solver is not None:
            check_chain(solver.chain)
        self.V, self.msh = V, V.mesh
        self.comm, self.dim = self.msh.comm, self.msh.geometry.dim
        self.dt, self.theta, self.restitution = float(dt_s), float(theta), float(restitution)
        self.rayleigh = tuple(float(x) for x in rayleigh)
        self.mass_kind, self.bcs = mass, list(bcs)
        self.interfaces = list(contact) if isinstance(contact, (list, tuple)) else [contact]
        self.options = solver if solver is not None else SolverOptions()
        self.timings, self.records = {}, []
        self.t = 0.0
        crushes = any(getattr(i, "crushing_strength_Pa", None) is not None
                      for i in self.interfaces)
        self._chatter = CrushChatterWatch() if crushes and self.theta == 0.5 else None
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        dx = ufl.Measure("dx", domain=self.msh, subdomain_data=cell_tags)
        self.a_form = dolfinx.fem.form(forms.elasticity_form(u, v, materials, dx, kind,
                                                             cell_tags))
        m = forms.mass_form(u, v, materials, dx)
        self.m_form = dolfinx.fem.form(m + added_mass(u, v) if added_mass is not None else m)
        t0 = time.perf_counter()
        K_probe = dolfinx.fem.petsc.assemble_matrix(self.a_form, bcs=self.bcs)
        K_probe.assemble()
        self.marker = setup.held_marker(K_probe, self.bcs)
        K_probe.destroy()
        self.bodies = setup.make_bodies(V, cell_tags, bodies, materials, self.marker)
        self.pairs, self.mu, self.m = pair_interfaces(V, self.interfaces, self.comm)
        if any(i.rigid for i in self.interfaces):
            raise InputError("contact: a rigid target is not supported by ImpactProblem; "
                             "mesh the obstacle and hold it with Dirichlet conditions")
        # Node–surface pairs follow the bodies: re-made before every step (``repair``).
        self.repairing = repair_pairs and any(i.pairing_used != "node_to_node"
                                              for i in self.interfaces)
        self._check_time_step(expected_contact_s)
        self.K, self.M = setup.assemble_matrices(self.a_form, self.m_form, self.bcs, mass,
                                                 self.marker)
        self.f = setup.load_vector(V, dolfinx.fem.form(loads) if loads is not None else None,
                                   self.bcs)
        self.timings["assemble_s"] = time.perf_counter() - t0
        self._factor_iteration_matrix(flexibility)
        self._init_state(initial_velocity, initial_displacement)
        lame = forms.lame_fields(self.msh, cell_tags, materials)
        self.outputs = ContactFields(V, self.comm, lambda w: forms.von_mises(w, lame, kind))
        self.velocity = dolfinx.fem.Function(V, name="velocity")
        self.u = self.outputs.u
        self._last_out = None
        self._to_functions()

    # ---- set-up -----------------------------------------------------------------------
    def _check_time_step(self, expected_contact_s: Optional[float]) -> None:
        if expected_contact_s is not None:
            if not (setup._finite(expected_contact_s) and expected_contact_s > 0):
                raise InputError(f"expected_contact_s={expected_contact_s!r}: must be a "
                                 "finite number > 0 s")
            t_c, how = float(expected_contact_s), "given as expected_contact_s"
        else:
            n = None
            if self.comm.rank == 0:
                n = np.abs(self.pairs.normal).mean(axis=0)
                n = n / max(np.linalg.norm(n), 1e-300)
            n = self.comm.bcast(n, root=0)
            t_c = setup.expected_contact_duration(self.bodies, n)
            how = "2L/c, the shortest wave round trip of the bodies along the contact normal"
        self.expected_contact_s = t_c
        setup.check_resolution(self.dt, t_c, how)

    def _factor_iteration_matrix(self, flexibility: str) -> None:
        t0 = time.perf_counter()
        self.W_hat = setup.iteration_matrix(self.K, self.M, self.dt, self.theta, self.rayleigh,
                                            self.marker)
        e, dt, th = self.restitution, self.dt, self.theta

        def kernel(dim, F, X, kpairs, mu, constrained, options):
            return _cpp.ImpactContact(dim, F, X, kpairs, mu, e, dt, th, constrained, options)

        if self.contact_operator == "factor":
            condensation = FactorImpactCondensation(
                self.W_hat, self.bcs, self.pairs, self.mu, self.dim, self.comm, self.options,
                restitution=e, dt_s=dt, theta=th, ordering=self.ordering)
            flexibility = "factor"
        else:
            condensation = Condensation(self.W_hat, self.bcs, self.pairs, self.mu, self.dim,
                                        self.comm, self.options, flexibility, kernel=kernel,
                                        ordering=self.ordering)
        self.stepper = Stepper(condensation, self.comm, expand_key="velocity_change_c",
                               timings=self.timings)
        self.flexibility_method = flexibility
        self.timings.update(condensation.timings)
        self.timings["iteration_matrix_s"] = time.perf_counter() - t0

    # ---- what the stepper holds, read where it lives ----------------------------------
    @property
    def back_substitutions(self) -> int:
        """Solves with the factor of Ŵ so far (a condensation and its expansion count as
        one)."""
        return self.stepper.back_substitutions

    @property
    def W_eff(self):
        """W_eff = B F̂ Bᵀ (rank 0)."""
        return self.stepper.operators()[1]

    def set_time_step(self, dt_s: float, expected_contact_s: Optional[float] = None) -> None:
        """Continue with the time step ``dt_s`` [s]: Ŵ = M + hθC + h²θ²K of the new h is
        factored once (``factorizations`` counts it) and W_eff rebuilt from it; pairs, state
        and energy account are kept. The new step is checked against the expected contact
        duration as in the constructor, before anything is changed. Collective."""
        setup.check_scheme(dt_s, self.restitution, self.theta, self.mass_kind, self.rayleigh)
        old = self.expected_contact_s
        if expected_contact_s is not None:
            if not (setup._finite(expected_contact_s) and expected_contact_s > 0):
                raise InputError(f"expected_contact_s={expected_contact_s!r}: must be a "
                                 "finite number > 0 s")
            old = float(expected_contact_s)
        setup.check_resolution(float(dt_s), old, "the expected contact duration")
        t0 = time.perf_counter()
        W_hat = setup.iteration_matrix(self.K, self.M, float(dt_s), self.theta, self.rayleigh,
                                       self.marker)
        try:
            self.stepper.set_flexibility(W_hat, self.flexibility_method, self.ordering,
                                         float(dt_s), "set_time_step")
        except ValueError:
            W_hat.destroy()
            raise
        self.W_hat.destroy()
        self.W_hat = W_hat
        self.dt, self.expected_contact_s = float(dt_s), old
        self.timings.setdefault("refactor_s", []).append(time.perf_counter() - t0)

    def repair(self) -> None:
        """Re-make the node–surface pairs at the current positions x + u⁻: B, x0 and W_eff
        from the stored F̂, no factorization; each pair keeps its last impulse and state as
        the next step's warm start. Collective."""
        self.stepper.repair(self.u_vec, self.mu, f"time step {len(self.records) + 1}")

    def _init_state(self, initial_velocity: Optional[dict], initial_displacement=None) -> None:
        self.u_vec = self.K.createVecLeft()
        self.u_vec.zeroEntries()
        strain0 = 0.0
        if initial_displacement is not None:
            setup.initial_displacement(self.u_vec, initial_displacement, self.V, self.marker)
            Ku = self.K.createVecLeft()
            self.K.mult(self.u_vec, Ku)
            strain0 = 0.5 * self.u_vec.dot(Ku)
            Ku.destroy()
        self.v_vec = self.K.createVecLeft()
        setup.initial_velocity(self.v_vec, self.bodies, initial_velocity, self.marker,
                               self.dim)
        self._work = [self.K.createVecLeft() for _ in range(3)]
        self.energy = EnergyAccount()
        Mv = self._work[0]
        self.M.mult(self.v_vec, Mv)
        self.energy.start(0.5 * Mv.dot(self.v_vec), strain0)
        self.momentum0 = self._momentum(Mv)

    def _momentum(self, Mv: PETSc.Vec) -> dict:
        """Momentum of each body, Σ over its DOFs of (M v) per component [N·s]."""
        arr = Mv.array_r
        local = np.array([[arr[d].sum() for d in b.dofs] for b in self.bodies])
        total = self.comm.allreduce(local, op=MPI.SUM)
        return {b.name: total[i].tolist() for i, b in enumerate(self.bodies)}

    # ---- one time step ---------------------------------------------------------------
    @property
    def one_back_substitution(self) -> bool:
        """True when a time step is one back-substitution (the factor condenses and
        expands); False: the two-solve fallback (two solves in steps with contact)."""
        return self.stepper.split

    def _step_rhs(self) -> PETSc.Vec:
        """r = h [f − C v⁻ − K (u⁻ + hθ v⁻)] in a work vector (overwritten by the next
        step's energy bookkeeping)."""
        h, (alpha, beta) = self.dt, self.rayleigh
        w, r, _ = self._work
        self.u_vec.copy(w)
        w.axpy(h * self.theta + beta, self.v_vec)
        self.K.mult(w, r)
        r.scale(-h)
        if alpha:
            self.M.mult(self.v_vec, w)
            r.axpy(-h * alpha, w)
        if self.f is not None:
            r.axpy(h, self.f)
        return r

    def step(self) -> ImpactStepRecord:
        """Advance one time step of size dt_s: Δv = Ŵ⁻¹ (r + Bᵀ P) through the stepper (one
        back-substitution with a factor that splits), v⁺ = v⁻ + Δv."""
        t0 = time.perf_counter()
        n_solves = self.back_substitutions
        where = f"time step {len(self.records) + 1}"
        if self.repairing and self.records:
            self.repair()
        c, root = self.condensation, self.comm.rank == 0
        uc, vc = c.gather(self.u_vec), c.gather(self.v_vec)
        v_new = self.K.createVecLeft()
        out = self.stepper.advance(self._step_rhs(), v_new, where=where,
                                   before=(uc, vc) if root else (),
                                   free_shift=vc if root else None)
        v_new.axpy(1.0, self.v_vec)
        du = self.K.createVecLeft()
        du.axpy(self.dt * self.theta, v_new)
        du.axpy(self.dt * (1.0 - self.theta), self.v_vec)
        self._book_energy(du, v_new, out)
        self.u_vec.axpy(1.0, du)
        v_new.copy(self.v_vec)
        for o in (du, v_new):
            o.destroy()
        self.t += self.dt
        rec = self._record(out, self.back_substitutions - n_solves)
        self.records.append(rec)
        self._last_out = out
        self._to_functions()
        self.timings.setdefault("steps_s", []).append(time.perf_counter() - t0)
        return rec

    def _book_energy(self, du: PETSc.Vec, v_new: PETSc.Vec, out: Optional[dict]) -> None:
        """The step's energies and works (energy.py) from its own definitions."""
        Mv, Ku, w = self._work
        alpha, beta = self.rayleigh
        damping = 0.0
        if alpha or beta:
            w.set(0.0)
            w.axpy(self.theta, v_new)
            w.axpy(1.0 - self.theta, self.v_vec)
            self.M.mult(w, Mv)
            self.K.mult(w, Ku)
            damping = self.dt * (alpha * w.dot(Mv) + beta * w.dot(Ku))
        external = self.f.dot(du) if self.f is not None else 0.0
        u_new = self.u_vec.copy()
        u_new.axpy(1.0, du)
        self.K.mult(u_new, Ku)
        strain = 0.5 * u_new.dot(Ku)
        u_new.destroy()
        numerical = self._numerical_dissipation(du, v_new)  # before Mv holds M v⁺
        self.M.mult(v_new, Mv)
        kinetic = 0.5 * v_new.dot(Mv)
        works = ((out["contact_work"], out["friction_work"], out["crush_work"])
                 if self.comm.rank == 0 else None)
        cw, fw, crw = self.comm.bcast(works, root=0)
        self.energy.add_step(kinetic, strain, external, damping, cw, fw, numerical, crw)
        self._last_momentum = self._momentum(Mv)

    def _numerical_dissipation(self, du: PETSc.Vec, v_new: PETSc.Vec) -> float:
        """(θ − ½)(‖Δv‖²_M + ‖Δu‖²_K) of the step [J]: what the θ-method takes away."""
        if self.theta == 0.5:
            return 0.0
        Mv, Ku, w = self._work
        v_new.copy(w)
        w.axpy(-1.0, self.v_vec)
        self.M.mult(w, Mv)
        self.K.mult(du, Ku)
        return (self.theta - 0.5) * (w.dot(Mv) + du.dot(Ku))

    def _record(self, out: Optional[dict], solves: int) -> ImpactStepRecord:
        rec = None
        if self.comm.rank == 0:
            s, rep = out["states"], out["report"]
            closed = np.asarray(out["active"], bool)
            rec = ImpactStepRecord(
                step=len(self.records) + 1, t_s=self.t,
                normal_force=float(out["normal_impulse"]) / self.dt,
                slave_force=(np.asarray(out["slave_impulse"]) / self.dt).tolist(),
                impulse=np.asarray(out["slave_impulse"]).tolist(),
                active=int(closed.sum()), stick=int(((s == STICK) & closed).sum()),
                slip=int(((s == SLIP) & closed).sum()), open=int((s == OPEN).sum()),
                back_substitutions=solves, solver=str(rep["solver"]),
                iterations=int(rep["iterations"]),
                max_penetration_m=float(out["max_penetration"]),
                crush=int(((s == CRUSH) & closed).sum()),
                crush_depth_max_m=float(np.max(out["crush_depth"], initial=0.0))
                if "crush_depth" in out else 0.0,
                crushed_volume_m3=float(np.dot(out["crush_depth"], self.pairs.tributary))
                if "crush_depth" in out else 0.0)
            if self._chatter is not None:
                self._chatter.observe(rec.step, (s == CRUSH) & closed, closed)
        rec = self.comm.bcast(rec, root=0)
        rec.energy = self.energy.history[-1]
        rec.momentum = self._last_momentum
        return rec

    @property
    def crush_chatter(self) -> Optional[CrushChatterWatch]:
        """The watch over a crushing front's chatter (crush_watch.py): only at θ = ½ with a
        crushing interface, else None. Rank 0 counts; other ranks hold zeros."""
        return self._chatter

    # ---- output -----------------------------------------------------------------------
    def _to_functions(self) -> None:
        """Displacement and velocity Functions from the state vectors."""
        for vec, f in ((self.u_vec, self.outputs.u), (self.v_vec, self.velocity)):
            n = vec.getLocalSize()
            f.x.array[:n] = vec.array_r
            f.x.scatter_forward()

    def fields(self) -> list[dolfinx.fem.Function]:
        """Output Functions (collective): displacement, velocity, contact pressure (mean over
        the last step, impulse / h / area), tangential traction, contact status (1 open,
        2 stick, 3 slip), von Mises."""
        self.outputs.write_back(self._last_increment(), self.pairs)
        f = self.outputs.all()
        return [f[0], self.velocity] + f[1:]

    def peak_contact_pressure_Pa(self, slave_only: bool = False) -> float:
        """The largest value of :meth:`fields`' contact pressure (Pa, 0 without contact),
        without writing any field: cheap enough for every step. ``slave_only``: over the
        slave nodes (postprocess.peak_pressure_Pa). Collective."""
        best = (peak_pressure_Pa(self._last_increment(), self.pairs, slave_only)
                if self.comm.rank == 0 else 0.0)
        return self.comm.bcast(best, root=0)

    def _last_increment(self):
        """The last step's pair forces (mean over the step) as postprocess reads them; all
        open before the first step and on ranks other than 0."""
        from types import SimpleNamespace
        d, out = self.dim, self._last_out
        if self.comm.rank == 0 and out is not None:
            return impact_step_forces(out, self.dt)
        m = self.m if self.comm.rank == 0 else 0
        return SimpleNamespace(lam=np.zeros((m, d)), states=np.full(m, OPEN),
                               tangential=np.zeros((m, d)))

    def run(self, t_end_s: float, writer: Optional[ResultWriter] = None, write_every: int = 1,
            progress: Optional[bool] = None) -> list[ImpactStepRecord]:
        """Steps until t_end_s; ``writer`` (a ResultWriter) gets the fields every
        ``write_every`` steps; a progress bar on rank 0 when ``progress`` (default: when
        stderr is a terminal)."""
        if not (setup._finite(t_end_s) and t_end_s > self.t):
            raise InputError(f"t_end_s={t_end_s!r}: must be finite and after t = {self.t:g} s")
        n = int(round((t_end_s - self.t) / self.dt))
        bar = None
        if self.comm.rank == 0 and (progress or (progress is None and sys.stderr.isatty())):
            from tqdm import tqdm
            bar = tqdm(total=n, unit="step", desc="impact", file=sys.stderr)
        if writer is not None and not self.records:
            writer.write(self, 0.0)
        try:
            for i in range(n):
                self.step()
                if writer is not None and (i + 1) % write_every == 0:
                    writer.write(self, self.t)
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
        return self.records
