"""The package's layers, lowest first (docs/architecture.md §6). A module may import from
its own layer and the layers below; tests/test_layers.py reads every import and fails on
one that goes up.

* ``kernel``: the compiled module ``_cpp`` (the C++ kernel and the PETSc/MUMPS bridge).
* ``base``: what every layer may use: the DOLFINx version differences (``compat``), MPI
  patterns, option names, the error classes, memory checks, this table.
* ``forms``: the UFL forms (the top-level folder forms/).
* ``core``: assembly, pairing, condensation, the stepper, the problem classes, output.
* ``meshes``: the gmsh geometries (the top-level folder meshes/).
* ``applications``: the dam job, the sweep and the command line.

Demos and benches sit above all of them and are not part of the package.
"""
from __future__ import annotations

LAYERS = ("kernel", "base", "forms", "core", "meshes", "applications")

_BASE = {"compat", "mpi", "names", "errors", "layers", "memory", "petsc_comm", "states"}
_APPLICATIONS = {"dam", "sweep", "__main__", "info"}


def layer_of(module: str) -> str:
    """The layer of a dotted module name of the package (``flexcontact.x.y``)."""
    parts = module.split(".")
    if parts[0] != "flexcontact":
        raise ValueError(f"{module!r} is not a module of flexcontact")
    if len(parts) == 1:
        return "core"  # the package's front door gathers the core's names
    head = parts[1]
    if head == "_cpp":
        return "kernel"
    if head in _BASE:
        return "base"
    if head == "forms":
        return "forms"
    if head == "meshes":
        return "meshes"
    if head in _APPLICATIONS:
        return "applications"
    return "core"
