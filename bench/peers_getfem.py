"""GetFEM's side of bench/peers.py: the same mesh, nodal Alart–Curnier contact.

The DOLFINx mesh's geometry and topology are copied into one GetFEM mesh per body (GetFEM
merges points that coincide, and the two bodies touch at the origin), so both codes work on
the same P1 simplices. Contact: ``add_nodal_contact_between_nonmatching_meshes_brick``
(the non-symmetric Alart–Curnier augmented Lagrangian; with friction when μ > 0), the slave
nodes on the upper body, whose nodes lie exactly above the block's (node–node pairs, as
flexcontact's). The multipliers are the slave nodes' normal contact forces. Supports as in
flexcontact's demos: the block's bottom clamped and the upper body's top lowered by δ
(simplified Dirichlet rows); in 3D the symmetry planes by normal Dirichlet multipliers.
Newton (GetFEM's standard solver) with MUMPS.
"""
from __future__ import annotations

import time

import numpy as np

from flexcontact import compat
from flexcontact.meshes import tags

from peers_cases import STEEL, Case, target_force

try:
    import getfem as gf
    gf.util_trace_level(0)
except ImportError:          # e.g. Debian 13's root without python3-getfem
    gf = None


def augmentation_Pa(case: Case, lengths_m) -> float:
    """Alart–Curnier's augmentation r [Pa] for the nodal brick with friction: E·l/h_contact.

    The brick scales r by α_i = M_ii / l per slave node (M the mass matrix of the slave
    surface, l the largest bounding-box side of the bodies, ``lengths_m``), so that r is
    "close to the Young modulus" as GetFEM advises. Its nodal augmentation r·α_i is then
    E·A_i/l, the stiffness of a column as long as the whole body under the node's
    tributary area A_i: in 3D about 1,000 times (2D 2,400 times) softer than the element
    layer under the node, E·A_i/h. With μ = 0.3 on the 60k-DOF Hertz quarter model that
    Newton then wanders (tiny line-search steps that raise the residual, 14 iterations for
    the first increment, no convergence in 100 at the sixth, measured). Taking
    r = E·l/h makes r·α_i ≈ E·M_ii/h, the element layer's stiffness, and Newton takes
    2–6 iterations per increment (bench/README.md). The solution does not depend on r.
    """
    return STEEL.E_Pa * max(lengths_m) / case.geo["h_contact"]


RELATIVE_RESIDUAL = 1e-9
"""GetFEM's Newton stops when its residual (in N/m or N) is below this times Hertz's load;
its round-off floor on these SI-valued problems is about 1e-10 of it."""

REGION = {tags.FIXED: 1, tags.LOADED: 2, tags.SLAVE: 3, tags.MASTER: 4,
          tags.SYMMETRY_X: 5, tags.SYMMETRY_Y: 6}


def available() -> bool:
    return gf is not None


def _body_mesh(case: Case, body_tag: int):
    """One body as a GetFEM mesh, with its tagged facets as regions (REGION numbers)."""
    msh, dim = case.msh, case.dim
    x = compat.geometry_x(msh)[:, :dim]
    cell_nodes = compat.geometry_dofmap(msh)
    body_cells = case.cells.indices[case.cells.values == body_tag]
    m = gf.Mesh("empty", dim)
    pts = np.transpose(x[cell_nodes[body_cells]], (2, 1, 0))   # (dim, nodes, cells)
    cvids = np.asarray(m.add_convex(gf.GeoTrans(f"GT_PK({dim},1)"), pts)).reshape(-1)
    convex_of = dict(zip(body_cells.tolist(), cvids.tolist()))
    fdim = dim - 1
    f2c, f2c_off = compat.connectivity(msh, fdim, dim)
    for tag, region in REGION.items():
        facets = case.facets.indices[case.facets.values == tag]
        faces = []
        fnodes = compat.entities_to_geometry(msh, fdim, facets) if len(facets) else []
        for f, nodes in zip(facets, fnodes):
            for c in f2c[f2c_off[f]:f2c_off[f + 1]]:
                if int(c) in convex_of:
                    # GetFEM's face i of a simplex is the one opposite its vertex i.
                    local = [i for i, n in enumerate(cell_nodes[c]) if n not in set(nodes)]
                    faces.append((convex_of[int(c)], local[0]))
        if faces:
            m.set_region(region, np.array(faces, dtype=np.int64).T)
    return m


