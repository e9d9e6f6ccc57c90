"""Cheap evaluators for the sweep tests, injected with ``engine.evaluator =
"sweep_fakes:LinearEvaluator"`` (tests/ on the path): outputs that are analytic functions of
the scenario's inputs, so that the worst case, the exceedance curve and the rank
correlations have exact expected values.

``SWEEP_FAKE_LOG``: a file to which every evaluation appends one line (the scenario's
swept inputs), so that a test can count evaluations across processes;
``SWEEP_FAKE_SLEEP_S``: seconds each evaluation waits (a sweep slow enough to be killed).
"""
import json
import os
import time

from mpi4py import MPI


def expected_outputs(speed_m_s, mu, length_m, rho_kg_m3, water_m):
    """The outputs of :class:`LinearEvaluator` for these inputs (plain floats)."""
    return {"peak_force_N_per_m": 1e6 * speed_m_s,
            "contact_duration_s": 2.0 * length_m / 4000.0,
            "impulse_N_s_per_m": rho_kg_m3 * length_m * speed_m_s,
            "log_momentum_change_N_s_per_m": -rho_kg_m3 * length_m * speed_m_s,
            "heel_stress_static_Pa": -4e5 + 1e3 * (27.0 - water_m),
            "heel_stress_impact_Pa": -4e5 + 1e5 * speed_m_s + 2e4 * mu,
            "peak_tensile_stress_Pa": 1e6 * speed_m_s * mu,
            "peak_contact_pressure_Pa": 3e7 * speed_m_s / (1.0 + mu),
            "steps": 100 + int(round(10 * length_m))}


def log_key(s) -> str:
    return json.dumps([float(s.log_speed_m_s).hex(), float(s.friction_mu).hex(),
                       float(s.log_length_m).hex(), float(s.wood.rho_kg_m3).hex(),
                       float(s.water_level_m).hex()])


class LinearEvaluator:
    """Counts like the reusing engine: two dam factorizations at set-up, one per new log
    geometry, and one back-substitution per step."""

    def __init__(self, base, dt_s=None, water_levels_m=None, comm=MPI.COMM_SELF):
        self.base, self.dt_s = base, dt_s
        self.logs = set()
        self._counts = {"factorizations": {"dam": 2, "log": 0},
                        "back_substitutions": {"steps": 0}}

    def evaluate(self, s) -> dict:
        path = os.environ.get("SWEEP_FAKE_LOG")
        if path:
            fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT)
            os.write(fd, (log_key(s) + "\n").encode())
            os.close(fd)
        time.sleep(float(os.environ.get("SWEEP_FAKE_SLEEP_S", "0")))
        out = expected_outputs(s.log_speed_m_s, s.friction_mu, s.log_length_m,
                               s.wood.rho_kg_m3, s.water_level_m)
        geometry = (s.log_length_m, s.log_diameter_m)
        if geometry not in self.logs:
            self.logs.add(geometry)
            self._counts["factorizations"]["log"] += 1
        self._counts["back_substitutions"]["steps"] += out["steps"]
        return out

    def counts(self) -> dict:
        return {k: dict(v) for k, v in self._counts.items()}


class CheckedLinearEvaluator(LinearEvaluator):
    """A LinearEvaluator that cannot compute speeds above 3.5 m/s (its ``check``)."""

    def check(self, s) -> None:
        if s.log_speed_m_s > 3.5:
            raise ValueError(f"log_speed_m_s={s.log_speed_m_s!r}: above this evaluator's "
                             f"3.5 m/s")


def sweep_time_step_s(scenarios):
    return 1e-4


END_FACTOR = {"flat": 1.0, "chamfered": 0.8, "rounded": 0.5}
"""The peak force of :class:`EndShapeEvaluator`, relative to the flat end's."""


class EndShapeEvaluator(LinearEvaluator):
    """:class:`LinearEvaluator` whose peak force scales with the log's end shape
    (:data:`END_FACTOR`): a categorical input with a known effect."""

    def evaluate(self, s) -> dict:
        out = super().evaluate(s)
        out["peak_force_N_per_m"] *= END_FACTOR[s.log_end_shape]
        return out


class BatchingEvaluator(LinearEvaluator):
    """A LinearEvaluator with ``evaluate_many`` (as the reusing engine's): per scenario its
    outputs or the error it raised. ``SWEEP_FAKE_FAIL_SPEED_ABOVE``: speeds above it fail."""

    def evaluate(self, s) -> dict:
        limit = os.environ.get("SWEEP_FAKE_FAIL_SPEED_ABOVE")
        if limit is not None and s.log_speed_m_s > float(limit):
            raise RuntimeError(f"log speed {s.log_speed_m_s!r} above {limit}")
        return super().evaluate(s)

    def evaluate_many(self, scenarios) -> list:
        out = []
        for s in scenarios:
            try:
                out.append(self.evaluate(s))
            except RuntimeError as err:
                out.append(err)
        return out
