"""The two DOLFINx bridge functions the package calls, each from this one place.

Both move from C++ (``_cpp``) to pure Python for DOLFINx 0.9, whose nanobind objects a
pybind11 module cannot take (DESIGN.md §3); the port then changes only these two bodies.
"""
from __future__ import annotations

import numpy as np

from . import _cpp, compat


def surface_nodes(V, facet_tags, value: int) -> dict:
    """Nodes of the facets tagged ``value``, gathered on rank 0: coordinates ``x``, DOFs
    ``dofs``, outward unit ``normal`` and tributary ``area`` per node."""
    return _cpp.surface_nodes(V, compat.cpp(facet_tags), value)


def set_nodal_values(u, dofs: np.ndarray, values: np.ndarray) -> None:
    """Set the Function ``u`` at the given DOF blocks (rank 0's data) on every rank."""
    _cpp.set_nodal_values(u, dofs, values)
