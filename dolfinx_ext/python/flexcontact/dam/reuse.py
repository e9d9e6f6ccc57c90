"""Many impact scenarios on one dam for the price of its factorizations.

Stage 2 (stage2.py) meshes the dam, its foundation and the log together and factors the
whole iteration matrix for every scenario. Here the bodies are apart (docs/architecture.md §7,
per-body condensation; they touch only through contact):

* :class:`~flexcontact.dam.dam_model.DamModel`: the dam + foundation without the log, with
  stage 1's K factored once (a water level is one back-substitution) and stage 2's Ŵ
  factored once at the sweep's time step, condensed on the face strip logs can hit;
* :class:`~flexcontact.dam.log_model.LogModel`: one log geometry and material in its own
  frame, factored once and cached; a scenario only places it (rotation + translation);
* :func:`~flexcontact.dam.coupled_step.run_impact`: the Moreau–Jean steps of one scenario
  with the kernel's ``ImpactContact`` on the block-diagonal flexibility [W_log, W_face].

:class:`ScenarioEvaluator` is what a sweep calls: ``evaluate(scenario) -> dict`` of plain
floats, ``counts()`` of factorizations and back-substitutions per body. One time step
serves the whole sweep (:func:`sweep_time_step_s`). 2D and 3D (the 3D block's face patch
and a round log placed by its pitch, yaw and position across the block).
"""
from __future__ import annotations

import time
from collections import OrderedDict
from typing import Optional, Sequence

from mpi4py import MPI

from .. import impact_setup as setup
from ..shared_solves import Together, serve_alone, serve_together, shares
from .coupled_step import AFTER_CONTACT, FHAT, expected_contact_s, impact_run, run_impact
from .dam_model import DamModel, front_end_span_m
from .log_model import LogMesh, LogModel, contact_ball
from .scenario import DamScenario
from .stage2 import sweep_time_step_s
from ..errors import InputError

KEEP_LOGS = 8
"""Log models a ScenarioEvaluator holds by default (LogCache ``keep``): a batch of the sweeps'
8. At the main job's mesh a model is about half a GB (its Schur and flight factors and its
front's flexibility); a sweep's batches are ordered by log, so the next batch's logs are
new ones or those it already holds."""

DAM_PARAMETERS = ("dim", "dam_height_m", "crest_width_m", "downstream_slope", "dam_width_m",
                  "foundation_depth_m", "foundation_upstream_m", "foundation_downstream_m",
                  "tailwater_level_m", "uplift_factor", "westergaard", "concrete", "rock",
                  "water_density_kg_m3", "gravity_m_s2", "mesh_size_far_m",
                  "mesh_size_impact_m", "impact_zone_m", "refine", "time_scheme_theta")
"""Parameters fixed by the dam's factorizations: a scenario must share them with the base."""


def check_same_dam(base: DamScenario, scenario: DamScenario) -> None:
    """ValueError naming the first dam parameter in which ``scenario`` differs from
    ``base`` (those need another DamModel)."""
    for name in DAM_PARAMETERS:
        a, b = getattr(base, name), getattr(scenario, name)
        if a != b:
            raise InputError(f"{name}={b!r} differs from the dam being reused ({name}={a!r}); "
                             "a scenario may change only the log, its speed and angles, the "
                             "friction and the water level")


def log_key(s: DamScenario) -> tuple:
    """What a LogModel depends on: length, diameter, density, added-mass coefficient, E, ν,
    the front end's shape, the element size on the log and, when the scenario refines the
    crushed patch, where (log_model.contact_ball)."""
    return (s.log_length_m, s.log_diameter_m, s.wood.rho_kg_m3, s.added_mass_coefficient,
            s.wood.E_Pa, s.wood.nu, s.log_end, s.h_log_m) + _ball_key(s)


def _ball_key(s: DamScenario) -> tuple:
    ball = contact_ball(s)
    return () if ball is None else (ball,)


