"""The increment protocol, written once: re-pair, condense, the kernel step, the failure on
every rank, expand (docs/architecture.md §5).

A static increment (``ContactProblem``) and an impact time step (``ImpactProblem``) are the
same crossing of the binding. Given a right-hand side b of the factored matrix A (K for an
increment, Ŵ = M + hθC + h²θ²K for a time step), the stepper returns

    y = A⁻¹ (b + Bᵀ λ)

and the kernel's step dict, where λ (or the impulses P) solves the condensed contact
problem built from A⁻¹ b:

* with a factor that splits its solves (``factor.has_condense``: MUMPS's Schur factor on one
  rank or several), b is condensed onto the contact DOFs (forward elimination), the kernel
  step takes the condensed values and returns the contact values of y, and the expansion
  finishes the one back-substitution;
* otherwise y₀ = A⁻¹ b is a full solve, the kernel step takes its contact values, and a
  second solve y = A⁻¹ (b + Bᵀ λ) follows only when a contact force acts.

On the dense path the kernel object lives on rank 0 and the others wait for it asleep; on
the factor path (``collective``) every rank runs the same deterministic kernel step, each W
column product being a collective solve. Either way a failure is raised on every rank.

The problem classes compute their right-hand sides and keep their records and energy; they
read B, W, x0 and the frames from here (``Stepper.operators``), never a copy of their own.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import numpy as np
from petsc4py import PETSc

from ._cpp import ConvergenceError
from .floating import NoEquilibriumError
from .mpi import raise_on_every_rank, wait_for_root
from .errors import InputError
from .shared_solves import Condense, Expand, Solve, serve_alone

Failure = tuple  # (message, report dict or None, no-equilibrium flag)


class Stepper:
    """One condensation (factor + kernel object) and the crossing of an increment.

    Parameters
    ----------
    condensation : a ``Condensation`` (dense W on rank 0) or ``FactorCondensation``
        (W never formed; the kernel object on every rank).
    comm : the problem's communicator.
    expand_key : the kernel step's entry holding the contact values of y on the split
        path ("solution_c" for an increment, "velocity_change_c" for a time step).
    timings : a dict that receives ``last_contact_step_s`` (the kernel step alone).

    ``back_substitutions`` counts the solves with the factor (a condensation and its
    expansion count as one); ``crossings`` the kernel steps; ``pairings`` the pairings made.
    """

    def __init__(self, condensation, comm, *, expand_key: str,
                 timings: Optional[dict] = None):
        self.condensation = condensation
        self.comm = comm
        self.expand_key = expand_key
        self.collective = bool(getattr(condensation, "collective", False))
        self.timings = timings if timings is not None else {}
        self.back_substitutions = 0
        self.crossings = 0
        self.pairings = 1
        self.last_local_q: Optional[np.ndarray] = None  # rank 0: q' of the last step

    # ---- what the condensation holds, read where it lives --------------------------------
    @property
    def contact(self):
        """The kernel's condensed problem (rank 0; every rank on the factor path)."""
        return self.condensation.contact

    @property
    def factor(self):
        return self.condensation.factor

    @property
    def split(self) -> bool:
        """True when a step is one back-substitution (the factor condenses and expands)."""
        return (not self.collective) and bool(getattr(self.factor, "has_condense", False))

    def operators(self) -> tuple:
        """(B, W, x0, frames) of the current pairs and factor (rank 0; None elsewhere; W is
        None on the factor path). Cached by the condensation until the pairs or the
        flexibility change."""
        c = self.condensation
        return c.B, c.W, c.x0, c.frames

    # ---- changes of the condensed problem ---------------------------------------------
    def repair(self, u: PETSc.Vec, mu: np.ndarray, where: str) -> None:
        """Re-make the pairs at the positions X + u (u distributed; rigid targets as set
        now): B, x0 and W from the stored flexibility, no factorization. A pairing error is
        raised on every rank as ValueError("<where>: re-pairing: …"). Collective."""
        c = self.condensation
        uc = c.gather(u)
        error = None
        if self.comm.rank == 0:
            try:
                c.pairs.repair(c.contact_values(uc))
                if not self.collective:
                    c.set_pairs(c.pairs, mu)
            except ValueError as e:
                error = f"{where}: re-pairing: {e}"
        raise_on_every_rank(self.comm, error)
        if self.collective:
            c.set_pairs(c.pairs, mu)  # collective: every rank's kernel object
        self.pairings += 1

    def set_flexibility(self, A: PETSc.Mat, method: str, ordering: str,
                        dt_s: float, where: str) -> None:
        """Factor a new matrix on the same contact DOFs (a new time step size) and give the
        kernel its flexibility; the old factor is released only once the kernel took the
        new one. Collective."""
        self.condensation.refactor(A, method, ordering, dt_s, where)

    # ---- one increment or time step ----------------------------------------------------
    def advance(self, rhs: PETSc.Vec, y: PETSc.Vec, *, where: str,
                before: Sequence = (), after: Sequence = (),
                free_shift: Optional[np.ndarray] = None,
                on_failure: Optional[Callable[[Failure], Failure]] = None) -> Optional[dict]:
        """y = A⁻¹ (rhs + Bᵀ λ) and the kernel's step dict (rank 0; every rank on the
        factor path; None elsewhere).

        The kernel step is called as ``step(*before, values, *after)``: ``values`` are the
        condensed right-hand side on the split path (``step_condensed``), else the contact
        values of A⁻¹ rhs plus ``free_shift`` (``step``). ``before`` and ``after`` are the
        caller's rank-0 arguments (the impact step's u⁻ and v⁻, the floating bodies'
        equilibrium loads). ``on_failure`` may reword a ConvergenceError (rank 0). Errors
        are raised on every rank: ConvergenceError (or NoEquilibriumError) with ``report``,
        ValueError for bad input such as a non-finite right-hand side. ``rhs`` is left as
        it was given (the fallback's second solve uses a copy)."""
        c, root = self.condensation, self.comm.rank == 0
        runs_kernel = root or self.collective
        y0 = None
        if self.split:
            values = self.factor.condense(rhs)
        else:
            y0 = rhs.duplicate()
            self.factor.solve(rhs, y0)
            values = c.gather(y0)
            if free_shift is not None and root:
                values = values + free_shift
        self.back_substitutions += 1
        if root:
            values = c.contact_values(values)
        if self.collective:
            # Every rank steps its own kernel object: each needs rank 0's arguments.
            values, before, after = self.comm.bcast(
                (values, tuple(before), tuple(after)) if root else None, root=0)
        out, failure = None, None
        if runs_kernel:
            out, failure = self._kernel_step(values, before, after, where, on_failure, root)
        if not self.collective:
            wait_for_root(self.comm)  # asleep through rank 0's kernel step, not spinning
        failure = self.comm.bcast(failure, root=0)
        if failure:
            if y0 is not None:
                y0.destroy()
            _raise(failure)
        self.crossings += 1
        self._expand(rhs, y, y0, out)
        return out

    def _kernel_step(self, values, before, after, where, on_failure, root) -> tuple:
        kernel = self.contact
        step = kernel.step_condensed if self.split else kernel.step
        out, failure = None, None
        try:
            t0 = time.perf_counter()
            out = step(*before, values, *after)  # the step's one crossing into the kernel
            self.timings["last_contact_step_s"] = time.perf_counter() - t0
            if root and "local_q" in out:
                self.last_local_q = np.asarray(out["local_q"])
        except ConvergenceError as err:
            report = dict(getattr(err, "report", {}))
            report["problem_path"] = getattr(err, "problem_path", None)
            failure = (f"{where}: {err}", report, False)
            if on_failure is not None and root:
                failure = on_failure(failure)
            if root and hasattr(kernel, "local_q") and hasattr(kernel, "last_q"):
                self.last_local_q = np.asarray(kernel.local_q(kernel.last_q))
        except ValueError as err:
            # e.g. a non-finite right-hand side: raised on every rank, not left to hang them
            failure = (f"{where}: {err}", None, False)
        return out, failure

    def _expand(self, rhs: PETSc.Vec, y: PETSc.Vec, y0: Optional[PETSc.Vec],
                out: Optional[dict]) -> None:
        """y from the kernel step: the expansion of the condensed rhs (split), or y₀, or a
        second solve when a contact force acts."""
        c, root = self.condensation, self.comm.rank == 0
        if self.split:
            n = c.dofs.size
            yc = np.asarray(out[self.expand_key])[:n] if root else np.zeros(0)
            self.factor.expand(yc, y)
            return
        reaction = out["reaction"] if root else None
        pushed = self.comm.bcast(bool(np.any(reaction != 0.0)) if root else None, root=0)
        if pushed:
            r = c.reaction(reaction)
            r.axpy(1.0, rhs)
            self.factor.solve(r, y)
            self.back_substitutions += 1
            r.destroy()
        else:
            y0.copy(y)
        y0.destroy()


