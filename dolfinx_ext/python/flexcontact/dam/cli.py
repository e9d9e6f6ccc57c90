"""``python3 -m flexcontact dam prepare CONFIG.toml`` writes a dam model (dam/model_file.py);
``python3 -m flexcontact dam what-if MODEL --log-speed-m-s 3 ...`` answers one scenario
from it in a new process, without factoring the dam (docs/dam.md, "A dam model file")."""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

WHAT_IF_HELP = {
    "log_speed_m_s": "the log's speed along its axis, m/s",
    "log_pitch_deg": "pitch, degrees (front end up for a positive angle)",
    "log_length_m": "log length, m",
    "log_diameter_m": "log diameter, m",
    "wood_density_kg_m3": "wood density, kg/m³",
    "friction_mu": "Coulomb friction between log and face",
    "water_level_m": "water level above the dam's base, m (within the model's range)",
    "added_mass_coefficient": "added mass of the water the log drags, C_a",
    "wood_crushing_strength_Pa": "crushing strength parallel to the grain, Pa",
    "log_end_shape": "flat, chamfered or rounded",
    "log_end_chamfer_m": "the bevel of a chamfered end, m",
    "log_end_radius_m": "the cap radius of a rounded end, m (at least D/2)",
    "log_yaw_deg": "3D: yaw about the vertical axis, degrees",
    "log_across_m": "3D: the log centre's y along the dam axis, m (0 to the block width)",
}
"""What each what-if option means, with its unit; every one defaults to the model's base."""

WHAT_IF_INPUTS = tuple(WHAT_IF_HELP)
"""The scenario's inputs a what-if may change (yaw and the place across the block in 3D);
the rest are the model's base."""


def add_parser(sub) -> None:
    p = sub.add_parser("dam", help="a dam model: prepare it once, ask it what-if questions")
    dsub = p.add_subparsers(dest="dam_cmd", required=True)
    prep = dsub.add_parser("prepare", help="factor the dam of a sweep config and save it")
    prep.add_argument("config", type=Path, help="a sweep config (TOML): its [base], its "
                      "water-level range and time step")
    prep.add_argument("--out", type=Path, default=None,
                      help="model directory (default results/dam_model/<config stem>)")
    w = dsub.add_parser("what-if", help="one scenario from a saved dam model")
    w.add_argument("model", type=Path, help="a model directory written by prepare")
    for name in WHAT_IF_INPUTS:
        w.add_argument("--" + name.replace("_", "-"), dest=name, default=None,
                       type=str if name == "log_end_shape" else float,
                       help=WHAT_IF_HELP[name] + " (default: the model's base scenario)")
    w.add_argument("--json", action="store_true", help="print the outputs as JSON")


def main(args) -> int:
    from ..errors import FlexcontactError
    try:
        return prepare(args) if args.dam_cmd == "prepare" else what_if(args)
    except (FlexcontactError, ValueError) as e:
        print(f"flexcontact dam {args.dam_cmd}: {e}", file=sys.stderr)
        return 2


def prepare(args) -> int:
    from ..sweep import load
    from ..sweep.scenarios import build_scenarios
    from .model_file import logs_of, prepare as write
    from .reuse import sweep_time_step_s
    cfg = load(args.config)
    base, _, scenarios = build_scenarios(cfg)
    from .dam_model import face_region_m
    levels = [s.water_level_m for s in scenarios] or [base.water_level_m]
    out = args.out or Path("results") / "dam_model" / args.config.stem
    strip, patch = face_region_m(base, scenarios, (min(levels), max(levels)))
    write(base, sweep_time_step_s(scenarios or [base]), (min(levels), max(levels)), out,
          levels=sorted(set(levels)) if len(set(levels)) <= 8 else None, strip_m=strip,
          patch_y_m=patch, logs=logs_of(base, scenarios))
    return 0


def what_if(args) -> int:
    t0 = time.perf_counter()
    from .model_file import load
    from ..sweep.quantities import quantity
    from ..sweep.scenarios import scenario_of
    ev = load(args.model)
    t_load = time.perf_counter() - t0
    point = {k: getattr(args, k) for k in WHAT_IF_INPUTS if getattr(args, k) is not None}
    s = scenario_of(ev.base, point)
    ev.check(s)
    t1 = time.perf_counter()
    out = ev.evaluate(s)
    t_eval = time.perf_counter() - t1
    counts = ev.counts()
    if args.json:
        print(json.dumps({"inputs": point, "outputs": out, "counts": counts,
                          "seconds": {"load": t_load, "evaluate": t_eval}}, default=float))
        return 0
    print(f"what-if on {args.model}: " + (", ".join(f"{k}={v}" for k, v in point.items())
                                          or "the model's base scenario"))
    for key in ("peak_force_filtered_N_per_m", "peak_force_N_per_m", "impulse_N_s_per_m",
                "heel_stress_static_Pa", "heel_stress_impact_Pa", "toe_stress_impact_Pa",
                "peak_tensile_stress_Pa", "contact_duration_s"):
        q = quantity(key, ev.base.dim)
        print(f"  {q.words}: {q.show(out[key])} {q.unit}")
    print(f"  dam: {counts.get('restorations', {})} restored, factorizations "
          f"{counts['factorizations']}; back-substitutions {counts['back_substitutions']}")
    print(f"  {t_load:.2f} s to load the model, {t_eval:.2f} s to answer")
    return 0
