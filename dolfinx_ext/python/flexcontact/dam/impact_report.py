"""The short markdown report of the dam demo, written from its summary.json content."""
from __future__ import annotations

from pathlib import Path

from .convergence import SAFETY_FACTOR, richardson
from .key_numbers import CONVERGENCE_QUANTITIES, MESH_STUDY_COLUMNS


def _mpa(x) -> str:
    return f"{x / 1e6:.4g}"


def _scenario(s: dict, log: dict) -> list:
    c, w = s["concrete"], s["wood"]
    return [
        "## Scenario", "",
        f"* Gravity dam {s['dam_height_m']:g} m high, crest {s['crest_width_m']:g} m, "
        f"downstream slope {s['downstream_slope']:g} (base {s['downstream_slope'] * s['dam_height_m']:g} m), "
        f"on a foundation block {s['foundation_depth_m']:g} m deep; "
        + ("plane-strain section (per metre of dam)." if s["dim"] == 2 else
           f"3D block {s['dam_width_m']:g} m wide."),
        f"* Reservoir {s['water_level_m']:g} m above the base, tailwater "
        f"{s['tailwater_level_m']:g} m, uplift factor {s['uplift_factor']:g}.",
        f"* Log {s['log_length_m']:g} m × Ø{s['log_diameter_m']:g} m, {_end(s)}, pitched "
        f"{s['log_pitch_deg']:g}°, floating with draft {log['draft_m']:.3f} m (axis at "
        f"{log['axis_elevation_m']:.3f} m), {s['log_speed_m_s']:g} m/s along its axis, "
        f"friction μ = {s['friction_mu']:g}, added-mass coefficient "
        f"{s['added_mass_coefficient']:g}.",
        f"* Concrete E = {c['E_Pa'] / 1e9:g} GPa, ν = {c['nu']:g}, {c['rho_kg_m3']:g} kg/m³, "
        f"tensile strength {_mpa(s['concrete_tensile_strength_Pa'])} MPa; wood (along the "
        f"grain) E = {w['E_Pa'] / 1e9:g} GPa, {w['rho_kg_m3']:g} kg/m³, crushing strength "
        f"{_mpa(s['wood_crushing_strength_Pa'])} MPa parallel to the grain, green; "
        + ("the log's front end crushes at it (docs/crushing.md)."
           if s.get("log_end_crushes", False) else
           "the log's end is elastic to the end (the upper bound of the force)."), ""]


def _end(s: dict) -> str:
    """The front end's shape in words, with its defaults (chamfer D/8, cap radius D)."""
    shape, D = s.get("log_end_shape", "flat"), s["log_diameter_m"]
    if shape == "chamfered":
        c = s.get("log_end_chamfer_m") or D / 8
        return f"front end chamfered {c:g} m at 45°"
    if shape == "rounded":
        rho = s.get("log_end_radius_m") or D
        return (f"front end a spherical cap of radius {rho:g} m (a drift log's worn end: its "
                "ends are a root mass and a broken top, not a saw cut; the radius is not "
                "measured, docs/dam.md)")
    return "flat (sawn) front end"


def _chatter(theta: float) -> str:
    """What the time scheme's θ does to a crushing end's numbers (docs/dam.md, "The time
    scheme")."""
    if theta > 0.5:
        return (f"Stage 2 steps with θ = {theta:g}, which damps the mesh's highest "
                "frequencies: at θ = ½ the crushing front chatters, and the force comes out "
                "about 15 % lower and sensitive to rounding. ")
    return ("Stage 2 steps with θ = ½, at which the crushing front chatters: the force is "
            "about 15 % low at the main job's meshes, and the impulse, the contact duration "
            "and the heel stress move by about 1 % with a change of 1e-14 in the speed; "
            "time_scheme_theta = 0.55 removes both. ")


