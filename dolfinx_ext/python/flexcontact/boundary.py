"""Dirichlet conditions on tagged facets, with values that load steps can change."""
from __future__ import annotations

from typing import TYPE_CHECKING, Optional, Sequence, Union

import numpy as np
import dolfinx.fem
from petsc4py import PETSc

from . import compat
from .errors import InputError

# DOLFINx 0.9's class names; 0.5 spells them *MetaClass, so never imported at run time.
if TYPE_CHECKING:
    from dolfinx.fem import Constant, DirichletBC, FunctionSpace
    from dolfinx.mesh import MeshTags


def dirichlet(V: FunctionSpace, facet_tags: MeshTags, value: int,
              components: Optional[Sequence[int]] = None,
              displacement_m: Union[float, Sequence[float]] = 0.0,
              ) -> tuple[list[DirichletBC], list[Constant]]:
    """Prescribe displacement components [m] on the facets tagged ``value``.

    Returns ``(bcs, constants)``: a list of DirichletBC (one per component) and the
    dolfinx Constants holding their values, so that a load step can change them in place
    (``constants[0].value = -1e-4``).
    """
    msh = V.mesh
    gdim = msh.geometry.dim
    facets = facet_tags.find(value) if hasattr(facet_tags, "find") else \
        facet_tags.indices[facet_tags.values == value]
    from mpi4py import MPI
    if msh.comm.allreduce(len(facets), op=MPI.SUM) == 0:
        raise InputError(f"Dirichlet condition: no facet carries the tag value {value} "
                         f"(values present: {sorted(set(np.unique(facet_tags.values).tolist()))})")
    comps = list(range(gdim)) if components is None else list(components)
    vals = np.broadcast_to(np.asarray(displacement_m, dtype=float), (len(comps),))
    bcs, consts = [], []
    for c, v in zip(comps, vals):
        if not 0 <= c < gdim:
            raise InputError(f"Dirichlet condition on tag {value}: component {c} does not "
                             f"exist in {gdim}D")
        k = dolfinx.fem.Constant(msh, PETSc.ScalarType(v))
        dofs = compat.locate_component_dofs(V, c, facets)
        bcs.append(dolfinx.fem.dirichletbc(k, dofs, V.sub(c)))
        consts.append(k)
    return bcs, consts


def hold_body(V: FunctionSpace, cell_tags: MeshTags, value: int) -> list[DirichletBC]:
    """Hold every node of the cells tagged ``value`` fixed: a rigid body (e.g. a wall an
    impact hits). Its contact DOFs then get no flexibility, so it does not deform at all.
    """
    msh = V.mesh
    tdim = msh.topology.dim
    cells = cell_tags.indices[cell_tags.values == value]
    from mpi4py import MPI
    if msh.comm.allreduce(len(cells), op=MPI.SUM) == 0:
        raise InputError(f"hold_body: no cell carries the tag value {value}")
    compat.create_connectivity(msh, tdim, tdim)  # DOLFINx 0.9 locates DOFs through it
    dofs = dolfinx.fem.locate_dofs_topological(V, tdim, cells)
    zero = np.zeros(msh.geometry.dim, dtype=PETSc.ScalarType)
    return [dolfinx.fem.dirichletbc(zero, dofs, V)]
