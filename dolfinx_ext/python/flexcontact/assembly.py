"""Assembly of the stiffness K and the load vector p by DOLFINx (PETSc objects)."""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc

from . import compat
from .errors import InputError


def assemble_stiffness(a_form, bcs: Sequence) -> PETSc.Mat:
    """K with the Dirichlet rows and columns replaced by the identity."""
    K = dolfinx.fem.petsc.assemble_matrix(a_form, bcs=list(bcs))
    K.assemble()
    return K


def assemble_load(V, a_form, L_form: Optional[object], bcs: Sequence, comm) -> PETSc.Vec:
    """p with the Dirichlet values of this increment lifted and set.

    Raises ValueError on every rank if any entry is not finite.
    """
    # Ghosted, as DOLFINx's lifting and ghost accumulation need.
    p = compat.create_petsc_vector(V)
    p.zeroEntries()
    if L_form is not None:
        dolfinx.fem.petsc.assemble_vector(p, L_form)
    # A condition holding zero lifts nothing, yet DOLFINx would compute the element matrix of
    # every cell touching its DOFs (in 3D the symmetry planes and the clamped base, at every
    # increment): lift with the conditions whose values are non-zero now. Same p exactly.
    lifted = [bc for bc in bcs if not compat.bc_is_homogeneous(bc)]
    if lifted:
        dolfinx.fem.petsc.apply_lifting(p, [a_form], bcs=[lifted])
    p.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    compat.set_bc(p, list(bcs))
    if not comm.allreduce(bool(np.all(np.isfinite(p.array_r))), op=MPI.LAND):
        p.destroy()
        raise InputError("the load vector is not finite (check the loads and Dirichlet "
                         "values of this increment)")
    return p