def _limits(st2: dict | None, westergaard: bool = False, dim: int = 2,
            theta: float = 0.5) -> list:
    water = ("Westergaard's added mass of the reservoir on the upstream face included"
             if westergaard else "no Westergaard added mass of the reservoir on the dam")
    crushes = bool(st2 and st2.get("log_end_crushes"))
    wood = ("the log's end crushes at the wood's crushing strength, capping the contact "
            "pressure averaged over each node's tributary measure (no rate effect)"
            if crushes else "no wood crushing")
    out = ["## Limits of the model", "",
           f"* Linear elasticity, small strain and small rotation; {wood}, no "
           f"concrete cracking, {water}, no "
           "water damping. The ratios below say how far each neglected effect is.", ""]
    if st2:
        out += [
            "| check | value | limit | ratio |", "|---|---|---|---|",
            f"| peak contact pressure / wood crushing strength | "
            f"{_mpa(st2['peak_contact_pressure_Pa'])} MPa | crushing | "
            f"{st2['peak_pressure_over_wood_crushing_strength']:.3g} |",
            f"| peak σ₁ at {st2['impact_offset_m']:g} m from the impact / concrete tensile "
            f"strength | {_mpa(st2['peak_max_principal_stress_near_impact_Pa'])} MPa | "
            f"cracking | {st2['peak_stress_over_tensile_strength']:.3g} |",
            *_halfspace_row(st2, "| half-space σ₁ at {r:g} m (Boussinesq + Cerruti + static) "
                            "/ concrete tensile strength | {v} MPa | cracking | {q:.3g} |"),
            f"| linearised heel stress during impact / tensile strength | "
            f"{_mpa(st2['sigma_heel_during_max_Pa'])} MPa | cracking | "
            f"{st2['sigma_heel_during_over_tensile_strength']:.3g} |",
            f"| log rigid rotation | {st2['log_max_rotation_rad']:.3g} rad | "
            f"{st2['log_rotation_limit_rad']:g} rad | "
            f"{st2['log_max_rotation_rad'] / st2['log_rotation_limit_rad']:.3g} |",
            f"| log largest principal strain | {st2['log_max_strain']:.3g} | "
            f"{st2['log_strain_limit']:g} | {st2['log_max_strain'] / st2['log_strain_limit']:.3g} |",
            "",
            ("The log's end crushed by up to "
             f"{st2.get('log_crush_depth_max_m', 0.0) * 1e3:.3g} mm, with up to "
             f"{st2.get('crushing_pairs_max', 0)} pairs at the cap at once, on elements of "
             f"{st2.get('contact_element_size_m', 0.0) * 1e3:.3g} mm about the first-contact "
             "point, dissipating "
             f"{st2.get('crushing_energy_J', 0.0):.4g} J"
             + (" per metre of dam" if dim == 2 else "")
             + "; the pressure ratio is at most 1 by the crushing law. "
             + _chatter(theta)
             if crushes else
             "A pressure ratio above 1 means the wood would crush locally where the end "
             "touches first (a mesh-dependent peak: the contact pressure is the mean over a "
             "node's tributary measure, singular under a flat end's corner), which would "
             "lower the peak force. ")
            + "A stress ratio above 1 would mean cracking, which the model cannot follow.",
            ""]
    return out


def _units(dim: int) -> dict:
    """Unit strings of forces, moments and impulses (per metre of dam in 2D)."""
    if dim == 2:
        return {"force": "N/m", "moment": "N·m/m", "impulse": "N·s/m", "mforce": "MN/m"}
    return {"force": "N", "moment": "N·m", "impulse": "N·s", "mforce": "MN"}