class LogCache:
    """The log models of one dam at the time step ``dt_s`` and the scheme's ``theta``: one
    LogMesh per log geometry (its mesh, K and unit mass, every density), one LogModel per
    log (log_key), each made on first use or restored from a model file. Elements of the
    scenario's h_log_m.

    ``keep``: how many log models to hold (None: all). A model holds its factors and its
    front's n² flexibility, hundreds of MB at the main job's mesh, and a sweep whose density
    is sampled continuously has a log per scenario: kept without bound, they exhausted the
    memory of a 3D sweep at the main job's mesh after 15 scenarios. Beyond ``keep``
    the least recently used model is let go, its counts and set-up time kept in the totals;
    asked for again, it is rebuilt, or restored from its model file. A sweep's batches are
    ordered by log, so a log let go is not asked for again in practice."""

    def __init__(self, dt_s: float, comm, theta: float, keep: Optional[int] = None):
        self.dt, self.comm, self.theta = float(dt_s), comm, float(theta)
        self.keep = self.checked_keep(keep)
        self.models: OrderedDict = OrderedDict()
        self.meshes: dict = {}
        self.saved: dict = {}  # log_key: (scenario, loader) of a model file's large logs
        self.adopted: dict = {}  # log_key: (scenario, LogMesh, factor) of its small ones
        self.mesh_s = 0.0
        # what the models let go had counted
        self.retired = {"factorizations": 0, "back_substitutions": 0, "restorations": 0,
                        "setup_s": 0.0, "released": 0}

    @staticmethod
    def checked_keep(keep: Optional[int], name: str = "keep") -> Optional[int]:
        """``keep`` if it is None (all) or an integer >= 1; else InputError naming ``name``."""
        if keep is None or (isinstance(keep, int) and not isinstance(keep, bool) and keep >= 1):
            return keep
        raise InputError(f"{name}={keep!r}: the log models to hold must be an integer >= 1")

    @staticmethod
    def _mesh_key(s: DamScenario) -> tuple:
        return (s.log_length_m, s.log_diameter_m, s.wood.E_Pa, s.wood.nu,
                s.log_end, s.h_log_m) + _ball_key(s)

    def get(self, s: DamScenario) -> LogModel:
        key = log_key(s)
        if key in self.models:
            self.models.move_to_end(key)
            return self.models[key]
        if key in self.saved:
            saved_s, load = self.saved[key]
            mesh, factor, W_front, flight = load()
            self.meshes.setdefault(self._mesh_key(saved_s), mesh)
            model = self._model(saved_s, mesh, factor, W_front, flight)
        elif key in self.adopted:
            model = self._model(*self.adopted[key])
        else:
            mesh_key = self._mesh_key(s)
            if mesh_key not in self.meshes:
                t0 = time.perf_counter()
                self.meshes[mesh_key] = LogMesh(*mesh_key[:4], h_m=s.h_log_m, comm=self.comm,
                                                end=s.log_end, dim=s.dim,
                                                ball=contact_ball(s))
                self.mesh_s += time.perf_counter() - t0
            model = self._model(s, self.meshes[mesh_key])
        self.models[key] = model
        self.trim()
        return model

    def trim(self, keep: Optional[int] = None) -> None:
        """Let the least recently used models go until at most ``keep`` (default: the
        cache's) are held; their counts stay in the totals."""
        keep = self.keep if keep is None else keep
        while keep is not None and len(self.models) > keep:
            _, old = self.models.popitem(last=False)
            for k in ("factorizations", "back_substitutions", "restorations", "setup_s"):
                self.retired[k] += getattr(old, k, 0)
            self.retired["released"] += 1

    def total(self, what: str):
        """A count over every model made so far (held or let go): "factorizations",
        "back_substitutions", "restorations" or "setup_s"."""
        return self.retired[what] + sum(getattr(m, what, 0) for m in self.models.values())

    def restore(self, s: DamScenario, mesh, factor) -> None:
        """Adopt the log of scenario ``s`` from a model file: its LogMesh without a mesh and
        its dense factor (counted as a restoration, not a factorization). A log saved
        without the contact ball its scenario now asks for is not adopted: it is built when
        asked."""
        if mesh.ball != contact_ball(s):
            return
        self.meshes.setdefault(self._mesh_key(s), mesh)
        self.adopted[log_key(s)] = (s, mesh, factor)
        self.models[log_key(s)] = self._model(s, mesh, factor)
        self.trim()

    def restore_later(self, s: DamScenario, ball, load) -> None:
        """Adopt the log of scenario ``s`` that a model file holds factored by MUMPS (a large
        log): ``load()`` returns (its LogMesh without a mesh, its restored Schur factor,
        W_front, its restored plain factor or None) and is called when the log is asked for
        (again, if it was let go), so that a scenario of another log reads none of its
        files. ``ball``: the contact ball it was meshed with (the same rule as
        :meth:`restore`)."""
        if ball != contact_ball(s):
            return
        self.saved[log_key(s)] = (s, load)

    def _model(self, s: DamScenario, mesh, factor=None, W_front=None,
               flight=None) -> LogModel:
        return LogModel(
            s.log_length_m, s.log_diameter_m, s.wood.rho_kg_m3 * (1 + s.added_mass_coefficient),
            s.wood.E_Pa, s.wood.nu, self.dt, h_m=s.h_log_m, theta=self.theta, comm=self.comm,
            mesh=mesh, dim=s.dim, factor=factor, W_front=W_front, flight_factor=flight)

    def setup_s(self) -> float:
        """Seconds of meshing, factorization and condensation of every log so far."""
        return self.mesh_s + self.total("setup_s")


