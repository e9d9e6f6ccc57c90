"""flexcontact's side of bench/peers.py, plus one plain linear-elastic solve for scale.

``Setup`` holds what flexcontact and the hand-written DOLFINx peer share: the space, the
elasticity form, the Dirichlet conditions and the prescribed approach δ [m]. Two bodies:
the upper body's top is lowered by δ. One body on a rigid target: the target moves by δ
towards the body (2D: the circle down; 3D: the plane up under the column, whose top is
held), so that every Dirichlet value stays zero.
"""
from __future__ import annotations

import time

import numpy as np
import ufl
from petsc4py import PETSc

import flexcontact as fc
from flexcontact import compat, forms
from flexcontact.meshes import tags

from peers_cases import R_M, STEEL, Case


class Setup:
    """Space, form, supports and approach of a case (built in the timed region)."""

    def __init__(self, case: Case):
        self.case = case
        msh, dim = case.msh, case.dim
        self.V = compat.vector_space(msh)
        u, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        self.u_trial, self.v = u, v
        dx = ufl.Measure("dx", domain=msh, subdomain_data=case.cells)
        present = [t for t in (tags.BASE, tags.UPPER) if t in set(case.cells.values.tolist())]
        self.a = forms.elasticity_form(u, v, {t: STEEL for t in present}, dx,
                                       "plane_strain" if dim == 2 else "3d")
        f = case.facets
        bcs, self.top = [], None
        if case.kind == "hertz" or dim == 2:
            bcs += fc.dirichlet(self.V, f, tags.FIXED)[0]
        if dim == 3:
            bcs += fc.dirichlet(self.V, f, tags.SYMMETRY_X, components=[0])[0]
            bcs += fc.dirichlet(self.V, f, tags.SYMMETRY_Y, components=[1])[0]
        if case.kind == "hertz" or dim == 3:
            top_bcs, consts = fc.dirichlet(self.V, f, tags.LOADED)
            bcs += top_bcs
            self.top = consts[-1]          # the vertical component
        self.bcs = bcs
        self.target = None
        if case.kind == "rigid":
            self.target = (fc.RigidTarget("circle", point_m=(0.0, R_M), radius_m=R_M,
                                          name="rigid cylinder") if dim == 2 else
                           fc.RigidTarget("plane", point_m=(0.0, 0.0, 0.0),
                                          normal=(0.0, 0.0, 1.0), name="rigid plane"))
        self.delta_m = 0.0

    def set_approach(self, delta_m: float):
        """Prescribe the approach δ [m]."""
        self.delta_m = float(delta_m)
        if self.case.kind == "hertz":
            self.top.value = -self.delta_m
        elif self.case.dim == 2:
            self.target.displacement_m = np.array([0.0, -self.delta_m])
        else:
            self.target.displacement_m = np.array([0.0, 0.0, self.delta_m])

    def interface(self, mu: float):
        f = self.case.facets
        if self.case.kind == "hertz":
            return fc.ContactInterface(f, slave=tags.SLAVE, master=tags.MASTER, mu=mu,
                                       name=self.case.name)
        return fc.ContactInterface(f, slave=self.case.slave_tag, master=self.target, mu=mu,
                                   name=self.case.name)


def solve(case: Case, delta_m: float, increments: int = 1, mu: float = 0.0) -> dict:
    """flexcontact from the mesh to the answer: form, assembly, factorization, condensation
    and ``increments`` increments ramping the approach to ``delta_m``. Returns the slave
    nodes (x, normal force), the total time [s] and flexcontact's own timings."""
    t0 = time.perf_counter()
    s = Setup(case)
    problem = fc.ContactProblem(s.a, None, s.bcs, s.interface(mu))
    for i in range(1, increments + 1):
        s.set_approach(delta_m * i / increments)
        problem.step()
    total = time.perf_counter() - t0
    pr, inc = problem.pairs, problem.increments[-1]
    return {"x": np.asarray(pr.x[:pr.m]), "fn": np.asarray(inc.lam[:, 0]), "time_s": total,
            "setup_s": total - sum(i.summary.time_s for i in problem.increments),
            "increment_s": [i.summary.time_s for i in problem.increments],
            "iterations": [i.summary.iterations for i in problem.increments],
            "contact_dofs": int(problem.n_contact_dofs),
            "parts_s": {**{k: v for k, v in problem.timings.items() if k.endswith("_s")},
                        **{k: v for k, v in problem.flex_info.items() if k.endswith("_s")}}}


def calibrate(case: Case) -> float:
    """The approach δ [m] that gives Hertz's load for a = A_TARGET_M: a trial approach,
    then δ scaled by (P_target / P_trial)^e (e = 1 in 2D, 2/3 in 3D, as δ ∝ P^(2/3))."""
    from peers_cases import A_TARGET_M, target_force
    trial = A_TARGET_M**2 / (2 * R_M)
    out = solve(case, trial)
    P = case.force_scale * float(out["fn"].sum())
    if P <= 0:
        raise RuntimeError(f"{case.name}: the trial approach {trial} m produced no contact")
    return trial * (target_force(case) / P) ** (1.0 if case.dim == 2 else 2.0 / 3.0)


def linear_solve(case: Case, delta_m: float, factor: str = "lu") -> dict:
    """One plain linear-elastic solve on the same mesh and supports, contact left out
    (for scale): assembly of K and of the lifted load, a MUMPS factorization through
    PETSc with MUMPS's own ordering (``factor`` "lu", PETSc's default for a user, or
    "cholesky", K flagged symmetric, as flexcontact factors it), one back-substitution.
    Returns the total and its parts [s]."""
    import dolfinx.fem
    import dolfinx.fem.petsc
    t0 = time.perf_counter()
    s = Setup(case)
    s.set_approach(delta_m)
    a = dolfinx.fem.form(s.a)
    K = dolfinx.fem.petsc.assemble_matrix(a, bcs=s.bcs)
    K.assemble()
    b = compat.create_petsc_vector(s.V)
    b.zeroEntries()
    dolfinx.fem.petsc.apply_lifting(b, [a], bcs=[s.bcs])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    compat.set_bc(b, s.bcs)
    if b.norm() == 0:
        b.set(1.0)          # every support homogeneous: any right-hand side times the same
        compat.set_bc(b, s.bcs)
    t_assembly = time.perf_counter() - t0
    if factor == "cholesky":
        K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    ksp = PETSc.KSP().create(case.msh.comm)
    ksp.setOperators(K)
    ksp.setType("preonly")
    ksp.getPC().setType(factor)
    ksp.getPC().setFactorSolverType("mumps")
    t1 = time.perf_counter()
    ksp.setUp()
    t_factor = time.perf_counter() - t1
    x = K.createVecRight()
    t1 = time.perf_counter()
    ksp.solve(b, x)
    t_solve = time.perf_counter() - t1
    total = time.perf_counter() - t0
    for obj in (ksp, K, b, x):
        obj.destroy()
    return {"time_s": total, "assembly_s": t_assembly, "factorization_s": t_factor,
            "backsolve_s": t_solve, "factor": factor}
