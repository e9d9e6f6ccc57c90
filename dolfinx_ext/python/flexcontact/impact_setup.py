"""Set-up of an impact problem: checks of the input, the bodies' DOFs, the matrices K, M
and the iteration matrix Ŵ = M + hθC + h²θ²K, and the estimate of the contact duration
that the time step must resolve (docs/impact.md).

Every check raises ValueError naming the parameter (or body) and its value, on every rank,
before anything is assembled or factored.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc

from . import compat, names
from .names import check_option
from .errors import InputError

MASS_KINDS = names.MASS_KINDS
MIN_STEPS_IN_CONTACT = 10
"""A time step must fit this many times into the expected contact duration."""


def _finite(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


def check_scheme(dt_s, restitution, theta, mass, rayleigh) -> None:
    """ValueError naming the first bad scheme parameter."""
    if not (_finite(dt_s) and dt_s > 0):
        raise InputError(f"dt_s={dt_s!r}: the time step must be a finite number > 0 s")
    if not (_finite(restitution) and 0.0 <= restitution <= 1.0):
        raise InputError(f"restitution={restitution!r}: Newton's coefficient of restitution "
                         "must lie in [0, 1]")
    if not (_finite(theta) and 0.5 <= theta <= 1.0):
        raise InputError(f"theta={theta!r}: the θ-scheme needs 0.5 <= theta <= 1")
    check_option(mass, MASS_KINDS, "mass")
    alpha, beta = rayleigh
    for name, value in (("alpha", alpha), ("beta", beta)):
        if not (_finite(value) and value >= 0):
            raise InputError(f"rayleigh {name}={value!r}: Rayleigh damping coefficients "
                             "must be finite and >= 0 (C = alpha M + beta K)")


@dataclass
class Body:
    """One named body: its cell tag, material, owned DOFs per component and extent."""

    name: str
    tag: int
    material: object
    dofs: list            # per component: owned local indices into a PETSc vector's array
    ghosted_blocks: np.ndarray  # local DOF blocks (owned and ghost) of its cells
    lower: np.ndarray     # bounding box (global, m)
    upper: np.ndarray
    free_dofs: int = 0    # DOFs not held by a Dirichlet condition (global)

    @property
    def wave_speed_m_s(self) -> float:
        """Bar wave speed sqrt(E/ρ) [m/s]."""
        return math.sqrt(self.material.E_Pa / self.material.rho_kg_m3)

    def extent_along(self, n: np.ndarray) -> float:
        """Extent of the bounding box along the unit direction n [m]."""
        return float(np.abs(n) @ (self.upper - self.lower))


def make_bodies(V, cell_tags, bodies: dict, materials: dict, held_marker: PETSc.Vec
                ) -> list[Body]:
    """The named bodies, checked: each has cells and a material of density > 0.

    ``held_marker`` holds 0 at Dirichlet DOFs and 1 elsewhere.
    """
    msh, comm = V.mesh, V.mesh.comm
    if not bodies:
        raise InputError("bodies={}: name at least one body {name: cell tag}")
    bs = V.dofmap.index_map_bs
    n_owned = V.dofmap.index_map.size_local
    cell_blocks = compat.cell_dofs(V)
    geo_nodes, geo_x = compat.geometry_dofmap(msh), compat.geometry_x(msh)
    gdim = msh.geometry.dim
    marker = held_marker.array_r
    out = []
    for name, tag in bodies.items():
        mat = materials.get(tag)
        if mat is None:
            raise InputError(f"body {name!r} (cell tag {tag}) has no material; materials are "
                             f"given for the tags {sorted(materials)}")
        rho = mat.rho_kg_m3
        if not (_finite(rho) and rho > 0):
            raise InputError(f"body {name!r} (cell tag {tag}): density rho_kg_m3={rho!r}; "
                             "a body in an impact needs a density > 0 kg/m³ (it has no mass)")
        cells = cell_tags.indices[cell_tags.values == tag]
        if comm.allreduce(len(cells), op=MPI.SUM) == 0:
            raise InputError(f"body {name!r}: no cell carries the tag {tag}, so the body has "
                             "no mass")
        blocks = np.unique(cell_blocks[cells].reshape(-1))
        owned = blocks[blocks < n_owned]
        dofs = [owned * bs + c for c in range(bs)]
        x = geo_x[np.unique(geo_nodes[cells].reshape(-1)), :gdim]
        lo = x.min(axis=0) if len(x) else np.full(gdim, np.inf)
        hi = x.max(axis=0) if len(x) else np.full(gdim, -np.inf)
        free = int(sum(marker[d].sum() for d in dofs))
        # Buffer reductions: the pickle-based allreduce would compare arrays with min().
        lo, hi = np.ascontiguousarray(lo, float), np.ascontiguousarray(hi, float)
        comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
        comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
        out.append(Body(name, tag, mat, dofs, blocks, lo, hi,
                        comm.allreduce(free, op=MPI.SUM)))
    return out


def expected_contact_duration(bodies: Sequence[Body], normal: np.ndarray) -> float:
    """Shortest wave round trip 2 L_b / c_b over the bodies that can move [s].

    L_b is the body's extent along the contact normal, c_b = sqrt(E/ρ) its bar wave speed:
    the contact of an elastic bar on a wall lasts exactly 2L/c, and a body's first wave
    round trip is the shortest time in which its contact force can change course. Bodies
    held entirely by Dirichlet conditions (rigid) do not count. For curved bodies the
    Hertz duration is longer (pass it as ``expected_contact_s``).
    """
    times = [2.0 * b.extent_along(normal) / b.wave_speed_m_s for b in bodies if b.free_dofs]
    times = [t for t in times if t > 0]
    return min(times) if times else math.inf


def check_resolution(dt_s: float, t_contact_s: float, how: str) -> None:
    """ValueError if fewer than MIN_STEPS_IN_CONTACT steps fit into the contact."""
    if not math.isfinite(t_contact_s):
        return
    if dt_s * MIN_STEPS_IN_CONTACT > t_contact_s:
        use = t_contact_s / MIN_STEPS_IN_CONTACT
        raise InputError(
            f"dt_s={dt_s:g} cannot resolve the contact: the expected contact duration is "
            f"{t_contact_s:.3g} s ({how}), only {t_contact_s / dt_s:.2g} steps; use "
            f"dt_s <= {use:.3g} (at least {MIN_STEPS_IN_CONTACT} steps per contact)")


def held_marker(template: PETSc.Mat, bcs: Sequence) -> PETSc.Vec:
    """1 at free DOFs, 0 at Dirichlet DOFs; ValueError if a Dirichlet value is not zero."""
    g = template.createVecLeft()
    g.zeroEntries()
    compat.set_bc(g, list(bcs))
    comm = template.getComm().tompi4py()
    worst = comm.allreduce(float(np.max(np.abs(g.array_r), initial=0.0)), op=MPI.MAX)
    g.destroy()
    if worst != 0.0:
        raise InputError(f"Dirichlet values up to {worst:g} m: the impact step holds supports "
                         "fixed (zero displacement); prescribed motions are not supported")
    marker = template.createVecLeft()
    marker.set(1.0)
    compat.set_bc(marker, list(bcs), scale=0.0)
    return marker


def assemble_matrices(a_form, m_form, bcs: Sequence, mass: str, marker: PETSc.Vec):
    """K and M with zero rows and columns at Dirichlet DOFs (their displacement and
    velocity stay zero). The lumped M is the row sum of the consistent one."""
    K = compat.assemble_matrix(a_form, list(bcs), diagonal=0.0)
    if mass == "consistent":
        M = compat.assemble_matrix(m_form, list(bcs), diagonal=0.0)
        return K, M
    full = dolfinx.fem.petsc.assemble_matrix(m_form)
    full.assemble()
    ones = full.createVecRight()
    ones.set(1.0)
    diag = full.createVecLeft()
    full.mult(ones, diag)
    diag.pointwiseMult(diag, marker)
    M = K.duplicate(copy=False)
    M.zeroEntries()
    M.setDiagonal(diag)
    M.assemble()
    for o in (full, ones, diag):
        o.destroy()
    return K, M


def iteration_matrix(K: PETSc.Mat, M: PETSc.Mat, dt_s: float, theta: float, rayleigh,
                     marker: PETSc.Vec) -> PETSc.Mat:
    """Ŵ = M + hθC + h²θ²K with C = αM + βK; identity rows at Dirichlet DOFs."""
    alpha, beta = rayleigh
    ht = dt_s * theta
    W = K.copy()
    W.scale(ht * ht + ht * beta)
    W.axpy(1.0 + ht * alpha, M, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    held = marker.duplicate()
    held.set(1.0)
    held.axpy(-1.0, marker)
    W.setDiagonal(held, addv=PETSc.InsertMode.ADD_VALUES)
    W.assemble()
    held.destroy()
    return W


def initial_velocity(v: PETSc.Vec, bodies: Sequence[Body], velocities: dict,
                     marker: PETSc.Vec, gdim: int) -> None:
    """v = the given velocity [m/s] on each named body's free DOFs, 0 elsewhere."""
    names = {b.name: b for b in bodies}
    v.zeroEntries()
    arr = v.array  # the owned values, writable in place
    for name, vel in (velocities or {}).items():
        if name not in names:
            raise InputError(f"initial_velocity names the body {name!r}; the bodies are "
                             f"{sorted(names)}")
        vel = np.asarray(vel, dtype=float).reshape(-1)
        if vel.size != gdim or not np.all(np.isfinite(vel)):
            raise InputError(f"initial_velocity[{name!r}]={vel.tolist()}: need {gdim} finite "
                             "components in m/s")
        for c, dofs in enumerate(names[name].dofs):
            arr[dofs] = vel[c]
    v.pointwiseMult(v, marker)