def _stage1(st1: dict, u: dict) -> list:
    sec = st1["base_section"]
    rows = ["## Stage 1: statics against hand statics", "",
            "| quantity | finite elements | hand statics | relative error |",
            "|---|---|---|---|"]
    for key, label in (("normal_force_N", f"N [{u['force']}]"),
                       ("shear_force_N", f"shear [{u['force']}]"),
                       ("moment_heel_Nm", f"M about the heel [{u['moment']}]"),
                       ("sigma_heel_Pa", "σ heel [Pa]"), ("sigma_toe_Pa", "σ toe [Pa]")):
        rows.append(f"| {label} | {sec[key]:.6e} | {sec[key + '_ref']:.6e} | "
                    f"{sec[key + '_error_rel']:.1e} |")
    rows += ["", f"Hydrostatic resultant on the face {st1['hydrostatic_resultant_N']:.6e} "
             f"(ρ_w g h²/2 = {st1['hydrostatic_resultant_N_ref']:.6e}) at "
             f"{st1['hydrostatic_height_m']:.6f} m (h/3 = {st1['hydrostatic_height_m_ref']:.6f} m).",
             ""]
    return rows


def _stage2(st2: dict, u: dict) -> list:
    return [
        "## Stage 2: the impact", "",
        f"* Peak contact force {st2['peak_force_filtered'] / 1e6:.4g} {u['mforce']} filtered "
        f"(centred moving average over {st2['force_filter_window_s'] * 1e3:.3g} ms, a tenth "
        f"of the log's 2L/c: the first steps of a discrete wave front overshoot the "
        f"plateau, a ringing of the mesh that the average removes and that keeps the exact "
        f"pulse's plateau); raw {st2['peak_force'] / 1e6:.4g} {u['mforce']} at t = "
        f"{st2['peak_force_t_s'] * 1e3:.3f} ms; contact {st2['contact_duration_s'] * 1e3:.3f} ms "
        f"(2L/c of the log {st2['contact_duration_s_ref_log_2L_c'] * 1e3:.3f} ms); impulse "
        f"{st2['impulse']:.6e} {u['impulse']} (the log's m Δv {st2['impulse_ref']:.6e}).",
        f"* Linearised heel stress: {_mpa(st2['sigma_heel_before_Pa'])} MPa before the impact "
        f"(hand statics {_mpa(st2['sigma_heel_before_Pa_ref'])} MPa), at most "
        f"{_mpa(st2['sigma_heel_during_max_Pa'])} MPa during the run (t = "
        f"{st2['sigma_heel_during_max_t_s'] * 1e3:.2f} ms); toe at least "
        f"{_mpa(st2['sigma_toe_during_min_Pa'])} MPa. Tension positive. The base responds "
        f"after the stress wave has crossed the dam, so its extreme comes well after the "
        f"contact: the run lasts {st2['duration_simulated_s'] * 1e3:.1f} ms.",
        f"* Peak largest principal stress at {st2['impact_offset_m']:g} m from the first "
        f"contact point: {_mpa(st2['peak_max_principal_stress_near_impact_Pa'])} MPa "
        f"(recovered: the nodal average of the cell stresses)."
        + "".join(_halfspace_row(st2, (
            " In 3D that tension lies in a layer of the face about 0.1 r deep, which the "
            "impact zone's elements do not resolve: this reading is low (docs/dam.md). "
            "The half-space value, the largest principal stress on the hemisphere of "
            "r = {r:g} m from the closed forms for the force at the filtered peak "
            "(Boussinesq for its normal part, Cerruti for its tangential part) plus the "
            "static stress there, is {v} MPa; the normal force alone would give "
            "(1 − 2ν) F / (2π r²) = {n} MPa. It assumes the face flat and the crest and "
            "the block's sides far compared with r."))),
        ""]


def _halfspace_row(st2: dict, text: str) -> list:
    """``text`` with the half-space tension filled in, or nothing (2D, older summaries)."""
    v = st2.get("halfspace_tension_at_offset_Pa")
    if v is None:
        return []
    n = st2.get("halfspace_tension_normal_force_only_Pa")
    return [text.format(r=st2["impact_offset_m"], v=_mpa(v), n="?" if n is None else _mpa(n),
                        q=st2["halfspace_tension_over_tensile_strength"])]


