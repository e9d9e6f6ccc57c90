"""The names users pass as strings, all in one place: flexibility methods, orderings, local
contact solvers, pairings, contact operators, zone-edge actions, elasticity kinds, mass
kinds and rigid-target kinds.

They are checked in Python, before any assembly or factorization, so that a typo fails at
once with the list of accepted names instead of minutes later inside the C++ layer; every
check raises an InputError (a ValueError) naming the parameter, its value and the choices.
"""
from __future__ import annotations

from typing import Iterable, Literal, get_args

from .errors import InputError

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

Pairing = Literal["auto", "node_to_node", "node_to_surface", "surface_to_surface"]
"""How a contact interface pairs its surfaces (docs/architecture.md §4): "auto" is
node–node where the surfaces' nodes match one to one, surface–surface otherwise."""

ContactOperator = Literal["dense", "factor"]
"""W formed densely, or never formed: the working set through the factor of K."""

ZoneEdgeAction = Literal["warn", "error", "ignore"]
"""What contact reaching the open edge of a tagged candidate surface does."""

ElasticityKind = Literal["plane_strain", "plane_stress", "3d"]
"""The elasticity model of a form."""

MassKind = Literal["lumped", "consistent"]
"""The mass matrix of an impact: row-sum lumped or consistent."""

RigidKind = Literal["plane", "circle", "sphere"]
"""The shape of a rigid target."""

FLEXIBILITY_METHODS: tuple[str, ...] = get_args(FlexibilityMethod)
ORDERINGS: tuple[str, ...] = get_args(Ordering)
SOLVER_NAMES: tuple[str, ...] = get_args(SolverName)
PAIRINGS: tuple[str, ...] = get_args(Pairing)
CONTACT_OPERATORS: tuple[str, ...] = get_args(ContactOperator)
ZONE_EDGE_ACTIONS: tuple[str, ...] = get_args(ZoneEdgeAction)
ELASTICITY_KINDS: tuple[str, ...] = get_args(ElasticityKind)
MASS_KINDS: tuple[str, ...] = get_args(MassKind)
RIGID_KINDS: tuple[str, ...] = get_args(RigidKind)


def check_option(value, choices: tuple[str, ...], name: str, where: str = "") -> str:
    """``value`` itself if it is one of ``choices``; an InputError reading
    "<where>: <name>='value'; it must be one of 'a', 'b'" otherwise."""
    if not isinstance(value, str) or value not in choices:
        head = f"{where}: " if where else ""
        raise InputError(f"{head}{name}={value!r}; it must be one of "
                         f"{', '.join(map(repr, choices))}")
    return value


def check_flexibility_method(method: str) -> FlexibilityMethod:
    """``method`` itself if it is a flexibility method; ValueError naming it otherwise."""
    if method not in FLEXIBILITY_METHODS:
        raise InputError(f"unknown flexibility method {method!r}; "
                         f"allowed: {', '.join(FLEXIBILITY_METHODS)}")
    return method


def check_ordering(ordering: str) -> Ordering:
    """``ordering`` itself if it is a factorization ordering; ValueError naming it otherwise."""
    if ordering not in ORDERINGS:
        raise InputError(f"unknown ordering {ordering!r}; allowed: {', '.join(ORDERINGS)}")
    return ordering


def check_chain(chain: Iterable[str]) -> list[SolverName]:
    """The chain as a list if every name is a local solver; ValueError naming the bad one."""
    names = list(chain)
    for name in names:
        if name not in SOLVER_NAMES:
            raise InputError(f"unknown contact solver {name!r} in the chain; "
                             f"allowed: {', '.join(SOLVER_NAMES)}")
    return names
