"""What a dam–debris impact scenario costs with the reused factorizations (dam/reuse.py).

For the default 2D scenario (``DamScenario()``, default mesh), measured in one run:

* the monolithic stage 1 + stage 2 (one mesh with the log, every matrix factored);
* the ScenarioEvaluator's set-up (the dam without the log: stage-1 K and stage-2 Ŵ factored
  once, W_face condensed; the static state at the base water level);
* its first scenario (the default one; includes the log's own mesh and factorization) and
  then ``--variants`` scenarios that reuse everything (other speeds, pitches, friction and
  a second water level), their mean time, and the ratio monolithic / per-scenario;
* the factorizations and back-substitutions per body, and the agreement of the default
  scenario's outputs with the monolithic run.

JIT compilation of the forms is warmed up first (both paths), so the times are those of a
sweep, not of a cold cache. Writes bench/sweep_engine.json.

    /usr/bin/python3 bench/sweep_engine.py [--variants 8]
"""
import argparse
import json
import time
from pathlib import Path

from mpi4py import MPI

from flexcontact.dam import DamScenario
from flexcontact.dam.reuse import ScenarioEvaluator, sweep_time_step_s
from flexcontact.dam.stage1 import solve_stage1
from flexcontact.dam.stage2 import solve_stage2
from flexcontact.info import describe

ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--variants", type=int, default=8)
ap.add_argument("--out", default=str(Path(__file__).with_name("sweep_engine.json")))
args = ap.parse_args()
comm = MPI.COMM_SELF

base = DamScenario()
levels = (base.water_level_m - 1.0, base.water_level_m)
variants = [base.replace(log_speed_m_s=v, log_pitch_deg=p, friction_mu=mu, water_level_m=z)
            for v, p, mu, z in [(1.0, 5.0, 0.3, levels[0]), (3.0, 10.0, 0.5, levels[1]),
                                (2.0, 0.0, 0.7, levels[0]), (4.0, 15.0, 0.2, levels[1]),
                                (1.5, 8.0, 0.4, levels[1]), (2.5, 12.0, 0.6, levels[0]),
                                (3.5, 3.0, 0.5, levels[1]), (2.0, 10.0, 0.1, levels[0])]]
variants = (variants * (1 + args.variants // len(variants)))[:args.variants]
dt = sweep_time_step_s([base] + variants)


def monolithic(s):
    t0 = time.perf_counter()
    r1 = solve_stage1(s, comm=comm)
    r2 = solve_stage2(s, r1, dt_s=dt)
    return time.perf_counter() - t0, r1, r2


# Warm the JIT caches of both paths on a coarse mesh (not timed).
coarse = base.replace(mesh_size_far_m=6.0, mesh_size_impact_m=0.4)
monolithic(coarse)
ScenarioEvaluator(coarse, dt).evaluate(coarse)

t_mono, r1, r2 = monolithic(base)
t0 = time.perf_counter()
ev = ScenarioEvaluator(base, dt, levels, comm)
t_setup = time.perf_counter() - t0
t0 = time.perf_counter()
first = ev.evaluate(base)
t_first = time.perf_counter() - t0
times = []
for s in variants:
    t0 = time.perf_counter()
    ev.evaluate(s)
    times.append(time.perf_counter() - t0)
per_scenario = sum(times) / len(times)

m = r2.metrics
agreement = {
    "impulse_rel": first["impulse_N_s_per_m"] / m["impulse"] - 1,
    "peak_force_rel": first["peak_force_N_per_m"] / m["peak_force"] - 1,
    "contact_duration_rel": first["contact_duration_s"] / m["contact_duration_s"] - 1,
    "heel_stress_static_rel": first["heel_stress_static_Pa"] / r1.section.sigma_heel_Pa - 1,
    "peak_tensile_stress_rel": first["peak_tensile_stress_Pa"] / r2.peak_tensile_stress_Pa - 1,
    "peak_contact_pressure_rel": (first["peak_contact_pressure_Pa"]
                                  / r2.peak_contact_pressure_Pa - 1),
}
report = {
    "scenario": "DamScenario() default, 2D, default mesh",
    "dt_s": dt,
    "monolithic_stage1_plus_stage2_s": t_mono,
    "monolithic_split_s": {"stage1": r1.timings_s["total"], "stage2_setup": r2.timings_s["setup"],
                           "stage2_steps": r2.timings_s["steps"]},
    "evaluator_setup_s": t_setup,
    "evaluator_first_scenario_s": t_first,
    "evaluator_per_scenario_s": per_scenario,
    "scenarios_timed": len(times),
    "ratio_monolithic_over_per_scenario": t_mono / per_scenario,
    "break_even_scenarios": (t_setup + t_first) / max(t_mono - per_scenario, 1e-12),
    "counts": ev.counts(),
    "dam_dofs": ev.dam.V.dofmap.index_map.size_global * 2,
    "face_strip_dofs": int(ev.dam.face_dofs.size),
    "steps_default": first["steps"],
    "monolithic": {"peak_force_N_per_m": m["peak_force"], "impulse_N_s_per_m": m["impulse"],
                   "contact_duration_s": m["contact_duration_s"],
                   "heel_stress_static_Pa": r1.section.sigma_heel_Pa,
                   "peak_tensile_stress_Pa": r2.peak_tensile_stress_Pa,
                   "peak_contact_pressure_Pa": r2.peak_contact_pressure_Pa},
    "evaluator": {k: v for k, v in first.items()},
    "agreement_evaluator_vs_monolithic": agreement,
    "machine": describe(),
}
Path(args.out).write_text(json.dumps(report, indent=2, default=float) + "\n")
print(json.dumps({k: report[k] for k in ("monolithic_stage1_plus_stage2_s", "evaluator_setup_s",
                                          "evaluator_first_scenario_s", "evaluator_per_scenario_s",
                                          "ratio_monolithic_over_per_scenario", "counts")},
                 indent=1))
print(json.dumps(agreement, indent=1))