def _design(s: dict, log: dict, st2: dict) -> list:
    """The model's force beside the design formulas for the same log and speed."""
    from .design_formulas import FORMULA_NAMES, comparison
    c = comparison(s, log["mass_kg"], st2["peak_force_filtered"])
    k, F = c["k_eff_N_m"], c["formulas_N"]
    end = ("its end crushing" if st2.get("log_end_crushes") else
           "its end elastic (the upper bound)")
    out = ["## Against design practice", "",
           f"The same log ({c['mass_kg']:.0f} kg, {c['speed_m_s']:g} m/s) in the published "
           "debris-impact formulas (`flexcontact.dam.design_formulas`), and the spring "
           "stiffness each implies, k_eff = F²/(m v²) (the model's with the added mass it "
           "moves, the formulas' with the log's own mass)"
           + (f"; the 2D model's force per metre is multiplied by the log's diameter "
              f"({c['width_m']:g} m), a rough conversion" if s["dim"] == 2 else "") + ".", "",
           "| | peak force [MN] | k_eff [MN/m] | model / formula |", "|---|---|---|---|",
           f"| this model, filtered peak, {end} | {c['model_N'] / 1e6:.3g} | "
           f"{k['model'] / 1e6:.3g} | 1 |"]
    for name, words in FORMULA_NAMES.items():
        out.append(f"| {words} | {F[name] / 1e6:.3g} | {k[name] / 1e6:.3g} | "
                   f"{c['model_N'] / F[name]:.2g} |")
    bar = c["model_N"] / F["eurocode_bar"]
    out += ["", f"The elastic bar's force A√(Eρ)·v is what an intact flat end sends into a "
            f"rigid wall; the model gives {bar:.2g} of it"
            + (": the crushing end caps the pressure where the log touches, and the force "
               "grows only as the crushed patch widens." if st2.get("log_end_crushes") else
               ".")
            + " Haehnel & Daly's stiffness was measured on full-scale logs striking end-on, "
            "with their ends as they were; ASCE 7 takes the log's momentum over 0.03 s. "
            "`demos/dam_design_formulas.py` runs the whole table over lengths and speeds "
            "(docs/dam.md, design formulas).", ""]
    return out


def _opt(r: dict, key: str, fmt: str, scale=1) -> str:
    """r[key] × scale formatted, or a dash for a row without it (an older summary)."""
    return format(r[key] * scale, fmt) if r.get(key) is not None else "–"


