"""The log alone in its own frame, factored once per log geometry and material.

The log (a 2D plane-strain slab L × D, axis along x, centre at the origin, front end at
x = +L/2) is meshed once; its iteration matrix Ŵ = M + (hθ)²K (no support: Ŵ is regular
where K is not) is factored once and condensed on the front end's nodes. A scenario with
the same log but another pitch, water level, speed or friction only places it: a rigid
rotation R (the pitch) and a translation. Positions and velocities rotate by R per node,
the flexibility blockwise, W_global = R W_local Rᵀ (Ŵ is isotropic: rotating the body
rotates its operators). A log refined at its first-contact point (a crushing end's patch)
is meshed with that refinement in its own frame; a round log is first turned about its
own axis onto the point (:func:`contact_ball`, :func:`placement`).

During an impact the log's displacement is split as u = V₀ t + w with V₀ its rigid approach
velocity: K V₀ = 0, so w and its velocity ω obey the homogeneous equations driven by the
contact impulses; before the first impulse ω = w = 0 and no back-substitution is needed.

A log factored by MUMPS with its Schur complement on the front also keeps a plain factor of
Ŵ for its flight after the contact: a full solve on the Schur factor is a condensation, a
product with the dense F* and an expansion, about three times a plain solve at the main
job's log (17.7 ms against 5.6 ms, 18,927 DOFs and 4,188 front DOFs), and such a log flies
for about 170 steps of a scenario after it has left the face.
"""
from __future__ import annotations

import math
import time
from typing import Optional

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem

from .. import _cpp, compat, saved_factor
from ..dense_factor import DenseFactor
from ..split_factor import SplitFactor
from .. import impact_setup as setup
from ..forms import Material, elasticity_form, mass_form
from ..meshes import dam as dam_mesh
from ..meshes import dam_tags as T
from ..pairing import _candidate_surface
from ..errors import InputError


SMALL_LOG_DOFS = 1500
"""Largest log (DOFs) held as a sparse split factor; a larger one is factored by MUMPS,
twice (its Schur complement on the front, and plain for its flight)."""


def rotation(pitch_deg: float, yaw_deg: float = 0.0, dim: int = 2) -> np.ndarray:
    """The rotation (2×2 or 3×3) taking the log's local x axis to its axis in the dam's
    frame (DamScenario.log_axis): pitched front end up for a positive pitch, then in 3D
    yawed about the vertical z."""
    t = math.radians(pitch_deg)
    c, s = math.cos(t), math.sin(t)
    if dim == 2:
        return np.array([[c, -s], [s, c]])
    p = math.radians(yaw_deg)
    pitch = np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])
    yaw = np.array([[math.cos(p), -math.sin(p), 0.0], [math.sin(p), math.cos(p), 0.0],
                    [0.0, 0.0, 1.0]])
    return yaw @ pitch


def contact_ball(s) -> Optional[tuple]:
    """Where scenario ``s`` refines its log's end (``mesh_size_contact_m`` below
    h_log), in the log's own frame: (a, b, size, zone), the ball of radius
    ``contact_zone_m`` at (a, b) (3D: (a, b, 0)) with elements of ``h_contact_m``; None
    without. (a, b) is the first-contact point: its axial and lateral (2D) or radial (3D)
    coordinates, to the micrometre so that every pitch and yaw with the same point shares
    one log. A round log is the same log turned about its axis, so in 3D the ball sits at
    azimuth 0 and :func:`placement` turns the log to the point's azimuth: a flat or
    chamfered end's first contact is on its rim whatever the pitch and yaw, so one log
    serves them all; a rounded end's moves along the cap with the angle. With
    ``contact_layer_m`` set, a fifth entry: the ball refines only that deep behind the
    front end."""
    if s.mesh_size_contact_m is None or s.h_contact_m >= s.h_log_m:
        return None
    q = _first_contact_local(s)
    b = q[1] if s.dim == 2 else math.hypot(q[1], q[2])
    ball = (round(float(q[0]), 6), round(float(b), 6), float(s.h_contact_m),
            float(s.contact_zone_m))
    return ball if s.contact_layer_m is None else ball + (float(s.contact_layer_m),)


