"""What a what-if question costs once the dam is saved (dam/model_file.py).

Prepares the dam model of ``examples/sweep_small.toml`` (the 2D section at its default
mesh; with ``--dim 3`` ``examples/sweep_3d.toml``, the 3D block at its default mesh), then
runs ``python3 -m flexcontact dam what-if MODEL ...`` ``--runs`` times, each a
new process, on the same scenario, and records in one run: the whole command's wall time,
the time to load the model and to answer (from the command's own --json), the counts
(nothing of the dam factored), and the machine's load. Writes bench/dam_what_if.json
(bench/dam_what_if_3d.json with ``--dim 3``). ``--main-job`` prepares
``examples/dam_model_main_job.toml`` instead, the 3D block at the main job's mesh with its
crushing end, and asks the main job's own scenario (bench/dam_what_if_main_job.json), so
that its outputs can be set beside the main job's. ``--ab-saved-logs`` also times, run
for run alternated with the model, the same model without its logs (the dam's files only,
the log then meshed and factored by each what-if), and records the ratio pair by pair.
``--ab-flight`` does the same against the model as format 3 wrote it: its large logs
without their plain factor, so that they fly after the contact on their Schur factor's full
solves (the answers must agree to 1e-10).

    /usr/bin/python3 bench/dam_what_if.py [--runs 5] [--dim 3 | --main-job]
                                          [--ab-saved-logs | --ab-flight]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--runs", type=int, default=5)
ap.add_argument("--dim", type=int, choices=(2, 3), default=2)
ap.add_argument("--main-job", action="store_true",
                help="the 3D block at the main job's mesh, crushing end, main job's scenario")
ap.add_argument("--ab-saved-logs", action="store_true",
                help="alternate each run with the same model stripped of its logs")
ap.add_argument("--ab-flight", action="store_true",
                help="alternate each run with the same model without its logs' plain factors")
ap.add_argument("--out", default=None)
args = ap.parse_args()
if args.ab_saved_logs and args.ab_flight:
    ap.error("--ab-saved-logs and --ab-flight: one comparison per run")
if args.main_job:
    args.dim = 3
if args.out is None:
    args.out = str(Path(__file__).with_name(
        "dam_what_if_main_job.json" if args.main_job
        else "dam_what_if.json" if args.dim == 2 else "dam_what_if_3d.json"))
CONFIG = ("examples/dam_model_main_job.toml" if args.main_job
          else "examples/sweep_small.toml" if args.dim == 2 else "examples/sweep_3d.toml")
sys.path.insert(0, str(ROOT / "bench"))
from machine import machine  # noqa: E402

ASK = ["--log-speed-m-s", "3", "--log-pitch-deg", "10", "--log-length-m", "12",
       "--water-level-m", "26"]
if args.dim == 3:
    ASK += ["--log-yaw-deg", "10", "--log-across-m", "6.5"]
if args.main_job:
    ASK = ["--log-speed-m-s", "2"]  # the model's own log (its rounded end), the main job's
with tempfile.TemporaryDirectory() as tmp:
    model = Path(tmp) / "model"
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "flexcontact", "dam", "prepare",
                    str(ROOT / CONFIG), "--out", str(model)],
                   check=True, cwd=ROOT, capture_output=True)
    prepare_s = time.perf_counter() - t0
    size = sum(p.stat().st_size for p in model.iterdir())
    bare = None

    def variant(name: str, leave_out: set, manifest: dict) -> Path:
        """A model beside ``model`` with its files (hard links) but ``leave_out``, and
        ``manifest``."""
        folder = Path(tmp) / name
        folder.mkdir()
        for p in model.iterdir():
            if p.name not in leave_out and p.name != "manifest.json":
                os.link(p, folder / p.name)
        (folder / "manifest.json").write_text(json.dumps(manifest))
        return folder

    manifest = json.loads((model / "manifest.json").read_text())
    if args.ab_saved_logs:
        # The same dam files, no log: a valid model whose what-if builds its log.
        if any(e.get("arrays") is None for e in manifest["logs"]):
            sys.exit("--ab-saved-logs: a log held dense sits in arrays.npz; this compares "
                     "large logs only")
        log_files = {f for e in manifest["logs"]
                     for f in [e["arrays"], *e["factor"]["files"],
                               *e.get("flight_factor", {}).get("files", [])]}
        manifest["files"] = {k: v for k, v in manifest["files"].items() if k not in log_files}
        manifest["logs"] = []
        bare = variant("model_without_logs", log_files, manifest)
    if args.ab_flight:
        # The same files, read as format 3: the large logs lose their plain factor.
        flight = {f for e in manifest["logs"] for f in e.pop("flight_factor", {}).get("files", [])}
        if not flight:
            sys.exit("--ab-flight: the model has no large log")
        manifest["format"] = 3
        bare = variant("model_format_3", flight, manifest)

    def what_if(path):
        t0 = time.perf_counter()
        r = subprocess.run([sys.executable, "-m", "flexcontact", "dam", "what-if", str(path),
                            *ASK, "--json"], check=True, cwd=ROOT, capture_output=True,
                           text=True)
        wall = time.perf_counter() - t0
        out = json.loads(r.stdout)
        return {"command_s": wall, **{f"{k}_s": v for k, v in out["seconds"].items()},
                "counts": out["counts"]}, out["outputs"]

    runs, runs_bare = [], []
    for _ in range(args.runs):
        run, outputs = what_if(model)
        runs.append(run)
        if bare is not None:
            run, bare_outputs = what_if(bare)
            runs_bare.append(run)
            timing = {"evaluate_s"}  # the evaluator's own clock, the only output that may differ
            if args.ab_saved_logs and (
                    {k: v for k, v in bare_outputs.items() if k not in timing}
                    != {k: v for k, v in outputs.items() if k not in timing}):
                sys.exit("--ab-saved-logs: the answers differ with and without the saved log")
            if args.ab_flight:
                # Another factor's round-off in the log's flight: equal to 1e-10.
                far = [k for k, v in outputs.items() if k not in timing
                       and isinstance(v, float) and abs(v - bare_outputs[k]) > 1e-10 * abs(v)]
                if far:
                    sys.exit(f"--ab-flight: the answers differ beyond 1e-10 in {far}")
result = {
    "what": ("dam what-if from a saved model, "
             + ("3D block at the main job's mesh, crushing end" if args.main_job
                else ("2D section" if args.dim == 2 else "3D block") + " at its default mesh")),
    "config": CONFIG, "scenario": ASK, "prepare_s": prepare_s,
    "outputs": {k: outputs[k] for k in ("peak_force_N_per_m", "peak_force_filtered_N_per_m",
                                        "impulse_N_s_per_m", "heel_stress_static_Pa",
                                        "heel_stress_impact_Pa", "peak_contact_pressure_Pa",
                                        "steps", "dam_back_substitutions",
                                        "log_back_substitutions")},
    "model_bytes": size, "runs": runs,
    "median_s": {k: statistics.median(r[k] for r in runs)
                 for k in ("command_s", "load_s", "evaluate_s")},
    "load_average_1min": os.getloadavg()[0], "machine": machine()}
if runs_bare:
    name = "saved_logs" if args.ab_saved_logs else "the_logs_plain_factors"
    result[f"runs_without_{name}"] = runs_bare
    result[f"with_over_without_{name}"] = {
        k: statistics.median(a[k] / b[k] for a, b in zip(runs, runs_bare))
        for k in ("command_s", "evaluate_s")}
Path(args.out).write_text(json.dumps(result, indent=1))
print(json.dumps(result["median_s"]), f"prepare {prepare_s:.1f} s, model {size / 1e6:.1f} MB")
if runs_bare:
    print(f"with / without {name.replace('_', ' ')}:",
          json.dumps(result[f"with_over_without_{name}"]))
