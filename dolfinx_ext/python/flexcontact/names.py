"""The names users pass as strings: flexibility methods and local contact solvers.

They are checked in Python, before any assembly or factorization, so that a typo fails at
once with the list of accepted names instead of minutes later inside the C++ layer.
"""
from __future__ import annotations

from typing import Iterable, Literal, get_args

FlexibilityMethod = Literal["schur", "inverse_entries", "matmatsolve"]
"""How F* = (K⁻¹)_cc is computed: MUMPS Schur complement (on several ranks from MUMPS driven
directly, distributed_schur.h), MUMPS selected inverse entries, or a multi-right-hand-side
solve."""

Ordering = Literal["auto", "metis", "mumps", "amd", "amf", "pord", "qamd"]
"""The fill-reducing ordering of the MUMPS factorization of K: "auto" (the default: "metis"
in 3D and for a 2D factor with a Schur complement of at least 100,000 rows, "mumps"
otherwise), "metis" (METIS nested dissection of the mesh nodes handed to MUMPS), "mumps"
(MUMPS's automatic choice among what Debian's MUMPS has: AMD, AMF, PORD, QAMD; only AMD with
a Schur complement), or one of those four. On several ranks MUMPS's automatic choice is
used. bench/ordering.py and bench/schur_ordering_2d.py measure them: in 3D METIS needs 2.7
times fewer flops at 30k DOFs; in 2D with a Schur complement it is faster from 200k DOFs on
(2.24 s against AMD's 2.74 s CPU on the Hertz mesh) and slower at 50k."""

SolverName = Literal["newton_ac", "active_set", "projection"]
"""Local contact solvers of ``SolverOptions.chain``: semi-smooth Newton on Alart–Curnier,
the Feng–Touzot active set, the De Saxcé–Feng projection."""

FLEXIBILITY_METHODS: tuple[str, ...] = get_args(FlexibilityMethod)
ORDERINGS: tuple[str, ...] = get_args(Ordering)
SOLVER_NAMES: tuple[str, ...] = get_args(SolverName)


def check_flexibility_method(method: str) -> FlexibilityMethod:
    """``method`` itself if it is a flexibility method; ValueError naming it otherwise."""
    if method not in FLEXIBILITY_METHODS:
        raise ValueError(f"unknown flexibility method {method!r}; "
                         f"allowed: {', '.join(FLEXIBILITY_METHODS)}")
    return method


def check_ordering(ordering: str) -> Ordering:
    """``ordering`` itself if it is a factorization ordering; ValueError naming it otherwise."""
    if ordering not in ORDERINGS:
        raise ValueError(f"unknown ordering {ordering!r}; allowed: {', '.join(ORDERINGS)}")
    return ordering


def check_chain(chain: Iterable[str]) -> list[SolverName]:
    """The chain as a list if every name is a local solver; ValueError naming the bad one."""
    names = list(chain)
    for name in names:
        if name not in SOLVER_NAMES:
            raise ValueError(f"unknown contact solver {name!r} in the chain; "
                             f"allowed: {', '.join(SOLVER_NAMES)}")
    return names
