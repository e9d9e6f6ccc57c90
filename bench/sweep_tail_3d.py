"""A 3D sweep's unfavourable tail at the main job's accuracy, end to end on two cores.

1,000 crushing scenarios on the main job's mesh would take hours (docs/dam.md, "The 3D
sweep's trade-off"); on the sweeps' mesh they take about 15 minutes, and that mesh's filtered
peak force is up to 9 % off. A design reads the unfavourable tail (the values exceeded with
probability 0.1 and 0.01, the worst), so this bench:

1. runs the sweep of ``--config`` (default bench/sweep_1000_3d_crushing.toml) on its own
   mesh, the screen (or reads a finished one, ``--coarse DIR``);
2. takes, for each design output screened (the filtered peak force, the linearised heel
   stress during the impact, the half-space tension 1 m from the impact), its ``--top``
   most unfavourable scenarios;
3. runs their union again on the main job's mesh (the dam block 3 m / 0.2 m, the log
   0.1 m, its end 12.5 mm about the first contact: dam/scenario.py's MAIN_JOB_MESH,
   MAIN_JOB_LOG_MESH_M and crushed_patch_mesh), at the screen's time step and face patch,
   with the same engine: a dam model prepared once, 2 workers, 8 scenarios side by side;
4. gives, per output, the main job's mesh's change over the screened value in the tail,
   the values exceeded with probability 0.1 / 0.01 and the worst with the tail's values
   replaced by the main job's mesh's, and whether the tail is closed: whether every
   scenario left on the screen's value stays below the tail's smallest value even if it
   rose by the largest change seen in the tail.

The recovered principal stress 1 m from the impact is not screened: no mesh in the
trade-off resolves it (docs/dam.md, "The peak principal stress near the impact"); the
half-space value stands for it.

    /usr/bin/python3 bench/sweep_tail_3d.py [--config ...] [--coarse DIR] [--top 15]
        [--out results/bench_tail] [--json bench/sweep_tail_3d.json]
"""
import argparse
import csv
import json
import math
import os
import shutil
import time
from pathlib import Path

import numpy as np

from flexcontact.dam.dam_model import face_region_m
from flexcontact.dam.scenario import MAIN_JOB_LOG_MESH_M, MAIN_JOB_MESH, crushed_patch_mesh
from flexcontact.info import describe
from flexcontact.sweep import config as sweep_config
from flexcontact.sweep import driver, engines, evaluators, stats
from flexcontact.sweep.evaluators import EvaluatorSpec
from flexcontact.sweep.scenarios import build_scenarios, point_hash
from flexcontact.sweep.sweep_report import exceeded_at

here = Path(__file__).resolve().parent

SCREENED = ("peak_force_filtered_N_per_m", "heel_stress_impact_Pa", "halfspace_tension_Pa")
"""The design outputs whose tail is re-run (the largest is the most unfavourable)."""
STATIC_HEEL = "heel_stress_static_Pa"
"""Read beside the heel stress: the impact's change Δσ_heel is what the mesh moves."""


def main_job_mesh(s):
    """Scenario ``s`` on the main job's mesh, its end's crushed patch as the main job's
    for that end's shape."""
    size, zone, layer = crushed_patch_mesh(3, s.log_end.shape)
    far, impact = MAIN_JOB_MESH[3]
    return s.replace(mesh_size_far_m=far, mesh_size_impact_m=impact,
                     mesh_size_log_m=MAIN_JOB_LOG_MESH_M[3], mesh_size_contact_m=size,
                     contact_zone_m=zone, contact_layer_m=layer)


def screened_rows(folder: Path, hashes: list) -> dict:
    """{id: {output: value}} of the screen's results.csv, checked against the sample."""
    rows = {}
    with open(folder / "results.csv", newline="") as f:
        for r in csv.DictReader(f):
            i = int(r["id"])
            if r["point_hash"] != hashes[i]:
                raise SystemExit(f"{folder}: row {i} is of another sample than the config's")
            rows[i] = {o: float(r[o]) if r[o] not in ("", "nan") else math.nan
                       for o in SCREENED + (STATIC_HEEL,)}
    if len(rows) != len(hashes):
        raise SystemExit(f"{folder}: {len(rows)} rows, the config has {len(hashes)} scenarios")
    return rows


def tail(rows: dict, top: int) -> dict:
    """{output: ids of its ``top`` largest finite screened values, largest first}."""
    out = {}
    for o in SCREENED:
        ok = [i for i in rows if math.isfinite(rows[i][o])]
        out[o] = sorted(ok, key=lambda i: (-rows[i][o], i))[:top]
    return out


