"""The dam and its foundation alone, factored once for a whole sweep of impacts.

docs/architecture.md §7 (per-body condensation): the dam is linear and touches the log only through
contact, so everything it contributes to an impact scenario comes from two factorizations
made once per dam mesh:

* stage 1: K (stage-1 supports) is factored once; a water level is a new right-hand side,
  one back-substitution (the static displacement and base section are cached per level).
  The face has nodes at both ends of the sweep's water-level range, where the reservoir
  load is integrated exactly; between them the water line crosses a facet and the kinked
  pressure is integrated approximately (heel stress within 1e-5 of the hand statics at
  0.4 m facets);
* stage 2: Ŵ = M + hθC + h²θ²K at the sweep's time step, factored once, and its condensed
  flexibility W_face = S Ŵ⁻¹ Sᵀ on every DOF of the face strip's nodes (``_cpp.flexibility``,
  the same call as Condensation), dense. A dam of at most split_factor.SPLIT_LIMIT DOFs (the
  2D section) is factored by the sparse split factor instead, whose solves have no set-up
  per call.

During an impact the dam's state is split as u = u_static + w: u_static is the stage-1
equilibrium under the constant loads, so w (and its velocity) obey the homogeneous
equations driven by the contact impulses alone. Before the first impulse w = 0 and the free
velocity is exactly zero: no back-substitution is needed then.

Outputs: the linearised heel stress is σ_static + g·w with g = −K_dam c (c: the section's
heel-stress coefficients of nodal forces at the base nodes, K_dam the stiffness of the dam's
cells alone), i.e. the section of the dam's internal nodal forces; the largest principal
stress near the impact point is read from the recovered stress at the stated offset.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem
import dolfinx.fem.petsc  # noqa: F401  (the submodule must be imported explicitly in 0.5)
import dolfinx.mesh

from .. import _cpp, compat
from .. import impact_setup as setup
from ..assembly import assemble_load, assemble_stiffness
from ..forms import elasticity_form, mass_form
from ..meshes import dam as dam_mesh
from ..meshes import dam_tags as T
from ..pairing import _candidate_surface
from ..split_factor import SplitFactor
from .section import BaseSection
from .stress_probe import ProbeSpace, RecoveredStressProbe
from .stage1 import DamMesh, _measures, _sections, body_loads
from .stage2 import stage2_supports
from ..errors import InputError, SolveError

STRIP = 1
"""Tag of the face-strip facets in the DamModel's own strip MeshTags."""
SECTION_QUANTITIES = ("sigma_heel_Pa", "sigma_toe_Pa", "normal_force_N", "moment_centre_Nm")
"""The base section's quantities whose change is linear in the dam's displacement w."""


@dataclass
class StaticState:
    """Stage 1 at one water level: displacement (Function, m), the base section from the
    dam's side (with uplift) and the hand statics of that level."""

    water_level_m: float
    u: Any
    section: BaseSection
    section_foundation: BaseSection


def default_patch_y_m(base, yaw_deg: float = 15.0, margin_m: float = 1.0):
    """3D: the y range (m) of the face patch that the front end of the base scenario's log,
    at its place across the block, can hit at any yaw up to ± max(|its yaw|, ``yaw_deg``),
    widened by ``margin_m`` each side and kept on the block; None in 2D."""
    if base.dim != 3:
        return None
    yaw = np.radians(max(abs(base.log_yaw_deg), yaw_deg))
    reach = (0.5 * base.log_length_m * np.cos(np.radians(base.log_pitch_deg)) * np.sin(yaw)
             + base.log_radius_m)
    y = float(base.log_centre[1])
    return (float(max(y - reach - margin_m, 0.0)),
            float(min(y + reach + margin_m, base.dam_width_m)))


def default_strip_m(base, water_levels_m, pitch_deg: float = 15.0,
                    margin_m: float = 1.0) -> tuple[float, float]:
    """Elevations (m) of the face strip that the front end of the base scenario's log can
    hit at any water level of the range and any pitch up to ± max(|its pitch|,
    ``pitch_deg``), widened by ``margin_m`` each side and kept on the face."""
    pitch = np.radians(max(abs(base.log_pitch_deg), pitch_deg))
    R, L = base.log_radius_m, base.log_length_m
    reach = 0.5 * L * np.sin(pitch) + R * np.cos(pitch)
    axis_lo = min(water_levels_m) - base.log_draft_m + R
    axis_hi = max(water_levels_m) - base.log_draft_m + R
    z0 = max(axis_lo - reach - margin_m, 0.5 * base.h_far_m)
    z1 = min(axis_hi + reach + margin_m, base.dam_height_m)
    return float(z0), float(z1)