def _first_contact_local(s) -> np.ndarray:
    R = rotation(s.log_pitch_deg, s.log_yaw_deg, s.dim)
    return R.T @ (np.asarray(s.log_front_point, float) - np.asarray(s.log_centre, float))


def placement(s, ball=None) -> np.ndarray:
    """The rotation placing the log of scenario ``s`` from its own frame: :func:`rotation`
    of its pitch and yaw, after, for a 3D log meshed with its contact ball (``ball``), the
    turn about its axis that takes the ball's azimuth (0) to the first-contact point's."""
    R = rotation(s.log_pitch_deg, s.log_yaw_deg, s.dim)
    if ball is None or s.dim == 2:
        return R
    q = _first_contact_local(s)
    phi = math.atan2(q[2], q[1]) if math.hypot(q[1], q[2]) > 1e-12 else 0.0
    c, si = math.cos(phi), math.sin(phi)
    return R @ np.array([[1.0, 0.0, 0.0], [0.0, c, -si], [0.0, si, c]])


def rotate_blocks(W: np.ndarray, R: np.ndarray) -> np.ndarray:
    """R W Rᵀ blockwise: every d×d node block W_ij → R W_ij Rᵀ (W node-major). R from the
    left on each block row, then Rᵀ from the right as one product over all the rows: at the
    main job's log (4,188² entries) 0.10 s, against 0.45 s for the one einsum over both."""
    d = R.shape[0]
    n = W.shape[0] // d
    left = np.matmul(R, np.asarray(W).reshape(n, d, n * d))
    return (left.reshape(-1, d) @ R.T).reshape(W.shape)