@dataclass
class CondensedBody:
    """One body factored on its own, for ``BodiesStepper``.

    ``factor`` serves the body's solves (``condense``/``expand`` when it splits, else
    ``solve``); ``dofs`` are the indices of the body's contact DOFs in its own vectors,
    node-major, in the order of its block of the kernel's flexibility; ``rotation`` (d × d)
    takes the body's own frame to the kernel's (None: the same frame); ``new_vector`` makes
    a zeroed vector of the body; ``counted`` is told of each back-substitution;
    ``flexibility``: the body's F̂ block in its own frame as a ``_cpp.DenseBlock``, for a
    kernel object that leaves the products with F̂ to the stepper
    (``FactorImpact.dense_blocks``).
    """

    name: str
    factor: object
    dofs: np.ndarray
    new_vector: Callable[[], PETSc.Vec]
    rotation: Optional[np.ndarray] = None
    counted: Optional[Callable[[], None]] = None
    flexibility: Optional[object] = None


class BodiesStepper:
    """The step protocol for bodies condensed separately (several factors, a
    block-diagonal flexibility), as the dam sweep factors the dam and each log once.

    ``advance([b_1, …], …)`` returns the kernel's step dict and, per body,
    y_b = A_b⁻¹ (b_b + S_bᵀ r_b) with r the contact reaction: one back-substitution per body
    with a factor that splits, split around one kernel step (``step_condensed``). A body
    whose right-hand side is None is at rest: it costs nothing, and its y is None, unless an
    impulse reaches it (then A_b⁻¹ S_bᵀ r_b). Serial (each body's vectors on one process).

    When every body brings its ``flexibility`` block and splits, the products with F̂ are
    made here, each in the body's own frame: F̂ b̃ with the condensation (runs that share a
    block share that product, shared_solves), the free velocity v + F̂ b̃ for the kernel step
    (``step(u, v, v_free)`` of a ``FactorImpact.dense_blocks``), F̂ r after it, and the
    expansion takes F̂ (b̃ + r).
    """

    def __init__(self, kernel, bodies: Sequence[CondensedBody], *, expand_key: str):
        self.kernel = kernel
        self.bodies = list(bodies)
        self.expand_key = expand_key
        sizes = [b.dofs.size for b in self.bodies]
        self._slices = [slice(a, a + n) for a, n in zip(np.cumsum([0] + sizes[:-1]), sizes)]
        self.back_substitutions = {b.name: 0 for b in self.bodies}
        self.crossings = 0

    @property
    def split(self) -> bool:
        return all(getattr(b.factor, "has_condense", False) for b in self.bodies)

    def _count(self, body: CondensedBody) -> None:
        self.back_substitutions[body.name] += 1
        if body.counted is not None:
            body.counted()

    @staticmethod
    def _to_kernel(body: CondensedBody, values: np.ndarray) -> np.ndarray:
        if body.rotation is None:
            return np.asarray(values)
        d = body.rotation.shape[0]
        return (np.asarray(values).reshape(-1, d) @ body.rotation.T).reshape(-1)

    @staticmethod
    def _from_kernel(body: CondensedBody, values: np.ndarray) -> np.ndarray:
        if body.rotation is None:
            return np.ascontiguousarray(values)
        d = body.rotation.shape[0]
        return (np.asarray(values).reshape(-1, d) @ body.rotation).reshape(-1)

    def advance(self, rhs: Sequence[Optional[PETSc.Vec]], *, where: str,
                before: Sequence = (), after: Sequence = (),
                free_shift: Optional[np.ndarray] = None) -> tuple:
        """(the kernel's step dict, [y_b or None per body]); see the class. The kernel step
        is ``step_condensed(*before, values, *after)`` on the split path, with ``values``
        the bodies' condensed right-hand sides, or ``step(*before, values, *after)`` with
        the contact values of A_b⁻¹ b_b plus ``free_shift`` otherwise."""
        return serve_alone(self.advance_requests(rhs, where=where, before=before, after=after,
                                                 free_shift=free_shift))

    def advance_requests(self, rhs: Sequence[Optional[PETSc.Vec]], *, where: str,
                         before: Sequence = (), after: Sequence = (),
                         free_shift: Optional[np.ndarray] = None):
        """:meth:`advance` as a generator that yields its solves (shared_solves) instead of
        making them, and returns advance's value: driven by shared_solves.serve_together,
        several runs sharing a body's factor share its calls."""
        split = self.split
        if split and all(b.flexibility is not None for b in self.bodies):
            return (yield from self._advance_outside(rhs, where, before, after, free_shift))
        ops, free = [], []
        for body, b in zip(self.bodies, rhs):
            if b is None:
                free.append(None)
            elif split:
                ops.append(Condense(body.factor, b))
                free.append(None)
            else:
                y0 = body.new_vector()
                ops.append(Solve(body.factor, b, y0))
                self._count(body)
                free.append(y0)
        answers = iter((yield ops) if ops else ())
        values = []
        for body, b, y0 in zip(self.bodies, rhs, free):
            if b is None:
                values.append(np.zeros(body.dofs.size))
                continue
            got = next(answers)
            values.append(self._to_kernel(body, got if split else y0.array_r[body.dofs]))
        values = np.concatenate(values)
        if not split and free_shift is not None:
            values = values + free_shift
        out = self._kernel_step(self.kernel.step_condensed if split else self.kernel.step,
                                (*before, values, *after), where)
        key = self.expand_key if split else "reaction"
        change = np.asarray(out[key])
        first, second, spent, ys = [], [], [], []
        for body, b, part, y0 in zip(self.bodies, rhs, self._slices, free):
            local = self._from_kernel(body, change[part])
            ys.append(self._body_solution(body, b, local, y0, split, first, second, spent))
        yield from self._expansions(first, second, spent)
        return out, ys

    @staticmethod
    def _expansions(first, second, spent):
        """Yields the bodies' solves after the kernel step, then frees their temporaries."""
        if first:
            yield first
        if second:
            yield second
        for v in spent:
            v.destroy()

    def _kernel_step(self, step, args, where: str) -> dict:
        try:
            out = step(*args)
        except ConvergenceError as err:
            error = ConvergenceError(f"{where}: {err}")
            error.report = dict(getattr(err, "report", {}))
            error.problem_path = getattr(err, "problem_path", None)
            raise error from None
        self.crossings += 1
        return out

    def _advance_outside(self, rhs, where, before, after, free_shift):
        """advance_requests with the products of F̂ made here (see the class)."""
        loaded = [i for i, b in enumerate(rhs) if b is not None]
        asks = [Condense(self.bodies[i].factor, rhs[i], self.bodies[i].flexibility)
                for i in loaded]
        answers = iter((yield asks) if asks else ())
        Fb = [np.zeros(b.dofs.size) for b in self.bodies]
        for i in loaded:
            Fb[i] = next(answers)[1]
        vfree = np.concatenate([self._to_kernel(b, f) for b, f in zip(self.bodies, Fb)])
        if free_shift is not None:
            vfree = vfree + free_shift
        out = self._kernel_step(self.kernel.step, (*before, vfree, *after), where)
        reaction = np.asarray(out["reaction"])
        first, second, spent, ys, change = [], [], [], [], []
        for body, b, part, fb in zip(self.bodies, rhs, self._slices, Fb):
            r = self._from_kernel(body, reaction[part])
            # r lives on the closed pairs' nodes: the block's product reads their columns.
            local = fb + (np.asarray(body.flexibility.product(r[:, None]))[:, 0]
                          if np.any(r != 0.0) else 0.0)
            change.append(self._to_kernel(body, local))
            ys.append(self._body_solution(body, b, local, None, True, first, second, spent))
        out[self.expand_key] = np.concatenate(change)
        yield from self._expansions(first, second, spent)
        return out, ys

    def _body_solution(self, body, b, local, y0, split, first, second,
                       spent) -> Optional[PETSc.Vec]:
        """The body's y, its solves appended to ``first`` (and to ``second`` when they need
        a condensation first), its temporary vectors to ``spent``."""
        pushed = bool(np.any(local != 0.0))
        if not pushed and b is None:
            return None                       # at rest and untouched: nothing to solve
        if split:
            y = body.new_vector()
            if b is None:
                zero = body.new_vector()      # an expansion follows its own condensation
                first.append(Condense(body.factor, zero))
                second.append(Expand(body.factor, local, y))
                spent.append(zero)
            else:
                first.append(Expand(body.factor, local, y))
            self._count(body)
            return y
        if not pushed:
            return y0
        r = body.new_vector() if b is None else b.copy()
        r.array[body.dofs] += local
        y = body.new_vector()
        first.append(Solve(body.factor, r, y))
        self._count(body)
        spent.append(r)
        if y0 is not None:
            spent.append(y0)
        return y