def front_end_span_m(s, axis: int) -> tuple[float, float]:
    """(lowest, highest) coordinate (m) along ``axis`` of the front end of scenario ``s``'s
    log: the disc (a segment in 2D) of its radius about the axis's end."""
    a = s.log_axis
    c = float(s.log_centre[axis] + 0.5 * s.log_length_m * a[axis])
    r = s.log_radius_m * float(np.sqrt(max(1.0 - a[axis] ** 2, 0.0)))
    return c - r, c + r


def face_region_m(base, scenarios, water_levels_m=None, margin_m: float = 1.0):
    """(strip_m, patch_y_m): the face strip's elevations and, in 3D, the patch's y range
    (None in 2D) that hold the base's default region and the front end of every one of
    ``scenarios`` with ``margin_m`` to spare each side, kept on the face."""
    lo, hi = _levels(base, water_levels_m)
    z0, z1 = default_strip_m(base, (lo, hi))
    patch = default_patch_y_m(base)
    for s in scenarios:
        lo, hi = front_end_span_m(s, s.dim - 1)
        z0, z1 = min(z0, lo - margin_m), max(z1, hi + margin_m)
        if patch is not None:
            lo, hi = front_end_span_m(s, 1)
            patch = (min(patch[0], lo - margin_m), max(patch[1], hi + margin_m))
    z0 = max(z0, 0.5 * base.h_far_m)
    z1 = min(z1, base.dam_height_m - 0.5 * base.h_impact_m)
    if patch is not None:
        patch = (float(max(patch[0], 0.0)), float(min(patch[1], base.dam_width_m)))
    return (float(z0), float(z1)), patch


COMPLIANCE_BLOCK = 128
"""Face nodes whose compliance one multiple-right-hand-side solve gives: at a 51,309-DOF
block 128 unit vectors are 53 MB, and the 2,470 of its face took 98 s one by one."""


