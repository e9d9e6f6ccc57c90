"""The 3D sweep's trade-off: the mesh of the factored dam and of the log's crushed end
against the error and the time of a scenario (dam/reuse.py).

A sweep of crushing impacts at the main job's accuracy costs about half a minute a scenario
on the factored dam block (docs/dam.md, "Sweeps"), so 1,000 of them take hours. This bench
measures, in one run, what coarser meshes buy: for each setting (far field, impact zone, the
log's crushed patch and, when given, the log's own element size ``mesh_size_log_m``), the
dam's set-up (meshing, its two factorizations, W_face, 1,200 lags of the response
functions, more than the runs use, the face compliance of the re-contact bound: what a model
file keeps), then three
crushing scenarios at one time step:

* A: the main job's own (10 m × Ø0.8 m log, 10° pitch, 2 m/s);
* B: a 12 m log at 3 m/s, 5° pitch, 10° yaw, 6.5 m across the block;
* C: an 8 m × Ø0.5 m log at 1.5 m/s, 12° pitch, −8° yaw, 9 m across.

All three have the end ``--end`` (default the main job's rounded one; the crushed patch's
ball is then ``crushed_patch_mesh``'s for that shape). Each scenario's log is meshed and
factored on first use (its set-up is timed apart from its steps, as a sweep meshes each log
geometry once). The errors are against the first setting (the main job's mesh: 3 m far,
0.2 m on the impact zone, the log at 0.1 m and its end 12.5 mm within the ball of the first
contact and 5 cm deep), scenario by scenario. The projection of 1,000
scenarios on 2 workers is the set-up plus 500 times the mean scenario's steps; it
leaves out the logs' set-up, paid once per log geometry, and a whole sweep costs about twice
that a scenario (a shorter time step, faster logs, two workers sharing the memory bus:
docs/dam.md, "The 3D sweep's trade-off").

    /usr/bin/python3 bench/sweep_tradeoff_3d.py [--end flat] [--settings 3,0.2,0.0125,0.1 ...]

Writes bench/sweep_tradeoff_3d.json.
"""
import argparse
import json
import os
import sys
import time
from pathlib import Path

from flexcontact.dam import DamScenario
from flexcontact.dam.reuse import ScenarioEvaluator, sweep_time_step_s
from flexcontact.dam.scenario import MAIN_JOB_LOG_MESH_M, MAIN_JOB_MESH, crushed_patch_mesh

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import machine  # noqa: E402

MAIN_JOB = "{},{},{},{}".format(*MAIN_JOB_MESH[3], crushed_patch_mesh(3)[0],
                                 MAIN_JOB_LOG_MESH_M[3])
DEFAULT_SETTINGS = [MAIN_JOB, "3,0.2,0.025,0.1", "3,0.3,0.025,0.1", "6,0.4,0.025,0.1",
                    "6,0.4,0.05,0.1", "6,0.4,0.05,0.15", "3,0.2,0.025,0.2", "3,0.3,0.025,0.2",
                    "6,0.4,0.025,0.2", "6,0.4,0.05,0.2", "6,0.4,0.025"]
OUTPUTS = ("peak_force_filtered_N_per_m", "impulse_N_s_per_m", "delta_heel_stress_Pa",
           "peak_tensile_stress_Pa")

ap = argparse.ArgumentParser(description=__doc__,
                             formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--settings", nargs="+", default=DEFAULT_SETTINGS,
                help="far,impact,contact[,log] element sizes (m); the first is the reference")
ap.add_argument("--end", choices=("rounded", "flat"), default="rounded",
                help="the logs' front end (the main job's: rounded)")
ap.add_argument("--zone-m", type=float, default=None,
                help="the crushed patch's ball radius (default: crushed_patch_mesh's for --end)")
ap.add_argument("--layer-m", type=float, default=None, help="its depth behind the end")
ap.add_argument("--out", default=str(Path(__file__).with_name("sweep_tradeoff_3d.json")))
args = ap.parse_args()
_, _zone, _layer = crushed_patch_mesh(3, args.end)
args.zone_m = _zone if args.zone_m is None else args.zone_m
args.layer_m = _layer if args.layer_m is None else args.layer_m


def parse(setting: str) -> tuple:
    sizes = [float(v) for v in setting.split(",")]
    if len(sizes) not in (3, 4):
        sys.exit(f"--settings {setting!r}: far,impact,contact[,log] in m")
    return tuple(sizes) + (None,) * (4 - len(sizes))