def read_off(values: np.ndarray, cfg) -> dict:
    """The values exceeded with probability 0.5, 0.1, 0.01 (those the sample resolves) and
    the largest, as the sweep report reads them."""
    curve = stats.exceedance(values, cfg.output["bootstrap"], cfg.output["band"], cfg.seed or 0)
    out = exceeded_at(curve)
    out["worst"] = float(np.nanmax(values))
    return out


def rise(fine: float, screened: float) -> float:
    """How much more unfavourable (larger) the re-run value is, over |screened|."""
    return (fine - screened) / abs(screened)


def closure(o: str, rows: dict, ids: list, fine: dict, levels: int) -> dict:
    """Whether the ``levels`` largest values after the re-run (the 1 % largest) are all
    re-run ones and can be no other scenario's: every scenario left on its screened value
    x stays below the smallest of them even at x + |x| × (the largest rise seen in the
    tail)."""
    largest = max([0.0] + [rise(fine[i][o], rows[i][o]) for i in ids if rows[i][o] != 0])
    merged = {i: (fine[i][o] if i in fine else rows[i][o]) for i in rows
              if math.isfinite(rows[i][o])}
    order = sorted(merged, key=lambda i: -merged[i])[:levels]
    floor = merged[order[-1]]
    left = [rows[i][o] for i in rows if i not in fine and math.isfinite(rows[i][o])]
    reach = max(x + abs(x) * largest for x in left) if left else -math.inf
    every = all(i in fine for i in order)
    return {"largest_rise": largest, "top_all_rerun": every, "tail_floor": floor,
            "largest_left_could_reach": reach, "closed": bool(every and reach < floor)}


def outputs_read_off(cfg, rows: dict, chosen: dict, fine: dict) -> dict:
    """Per screened output: the re-run's change in its tail, the values read off the
    screen, those of the 1 % largest with the tail re-run (the value exceeded with
    probability 0.01 and the worst), and the tail's closure."""
    fine = {i: {o: float(v[o]) for o in SCREENED + (STATIC_HEEL,)} for i, v in fine.items()}
    # The values exceeded with probability 0.01 are the 1 % largest: those the re-run holds.
    levels = max(1, int(round(0.01 * len(rows))))
    out = {}
    for o in SCREENED:
        mine = [i for i in chosen[o] if i in fine]
        out[o] = {"tail_ids": chosen[o],
                  "change_in_tail": spread([rise(fine[i][o], rows[i][o]) for i in mine
                                            if rows[i][o] != 0]),
                  "screened": read_off(np.array([rows[i][o] for i in sorted(rows)]), cfg),
                  "with_tail_rerun": {p: v for p, v in read_off(np.array(
                      [fine[i][o] if i in fine else rows[i][o] for i in sorted(rows)]),
                      cfg).items() if p == "worst" or float(p) * len(rows) <= levels},
                  "closure": closure(o, rows, mine, fine, levels)}
        if o == "heel_stress_impact_Pa":
            before = {i: rows[i][o] - rows[i][STATIC_HEEL] for i in mine}
            out[o]["change_of_delta_in_tail"] = spread(
                [rise(fine[i][o] - fine[i][STATIC_HEEL], before[i]) for i in mine
                 if before[i] != 0])
    return out


def spread(changes: list):
    """Mean, smallest and largest of ``changes`` (None if there are none)."""
    if not changes:
        return None
    return {"mean": float(np.mean(changes)), "min": float(np.min(changes)),
            "max": float(np.max(changes))}


