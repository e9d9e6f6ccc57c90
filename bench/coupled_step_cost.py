"""Where the time of a 3D what-if goes, step by step, and what stopping the dam after the
contact saves when the log's end crushes.

Loads a dam model (``flexcontact dam prepare``; default: prepares
``examples/dam_model_main_job.toml``, the 3D block at the main job's mesh with its
crushing end) and answers the main job's scenario (2 m/s) in one process, alternating
``--rounds`` times two variants of the test that stops stepping the dam once the log has
left (dam/coupled_step.py, ``_cannot_touch``):

* "crushed surface": as shipped, a crushed node re-contacts from its crushed surface;
* "nodes": the crushed end taken where its nodes are, as before: the crushed nodes then
  seem to reach into the face for ever, and the dam is stepped to the end of the run.

It records per variant the seconds of the steps with the dam stepped and with the log
alone, and the seconds spent in the kernel's contact step, in the log's and in the dam's
back-substitutions (each a condensation and an expansion, or a full solve), with their
counts; and checks that both variants give the same outputs (1e-8).
Writes bench/coupled_step_cost.json.

    /usr/bin/python3 bench/coupled_step_cost.py [--model DIR] [--rounds 2]
"""
import argparse
import collections
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
from machine import machine  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--model", default=None, help="a prepared dam model (default: prepare one)")
ap.add_argument("--rounds", type=int, default=2)
ap.add_argument("--out", default=str(Path(__file__).with_name("coupled_step_cost.json")))
args = ap.parse_args()

from flexcontact import _cpp  # noqa: E402
import flexcontact.dam.coupled_step as coupled  # noqa: E402
from flexcontact.dam.model_file import load  # noqa: E402
from flexcontact.sweep.scenarios import scenario_of  # noqa: E402

seconds = collections.Counter()
calls = collections.Counter()


def timed(name, f):
    def call(*a, **k):
        t0 = time.perf_counter()
        out = f(*a, **k)
        seconds[name] += time.perf_counter() - t0
        calls[name] += 1
        return out
    return call


class TimedFactor:
    """A body's factor, its solves timed under the body's name."""

    def __init__(self, inner, name):
        self._inner, self._name = inner, name
        for method in ("condense", "expand", "solve"):
            setattr(self, method, timed(name, getattr(inner, method)))

    def __getattr__(self, attr):
        return getattr(self._inner, attr)


class TimedKernel:
    def __init__(self, inner):
        self._inner = inner
        self.step_condensed = timed("kernel", inner.step_condensed)

    def __getattr__(self, attr):
        return getattr(self._inner, attr)


Plain = _cpp.ImpactContact
shipped_recess = coupled._crush_recess
tmp = None
if args.model is None:
    tmp = tempfile.TemporaryDirectory()
    args.model = str(Path(tmp.name) / "model")
    subprocess.run([sys.executable, "-m", "flexcontact", "dam", "prepare",
                    str(ROOT / "examples/dam_model_main_job.toml"), "--out", args.model],
                   check=True, cwd=ROOT, capture_output=True)
ev = load(args.model)
scenario = scenario_of(ev.base, {"log_speed_m_s": 2.0})
log = ev.log_model(scenario)   # meshed and factored outside the timed runs
static = ev.dam.static_state(scenario.water_level_m)
log.factor = TimedFactor(log.factor, "log")
ev.dam.factor = TimedFactor(ev.dam.factor, "dam")
coupled._cpp.ImpactContact = lambda *a: TimedKernel(Plain(*a))
VARIANTS = {"crushed surface": shipped_recess, "nodes": lambda kernel, pairs: None}
runs = {name: [] for name in VARIANTS}
outputs = {}
for _ in range(args.rounds):
    for name, recess in VARIANTS.items():
        coupled._crush_recess = recess
        seconds.clear()
        calls.clear()
        timings = {}
        out = coupled.run_impact(ev.dam, log, scenario, static, ev.offset_m, ev.after_contact,
                                 timings=timings)
        runs[name].append({**timings,
                           **{f"{k}_s": v for k, v in seconds.items()},
                           **{f"{k}_calls": v for k, v in calls.items()},
                           "dam_back_substitutions": out["dam_back_substitutions"],
                           "log_back_substitutions": out["log_back_substitutions"],
                           "dam_steps_convolved": out["dam_steps_convolved"]})
        outputs[name] = out
        print(name, json.dumps(runs[name][-1]), flush=True)
coupled._crush_recess = shipped_recess
coupled._cpp.ImpactContact = Plain
keys = ("peak_force_filtered_N_per_m", "impulse_N_s_per_m", "heel_stress_impact_Pa",
        "toe_stress_impact_Pa", "base_moment_change_Nm_per_m", "peak_tensile_stress_Pa",
        "log_rotation_rad")
ref, new = outputs["nodes"], outputs["crushed surface"]
difference = {k: abs(new[k] - ref[k]) / abs(ref[k]) for k in keys}
assert max(difference.values()) <= 1e-8, difference
total = {name: [r["coupled_steps_s"] + r["log_only_steps_s"] + r["convolution_s"]
                for r in rs] for name, rs in runs.items()}
result = {
    "what": "a 3D what-if's steps at the main job's mesh (crushing end, 2 m/s): where the "
            "time goes, and the dam stopped after the contact from the crushed surface "
            "against from the crushed nodes",
    "model": args.model if tmp is None else "examples/dam_model_main_job.toml (prepared)",
    "contact_dofs": {"log": int(log.front_dofs.size), "dam_face": int(ev.dam.face_dofs.size)},
    "dofs": {"log": int(log.new_vector().getSize()), "dam": int(ev.dam.new_vector().getSize())},
    "steps": new["steps"], "runs": runs,
    "steps_s_median": {name: statistics.median(v) for name, v in total.items()},
    "ratio_nodes_over_crushed_surface": (statistics.median(total["nodes"])
                                         / statistics.median(total["crushed surface"])),
    "relative_difference_of_outputs": difference,
    "load_average_1min": os.getloadavg()[0], "machine": machine()}
Path(args.out).write_text(json.dumps(result, indent=1))
print(json.dumps(result["steps_s_median"]), result["ratio_nodes_over_crushed_surface"])