class StepperViews:
    """What a problem class reads from its ``stepper``, where it lives: the condensation,
    the factor, the kernel object and its operators are never copied into the problem, so
    a re-pairing or a new factor cannot leave one stale."""

    stepper: Stepper

    @property
    def condensation(self):
        return self.stepper.condensation

    @property
    def contact(self):
        """The kernel's condensed problem (rank 0; every rank on the factor path)."""
        return self.stepper.contact

    @property
    def factor(self):
        """The factorization that serves every solve."""
        return self.stepper.factor

    @factor.setter
    def factor(self, factor) -> None:
        # e.g. a wrapper that times the solves, or one without condense/expand
        self.stepper.condensation.factor = factor

    @property
    def flex_info(self) -> dict:
        """What the factorization did (method, ordering, sizes, times)."""
        return self.stepper.condensation.flex_info

    @property
    def n_contact_dofs(self) -> int:
        return self.stepper.condensation.n_contact_dofs

    @property
    def factorizations(self) -> int:
        """Sparse factorizations made (one, plus one per new time step size)."""
        return self.stepper.condensation.factorizations

    @property
    def pairings(self) -> int:
        """How often the pairs were made (once, plus each re-pairing)."""
        return self.stepper.pairings

    @property
    def B(self):
        """The gap operator (rank 0)."""
        return self.stepper.operators()[0]


def _raise(failure: Failure):
    """The error a failure tuple stands for, with the solvers' report attached."""
    message, report, no_equilibrium = failure
    if report is None:
        raise InputError(message)
    error = (NoEquilibriumError if no_equilibrium else ConvergenceError)(message)
    error.report = report  # what the solvers did, on every rank
    # The saved local problem (problem_files.py), named in the message; None if none was.
    error.problem_path = report.get("problem_path")
    raise error