def _mesh_study(rows: list) -> list:
    out = ["## Mesh study", "",
           "| h impact [m] | h far [m] | h contact [mm] | cells | DOFs | "
           + " | ".join(h for _, h, _ in MESH_STUDY_COLUMNS) + " |",
           "|---" * (5 + len(MESH_STUDY_COLUMNS)) + "|"]
    for r in rows:
        vals = " | ".join(f"{r[k] * scale:.4g}" for k, _, scale in MESH_STUDY_COLUMNS)
        out.append(f"| {r['h_impact_m']:.3g} | {r['h_far_m']:.3g} | "
                   f"{_opt(r, 'h_contact_m', '.3g', 1e3)} | {r['cells']} | "
                   f"{_opt(r, 'dofs', 'd')} | {vals} |")
    out.append("")
    contact = [r.get("h_contact_m") for r in rows]
    kept = len(rows) == 3 and None not in contact and contact[0] == contact[2] and (
        contact[0] < rows[0]["h_impact_m"])
    if kept:
        out += [f"The contact zone's elements (the crushed patch's, {contact[0] * 1e3:.3g} mm) "
                "are kept at their size on all three meshes; only the dam's and the log's "
                "near and far field are refined. So the study measures the discretisation "
                "error of the stresses away from the contact, and not that of the contact "
                "force, which depends mostly on the patch's elements (docs/dam.md gives the "
                "force on a coarser patch).", ""]
    if len(rows) == 3:
        ratio = rows[0]["h_impact_m"] / rows[1]["h_impact_m"]
        what = "every element size but the contact zone's" if kept else "every element size"
        out += ["### Convergence", "",
                f"Three meshes, {what} divided by {ratio:.3g} from one to the "
                "next, the default first. Richardson extrapolation from the three, the "
                "observed order p, and the default mesh's grid convergence index "
                f"GCI = {SAFETY_FACTOR:g} |f_default − f_ext| / |f_default| (docs/dam.md). "
                "Where p falls outside [0.5, 3] or the changes alternate in sign, the meshes "
                "are not in the asymptotic range and no error is given.", "",
                "| quantity | default | finer | finest | extrapolated | p | GCI default |",
                "|---|---|---|---|---|---|---|"]
        for key, head, scale in CONVERGENCE_QUANTITIES:
            if not all(key in r for r in rows):
                continue
            c = richardson([r[key] for r in rows], ratio)
            vals = " | ".join(f"{v * scale:.4g}" for v in c.values)
            ext = f"{c.extrapolated * scale:.4g}" if c.extrapolated is not None else "–"
            p = f"{c.order:.2f}" if c.order is not None else "–"
            gci = f"{c.gci_default * 100:.1f} %" if c.asymptotic else c.note
            out.append(f"| {head} | {vals} | {ext} | {p} | {gci} |")
        out += ["", "Δσ is the impact's change of the linearised stress (during − before): "
                "the static part is exact on any mesh and would dilute the error. The "
                "peak contact pressure is no design value: it is capped at the crushing "
                "strength where the end crushes, and otherwise grows with refinement "
                "under a flat end's corner.", ""]
    return out


def write_report(folder, summary: dict, mesh_study: list | None = None,
                 paraview: tuple | None = None) -> Path:
    """Write ``folder/report.md`` from the demo's summary (rank 0 only)."""
    folder = Path(folder)
    s, st1, st2 = summary["scenario"], summary["stage1"], summary.get("stage2")
    unit = _units(s["dim"])
    lines = ["# Floating log against a concrete gravity dam", "",
             "Written by `demos/dam_debris.py`; numbers from `summary.json` (SI, tension "
             "positive" + (", per metre of dam" if s["dim"] == 2 else "") + ").", ""]
    limits = _limits(st2, bool(s.get("westergaard")), s["dim"], s.get("time_scheme_theta", 0.5))
    lines += _scenario(s, summary["log"]) + limits + _stage1(st1, unit)
    if st2:
        lines += _stage2(st2, unit) + _design(s, summary["log"], st2)
    if mesh_study:
        lines += _mesh_study(mesh_study)
    else:
        lines += ["## Mesh study", "", "Not run: `demos/dam_debris.py --mesh-study` adds the "
                  "same numbers on two finer meshes (element sizes / √2 and / 2) and their "
                  "Richardson extrapolation.", ""]
    lines += ["## Figures", ""]
    if (folder / "geometry.png").is_file():  # drawn in 2D only
        lines += ["![mesh and groups](geometry.png)", ""]
    if st2:
        lines += ["![contact force and energies](impact_force.png)", "",
                  "![contact force, peak tensile stress and base stresses]"
                  "(impact_stresses.png)", ""]
    if paraview is not None:
        done, message = paraview
        lines += ["![largest principal stress at the peak force, ParaView](stress_paraview.png)"
                  if done else f"No ParaView picture: {message}.", ""]
    lines += ["Time series for ParaView: `stage1.xdmf`, `impact.xdmf` (every 5th step), "
              "`impact_peak.xdmf` (the step of the peak force); per step: `impact_force.csv` "
              "(contact force, energies), `base_section.csv` (base force, moment, "
              "linearised heel and toe stresses).", ""]
    path = folder / "report.md"
    path.write_text("\n".join(lines))
    return path