class GetfemHertz:
    """The two-body Hertz problem in GetFEM; ``solve(delta_m)`` at one approach δ [m]."""

    def __init__(self, case: Case, mu: float):
        if case.kind != "hertz":
            raise ValueError(f"case {case.name!r}: the GetFEM peer handles two bodies")
        self.case, self.mu = case, mu
        dim = case.dim
        E, nu = STEEL.E_Pa, STEEL.nu
        md = gf.Model("real")
        md.add_initialized_data("lambda", [E * nu / ((1 + nu) * (1 - 2 * nu))])
        md.add_initialized_data("mu", [E / (2 * (1 + nu))])
        md.add_initialized_data("zero", np.zeros(dim))
        md.add_initialized_data("top", np.zeros(dim))
        self.mfs = {}
        for name, body in (("u1", tags.UPPER), ("u2", tags.BASE)):  # u1: slave body
            m = _body_mesh(case, body)
            mf = gf.MeshFem(m, dim)
            mf.set_classical_fem(1)
            mim = gf.MeshIm(m, gf.Integ("IM_TRIANGLE(2)" if dim == 2 else "IM_TETRAHEDRON(2)"))
            md.add_fem_variable(name, mf)
            # Plane strain in 2D: the Lamé coefficients enter as they are.
            md.add_isotropic_linearized_elasticity_brick(mim, name, "lambda", "mu")
            if dim == 3:
                for region in (REGION[tags.SYMMETRY_X], REGION[tags.SYMMETRY_Y]):
                    md.add_normal_Dirichlet_condition_with_multipliers(mim, name, 1, region)
            self.mfs[name] = (m, mf, mim)
        lengths = [float(np.ptp(np.asarray(m.pts()), axis=1).max())
                   for m, _, _ in self.mfs.values()]
        # Frictionless single steps keep GetFEM's advised r = E: with E·l/h the 2D step
        # stopped after 2 iterations at a wrong answer (a +19 %, measured), since the
        # contact rows of GetFEM's residual are divided by r and its test misses them.
        self.r_Pa = augmentation_Pa(case, lengths) if mu > 0 else STEEL.E_Pa
        md.add_initialized_data("r", [self.r_Pa])
        md.add_Dirichlet_condition_with_simplification("u1", REGION[tags.LOADED], "top")
        md.add_Dirichlet_condition_with_simplification("u2", REGION[tags.FIXED], "zero")
        mim1, mim2 = self.mfs["u1"][2], self.mfs["u2"][2]
        slave, master = REGION[tags.SLAVE], REGION[tags.MASTER]
        if mu > 0:
            md.add_initialized_data("fr", [mu])
            # Debian's 5.4 interface reads one more data name than it documents before
            # the friction coefficient's (measured: the last is the friction coefficient,
            # the one before it the augmentation), so r is named twice.
            md.add_nodal_contact_between_nonmatching_meshes_brick(
                mim1, mim2, "u1", "u2", "lambda_n", "lambda_t", "r", "r", "fr", slave, master)
        else:
            md.add_nodal_contact_between_nonmatching_meshes_brick(
                mim1, mim2, "u1", "u2", "lambda_n", "r", slave, master)
        self.md = md
        dofs = np.asarray(self.mfs["u1"][1].basic_dof_on_region(REGION[tags.LOADED])).reshape(-1)
        self.top_dofs = dofs[dofs % dim == dim - 1]
        self.iterations = []

    def solve(self, delta_m: float):
        top = np.zeros(self.case.dim)
        top[-1] = -delta_m
        self.md.set_variable("top", top)
        # A simplified Dirichlet row is not part of GetFEM's residual: move the top's DOFs
        # to δ first, so that the interior's residual starts Newton's iterations.
        u1 = np.asarray(self.md.variable("u1")).copy()
        u1[self.top_dofs] = -delta_m
        self.md.set_variable("u1", u1)
        out = self.md.solve("max_res", RELATIVE_RESIDUAL * target_force(self.case),
                            "max_iter", 100, "lsolver", "mumps")
        nbit, converged = (out if isinstance(out, (tuple, list)) else (out, True))
        if not converged:
            raise RuntimeError(f"GetFEM did not converge at δ = {delta_m} m")
        self.iterations.append(int(nbit))

    def nodal_forces(self):
        """Slave-node coordinates and normal contact forces [N/m or N] (≥ 0 in contact)."""
        m, mf, _ = self.mfs["u1"]
        dofs = np.asarray(mf.basic_dof_on_region(REGION[tags.SLAVE])).reshape(-1)
        nodes = np.sort(dofs[dofs % self.case.dim == 0])
        x = np.asarray(mf.basic_dof_nodes(nodes)).T
        lam = np.asarray(self.md.variable("lambda_n")).reshape(-1)
        return x, -lam if lam.sum() < 0 else lam


def solve(case: Case, delta_m: float, increments: int = 1, mu: float = 0.0) -> dict:
    """GetFEM from the copied mesh to the answer (the copy is timed too), ramping δ."""
    t0 = time.perf_counter()
    peer = GetfemHertz(case, mu)
    for i in range(1, increments + 1):
        peer.solve(delta_m * i / increments)
    total = time.perf_counter() - t0
    x, fn = peer.nodal_forces()
    return {"x": x, "fn": fn, "time_s": total, "iterations": peer.iterations,
            "augmentation_r_Pa": peer.r_Pa}