def scenarios(far: float, impact: float, contact: float, log) -> list[DamScenario]:
    base = DamScenario(dim=3, mesh_size_far_m=far, mesh_size_impact_m=impact,
                       mesh_size_log_m=log,
                       mesh_size_contact_m=contact, contact_zone_m=args.zone_m,
                       contact_layer_m=args.layer_m, log_end_crushes=True,
                       log_end_shape=args.end)
    return [base,
            base.replace(log_length_m=12.0, log_speed_m_s=3.0, log_pitch_deg=5.0,
                         log_yaw_deg=10.0, log_across_m=6.5),
            base.replace(log_length_m=8.0, log_diameter_m=0.5, log_speed_m_s=1.5,
                         log_pitch_deg=12.0, log_yaw_deg=-8.0, log_across_m=9.0)]


# One time step for every setting and scenario: the sweep's (its shortest log's).
dt = sweep_time_step_s(scenarios(*parse(args.settings[0])))
results = []
for setting in args.settings:
    far, impact, contact, log_m = parse(setting)
    group = scenarios(far, impact, contact, log_m)
    t0 = time.perf_counter()
    ev = ScenarioEvaluator(group[0], dt)
    dam_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    ev.dam.responses().ensure(1200)  # more lags than any of the three runs
    ev.dam.face_compliance(0)
    response_s = time.perf_counter() - t0
    runs = []
    for s in group:
        t0 = time.perf_counter()
        log = ev.log_model(s)
        log_s = time.perf_counter() - t0
        out = ev.evaluate(s)
        runs.append({"log_dofs": int(log.W_hat.getSize()[0]),
                     "front_dofs": int(log.front_dofs.size), "log_setup_s": log_s,
                     "steps_s": out["evaluate_s"], "steps": out["steps"],
                     "delta_heel_stress_Pa": out["heel_stress_impact_Pa"]
                     - out["heel_stress_static_Pa"],
                     **{k: out[k] for k in OUTPUTS if k in out}})
        print(f"{setting}: log {runs[-1]['log_dofs']} DOFs ({runs[-1]['front_dofs']} front), "
              f"set-up {log_s:.1f} s, steps {out['evaluate_s']:.1f} s, filtered peak "
              f"{out['peak_force_filtered_N_per_m'] / 1e6:.4f} MN", flush=True)
    mean_steps = sum(r["steps_s"] for r in runs) / len(runs)
    results.append({"far_m": far, "impact_m": impact, "contact_m": contact,
                    "log_m": group[0].h_log_m,
                    "dam_dofs": int(ev.dam.W_hat.getSize()[0]),
                    "face_dofs": int(ev.dam.face_dofs.size),
                    "dam_setup_s": dam_s, "response_s": response_s, "scenarios": runs,
                    "mean_steps_s": mean_steps,
                    "projected_1000_on_2_workers_s": dam_s + response_s + 500 * mean_steps,
                    "counts": ev.counts()})
ref = results[0]["scenarios"]
for r in results:
    for run, base in zip(r["scenarios"], ref):
        run["relative_error"] = {k: run[k] / base[k] - 1.0 for k in OUTPUTS}
    r["largest_error"] = {k: max(abs(run["relative_error"][k]) for run in r["scenarios"])
                          for k in OUTPUTS}
    print(f"{r['far_m']:g} m / {r['impact_m']:g} m / {r['contact_m'] * 1e3:g} mm, log "
          f"{r['log_m']:g} m: "
          f"dam {r['dam_dofs']} DOFs ({r['face_dofs']} face), set-up "
          f"{r['dam_setup_s'] + r['response_s']:.0f} s, {r['mean_steps_s']:.1f} s a scenario, "
          f"1,000 on 2 workers ~{r['projected_1000_on_2_workers_s'] / 60:.0f} min; largest "
          "error " + ", ".join(f"{k} {100 * v:.1f} %" for k, v in r["largest_error"].items()))
Path(args.out).write_text(json.dumps(
    {"what": "3D crushing scenarios on the factored dam block at several meshes",
     "dt_s": dt, "end": args.end, "zone_m": args.zone_m, "layer_m": args.layer_m,
     "settings": results,
     "load_average_1min": os.getloadavg()[0], "machine": machine()}, indent=1))