class LogMesh:
    """The log's mesh in its own frame with its stiffness K and its unit-density mass M₁,
    shared by every density of one log geometry: a new density only rescales M (M = ρ M₁),
    so it costs no meshing and no form compilation (the forms hold no density). ``dim``:
    2 (a plane-strain slab) or 3 (a round log). Serial."""

    def __init__(self, length_m: float, diameter_m: float, E: float, nu: float,
                 h_m: float = None, comm=MPI.COMM_SELF, end=None, dim: int = 2,
                 ball: Optional[tuple] = None):
        if comm.size != 1:
            raise InputError(f"comm of size {comm.size}: LogModel is serial (one rank)")
        self.length_m, self.diameter_m = float(length_m), float(diameter_m)
        h = h_m if h_m is not None else diameter_m / 4
        self.dim = int(dim)
        self.ball = None if ball is None else tuple(float(v) for v in ball)
        self.msh, self.cell_tags, self.facet_tags, _ = dam_mesh.build_log(
            comm, length_m, diameter_m, h, end, dim=self.dim, ball=self.ball)
        self.V = compat.vector_space(self.msh)
        mat = Material(E_Pa=E, nu=nu, rho_kg_m3=1.0, name="wood")
        u, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        dx = ufl.Measure("dx", domain=self.msh)
        kind = "plane_strain" if self.dim == 2 else "3d"
        a = dolfinx.fem.form(elasticity_form(u, v, mat, dx, kind))
        m = dolfinx.fem.form(mass_form(u, v, 1.0, dx))
        n = self.V.dofmap.index_map.size_local * self.V.dofmap.index_map_bs
        marker = PETSc.Vec().createSeq(n, comm=PETSc.COMM_SELF)
        marker.set(1.0)  # no support: every DOF free
        self.K, self.M1 = setup.assemble_matrices(a, m, [], "consistent", marker)
        marker.destroy()
        self.front = _candidate_surface(self.V, self.facet_tags, T.LOG_FRONT)
        self.front_dofs = np.asarray(self.front["dofs"], np.int64).reshape(-1)
        self.x_nodes = self.V.tabulate_dof_coordinates()[:, :self.dim].copy()

    FRONT_KEYS = ("x", "dofs", "normal", "area", "facets", "facet_normal", "open_edge")

    def arrays(self, prefix: str) -> dict:
        """What a model file keeps of this log mesh (no mesh: K, M₁ as CSR, the nodes and
        the front end's surface), as arrays named ``prefix`` + name."""
        out = {f"{prefix}x_nodes": self.x_nodes, f"{prefix}dims": np.array(
            [self.dim, self.length_m, self.diameter_m])}
        if self.ball is not None:
            out[f"{prefix}ball"] = np.array(self.ball)
        for name, A in (("K", self.K), ("M1", self.M1)):
            ai, aj, av = A.getValuesCSR()
            out.update({f"{prefix}{name}_indptr": ai, f"{prefix}{name}_indices": aj,
                        f"{prefix}{name}_data": av})
        out.update({f"{prefix}front_{k}": np.asarray(self.front[k]) for k in self.FRONT_KEYS
                    if k in self.front})
        return out

    @classmethod
    def from_arrays(cls, arrays: dict, prefix: str) -> "LogMesh":
        """The log mesh of :meth:`arrays`, without a mesh (nothing meshed or assembled)."""
        self = cls.__new__(cls)
        dim, self.length_m, self.diameter_m = arrays[f"{prefix}dims"]
        self.dim = int(dim)
        ball = arrays.get(f"{prefix}ball")
        self.ball = None if ball is None else tuple(float(v) for v in np.asarray(ball))
        self.msh = self.cell_tags = self.facet_tags = self.V = None
        self.x_nodes = np.asarray(arrays[f"{prefix}x_nodes"])
        n = self.x_nodes.shape[0] * self.dim
        mats = []
        for name in ("K", "M1"):
            csr = tuple(np.asarray(arrays[f"{prefix}{name}_{k}"])
                        for k in ("indptr", "indices", "data"))
            A = PETSc.Mat().createAIJ(size=(n, n), csr=csr, comm=PETSc.COMM_SELF)
            A.assemble()
            mats.append(A)
        self.K, self.M1 = mats
        self.front = {k: np.asarray(arrays[f"{prefix}front_{k}"]) for k in self.FRONT_KEYS
                      if f"{prefix}front_{k}" in arrays}
        self.front_dofs = np.asarray(self.front["dofs"], np.int64).reshape(-1)
        return self


