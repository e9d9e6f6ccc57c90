"""Runs that ask for their solves instead of making them, so that several runs sharing a
factor can have it read once for all of them (docs/architecture.md §7, "Several right-hand
sides at once").

A run written as a generator yields a list of solves (``Condense``, ``Expand``, ``Solve``)
and gets back, in the same order, what each returns. A condensation can ask for its
product with the body's dense F̂ block as well: runs that share the block share that
product, one matrix product for all their columns. :func:`serve_alone` serves them one by
one: that is a run's ordinary execution. :func:`serve_together` drives several runs in
lockstep: each round it serves every live run's list, the solves of one factor in one call
(``condense_many``, ``expand_many``, ``solve_many``), and sends each run its answers.

A factor holds one pending condensation, so within a round the expansions are served
first (they close the condensations of the round before, every run of which asks for its
expansion next: the stepper's protocol), then the plain solves, then the condensations.
A run that fails between its condensation and its expansion leaves a zero column in the
expansion of the others. Which runs share a call depends only on the runs themselves, so
the same runs give the same answers; a run's answers differ from its answers alone by
round-off (MUMPS's blocked kernels sum in another order for several columns), which a
contact step's index set can amplify (docs/dam.md, "Sweeps").
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Generator, Optional, Sequence

import numpy as np
from petsc4py import PETSc


@dataclass
class Condense:
    """b̃_c of b (returns the factor's condensation, an array). With ``block`` (the body's
    F̂ block, a ``_cpp.DenseBlock``), returns (b̃_c, F̂ b̃_c): the product that the kernel
    step would otherwise make, made here so that runs sharing the block read it once
    (stepper.BodiesStepper)."""
    factor: object
    b: PETSc.Vec
    block: Optional[object] = None


@dataclass
class Expand:
    """y from the contact values ``local``, after this run's own condensation (returns None)."""
    factor: object
    local: np.ndarray
    y: PETSc.Vec


@dataclass
class Solve:
    """y = A⁻¹ b (returns None)."""
    factor: object
    b: PETSc.Vec
    y: PETSc.Vec


def _serve_one(op):
    if isinstance(op, Condense):
        c = np.asarray(op.factor.condense(op.b))
        return c if op.block is None else (c, _product(op.block, c[:, None])[:, 0])
    if isinstance(op, Expand):
        op.factor.expand(op.local, op.y)
        return None
    op.factor.solve(op.b, op.y)
    return None


def serve_alone(run: Generator):
    """Run one generator to its end, serving its solves one by one; its return value."""
    try:
        ops = next(run)
        while True:
            ops = run.send([_serve_one(op) for op in ops])
    except StopIteration as stop:
        return stop.value


def shares(factor) -> bool:
    """Whether ``factor`` serves several runs' condensations at once (MUMPS's Schur factor
    on one rank). A split factor without it holds one pending condensation of one run only."""
    return hasattr(factor, "condense_many")


class Together:
    """The calls a :func:`serve_together` made: ``calls`` per kind, ``columns`` (the
    right-hand sides they carried: calls/columns says how much was shared), and
    ``seconds``: wall time in those calls per kind, and in the runs' own code between them
    ("runs": their kernel steps, right-hand sides and outputs)."""

    def __init__(self):
        self.calls = {"condense": 0, "expand": 0, "solve": 0, "product": 0}
        self.columns = {"condense": 0, "expand": 0, "solve": 0, "product": 0}
        self.seconds = {"condense": 0.0, "expand": 0.0, "solve": 0.0, "product": 0.0,
                        "runs": 0.0}

    def count(self, kind: str, columns: int) -> None:
        self.calls[kind] += 1
        self.columns[kind] += columns


