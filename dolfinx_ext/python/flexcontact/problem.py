"""Static frictional contact between deformable bodies, loaded in increments.

The flow is one-directional (docs/architecture.md §2), one module per stage: ``assembly`` (K, p),
``pairing`` (node pairs of the contact interfaces), ``condensation`` (one MUMPS
factorization gives F* = (K⁻¹)_cc on the contact DOFs; the kernel object holds B, x0,
W = B F* Bᵀ and solves x = W λ + q per increment), ``postprocess`` (summaries and the
contact fields). u = K⁻¹ (p + Bᵀ λ) comes from the same factor: with MUMPS's Schur factor
(serial) an increment is one back-substitution, p condensed onto the contact DOFs before
the contact solve and the solution expanded after it.
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Optional, Sequence, Union

import numpy as np

import dolfinx.fem

from . import compat
from ._cpp import SolverOptions
from .assembly import assemble_load, assemble_stiffness
from .condensation import Condensation
from . import factor_path
from .states import OPEN
from .stepper import Stepper, StepperViews
from .names import (PAIRINGS, ZONE_EDGE_ACTIONS, ContactOperator, FlexibilityMethod, Ordering,
                    Pairing, ZoneEdgeAction, check_chain, check_flexibility_method,
                    check_option, check_ordering)
from .pairing import pair_interfaces
from .postprocess import (STATE_NAMES, ContactFields, IncrementResult,  # noqa: F401
                          IncrementSummary, record_increment)
from .rigid import RigidTarget
from .floating import FloatingBodies, NoEquilibriumError, TippingWarning
from .rigid_modes import check_bodies, free_bodies
from .errors import FlexcontactError, InputError, InputTypeError

# Annotations use DOLFINx 0.9's class names; 0.5 spells them *MetaClass, so never at run time.
if TYPE_CHECKING:
    import ufl
    from dolfinx.fem import DirichletBC
    from dolfinx.mesh import MeshTags

    from .output import ResultWriter




class ContactZoneWarning(UserWarning):
    """Contact reached the edge of a tagged candidate surface (see zone.py)."""


class ContactZoneError(FlexcontactError, RuntimeError):
    """Contact reached the edge of a tagged candidate surface and the interface asked for
    an error (``zone_edge="error"``); the increment is recorded before it is raised."""


@dataclass
class ContactInterface:
    """Two tagged contact surfaces, or a tagged surface and a rigid target, and their
    Coulomb friction coefficient.

    ``slave`` is the tag of the surface whose nodes are paired; ``master`` the tag of the
    target surface, or a RigidTarget (rigid.py: a plane, circle or sphere with no DOFs).
    The master's outward normal defines the local frame.

    ``pairing`` chooses the model for two tagged surfaces (docs/architecture.md §4):

    * "auto" (default): "node_to_node" when the two surfaces' nodes match one to one, else
      "surface_to_surface" (the pairing that passes the contact patch test on non-matching
      meshes).
      ``pairing_used`` tells, once the problem is built, which one was taken.
    * "node_to_node": each slave node with the master node on its master normal
      line. Needs matching interface nodes, and master normals along the lines joining
      them: make the flat surface the master when the other is curved.
    * "node_to_surface": each slave node with its closest point on the master facets
      (non-matching meshes, curved surfaces, either body as slave); pairs are re-made before
      every increment from the current positions, with the F* computed once on all nodes
      of both tagged surfaces (so tag them generously: the candidate zone).
    * "surface_to_surface": integrated, mortar-type rows (mortar.py): one row per slave
      node, its weak gap with the dual multiplier basis integrated exactly over the overlaps
      (segment intersection in 2D; in 3D triangle and quadrilateral facets, i.e. tetrahedral
      and hexahedral meshes, clipped in the slave facet's plane: exact on triangles and
      parallelograms), along the slave node's normal. Uniform pressure is transmitted exactly
      across non-matching meshes (the patch test); re-made before every increment like
      node–surface pairs.

    ``tolerance_m`` is the largest tangential offset between node–node pairs (default:
    1e-6 of the surfaces' extent). ``zone_edge`` is what happens when a pair closes at an
    open edge of a candidate surface (zone.py): "warn" (a ContactZoneWarning), "error"
    (ContactZoneError after the increment is recorded) or "ignore"; the increment summary
    lists the interface in ``zone_edge`` either way.

    ``crushing_strength_Pa`` (σ_c, default None: no crushing) makes the slave surface
    crushable (docs/crushing.md): each pair's normal force is capped at σ_c times the
    measure it acts on (a mortar row's D_jj, else the slave node's tributary length or
    area), a cap on the nodal-average pressure. Where the cap binds, the slave surface
    crushes irreversibly along the pair normal; each slave node keeps its crush depth
    across increments, time steps and re-pairing, and friction is bounded by μ times the
    capped force.

    A master surface on the slave's own body (the mesh connects their nodes) is refused with
    an error naming both tags, as it is almost always a boundary tag given as the master;
    ``self_contact=True`` says a body touching itself is meant (a SelfContactWarning then).
    """

    facet_tags: MeshTags
    slave: int
    master: Union[int, RigidTarget]
    mu: float
    tolerance_m: Optional[float] = None
    name: str = ""
    pairing: Pairing = "auto"
    zone_edge: ZoneEdgeAction = "warn"
    self_contact: bool = False
    crushing_strength_Pa: Optional[float] = None

    def __post_init__(self):
        self.mu = _friction_coefficient(self.mu, self.label)
        if self.crushing_strength_Pa is not None:
            self.crushing_strength_Pa = _crushing_strength(self.crushing_strength_Pa,
                                                           self.label)
        where = f"contact interface {self.label}"
        check_option(self.pairing, PAIRINGS, "pairing", where)
        check_option(self.zone_edge, ZONE_EDGE_ACTIONS, "zone_edge", where)
        if not isinstance(self.self_contact, (bool, np.bool_)):
            raise InputError(f"{where}: self_contact={self.self_contact!r}; it must be True "
                             "or False")
        if not isinstance(self.master, (int, np.integer, RigidTarget)):
            raise InputTypeError(f"contact interface {self.label}: master={self.master!r}; it "
                            "must be a facet tag value or a RigidTarget")
        if self.slave == self.master:
            raise InputError(f"contact interface {self.label}: slave and master are the same "
                             f"tag ({self.slave})")

    @property
    def label(self) -> str:
        if self.name:
            return self.name
        master = (f"rigid target {self.master.name!r}" if isinstance(self.master, RigidTarget)
                  else f"master tag {self.master}")
        return f"slave tag {self.slave} / {master}"

    @property
    def rigid(self) -> bool:
        return isinstance(self.master, RigidTarget)


def _crushing_strength(sigma, label: str) -> float:
    """σ_c as a float: a real number, finite and > 0."""
    value = None
    if not isinstance(sigma, (bool, np.bool_)):
        arr = (np.asarray(sigma) if isinstance(sigma, (int, float, np.number, np.ndarray))
               else None)
        if arr is not None and arr.ndim == 0 and np.issubdtype(arr.dtype, np.number) \
                and not np.issubdtype(arr.dtype, np.complexfloating):
            value = float(arr)
    if value is None or not math.isfinite(value) or value <= 0:
        raise InputError(f"contact interface {label}: crushing_strength_Pa={sigma!r}; it must "
                         "be a finite real number > 0 [Pa] (None: the surface does not crush)")
    return value


def _friction_coefficient(mu, label: str) -> float:
    """μ as a float: a Python or NumPy real number, or a 0-d array; finite and ≥ 0."""
    value = None
    if not isinstance(mu, (bool, np.bool_)):
        arr = np.asarray(mu) if isinstance(mu, (int, float, np.number, np.ndarray)) else None
        if arr is not None and arr.ndim == 0 and np.issubdtype(arr.dtype, np.number) \
                and not np.issubdtype(arr.dtype, np.complexfloating):
            value = float(arr)
    if value is None or not math.isfinite(value) or value < 0:
        raise InputError(f"contact interface {label}: friction coefficient mu={mu!r}; "
                         "it must be a finite real number ≥ 0 (a Python or NumPy scalar)")
    return value


class ContactProblem(StepperViews):
    """Static contact of deformable bodies with Coulomb friction, by condensation.

    Parameters
    ----------
    a : UFL bilinear form of linear elasticity (K); must not change between increments.
    L : UFL linear form of the loads (p), or None. Loads change between increments through
        the dolfinx Constants/Functions it contains, set by ``solve``'s ``load`` callback.
    bcs : Dirichlet conditions (values may also change per increment).
    contact : one ContactInterface or a list of them.
    bodies : optional ``(cell_tags, {name: value})``; each body's rigid modes are checked
        so that a singular K is reported with the body's name.
    floating : with ``bodies``, let contact alone hold the bodies whose rigid modes no
        Dirichlet condition holds (floating.py): their equilibrium joins the condensed
        problem as extra equations (FETI style). A mode no load drives and no contact
        resists takes the minimum-norm value with a FreeModeWarning; a load no contact
        force can balance raises NoEquilibriumError naming the body and the mode; a body
        whose contact force resultant reaches the edge of its contact zone gets a
        TippingWarning. Default False: such a body is an error, as without contact.
    stress : optional callable u -> UFL scalar (e.g. von Mises) written as a DG0 field.
    solver : kernel SolverOptions (tolerance, max_iterations, chain).
    flexibility : "schur" (MUMPS Schur complement; on several ranks MUMPS is driven
        directly, the complement centralised on rank 0), "inverse_entries" (MUMPS selected
        inverse entries), or "matmatsolve" (a multi-right-hand-side solve, the reference).
        Each makes one sparse factorization, which then serves every solve.
    ordering : fill-reducing ordering of that factorization: "auto" (default: "metis" in
        3D, "mumps" in 2D), "metis" (METIS nested dissection handed to MUMPS), "mumps"
        (MUMPS's automatic choice), "amd", "amf", "pord" or "qamd" (names.Ordering;
        bench/ordering.py compares them).
    repair_pairs : True (default): node–surface, surface–surface and rigid-target pairs
        are re-made before every increment at the current positions; a slave node that
        keeps a pair keeps its λ and state as the next increment's warm start, and its slip
        is measured from where it now is on the master. False keeps the pairs of the
        reference positions (each slave node tied to a fixed master point; for comparisons
        and small slips).
    contact_operator : "dense" (default): F* and W = B F* Bᵀ formed densely (8·n_c² and
        8·(m·d)² bytes on rank 0; a ContactMemoryError before any allocation when they would
        not fit), the local solver chain on W. "factor": one plain factorization, F* never
        formed; the local problem solved on a working set of W's columns (the pairs that
        come into contact, computed through the factor by blocks of right-hand sides and
        kept across increments), or past its memory cap by an iteration on W·x: memory
        O(n_c·pairs in contact) for large candidate zones (docs/large_contact.md).

    On rank 0, ``contact`` is the kernel's condensed problem and ``B``, ``W``, ``x0``,
    ``frames`` its operators; ``local_problem`` is the last increment's {dim, W, q, mu}.
    Node–surface and rigid-target pairs are re-made before every increment (``repair``)
    unless ``repair_pairs`` is False;
    ``factorizations`` counts the sparse factorizations (one) and ``pairings`` how often
    the pairs were made.
    """

    def __init__(self, a: ufl.Form, L: Optional[ufl.Form], bcs: Sequence[DirichletBC],
                 contact: Union[ContactInterface, Sequence[ContactInterface]], *,
                 bodies: Optional[tuple[MeshTags, dict[str, int]]] = None,
                 stress: Optional[Callable] = None, solver: Optional[SolverOptions] = None,
                 flexibility: FlexibilityMethod = "schur", ordering: Ordering = "auto",
                 repair_pairs: bool = True, floating: bool = False,
                 contact_operator: ContactOperator = "dense"):
        check_flexibility_method(flexibility)
        factor_path.check_contact_operator(contact_operator, floating)
        self.contact_operator = contact_operator
        if not isinstance(repair_pairs, (bool, np.bool_)):
            raise InputError(f"repair_pairs={repair_pairs!r}; it must be True or False")
        check_ordering(ordering)
        if solver is not None:
            check_chain(solver.chain)
        self.interfaces = list(contact) if isinstance(contact, (list, tuple)) else [contact]
        if not self.interfaces:
            raise InputError("no contact interface given")
        self.bcs = list(bcs)
        self.a_form = dolfinx.fem.form(a)
        self.L_form = dolfinx.fem.form(L) if L is not None else None
        self.V = a.arguments()[0].ufl_function_space()
        self.msh = self.V.mesh
        self.comm = self.msh.comm  # the mesh's: it may live on a sub-communicator
        self.dim = self.msh.geometry.dim
        self.stress = stress
        self.options = solver if solver is not None else SolverOptions()
        self.flexibility_method = flexibility
        self.ordering = ordering
        self.timings = {}
        self.increments: list[IncrementResult] = []

        t0 = time.perf_counter()
        self.K = assemble_stiffness(self.a_form, self.bcs)
        self.timings["assemble_K_s"] = time.perf_counter() - t0
        free = []
        if bodies is not None:
            cell_tags, names = bodies
            if floating:
                free = free_bodies(self.K, self.V, cell_tags, names, self.comm)
            else:
                check_bodies(self.K, self.V, cell_tags, names, self.comm)
        elif floating:
            raise InputError("floating=True needs bodies=(cell_tags, {name: cell tag}) to find "
                             "the bodies held only by contact")
        t0 = time.perf_counter()
        self.pairs, self.mu, self.m = pair_interfaces(self.V, self.interfaces, self.comm)
        self.timings["pairing_s"] = time.perf_counter() - t0
        # Bodies held only by contact: fixing DOFs make the factor a generalized inverse.
        self.floating = (FloatingBodies(self.K, self.V, free, self.bcs, self.pairs, self.comm)
                         if free else None)
        # Node–surface and rigid-target pairs follow the bodies: re-made before each increment.
        self.repairing = bool(repair_pairs) and any(i.pairing_used != "node_to_node"
                                                    for i in self.interfaces)
        if contact_operator == "factor":
            condensation = factor_path.FactorCondensation(
                self.K, self.bcs, self.pairs, self.mu, self.dim, self.comm, self.options,
                ordering=self.ordering)
        else:
            condensation = Condensation(self.K, self.bcs, self.pairs, self.mu, self.dim,
                                        self.comm, self.options, self.flexibility_method,
                                        ordering=self.ordering)
        self.stepper = Stepper(condensation, self.comm, expand_key="solution_c",
                               timings=self.timings)
        c = condensation
        self.timings.update(c.timings)
        if self.floating is not None:
            Rc = self.floating.contact_modes(c)
            self.floating.check_touched(Rc)
            if self.comm.rank == 0:
                c.contact.set_rigid_modes(Rc)
        self.outputs = ContactFields(self.V, self.comm, stress)
        o = self.outputs
        self.u, self.pressure, self.traction, self.status = o.u, o.pressure, o.traction, o.status
        self.von_mises = o.von_mises

    # ---- what the stepper holds, read where it lives ----------------------------------
    @property
    def W(self) -> Optional[np.ndarray]:
        """W = B F* Bᵀ of the current pairs (rank 0; None elsewhere and on the factor
        path)."""
        return self.stepper.operators()[1]

    @property
    def x0(self) -> Optional[np.ndarray]:
        """The initial gaps of the current pairs (rank 0)."""
        return self.stepper.operators()[2]

    @property
    def frames(self) -> Optional[np.ndarray]:
        """(m, d, d) local frames of the current pairs (rank 0)."""
        return self.stepper.operators()[3]

    @property
    def local_problem(self) -> Optional[dict]:
        """Rank 0: the last increment's local problem {dim, W, q, mu}, u = W λ + q (slip
        measured from the last gap), for inspection and cross-checks with other solvers."""
        q = self.stepper.last_local_q
        if q is None or self.comm.rank != 0:
            return None
        return {"dim": self.dim, "W": self.W, "q": q, "mu": self.mu}

    # ---- one increment ---------------------------------------------------------------
    def step(self) -> IncrementResult:
        """Solve one increment with the loads and Dirichlet values as they are set now."""
        t0 = time.perf_counter()
        root = self.comm.rank == 0
        number = len(self.increments) + 1
        where = f"increment {number}"
        if self.repairing:
            self.stepper.repair(compat.petsc_vec(self.u), self.mu, where)
        p = assemble_load(self.V, self.a_form, self.L_form, self.bcs, self.comm)
        after, on_failure = (), None
        if self.floating is not None:
            e = self.floating.loads(p)       # −Rᵀp, before K⁺ drops the fixing DOFs' loads
            self.floating.zero_fixed(p)
            after = (e,) if root else ()
            on_failure = lambda failure: self._no_equilibrium(number, e, failure)  # noqa: E731
        try:
            out = self.stepper.advance(p, compat.petsc_vec(self.u), where=where, after=after,
                                       on_failure=on_failure)
        finally:
            p.destroy()
        if self.floating is not None:
            alpha = self.comm.bcast(out["alpha"] if root else None, root=0)
            self.floating.add_modes(compat.petsc_vec(self.u), alpha)
        self.u.x.scatter_forward()
        inc = record_increment(out if root else None, number, self.u, self.comm, self.dim,
                               time.perf_counter() - t0)
        self.increments.append(inc)
        if self.floating is not None:
            inc.alpha = alpha
            self._floating_warnings(out, number)
        self.outputs.write_back(inc, self.pairs)
        self._guard_zone(inc)
        return inc

    def _no_equilibrium(self, number: int, e: np.ndarray, failure: tuple) -> tuple:
        """The failure of a bordered increment, with the body and mode that no contact force
        can balance when the solver's best iterate shows one (rank 0)."""
        lam = failure[1].get("lambda")
        if lam is None:
            return failure
        text = self.floating.no_equilibrium_text(np.asarray(self.contact.border), e,
                                                 np.asarray(lam), np.asarray(self.mu), self.dim,
                                                 np.asarray(self.pairs.x)[:self.m])
        if text is None:
            return failure
        return (f"increment {number}: {text}. {failure[0].split(': ', 1)[1]}", failure[1], True)

    def _floating_warnings(self, out, number: int) -> None:
        """FreeModeWarning for modes no contact resists, TippingWarning for bodies about to
        tip (rank 0)."""
        if self.comm.rank != 0:
            return
        self.floating.warn_undetermined(np.asarray(out["undetermined"]), number)
        x = np.asarray(self.pairs.x)[:self.m]
        for text in self.floating.tipping(np.asarray(self.contact.border),
                                          np.asarray(out["lambda"]).ravel(), x, self.dim):
            warnings.warn(f"increment {number}: {text}", TippingWarning, stacklevel=3)

    def repair(self) -> None:
        """Re-make node–surface and rigid-target pairs at the current positions (the last
        increment's displacement, the rigid targets' displacement as set now): B, x0 and W
        are rebuilt from the stored F*, with no new factorization. Collective."""
        self.stepper.repair(compat.petsc_vec(self.u), self.mu,
                            f"increment {len(self.increments) + 1}")

    def _guard_zone(self, inc: IncrementResult) -> None:
        """Name the interfaces whose contact reached an open edge of a candidate surface
        (zone.py) in the increment's summary; warn or raise as each interface asks."""
        labels = None
        if self.comm.rank == 0:
            edge = getattr(self.pairs, "at_edge", None)
            where = getattr(self.pairs, "interface", None)
            labels = []
            if edge is not None and where is not None:
                hit = np.unique(where[(inc.states > OPEN) & edge])
                labels = [self.interfaces[int(i)].label for i in hit]
        labels = self.comm.bcast(labels, root=0)
        inc.summary.zone_edge = labels
        n = inc.summary.increment
        errors = []
        for itf in self.interfaces:
            if itf.label not in labels or itf.zone_edge == "ignore":
                continue
            text = (f"contact interface {itf.label}: increment {n}: contact reached the edge "
                    "of the tagged candidate surface (a pair closed at its open edge); the "
                    "contact zone may extend past the tagged zone: tag a larger candidate "
                    "surface")
            if itf.zone_edge == "error":
                errors.append(text)
            elif self.comm.rank == 0:
                warnings.warn(text, ContactZoneWarning, stacklevel=3)
        if errors:
            raise ContactZoneError("; ".join(errors))

    # ---- driver -------------------------------------------------------------------
    def solve(self, increments: int, load: Optional[Callable[[int, float], None]] = None,
              writer: Optional[ResultWriter] = None,
              verbose: bool = True) -> list[IncrementSummary]:
        """Run ``increments`` load increments.

        ``load(i, t)`` is called before increment i (1-based), t = i/increments, to set the
        loads and Dirichlet values of that increment (dolfinx Constants). ``writer`` (a
        ResultWriter) receives the fields after each increment. If an increment fails, the
        increments already done stay written and the error is raised; a ConvergenceError
        carries ``report``, a dict of what the solvers did (attempts, residual, iterations).
        """
        if not isinstance(increments, (int, np.integer)) or increments < 1:
            raise InputError(f"increments={increments!r}; it must be a positive integer")
        out = []
        for i in range(1, increments + 1):
            if load is not None:
                load(i, i / increments)
            inc = self.step()
            out.append(inc.summary)
            if writer is not None:
                writer.write(self, float(i))
            if verbose and self.comm.rank == 0:
                print(inc.summary.line(), flush=True)
        return out

    def fields(self) -> list[dolfinx.fem.Function]:
        """The output Functions (displacement, pressure, traction, status[, von Mises])."""
        return self.outputs.all()
