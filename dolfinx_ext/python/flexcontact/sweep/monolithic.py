"""The sweep's reference evaluator: every scenario meshed and solved from scratch.

:class:`MonolithicEvaluator` has the interface of the factorization-reusing
``flexcontact.dam.reuse.ScenarioEvaluator`` but runs today's two stages per scenario
(:func:`~flexcontact.dam.stage1.solve_stage1`, then
:func:`~flexcontact.dam.stage2.solve_stage2`) on a mesh of its own, so it pays — and counts
— two sparse factorizations per scenario (K for stage 1, the iteration matrix of stage 2).
It is the baseline the reusing engine is checked and timed against.

The heel stress during the impact is the linearised σ_heel (tension positive) of the base
section read, after every step, from the dam's elastic nodal forces at its base (loads minus
internal forces of the dam's cells, as stage 1 reads the static one), and its maximum over
the simulated window, which starts at the static state: it is never below the static value.
Before the first contact the dam is at rest in equilibrium, so the section is read from the
first step in contact on.
The window is the approach plus 1.5 × the log's 2L/c, much shorter than the dam's own
fundamental period, so the dam's later swaying is not in it.
"""
from __future__ import annotations

import math
import time

import ufl
from mpi4py import MPI

import dolfinx.fem

from ..dam.stage2 import default_time_step_s

IMPACT_OFFSET_M = 1.0
"""Distance from the first-contact point at which the dam's peak largest principal stress
is read (m): solve_stage2's default, and the reusing evaluator's (the corner's own stress
grows with refinement)."""

OUTPUTS = ("peak_force_N_per_m", "contact_duration_s", "impulse_N_s_per_m",
           "log_momentum_change_N_s_per_m", "heel_stress_static_Pa", "heel_stress_impact_Pa",
           "peak_tensile_stress_Pa", "peak_contact_pressure_Pa", "steps")
"""The evaluator's outputs (plain floats; ``steps`` an integer)."""


def sweep_time_step_s(scenarios) -> float:
    """One time step for the whole sweep, from its most demanding scenario: the smallest
    of the scenarios' default steps (the log's 2L/c along x over 40), s."""
    steps = [default_time_step_s(s) for s in scenarios]
    if not steps:
        raise ValueError("scenarios=[]: a sweep needs at least one scenario")
    return min(steps)


class HeelMonitor:
    """Largest linearised heel stress σ_heel (Pa) of the dam's base section over a run."""

    def __init__(self, scenario, stage1):
        from ..dam.section import nodal_section
        from ..dam.stage1 import _measures, body_loads
        from ..forms import elasticity_form
        from ..meshes import dam_tags as T
        self._section, self._T = nodal_section, T
        self.scenario, self.stage1 = scenario, stage1
        self._parts = (_measures, body_loads, elasticity_form)
        self._form = None
        self.peak_Pa = stage1.section.sigma_heel_Pa
        self.started = False

    def __call__(self, problem) -> None:
        s, st1, T = self.scenario, self.stage1, self._T
        self.started = self.started or bool(problem.records and problem.records[-1].active)
        if not self.started:
            return
        if self._form is None:
            measures, body_loads, elasticity_form = self._parts
            dx, ds = measures(st1.mesh)
            v = ufl.TestFunction(st1.V)
            loads = body_loads(s, v, dx, ds)
            r = loads["dam"] - elasticity_form(problem.u, v, s.concrete, dx(T.DAM), st1.kind)
            self._form = dolfinx.fem.form(r)
        w = 1.0 if s.dim == 2 else s.dam_width_m
        sec = self._section(st1.V, self._form, st1.mesh.facet_tags, T.DAM_BASE,
                            s.base_width_m, w)
        self.peak_Pa = max(self.peak_Pa, sec.sigma_heel_Pa)


class MonolithicEvaluator:
    """Evaluate scenarios one by one, each on its own mesh (two factorizations each).

    ``base``: the sweep's base scenario (kept for the interface; every scenario is meshed
    on its own); ``dt_s``: the impact time step of every scenario (default: each one's own
    :func:`~flexcontact.dam.stage2.default_time_step_s`); ``water_levels_m``: accepted for
    the interface and unused (each mesh has its own water line); ``comm``: the communicator
    each scenario is solved on.
    """

    def __init__(self, base, dt_s: float | None = None, water_levels_m=None,
                 comm=MPI.COMM_SELF):
        if dt_s is not None and not (isinstance(dt_s, (int, float)) and math.isfinite(dt_s)
                                     and dt_s > 0):
            raise ValueError(f"dt_s={dt_s!r}: must be None or a finite number > 0 s")
        self.base, self.dt_s, self.comm = base, dt_s, comm
        self._counts = {"factorizations": {"stage1": 0, "stage2": 0},
                        "back_substitutions": {"stage1": 0, "stage2": 0}}
        self._timings = dict.fromkeys(("mesh_s", "stage1_s", "stage2_setup_s", "steps_s",
                                       "outputs_s"), 0.0)

    def evaluate(self, scenario) -> dict:
        """The outputs of one scenario (see :data:`OUTPUTS`). Collective over ``comm``."""
        from ..dam.stage1 import solve_stage1
        from ..dam.stage2 import response_duration_s, solve_stage2
        stage1 = solve_stage1(scenario, comm=self.comm)
        self._add("stage1", 1, 1)
        heel = HeelMonitor(scenario, stage1)
        st2 = solve_stage2(scenario, stage1, dt_s=self.dt_s, offset_m=IMPACT_OFFSET_M,
                           duration_s=response_duration_s(scenario), comm=self.comm,
                           on_step=heel)
        t_out = time.perf_counter()
        p = st2.problem
        self._add("stage2", getattr(p.condensation, "factorizations", 1),
                  p.back_substitutions + int(p.flex_info.get("solves", 0)))
        m = st2.metrics
        out = {"peak_force_N_per_m": m["peak_force"],
               "contact_duration_s": m["contact_duration_s"],
               "impulse_N_s_per_m": m["impulse"],
               "log_momentum_change_N_s_per_m": st2.log_momentum_change,
               "heel_stress_static_Pa": stage1.section.sigma_heel_Pa,
               "heel_stress_impact_Pa": heel.peak_Pa,
               "peak_tensile_stress_Pa": st2.peak_tensile_stress_Pa,
               "peak_contact_pressure_Pa": st2.peak_contact_pressure_Pa}
        out = {k: float(v) for k, v in out.items()}
        out["steps"] = int(st2.timings_s["steps_n"])
        t = self._timings
        t["mesh_s"] += stage1.timings_s["mesh"]
        t["stage1_s"] += stage1.timings_s["total"] - stage1.timings_s["mesh"]
        t["stage2_setup_s"] += st2.timings_s["setup"]
        t["steps_s"] += st2.timings_s["steps"]
        t["outputs_s"] += time.perf_counter() - t_out
        return out

    def _add(self, stage: str, factorizations: int, solves: int) -> None:
        self._counts["factorizations"][stage] += int(factorizations)
        self._counts["back_substitutions"][stage] += int(solves)

    def timings(self) -> dict:
        """Seconds so far: meshing, stage 1 (assembly, factorization, solve, sections),
        stage 2's set-up (assembly, factorization of the iteration matrix, condensation),
        its steps (with the stresses and the heel section read during the run), outputs."""
        return dict(self._timings)

    def counts(self) -> dict:
        """{"factorizations": {stage: n}, "back_substitutions": {stage: n}} so far."""
        return {k: dict(v) for k, v in self._counts.items()}