class ScenarioEvaluator:
    """Evaluate impact scenarios of one dam (that of ``base``) cheaply.

    ``dt_s``: the sweep's time step (default: :func:`sweep_time_step_s` of ``[base]``);
    ``water_levels_m``: (lowest, highest) water level of the sweep (default: the base's);
    ``comm``: one rank (a parallel sweep runs one evaluator per process); ``strip_m``:
    the elevations of the face strip (default: dam_model.default_strip_m); in 3D
    ``patch_y_m``: its range across the block (default: dam_model.default_patch_y_m);
    ``offset_m``:
    the distance from the first-contact point at which the peak principal stress is read;
    ``after_contact``: "convolve" (default: the dam is not stepped once the log has left it
    for good, the base section then comes from its response functions) or "step";
    ``fhat``: how each scenario's kernel holds F̂ (coupled_step.FHAT; default "auto");
    ``keep_logs``: how many log models to hold (:class:`LogCache`; default
    :data:`KEEP_LOGS`, and never fewer than the scenarios of one :meth:`evaluate_many`).
    """

    def __init__(self, base: DamScenario, dt_s: Optional[float] = None,
                 water_levels_m: Optional[tuple[float, float]] = None,
                 comm: MPI.Comm = MPI.COMM_SELF, *,
                 strip_m: Optional[tuple[float, float]] = None, offset_m: float = 1.0,
                 patch_y_m: Optional[tuple[float, float]] = None,
                 after_contact: str = "convolve", dam: Optional[DamModel] = None,
                 fhat: str = "auto", keep_logs: Optional[int] = None):
        if base.westergaard:
            raise InputError("westergaard=True: the reservoir's added mass depends on the water "
                             "level, so one factored dam cannot serve a sweep over it; use the "
                             "monolithic evaluator (engine.evaluator = \"monolithic\")")
        if not offset_m > 0:
            raise InputError(f"offset_m={offset_m!r}: must be > 0 m")
        if after_contact not in AFTER_CONTACT:
            raise InputError(f"after_contact={after_contact!r}: one of {AFTER_CONTACT}")
        if fhat not in FHAT:
            raise InputError(f"fhat={fhat!r}: one of {FHAT}")
        keep_logs = LogCache.checked_keep(KEEP_LOGS if keep_logs is None else keep_logs,
                                          "keep_logs")
        self.base, self.offset_m, self.after_contact = base, float(offset_m), after_contact
        self.fhat = fhat
        self.dt = (dam.dt if dam is not None else
                   float(dt_s) if dt_s is not None else sweep_time_step_s([base]))
        t0 = time.perf_counter()
        # dam: a DamModel already built for this base and time step (restored from a model
        # file, dam/model_file.py); otherwise it is built and factored here.
        self.dam = dam if dam is not None else DamModel(base, self.dt, water_levels_m, comm,
                                                        strip_m=strip_m,
                                                        patch_y_m=patch_y_m)
        self.dam.static_state(base.water_level_m)
        self.logs = LogCache(self.dt, self.dam.comm, self.dam.theta, keep=keep_logs)
        self._steps_s = 0.0
        self._split: dict = {}  # run_impact's coupled steps, log-only steps, convolution
        self.together = Together()  # evaluate_many's shared calls
        self.setup_s = time.perf_counter() - t0

    def check(self, scenario: DamScenario) -> None:
        """ValueError naming the parameter if ``scenario`` cannot reuse this dam."""
        check_same_dam(self.base, scenario)
        lo, hi = self.dam.water_levels_m
        if not lo <= scenario.water_level_m <= hi:
            raise InputError(f"water_level_m={scenario.water_level_m!r}: outside the range "
                             f"{(lo, hi)} the dam was built for (water_levels_m)")
        setup.check_resolution(self.dt, expected_contact_s(scenario, self.dam),
                               "2L/c of the log along the face normal")
        z0, z1 = self.dam.strip_m
        lo, hi = front_end_span_m(scenario, scenario.dim - 1)
        if not (z0 <= lo and hi <= z1):
            raise InputError(
                f"log_pitch_deg={scenario.log_pitch_deg!r}, water_level_m="
                f"{scenario.water_level_m!r}: the log's front end (elevations "
                f"{lo:.3f}..{hi:.3f} m) leaves the face strip "
                f"{z0:.3f}..{z1:.3f} m of this dam (strip_m)")
        if self.dam.patch_y_m is not None:
            (y0, y1), (lo, hi) = self.dam.patch_y_m, front_end_span_m(scenario, 1)
            if not (y0 <= lo and hi <= y1):
                raise InputError(
                    f"log_yaw_deg={scenario.log_yaw_deg!r}: the log's front end (y "
                    f"{lo:.3f}..{hi:.3f} m) leaves the face patch {y0:.3f}..{y1:.3f} m "
                    f"across this dam block (patch_y_m)")

    def log_model(self, s: DamScenario) -> LogModel:
        """The cached LogModel of the scenario's log (made on first use)."""
        return self.logs.get(s)

    def evaluate(self, scenario: DamScenario) -> dict[str, float]:
        """The outputs of one scenario (plain floats): peak_force_N_per_m,
        contact_duration_s, impulse_N_s_per_m, log_momentum_change_N_s_per_m (along x,
        negative: the log is slowed), heel_stress_static_Pa, heel_stress_impact_Pa (most
        tensile linearised heel stress from the first impulse to the end of the run),
        peak_tensile_stress_Pa (largest principal stress at ``offset_m`` from the
        first-contact point, peak over the steps in contact), peak_contact_pressure_Pa,
        log_rotation_rad (the log's rigid rotation at the end), steps, and a few more."""
        self.check(scenario)
        log = self.log_model(scenario)
        static = self.dam.static_state(scenario.water_level_m)
        t0 = time.perf_counter()
        out = run_impact(self.dam, log, scenario, static, self.offset_m, self.after_contact,
                         timings=self._split, fhat=self.fhat)
        out["evaluate_s"] = time.perf_counter() - t0
        self._steps_s += out["evaluate_s"]
        return out

    def evaluate_many(self, scenarios: Sequence[DamScenario]) -> list:
        """The outputs of several scenarios stepped side by side (docs/architecture.md §7,
        "Several right-hand sides at once"): each step's solves of the dam, and of the logs
        they share, made in one call per factor (shared_solves.serve_together). Per
        scenario, its outputs as :meth:`evaluate` gives them to round-off, or the error
        it raised (a bad scenario fails alone; the others go on). ``evaluate_s`` is the
        batch's wall time shared equally. A dam or log factor that holds one pending
        condensation only (a split factor: the 2D section, a small log) cannot be shared:
        the scenarios are then evaluated one after the other."""
        scenarios = list(scenarios)
        # The batch's own logs stay held until it is done.
        keep = self.logs.keep
        if keep is not None:
            self.logs.keep = max(keep, len(scenarios))
        try:
            return self._evaluate_many(scenarios)
        finally:
            self.logs.keep = keep
            self.logs.trim()

    def _evaluate_many(self, scenarios: list) -> list:
        results: list = [None] * len(scenarios)
        runs, where = [], []
        for k, s in enumerate(scenarios):
            try:
                self.check(s)
                log = self.log_model(s)
                static = self.dam.static_state(s.water_level_m)
            except Exception as err:  # noqa: BLE001: the scenario's failure is its result
                results[k] = err
                continue
            runs.append(impact_run(self.dam, log, s, static, self.offset_m, self.after_contact,
                                   fhat=self.fhat))
            where.append(k)
        together = shares(self.dam.factor) and all(
            shares(self.log_model(scenarios[k]).factor) for k in where)
        t0 = time.perf_counter()
        if together:
            done = serve_together(runs, self.together)
        else:
            done = []
            for run in runs:
                try:
                    done.append(serve_alone(run))
                except Exception as err:  # noqa: BLE001
                    done.append(err)
        wall = time.perf_counter() - t0
        self._steps_s += wall
        for k, out in zip(where, done):
            if isinstance(out, dict):
                out["evaluate_s"] = wall / max(len(runs), 1)
            results[k] = out
        return results

    def timings(self) -> dict:
        """Cumulative seconds: the dam's set-up (meshing, assembly, its two factorizations and
        W_face), the logs' set-up (meshing, factorization, condensation) and the time steps
        with the outputs they monitor, split into the steps with the dam stepped (the
        contact), those with the log alone, and the convolution after them; for the
        scenarios evaluated side by side (:meth:`evaluate_many`), the shared calls'
        seconds per kind and the runs' own ("shared_condense_s", …, "shared_runs_s")."""
        shared = {f"shared_{k}_s": v for k, v in self.together.seconds.items() if v}
        return {"dam_setup_s": self.setup_s,
                "log_setup_s": self.logs.setup_s(),
                "steps_s": self._steps_s, **self._split, **shared}

    def counts(self) -> dict:
        """{"factorizations": {"dam_stage1", "dam_stage2", "log"} (and "dam_response" where the
        response functions took a plain factor, DamModel.response_factor), "back_substitutions":
        {same keys}}; "log" sums over every log model made, held or let go."""
        c = self.dam.counts()
        c["factorizations"]["log"] = self.logs.total("factorizations")
        c["back_substitutions"]["log"] = self.logs.total("back_substitutions")
        restored = self.logs.total("restorations")
        if restored:
            c.setdefault("restorations", {})["log"] = restored
        return c