def initial_displacement(u: PETSc.Vec, u0, V, marker: PETSc.Vec) -> None:
    """u = the Function ``u0`` [m] on V's owned DOFs, zero at held DOFs."""
    x = getattr(u0, "x", None)
    n = u.getLocalSize()
    owned = None if x is None else u0.function_space.dofmap.index_map.size_local * \
        u0.function_space.dofmap.index_map_bs
    if owned != n:
        raise InputError(f"initial_displacement={u0!r}: must be a Function on the problem's "
                         f"vector space V ({n} owned values on this rank, got {owned})")
    vals = x.array[:n]
    if not np.all(np.isfinite(vals)):
        raise InputError("initial_displacement has non-finite values")
    u.array[:] = vals
    u.pointwiseMult(u, marker)


def load_vector(V, L_form, bcs: Sequence) -> Optional[PETSc.Vec]:
    """The constant external load f [N] with zeros at Dirichlet DOFs, or None."""
    if L_form is None:
        return None
    f = dolfinx.fem.petsc.assemble_vector(L_form)
    f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    compat.set_bc(f, list(bcs), scale=0.0)
    return f


def unloaded_step_rhs(K: PETSc.Mat, h: float, theta: float, w: PETSc.Vec,
                      omega: PETSc.Vec) -> PETSc.Vec:
    """h[−K (w + hθ ω)]: the right-hand side of a θ-step of a body with no load and no
    damping, from its displacement w and velocity ω (a new Vec); Δv = Ŵ⁻¹ of it."""
    y = w.copy()
    y.axpy(h * theta, omega)
    r = K.createVecLeft()
    K.mult(y, r)
    r.scale(-h)
    y.destroy()
    return r
