"""A frictionless penalty contact against a rigid obstacle, written by hand in UFL and
solved by PETSc SNES inside DOLFINx: the peer a FEniCSx user would write.

The gap to the rigid target at the current position x + u is, for a circle of centre c
(moved by δ) and radius R, g = |x + u − c| − R with the normal n = (x + u − c)/|x + u − c|,
and for a plane through p with normal n, g = (x + u − p)·n. The penalty traction
κ ⟨−g⟩₊ n acts on the slave facets; the residual

    F(u; v) = a(u, v) − ∫_Γc κ ⟨−g(u)⟩₊ n(u)·v ds

is integrated with the vertex rule (nodal contact, as flexcontact's pairs), and its exact
Jacobian comes from ufl.derivative. SNES: Newton with a backtracking line search, MUMPS LU
for each linear solve. κ [Pa/m] is ``kappa_factor`` · E / h_contact; the penetration
p/κ at the peak pressure is then a fraction 1/kappa_factor of an element's size times
p0/E, far below what a, p0 and P need to agree to 0.5 %.
"""
from __future__ import annotations

import logging
import time

import numpy as np
import ufl
from petsc4py import PETSc

import dolfinx
import dolfinx.fem
import dolfinx.fem.petsc
from flexcontact import compat

from peers_cases import R_M, STEEL, Case, target_force
from peers_flexcontact import Setup

# UFL warns that the custom rule's arrays enter the form's signature through str().
logging.getLogger("UFL").setLevel(logging.ERROR)

KAPPA_FACTOR = 1e3
"""κ = KAPPA_FACTOR · E / h_contact [Pa/m]."""


def kappa(case: Case) -> float:
    return KAPPA_FACTOR * STEEL.E_Pa / case.geo["h_contact"]


def _vertex_rule(dim: int) -> dict:
    """The vertex (nodal) quadrature of a facet, given as a custom rule (FFCx's "vertex"
    scheme is made for cells)."""
    if dim == 2:
        pts, w = np.array([[0.0], [1.0]]), np.array([0.5, 0.5])
    else:
        pts, w = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), np.full(3, 1.0 / 6.0)
    return {"quadrature_rule": "custom", "quadrature_points": pts, "quadrature_weights": w,
            "quadrature_degree": 1}


def _gap_and_normal(case: Case, u, delta):
    x = ufl.SpatialCoordinate(case.msh)
    if case.dim == 2:
        c = ufl.as_vector((0.0, R_M)) - ufl.as_vector((0.0, 1.0)) * delta
        r = x + u - c
        dist = ufl.sqrt(ufl.dot(r, r))
        return dist - R_M, r / dist
    n = ufl.as_vector((0.0, 0.0, 1.0))
    return ufl.dot(x + u, n) - delta, n


class PenaltySNES:
    """The hand-written peer; ``solve(delta_m)`` solves at one approach δ [m], starting
    from the last solution."""

    def __init__(self, case: Case, kappa_Pa_m: float):
        if case.kind != "rigid":
            raise ValueError(f"case {case.name!r}: the SNES peer handles a rigid target only")
        self.case, self.s = case, Setup(case)
        V = self.s.V
        self.u = dolfinx.fem.Function(V)
        self.delta = dolfinx.fem.Constant(case.msh, PETSc.ScalarType(0.0))
        g, n = _gap_and_normal(case, self.u, self.delta)
        ds = ufl.Measure("ds", domain=case.msh, subdomain_data=case.facets,
                         metadata=_vertex_rule(case.dim))
        k = dolfinx.fem.Constant(case.msh, PETSc.ScalarType(kappa_Pa_m))
        pen = k * 0.5 * (abs(g) - g)                     # κ ⟨−g⟩₊ ≥ 0
        contact = pen * ufl.dot(n, self.s.v) * ds(case.slave_tag)
        F = ufl.action(self.s.a, self.u) - contact
        J = ufl.derivative(F, self.u, self.s.u_trial)
        self.F, self.J = dolfinx.fem.form(F), dolfinx.fem.form(J)
        self.contact = dolfinx.fem.form(contact)
        self.A = dolfinx.fem.petsc.create_matrix(self.J)
        self.b = compat.create_petsc_vector(V)
        self.snes = self._snes()
        self.iterations = []

    def _snes(self):
        snes = PETSc.SNES().create(self.case.msh.comm)
        snes.setFunction(self._residual, self.b)
        snes.setJacobian(self._jacobian, self.A)
        snes.setType("newtonls")
        opts = PETSc.Options()
        opts["snes_linesearch_type"] = "basic"
        snes.setFromOptions()
        # Newton stops at 1e-10 of Hertz's load in the residual (N/m or N): the round-off
        # floor of these SI-valued systems is near 1e-12 of it.
        snes.setTolerances(rtol=1e-12, atol=1e-10 * target_force(self.case), max_it=50)
        snes.setConvergenceHistory()
        ksp = snes.getKSP()
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        return snes

    def _update(self, x):
        x.copy(compat.petsc_vec(self.u))
        self.u.x.scatter_forward()

    def _residual(self, snes, x, b):
        self._update(x)
        with b.localForm() as local:
            local.set(0.0)
        dolfinx.fem.petsc.assemble_vector(b, self.F)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        compat.set_bc(b, self.s.bcs, 0.0)   # homogeneous supports: no residual there

    def _jacobian(self, snes, x, A, P):
        self._update(x)
        A.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(A, self.J, bcs=self.s.bcs)
        A.assemble()

    def solve(self, delta_m: float):
        self.delta.value = delta_m
        x = compat.petsc_vec(self.u).copy()
        self.snes.solve(None, x)
        reason = self.snes.getConvergedReason()
        if reason <= 0:
            history = self.snes.getConvergenceHistory()[0][-5:]
            raise RuntimeError(f"SNES did not converge at δ = {delta_m} m (reason {reason}; "
                               f"last residuals {history})")
        self.iterations.append(self.snes.getIterationNumber())
        self._update(x)
        x.destroy()

    def nodal_forces(self):
        """Slave-node coordinates and normal contact forces |f| [N/m or N]."""
        f = dolfinx.fem.petsc.assemble_vector(self.contact)
        f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        d = self.case.dim
        vals = f.array_r.reshape(-1, d)
        f.destroy()
        x = self.s.V.tabulate_dof_coordinates()[:vals.shape[0]]
        return x, np.linalg.norm(vals, axis=1)


def solve(case: Case, delta_m: float, increments: int = 1) -> dict:
    """The SNES peer from the mesh to the answer, ramping δ over ``increments``."""
    t0 = time.perf_counter()
    peer = PenaltySNES(case, kappa(case))
    for i in range(1, increments + 1):
        peer.solve(delta_m * i / increments)
    total = time.perf_counter() - t0
    x, fn = peer.nodal_forces()
    return {"x": x, "fn": fn, "time_s": total, "iterations": peer.iterations,
            "kappa_Pa_per_m": kappa(case), "kappa_factor_E_over_h": KAPPA_FACTOR}