class LogModel:
    """One log geometry and material at the time step ``dt_s``, factored once.

    ``rho_effective_kg_m3``: the wood's density with the added mass of the water,
    ρ (1 + C_a); ``E``, ``nu``: the wood's along-grain modulus (Pa) and Poisson's ratio;
    ``h_m``: element size (default D/4); ``mesh``: a :class:`LogMesh` of the same length,
    diameter, E and ν to reuse (made here when None); ``end``: the front end's
    :class:`~flexcontact.meshes.log_end.LogEnd` (None: flat); ``dim``: 2 or 3 (that of
    ``mesh`` when given). ``mass_kg_per_m``: the log's mass with its added mass (kg/m in
    2D, kg in 3D). ``factor_kind``: "split" (a log of at most :data:`SMALL_LOG_DOFS` DOFs,
    held as a sparse split factor, split_factor.SplitFactor), "dense" (such a log restored
    from a model file of format 4 or older, held as dense blocks) or "mumps_schur".
    ``factor``: a factor restored from a model file instead of factoring (a SplitFactor or
    DenseFactor, or MUMPS's Schur factor with its
    flexibility ``W_front`` on the front DOFs); ``flight_factor``: the plain factor of Ŵ
    restored with it (:meth:`free_factor`; None: a model file that has none, and the flight
    then takes the Schur factor's full solves). Serial.
    """

    def __init__(self, length_m: float, diameter_m: float, rho_effective_kg_m3: float,
                 E: float, nu: float, dt_s: float, h_m: float = None, theta: float = 0.5,
                 comm=MPI.COMM_SELF, mesh: "LogMesh" = None, end=None, dim: int = 2,
                 factor=None, W_front: Optional[np.ndarray] = None, flight_factor=None):
        if comm.size != 1:
            raise InputError(f"comm of size {comm.size}: LogModel is serial (one rank)")
        setup.check_scheme(dt_s, 0.0, theta, "consistent", (0.0, 0.0))
        self.restorations = 0
        self.material = Material(E_Pa=E, nu=nu, rho_kg_m3=rho_effective_kg_m3,
                                 name="wood+added mass")
        self.length_m, self.diameter_m = float(length_m), float(diameter_m)
        self.dt, self.theta = float(dt_s), float(theta)
        self.factorizations, self.back_substitutions = 0, 0
        t0 = time.perf_counter()
        self.mesh = mesh if mesh is not None else LogMesh(length_m, diameter_m, E, nu, h_m, comm,
                                                          end, dim)
        self.dim = self.mesh.dim
        self.msh, self.cell_tags, self.facet_tags = (self.mesh.msh, self.mesh.cell_tags,
                                                     self.mesh.facet_tags)
        self.V = self.mesh.V
        self._factor()
        self.front, self.front_dofs = self.mesh.front, self.mesh.front_dofs
        n = self.W_hat.getSize()[0]
        self.flight_factor = None
        if isinstance(factor, (SplitFactor, DenseFactor)):
            # Restored from a model file (dam/model_file.py): nothing factored.
            if factor.n != n or not np.array_equal(factor.c, self.front_dofs):
                raise InputError(f"a saved log factor of {factor.n} DOFs does not fit this "
                                 f"log of {n} DOFs")
            self.factor, self.W_front = factor, factor.W
            self.restorations += 1
            self.factor_kind = "split" if isinstance(factor, SplitFactor) else "dense"
        elif factor is not None:
            # MUMPS's Schur factor restored from a model file with its F* (W_front).
            c = self.front_dofs.size
            if factor.size != n or factor.n_schur != c or W_front is None \
                    or np.shape(W_front) != (c, c):
                raise InputError(f"a saved log factor of {factor.size} DOFs and "
                                 f"{factor.n_schur} front DOFs does not fit this log of {n} "
                                 f"DOFs and {c} front DOFs")
            self.factor, self.W_front = factor, np.asarray(W_front)
            self.restorations += 1
            self.factor_kind = "mumps_schur"
            if flight_factor is not None:
                if int(flight_factor.size) != n:
                    raise InputError(f"a saved plain log factor of {int(flight_factor.size)} "
                                     f"DOFs does not fit this log of {n} DOFs")
                self.flight_factor = flight_factor
                self.restorations += 1
        elif n <= SMALL_LOG_DOFS:
            # A sparse split factor: neither MUMPS's fixed cost per solve nor dense blocks'
            # n² products and n³ set-up.
            self.factor = SplitFactor(self.W_hat, self.front_dofs)
            self.W_front = self.factor.W
            self.factorizations += 1
            self.factor_kind = "split"
        else:
            F, self.factor, info = _cpp.flexibility(self.W_hat, self.front_dofs, "schur")
            self.W_front = np.asarray(F)
            self.factorizations += int(info["factorizations"])
            self.factor_kind = "mumps_schur"
            self.flight_factor = saved_factor.factor_matrix(self.W_hat)
            self.factorizations += 1
        self.setup_s = time.perf_counter() - t0

    def _factor(self):
        self.K = self.mesh.K
        self.M = self.mesh.M1.copy()
        self.M.scale(self.material.rho_kg_m3)
        marker = self.new_vector()
        marker.set(1.0)
        self.W_hat = setup.iteration_matrix(self.K, self.M, self.dt, self.theta, (0.0, 0.0),
                                            marker)
        d = self.dim
        ones = [self.new_vector() for _ in range(d)]
        for k, o in enumerate(ones):
            o.array[k::d] = 1.0
        Mo = self.new_vector()
        self.M.mult(ones[0], Mo)
        self.mass_kg_per_m = float(Mo.sum())  # Σ M over the x DOFs: the log's mass
        self._rigid = ones
        for o in (marker, Mo):
            o.destroy()
        self.x_nodes = self.mesh.x_nodes

    def new_vector(self) -> PETSc.Vec:
        if hasattr(self, "K"):
            x = self.K.createVecLeft()
        else:
            n = self.V.dofmap.index_map.size_local * self.V.dofmap.index_map_bs
            x = PETSc.Vec().createSeq(n, comm=PETSc.COMM_SELF)
        x.zeroEntries()
        return x

    def placement(self, s) -> np.ndarray:
        """The rotation placing this log for scenario ``s`` (log_model.placement)."""
        return placement(s, self.mesh.ball)

    def placed_front(self, R: np.ndarray, centre: np.ndarray) -> dict:
        """The front end's surface dict (surface_nodes layout) placed in the dam's frame."""
        f = dict(self.front)
        f["x"] = np.asarray(centre)[None, :] + np.asarray(self.front["x"]) @ R.T
        f["normal"] = np.asarray(self.front["normal"]) @ R.T
        if "facet_normal" in f:
            f["facet_normal"] = np.asarray(self.front["facet_normal"]) @ R.T
        return f

    def W_front_global(self, R: np.ndarray) -> np.ndarray:
        return rotate_blocks(self.W_front, R)

    @property
    def front_block(self):
        """W_front as the kernel's shared block (``_cpp.DenseBlock``), made once: every
        placement of this log uses it through its rotation, with no rotated copy. The block
        reads W_front in place, and W_front becomes its read-only view: one copy of the
        front's n² values, not two."""
        if getattr(self, "_front_block", None) is None:
            self._front_block = _cpp.DenseBlock(self.W_front)
            self.W_front = self._front_block.matrix
        return self._front_block

    def free_factor(self):
        """The factor of a step without contact: the plain one where the log has one, else
        its contact factor."""
        return self.factor if self.flight_factor is None else self.flight_factor

    def step_rhs(self, w: PETSc.Vec, omega: PETSc.Vec) -> PETSc.Vec:
        """h[−K (w + hθ ω)]: the right-hand side of a time step with no load, local frame
        (a new Vec)."""
        return setup.unloaded_step_rhs(self.K, self.dt, self.theta, w, omega)

    def momentum_local(self, omega: PETSc.Vec) -> np.ndarray:
        """Σ (M ω) per local component (N·s/m): the momentum of the velocity ω."""
        Mw = self.new_vector()
        self.M.mult(omega, Mw)
        out = np.array([Mw.dot(o) for o in self._rigid])
        Mw.destroy()
        return out

    def rotation_rad(self, w: PETSc.Vec) -> float:
        """The rigid rotation (rad) best fitting the displacement w about the log's centre:
        in 2D Σ x × w / Σ |x|² (counter-clockwise), in 3D the size of the small-rotation
        vector θ minimising Σ |w − θ × x|² (the translation is removed first)."""
        x = self.x_nodes
        wv = w.array_r.reshape(-1, self.dim)
        if self.dim == 2:
            return float(np.sum(x[:, 0] * wv[:, 1] - x[:, 1] * wv[:, 0]) / np.sum(x * x))
        xc, wc = x - x.mean(axis=0), wv - wv.mean(axis=0)
        J = np.eye(3) * np.sum(xc * xc) - xc.T @ xc  # the nodes' "inertia"
        return float(np.linalg.norm(np.linalg.solve(J, np.cross(xc, wc).sum(axis=0))))