class DamModel:
    """The dam + foundation of ``base`` (without the log), factored for a sweep at
    ``dt_s`` and the base's ``time_scheme_theta``; see the module docstring.
    ``water_levels_m`` = (lo, hi): the range of water levels of the sweep (the face has
    nodes at both). ``strip_m``: the face strip's elevations (default_strip_m); in 3D
    ``patch_y_m``: its y range (default_patch_y_m). Serial (``comm`` of one rank).

    Counters: ``factorizations`` and ``back_substitutions``, dicts by stage.
    """

    def __init__(self, base, dt_s: float, water_levels_m=None, comm=MPI.COMM_SELF,
                 strip_m=None, restored: Optional[dict] = None,
                 patch_y_m=None, saveable: bool = False):
        if comm.size != 1:
            raise InputError(f"comm of size {comm.size}: DamModel is serial (one rank; "
                             "parallel sweeps run one DamModel per process)")
        theta = base.time_scheme_theta
        setup.check_scheme(dt_s, 0.0, theta, "consistent", (0.0, 0.0))
        lo, hi = _levels(base, water_levels_m)
        self.base, self.dt, self.theta, self.comm = base, float(dt_s), float(theta), comm
        self.water_levels_m = (lo, hi)
        self.strip_m = tuple(strip_m) if strip_m is not None else default_strip_m(base, (lo, hi))
        self.patch_y_m = (tuple(float(y) for y in patch_y_m) if patch_y_m is not None
                          else default_patch_y_m(base))
        # restored: {"stage1": factor of K, "stage2": factor of Ŵ, "W_face": array,
        # "face_compliance_x": array} read from a model file (dam/model_file.py): nothing is
        # factored, the restorations are counted instead.
        self._restored = restored
        # saveable: K factored as a SavedFactor (model_file.prepare writes it, no second
        # factorization). Ŵ's factors can be saved either way: MUMPS's Schur factor
        # (DistributedSchur) writes its files with its split, the split factor its arrays.
        self._saveable = bool(saveable) and restored is None
        self._compliance = ({0: restored["face_compliance_x"]}
                            if restored is not None and "face_compliance_x" in restored else {})
        self.factorizations = {"dam_stage1": 0, "dam_stage2": 0}
        self.restorations = {"dam_stage1": 0, "dam_stage2": 0}
        self.back_substitutions = {"dam_stage1": 0, "dam_stage2": 0}
        self.timings = {}
        t0 = time.perf_counter()
        self.mesh = DamMesh(*dam_mesh.build_dam_only(comm, base, self.strip_m, (lo, hi),
                                                     self.patch_y_m))
        self.timings["mesh_s"] = time.perf_counter() - t0
        self.V = compat.vector_space(self.mesh.msh)
        self.kind = "plane_strain" if base.dim == 2 else "3d"
        self.materials = {T.DAM: base.concrete, T.FOUNDATION: base.rock}
        self.bcs = stage2_supports(base, self.V, self.mesh)
        self._statics: dict = {}
        self._stage1()
        self._stage2()
        self._heel_functional()
        self._u_total = dolfinx.fem.Function(self.V)   # u_static + w, read by stress probes
        self._probe_space = None                       # shared by the stress probes
        self.timings["setup_s"] = time.perf_counter() - t0

    # ---- stage 1 -------------------------------------------------------------------------
    def _stage1(self):
        t0 = time.perf_counter()
        u, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        self.dx, self.ds = _measures(self.mesh)
        self.a_form = dolfinx.fem.form(elasticity_form(u, v, self.materials, self.dx, self.kind,
                                                       cell_tags=self.mesh.cell_tags))
        K1 = assemble_stiffness(self.a_form, self.bcs)
        self._K1 = K1
        if self._restored is not None:
            self._ksp1, self._factor1 = None, self._restored["stage1"]
            self.restorations["dam_stage1"] += 1
            self.timings["stage1_factor_s"] = time.perf_counter() - t0
            return
        if self._saveable:
            from ..saved_factor import factor_matrix
            self._ksp1, self._factor1 = None, factor_matrix(K1)
            self.factorizations["dam_stage1"] += 1
            self.timings["stage1_factor_s"] = time.perf_counter() - t0
            return
        ksp = PETSc.KSP().create(K1.getComm())
        ksp.setOperators(K1)
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.setUp()  # the one numerical factorization of K
        self.factorizations["dam_stage1"] += 1
        self._ksp1, self._factor1 = ksp, None
        self.timings["stage1_factor_s"] = time.perf_counter() - t0

    def static_state(self, water_level_m: float) -> StaticState:
        """Stage 1 at ``water_level_m`` (cached): one back-substitution with K's factor."""
        key = float(water_level_m)
        if key in self._statics:
            return self._statics[key]
        s = self.base.replace(water_level_m=key)
        v = ufl.TestFunction(self.V)
        loads = body_loads(s, v, self.dx, self.ds)
        p = assemble_load(self.V, self.a_form, dolfinx.fem.form(loads["dam"] + loads["foundation"]),
                          self.bcs, self.comm)
        uh = dolfinx.fem.Function(self.V, name="displacement_m")
        x = compat.petsc_vec(uh)
        self._solve1(p, x, f"stage 1 at water_level_m={key}")
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        p.destroy()
        self.back_substitutions["dam_stage1"] += 1
        dam, found = _sections(s, self.V, uh, loads, self.dx, self.kind, self.mesh)
        state = StaticState(key, uh, dam, found)
        self._statics[key] = state
        return state

    def _solve1(self, b: PETSc.Vec, x: PETSc.Vec, what: str) -> None:
        """x = K⁻¹ b with stage 1's factor (its own, or the one restored from a file)."""
        if self._factor1 is not None:
            self._factor1.solve(b, x)
            return
        self._ksp1.solve(b, x)
        if self._ksp1.getConvergedReason() < 0:
            raise SolveError(f"{what}: the MUMPS solve failed")

    # ---- stage 2 -------------------------------------------------------------------------
    def _stage2(self):
        t0 = time.perf_counter()
        u, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        m_form = dolfinx.fem.form(mass_form(u, v, self.materials, self.dx))
        marker = setup.held_marker(self._K1, self.bcs)
        self.K, self.M = setup.assemble_matrices(self.a_form, m_form, self.bcs, "consistent",
                                                 marker)
        self.W_hat = setup.iteration_matrix(self.K, self.M, self.dt, self.theta, (0.0, 0.0),
                                            marker)
        marker.destroy()
        self.strip_tags = self._strip_tags()
        self.face = _candidate_surface(self.V, self.strip_tags, STRIP)
        self.face_dofs = np.asarray(self.face["dofs"], np.int64).reshape(-1)
        if self._restored is not None:
            self.factor = self._restored["stage2"]
            if int(self.factor.size) != self.W_hat.getSize()[0]:
                raise SolveError(f"a stage-2 factor of {int(self.factor.size)} rows restored "
                                 f"for a dam of {self.W_hat.getSize()[0]} DOFs")
            self.W_face = np.asarray(self._restored["W_face"])
            if self.W_face.shape != (self.face_dofs.size,) * 2:
                raise SolveError(f"W_face of shape {self.W_face.shape} restored for a face of "
                                 f"{self.face_dofs.size} DOFs")
            self.restorations["dam_stage2"] += 1
            self.flex_info = {"restored": True,
                              "split": bool(getattr(self.factor, "has_condense", False))}
        elif SplitFactor.worth_it(self.W_hat.getSize()[0]):
            # A small dam (the 2D section): MUMPS's set-up per solve would be most of a step.
            # Its arrays are what a model file keeps, so a saveable model takes it too.
            self.factor = SplitFactor(self.W_hat, self.face_dofs)
            self.W_face = self.factor.W
            self.factorizations["dam_stage2"] += 1
            self.flex_info = {"factor": "split", "factor_entries": self.factor.factor_entries}
        else:
            F, self.factor, info = _cpp.flexibility(self.W_hat, self.face_dofs, "schur")
            self.W_face = np.asarray(F)
            self.factorizations["dam_stage2"] += int(info["factorizations"])
            self.flex_info = dict(info)
        self.timings["stage2_factor_s"] = time.perf_counter() - t0

    @property
    def face_block(self):
        """W_face as the kernel's shared block (``_cpp.DenseBlock``), made once for every
        scenario of this model. The block reads W_face in place, and W_face becomes its
        read-only view: one copy of the face's n² values, not two."""
        if getattr(self, "_face_block", None) is None:
            self._face_block = _cpp.DenseBlock(self.W_face)
            self.W_face = self._face_block.matrix
        return self._face_block

    def _strip_tags(self):
        """MeshTags of the upstream-face facets inside the strip (their midpoints)."""
        msh, ft = self.mesh.msh, self.mesh.facet_tags
        fdim = msh.topology.dim - 1
        up = np.sort(ft.indices[ft.values == T.DAM_UPSTREAM]).astype(np.int32)
        mid = dolfinx.mesh.compute_midpoints(msh, fdim, up)[:, :msh.geometry.dim]
        z0, z1 = self.strip_m
        tol = 1e-9 * self.base.dam_height_m
        keep = (mid[:, -1] >= z0 - tol) & (mid[:, -1] <= z1 + tol)
        if self.patch_y_m is not None:
            y0, y1 = self.patch_y_m
            keep &= (mid[:, 1] >= y0 - tol) & (mid[:, 1] <= y1 + tol)
        inside = up[keep]
        return dolfinx.mesh.meshtags(msh, fdim, inside, np.full(inside.size, STRIP, np.int32))

    def new_vector(self) -> PETSc.Vec:
        x = self.K.createVecLeft()
        x.zeroEntries()
        return x

    def step_rhs(self, w: PETSc.Vec, omega: PETSc.Vec) -> PETSc.Vec:
        """h[−K (w + hθ ω)]: the right-hand side of a time step with no load (a new Vec)."""
        return setup.unloaded_step_rhs(self.K, self.dt, self.theta, w, omega)

    def _heel_functional(self):
        """Gradients g with q(w) − q(0) = g·w of the base section's quantities q (heel and
        toe stress, normal force, moment about the centre) of the dam's internal nodal
        forces −K_dam w at the base nodes (each linear in w)."""
        s, V, msh = self.base, self.V, self.mesh.msh
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        a_dam = dolfinx.fem.form(elasticity_form(u, v, s.concrete, self.dx(T.DAM), self.kind))
        K_dam = dolfinx.fem.petsc.assemble_matrix(a_dam)
        K_dam.assemble()
        ft = self.mesh.facet_tags
        blocks = dolfinx.fem.locate_dofs_topological(V, msh.topology.dim - 1,
                                                     ft.indices[ft.values == T.DAM_BASE])
        pts = V.tabulate_dof_coordinates()[blocks, :s.dim]
        B, width = s.base_width_m, self.section_width_m
        self.section_gradients = {}
        for name in SECTION_QUANTITIES:
            c = K_dam.createVecRight()
            c.zeroEntries()
            for k in range(s.dim):
                unit = np.zeros((len(blocks), s.dim))
                unit[:, k] = 1.0
                coeff = [getattr(BaseSection.from_forces(p[None, :], f[None, :], B, width), name)
                         for p, f in zip(pts, unit)]
                c.array[blocks * s.dim + k] = coeff
            g = K_dam.createVecLeft()
            K_dam.mult(c, g)
            self.section_gradients[name] = -g.array_r.copy()
            c.destroy()
            g.destroy()
        self.heel_gradient = self.section_gradients["sigma_heel_Pa"]
        K_dam.destroy()

    @property
    def section_width_m(self) -> float:
        """The base section's width along the dam axis: 1 m in 2D (values per metre), the
        block's width in 3D."""
        return 1.0 if self.base.dim == 2 else float(self.base.dam_width_m)

    def face_compliance(self, axis: int = 0) -> np.ndarray:
        """(K⁻¹)_ii for the face DOFs i along ``axis`` (m/N, cached): with the dam's energy
        E (kinetic + strain), |w_i| ≤ sqrt(2 E (K⁻¹)_ii) as long as E does not grow. One
        back-substitution with K's factor per face node, counted in "dam_response"; a
        factor that takes several right-hand sides at once (``solve_many``) takes them
        :data:`COMPLIANCE_BLOCK` at a time."""
        if axis not in self._compliance:
            d = self.base.dim
            dofs = self.face_dofs[axis::d]
            out = np.empty(dofs.size)
            if hasattr(self._factor1, "solve_many"):
                n = self.K.getSize()[0]
                for a in range(0, dofs.size, COMPLIANCE_BLOCK):
                    block = dofs[a:a + COMPLIANCE_BLOCK]
                    E = np.zeros((n, block.size), order="F")
                    E[block, np.arange(block.size)] = 1.0
                    X = self._factor1.solve_many(E)
                    out[a:a + block.size] = X[block, np.arange(block.size)]
            else:
                e, x = self.new_vector(), self.new_vector()
                for j, i in enumerate(dofs):
                    e.zeroEntries()
                    e.array[i] = 1.0
                    self._solve1(e, x, "the face's compliance")
                    out[j] = x.array_r[i]
                e.destroy()
                x.destroy()
            self.back_substitutions["dam_response"] = (
                self.back_substitutions.get("dam_response", 0) + dofs.size)
            self._compliance[axis] = out
        return self._compliance[axis]

    def energy_J(self, w: PETSc.Vec, omega: PETSc.Vec) -> float:
        """½ωᵀMω + ½wᵀKw of the motion (w, ω) about the static state (J; J/m in 2D)."""
        y = self.new_vector()
        self.M.mult(omega, y)
        e = 0.5 * omega.dot(y)
        self.K.mult(w, y)
        e += 0.5 * w.dot(y)
        y.destroy()
        return float(e)

    def response_factor(self):
        """The factor of Ŵ the response functions are tabulated with: a plain one (no Schur
        complement, counted in factorizations["dam_response"], made on first use) where the
        stage-2 factor is MUMPS's Schur factor and was factored in this process, whose full
        solve costs a product with the dense F* besides the two partial solves; otherwise
        the stage-2 factor itself (a split factor's solve is plain already, and a dam
        restored from a model file is not factored again)."""
        if self._restored is not None or not isinstance(self.factor, _cpp.DistributedSchur):
            return self.factor
        if getattr(self, "_response_factor", None) is None:
            from ..saved_factor import factor_matrix
            self._response_factor = factor_matrix(self.W_hat)
            self.factorizations["dam_response"] = self.factorizations.get("dam_response", 0) + 1
        return self._response_factor

    def responses(self):
        """The base section's response functions (dam/response.py), made on first use."""
        if getattr(self, "_responses", None) is None:
            from .response import ResponseFunctions
            self._responses = ResponseFunctions(self)
        return self._responses

    def section_change(self, w: PETSc.Vec) -> dict:
        """{quantity: its change q(u_static + w) − q(u_static)} of the base section."""
        x = w.array_r
        return {k: float(g @ x) for k, g in self.section_gradients.items()}

    def heel_stress_Pa(self, static: StaticState, w: Optional[PETSc.Vec]) -> float:
        """Linearised heel stress (Pa, tension positive) of the state u_static + w."""
        sigma = static.section.sigma_heel_Pa
        return sigma if w is None else sigma + float(self.heel_gradient @ w.array_r)

    def stress_probe(self, point_m, offset_m: float) -> RecoveredStressProbe:
        """The recovered largest principal stress of u_static + w at ``offset_m`` from
        ``point_m`` in the dam (see :class:`RecoveredStressProbe`), for
        :meth:`peak_principal_Pa`."""
        if self._probe_space is None:
            self._probe_space = ProbeSpace(self.mesh.msh, self.mesh.cell_tags, self.materials,
                                           self.kind, T.DAM)
        return RecoveredStressProbe(self._u_total, self.mesh.cell_tags, self.materials,
                                    self.kind, point_m, offset_m, T.DAM, space=self._probe_space)

    def peak_principal_Pa(self, static: StaticState, w: PETSc.Vec,
                          probe: RecoveredStressProbe) -> float:
        """Largest recovered principal stress (Pa) of u_static + w over ``probe``'s samples
        (nan if none lies in the dam)."""
        n = w.getLocalSize()
        self._u_total.x.array[:n] = static.u.x.array[:n] + w.array_r
        self._u_total.x.scatter_forward()
        return probe.peak()[0]

    def static_stress_Pa(self, static: StaticState, probe: RecoveredStressProbe) -> np.ndarray:
        """The recovered static stress (3, 3) in Pa averaged over ``probe``'s samples (see
        :meth:`RecoveredStressProbe.mean`)."""
        n = compat.petsc_vec(static.u).getLocalSize()
        self._u_total.x.array[:n] = static.u.x.array[:n]
        self._u_total.x.scatter_forward()
        return probe.mean()

    def counts(self) -> dict:
        out = {"factorizations": dict(self.factorizations),
               "back_substitutions": dict(self.back_substitutions)}
        if any(self.restorations.values()):
            out["restorations"] = dict(self.restorations)
        return out

    def mesh_hash(self) -> str:
        """SHA-256 of what the saved operators are numbered by: the node coordinates, the
        cells, the DOFs of the face strip and the cell tags (a model file is refused if the
        mesh rebuilt in another process differs)."""
        import hashlib
        h = hashlib.sha256()
        msh = self.mesh.msh
        for a in (compat.geometry_x(msh), compat.geometry_dofmap(msh), self.face_dofs,
                  self.mesh.cell_tags.indices, self.mesh.cell_tags.values):
            a = np.ascontiguousarray(a)
            h.update(str((a.dtype.str, a.shape)).encode())
            h.update(a.tobytes())
        return h.hexdigest()


def _levels(base, water_levels_m) -> tuple[float, float]:
    """The checked (lo, hi) water-level range (m); the base's level when None."""
    if water_levels_m is None:
        return float(base.water_level_m), float(base.water_level_m)
    try:
        lo, hi = (float(z) for z in water_levels_m)
    except (TypeError, ValueError):
        raise InputError(f"water_levels_m={water_levels_m!r}: give (lowest, highest) in m")
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi <= base.dam_height_m):
        raise InputError(f"water_levels_m={water_levels_m!r}: need 0 < lowest <= highest <= "
                         f"dam_height_m={base.dam_height_m}")
    for z in (lo, hi):
        base.replace(water_level_m=z)  # the log must float at both ends (checked there)
    return lo, hi