def even_units(engine: dict, n: int) -> dict:
    """``engine`` with its batch cut so that ``n`` scenarios make whole rounds of its
    workers: 40 in units of 8 on 2 workers left the fifth unit alone on one worker for a
    third of the re-run."""
    workers = engine.get("workers") or engines.default_workers()
    k = max(1, int(engine.get("batch", 1)))
    rounds = math.ceil(n / (workers * k))
    return {**engine, "batch": math.ceil(n / (rounds * workers))}


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--config", default=str(here / "sweep_1000_3d_crushing.toml"))
    ap.add_argument("--coarse", default=None,
                    help="a finished sweep of --config to read instead of running it")
    ap.add_argument("--top", type=int, default=15, help="scenarios re-run per output")
    ap.add_argument("--out", default="results/bench_tail")
    ap.add_argument("--json", default=str(here / "sweep_tail_3d.json"))
    args = ap.parse_args()
    if args.top < 10:
        raise SystemExit(f"--top {args.top}: at least 10, the scenarios beyond P = 0.01")
    load0 = os.getloadavg()[0]
    out = Path(args.out)
    cfg = sweep_config.load(args.config)
    base, points, scenarios = build_scenarios(cfg)
    hashes = [point_hash(p) for p in points]
    t0 = time.perf_counter()
    if args.coarse is None:
        coarse = out / "screen"
        if coarse.exists():
            shutil.rmtree(coarse)
        screen = driver.run(cfg, out=coarse)
        screen_wall = time.perf_counter() - t0
        screened_here = True
    else:
        coarse = Path(args.coarse)
        screen = json.loads((coarse / "summary.json").read_text())
        screen_wall = float(screen["wall_s"])
        screened_here = False
    rows = screened_rows(coarse, hashes)
    chosen = tail(rows, args.top)
    ids = sorted({i for v in chosen.values() for i in v})
    print(f"screen: {len(rows)} scenarios in {screen_wall:.0f} s; re-running {len(ids)} "
          f"(the {args.top} most unfavourable of each of {len(SCREENED)} outputs)", flush=True)

    # The main job's mesh at the screen's time step and face patch (the patch shapes the
    # dam's mesh: it is imprinted on the face).
    t1 = time.perf_counter()
    fine_all = [main_job_mesh(s) for s in scenarios]
    fine_base = main_job_mesh(base)
    dt = float(screen["dt_s"])
    if evaluators.sweep_time_step("reuse", fine_all) != dt:
        raise SystemExit("the main job's mesh would change the sweep's time step")
    levels = [float(s.water_level_m) for s in scenarios]
    strip, patch = face_region_m(fine_base, fine_all, (min(levels), max(levels)))
    face = {"strip_m": strip, "patch_y_m": patch}
    folder = out / "tail"
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    model = driver.dam_model(folder / "dam_model", fine_base, dt, levels, face, (), owned=True)
    prepare_s = time.perf_counter() - t1
    print(f"main job's mesh: dam model prepared in {prepare_s:.0f} s", flush=True)
    spec = EvaluatorSpec("reuse", fine_base, dt, (min(levels), max(levels)), face=face,
                         model=str((folder / "dam_model").resolve()), model_if_seen=True)
    fine, failed, seconds = {}, {}, []

    def on_result(res):
        fine[res["id"]] = res["outputs"]
        seconds.append(res["seconds"])
        print(f"  {len(fine)}/{len(ids)} re-run, {time.perf_counter() - t2:.0f} s", flush=True)

    t2 = time.perf_counter()
    try:
        engines.run(even_units(cfg.engine, len(ids)), spec, [(i, fine_all[i]) for i in ids],
                    on_result)
    except Exception as e:  # noqa: BLE001: the rows done so far are reported
        failed["error"] = str(e)
    rerun_s = time.perf_counter() - t2
    total = screen_wall + (time.perf_counter() - t1)

    result = {"what": "the unfavourable tail of a 3D sweep re-run on the main job's mesh",
              "config": os.path.relpath(args.config, here.parent), "top": args.top,
              "scenarios": len(rows),
              "rerun": len(ids), "screened_in_this_run": screened_here,
              "screen_wall_s": screen_wall, "prepare_s": prepare_s, "rerun_wall_s": rerun_s,
              "end_to_end_s": total,
              "rerun_seconds_per_scenario_mean": float(np.mean(seconds)) if seconds else None,
              "dam_model": {k: v for k, v in model.items() if k != "path"}, "dt_s": dt,
              "mesh": {
                  "screen": driver._element_sizes(base),
                  "main_job": driver._element_sizes(fine_base)},
              "load_average_1min": load0, "machine": describe(),
              "outputs": outputs_read_off(cfg, rows, chosen, fine),
              "scenarios_rerun": {str(i): {"screened": rows[i], "main_job_mesh": {
                  o: float(fine[i][o]) for o in SCREENED + (STATIC_HEEL,)}}
                  for i in sorted(fine)}}
    if failed:
        result["failed"] = failed
    Path(args.json).write_text(json.dumps(result, indent=1) + "\n")
    print(json.dumps({k: result[k] for k in ("rerun", "screen_wall_s", "prepare_s",
                                             "rerun_wall_s", "end_to_end_s")}))
    for o, r in result["outputs"].items():
        print(o, json.dumps({k: r[k] for k in ("change_in_tail", "screened", "with_tail_rerun",
                                               "closure")}))


if __name__ == "__main__":
    main()