def serve_together(runs: Sequence[Generator], stats: Optional[Together] = None) -> list:
    """Drive ``runs`` in lockstep; per run, its return value or the exception it raised."""
    stats = stats if stats is not None else Together()
    out: list = [None] * len(runs)
    asked: dict = {}            # run index: its list of solves waiting for this round
    pending: dict = {}          # id(factor): [(run, column)] of its last condense_many

    def resume(i: int, answers) -> None:
        t0 = time.perf_counter()
        try:
            asked[i] = next(runs[i]) if answers is None else runs[i].send(answers)
        except StopIteration as stop:
            out[i] = stop.value
        except Exception as err:  # noqa: BLE001: the run's failure is its result
            out[i] = err
        stats.seconds["runs"] += time.perf_counter() - t0

    for i in range(len(runs)):
        resume(i, None)
    while asked:
        round_, asked = asked, {}
        answers = {i: [None] * len(ops) for i, ops in round_.items()}
        by_kind: dict = {Expand: {}, Solve: {}, Condense: {}}
        for i in sorted(round_):
            for j, op in enumerate(round_[i]):
                by_kind[type(op)].setdefault(id(op.factor), []).append((i, j, op))
        t0 = time.perf_counter()
        for key, items in by_kind[Expand].items():
            _expand(items, pending.pop(key, None), stats)
        t1 = time.perf_counter()
        for items in by_kind[Solve].values():
            _solve(items, answers, stats)
        t2, products = time.perf_counter(), stats.seconds["product"]
        for key, items in by_kind[Condense].items():
            pending[key] = _condense(items, answers, stats)
        t3 = time.perf_counter() - (stats.seconds["product"] - products)
        for kind, dt in (("expand", t1 - t0), ("solve", t2 - t1), ("condense", t3 - t2)):
            stats.seconds[kind] += dt
        for i in sorted(round_):
            resume(i, answers[i])
    return out


def _condense(items, answers, stats) -> Optional[list]:
    factor = items[0][2].factor
    if not shares(factor):
        if len(items) > 1:
            raise RuntimeError(f"{len(items)} runs condense on one factor that holds a single "
                               "pending condensation; serve them alone")
        i, j, op = items[0]
        C = np.asarray(factor.condense(op.b))[:, None]
        stats.count("condense", 1)
        members = None
    else:
        B = np.asfortranarray(np.column_stack([op.b.array_r for _, _, op in items]))
        C = factor.condense_many(B)
        stats.count("condense", len(items))
        members = [i for i, _, _ in items]
    blocks = {id(op.block): op.block for _, _, op in items if op.block is not None}
    FC = {}
    if blocks:
        t0 = time.perf_counter()
        for key, block in blocks.items():
            cols = [col for col, (_, _, op) in enumerate(items) if id(op.block) == key]
            Y = _product(block, np.asfortranarray(C[:, cols]))
            FC.update({col: Y[:, a] for a, col in enumerate(cols)})
            stats.count("product", len(cols))
        stats.seconds["product"] += time.perf_counter() - t0
    for col, (i, j, _) in enumerate(items):
        c = np.array(C[:, col])
        answers[i][j] = (c, np.array(FC[col])) if col in FC else c
    return members


def _product(block, X: np.ndarray) -> np.ndarray:
    return np.asarray(block.product(X))


def _expand(items, members: Optional[list], stats) -> None:
    factor = items[0][2].factor
    if members is None:  # a factor serving one run: its own pending condensation
        if len(items) > 1:
            raise RuntimeError(f"{len(items)} runs expand on one factor with no shared "
                               "condensation pending")
        _serve_one(items[0][2])
        stats.count("expand", 1)
        return
    ops = {i: op for i, _, op in items}
    if set(ops) - set(members):
        raise RuntimeError("a run expands on a factor it did not condense on in the round "
                           "before")
    U = np.zeros((int(factor.n_schur), len(members)), order="F")
    for col, i in enumerate(members):
        if i in ops:                       # else the run failed in between: a zero column
            U[:, col] = ops[i].local
    X = factor.expand_many(U)
    stats.count("expand", len(members))
    for col, i in enumerate(members):
        if i in ops:
            ops[i].y.array[:] = X[:, col]


def _solve(items, answers, stats) -> None:
    factor = items[0][2].factor
    if len(items) > 1 and hasattr(factor, "solve_many"):
        B = np.asfortranarray(np.column_stack([op.b.array_r for _, _, op in items]))
        X = factor.solve_many(B)
        stats.count("solve", len(items))
        for col, (_, _, op) in enumerate(items):
            op.y.array[:] = X[:, col]
        return
    for _, _, op in items:
        _serve_one(op)
        stats.count("solve", 1)
