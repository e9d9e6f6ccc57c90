"""The sweep's reference evaluator: every scenario meshed and solved from scratch.

:class:`MonolithicEvaluator` has the interface of the factorization-reusing
``flexcontact.dam.reuse.ScenarioEvaluator`` but runs today's two stages per scenario
(:func:`~flexcontact.dam.stage1.solve_stage1`, then
:func:`~flexcontact.dam.stage2.solve_stage2`) on a mesh of its own, so it pays — and counts
— two sparse factorizations per scenario (K for stage 1, the iteration matrix of stage 2).
It is the baseline the reusing engine is checked and timed against.

The heel stress during the impact is the largest linearised σ_heel (tension positive) of
the base section that stage 2 records at every step (``Stage2Result.section_extremes``),
never below the static value; the run lasts until the base has responded
(:func:`~flexcontact.dam.stage2.response_duration_s`).
"""
from __future__ import annotations

import math
import time

from mpi4py import MPI

from ..dam.stage2 import sweep_time_step_s  # noqa: F401  (the sweep reads it from here)
from ..errors import InputError

IMPACT_OFFSET_M = 1.0
"""Distance from the first-contact point at which the dam's peak largest principal stress
is read (m): solve_stage2's default, and the reusing evaluator's (the corner's own stress
grows with refinement)."""

OUTPUTS = ("peak_force_N_per_m", "peak_force_filtered_N_per_m", "contact_duration_s",
           "impulse_N_s_per_m",
           "log_momentum_change_N_s_per_m", "heel_stress_static_Pa", "heel_stress_impact_Pa",
           "peak_tensile_stress_Pa", "peak_contact_pressure_Pa", "steps")
"""The evaluator's outputs (plain floats; ``steps`` an integer); in 3D also
``halfspace_tension_Pa``."""


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
            raise InputError(f"dt_s={dt_s!r}: must be None or a finite number > 0 s")
        self.base, self.dt_s, self.comm = base, dt_s, comm
        self._counts = {"factorizations": {"stage1": 0, "stage2": 0},
                        "back_substitutions": {"stage1": 0, "stage2": 0}}
        self._timings = dict.fromkeys(("mesh_s", "stage1_s", "stage2_setup_s", "steps_s",
                                       "outputs_s"), 0.0)

    def evaluate(self, scenario) -> dict:
        """The outputs of one scenario (see :data:`OUTPUTS`). Collective over ``comm``."""
        from ..dam.key_numbers import halfspace_tension_Pa
        from ..dam.stage1 import solve_stage1
        from ..dam.stage2 import response_duration_s, solve_stage2
        stage1 = solve_stage1(scenario, comm=self.comm)
        self._add("stage1", 1, 1)
        st2 = solve_stage2(scenario, stage1, dt_s=self.dt_s, offset_m=IMPACT_OFFSET_M,
                           duration_s=response_duration_s(scenario))
        t_out = time.perf_counter()
        p = st2.problem
        self._add("stage2", getattr(p.condensation, "factorizations", 1),
                  p.back_substitutions + int(p.flex_info.get("solves", 0)))
        m = st2.metrics
        out = {"peak_force_N_per_m": m["peak_force"],
               "peak_force_filtered_N_per_m": m["peak_force_filtered"],
               "contact_duration_s": m["contact_duration_s"],
               "impulse_N_s_per_m": m["impulse"],
               "log_momentum_change_N_s_per_m": st2.log_momentum_change,
               "heel_stress_static_Pa": stage1.section.sigma_heel_Pa,
               "heel_stress_impact_Pa": max(
                   stage1.section.sigma_heel_Pa,
                   st2.section_extremes().get("sigma_heel_max_Pa", -math.inf)),
               "peak_tensile_stress_Pa": st2.peak_tensile_stress_Pa,
               "peak_contact_pressure_Pa": st2.peak_contact_pressure_Pa}
        halfspace = halfspace_tension_Pa(scenario, st2.force_at_filtered_peak_N,
                                         st2.static_stress_near_impact_Pa, IMPACT_OFFSET_M)
        if halfspace is not None:
            out["halfspace_tension_Pa"] = halfspace
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
