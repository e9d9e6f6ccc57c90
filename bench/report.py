"""Ratios, the targets of issue 18 (item 2) and bench/RESULTS.md from the cases of one run."""
from __future__ import annotations

LARGE_DOFS = {2: 200_000, 3: 100_000}  # the targets hold on meshes at least this large
TARGET_CONTACT_DOFS = 4_500            # "(b)/(a) ≤ 1 up to 4,000 contact DOFs" (the ~4k sets)
STEP_3D_DOFS = 300_000                 # "(c)/(d) ≤ 3 in 3D with 1,000 pairs at ≥ 300k DOFs"


def derive(case: dict) -> dict:
    """Add (a)–(d) and their ratios to a case that ran."""
    if "error" in case:
        return case
    lin, con = case["linear"], case["contact"]
    a, b = lin["factorization_s"], con["fstar_w_s"]
    c, d = con["increment_s"], con["backsolve_s"]
    whole = con["setup_s"] + con["first_increment_s"]
    case.update({
        "contact_dofs": con["contact_dofs"], "pairs": con["pairs"],
        "factorization_s": a, "fstar_w_s": b, "increment_s": c, "backsolve_s": d,
        "contact_solve_s": con["contact_solve_s"],
        "factorization_peak_mb": lin["peak_mb"], "contact_peak_mb": con["peak_mb"],
        "fstar_w_over_factorization": b / a,
        "step_over_backsolve": c / d,
        "contact_solve_over_backsolve": con["contact_solve_s"] / d,
        "memory_over_factorization": con["peak_mb"] / lin["peak_mb"],
        "contact_solve_total_s": whole,
        "linear_solve_s": lin["solve_s"],
        "contact_over_linear_solve": whole / lin["solve_s"],
    })
    return case


def one_line(c: dict) -> str:
    if "error" in c:
        return f"{c['name']}: {c['error']}"
    return (f"{c['dofs']:,} DOFs, {c['contact_dofs']:,} contact DOFs: "
            f"(a) {c['factorization_s']:.2f} s (b) {c['fstar_w_s']:.2f} s (c) {c['increment_s'] * 1e3:.1f} ms (d) "
            f"{c['backsolve_s'] * 1e3:.1f} ms | b/a {c['fstar_w_over_factorization']:.2f} "
            f"c/d {c['step_over_backsolve']:.2f} memory {c['memory_over_factorization']:.2f} "
            f"whole/linear {c['contact_over_linear_solve']:.2f}")


def _large(c: dict) -> bool:
    return "error" not in c and c["dofs"] >= LARGE_DOFS[c["dim"]]


def targets(cases: list[dict]) -> list[dict]:
    """Each target on each large case: the value, the limit, met or by how much it misses."""
    rows = []

    def check(c, what, key, limit, note=""):
        v = c[key]
        rows.append({"case": c["name"], "target": what, "value": v, "limit": limit,
                     "met": v <= limit, "miss_pct": max(0.0, 100 * (v / limit - 1)),
                     "note": note})

    for c in filter(_large, cases):
        if c["contact_dofs"] <= TARGET_CONTACT_DOFS:
            check(c, "(b)/(a) ≤ 1", "fstar_w_over_factorization", 1.0)
        if c["dim"] == 2:
            check(c, "(c)/(d) ≤ 2 (2D)", "step_over_backsolve", 2.0)
        elif c["dofs"] >= STEP_3D_DOFS:
            check(c, "(c)/(d) ≤ 3 (3D, ≥ 300k DOFs)", "step_over_backsolve", 3.0)
        else:
            check(c, "(c)/(d) ≤ 3 (3D)", "step_over_backsolve", 3.0,
                  "indicative: the target is set at ≥ 300k DOFs (--full)")
        check(c, "peak memory ≤ 2× factorization", "memory_over_factorization", 2.0)
    return rows


# ---- serial against mpirun -n 2 (bench/run.py --mpi) -------------------------------------
MPI_PHASES = [("factorization (a)", "linear", "factorization_s"),
              ("F* (factorization with Schur complement, F*)", "contact", "flexibility_s"),
              ("F* + W (b)", "contact", "fstar_w_s"),
              ("increment (c)", "contact", "increment_s"),
              ("back-substitution (d)", "contact", "backsolve_s"),
              ("set-up", "contact", "setup_s")]


def _max_rel(a, b) -> float | None:
    """max |a − b| / max |b| (None if either is missing or the shapes differ)."""
    import numpy as np
    if a is None or b is None:
        return None
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape != b.shape or not b.size:
        return None
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


def mpi_compare(serial: dict, par: dict, ans1: dict | None, ans2: dict | None) -> dict:
    """Per phase the serial and two-rank times and the speed-up; the answers' differences."""
    row = {"name": serial.get("name", par.get("name")), "serial": serial, "np2": par}
    if "error" in serial or "error" in par:
        row["error"] = serial.get("error") or par.get("error")
        return row
    row.update(dofs=serial["dofs"], dim=serial["dim"],
               contact_dofs=serial["contact"]["contact_dofs"], phases=[])
    for label, part, key in MPI_PHASES:
        t1, t2 = serial[part][key], par[part][key]
        row["phases"].append({"phase": label, "key": key, "serial_s": t1, "np2_s": t2,
                              "speedup": t1 / t2 if t2 else None})
    row["wall_speedup"] = serial["wall_s"] / par["wall_s"]
    a1, a2 = ans1 or {}, ans2 or {}
    row["max_rel_diff"] = {k: _max_rel(a2.get(k), a1.get(k))
                           for k in ("u", "pressure", "normal_force")}
    row["load_average"] = {"serial": serial.get("load_average"),
                           "np2": par.get("load_average")}
    row["mumps_ordering"] = {"serial": serial["contact"]["mumps_ordering"],
                             "np2": par["contact"]["mumps_ordering"]}
    return row


def mpi_line(r: dict) -> str:
    if "error" in r:
        return f"{r['name']}: {r['error']}"
    sp = " ".join(f"{p['key']} ×{_f(p['speedup'])}" for p in r["phases"])
    d = r["max_rel_diff"]
    return f"{r['name']}: {sp}; max rel diff u {_e(d['u'])} p {_e(d['pressure'])}"


def _e(v):
    return "—" if v is None else f"{v:.1e}"


def _ceiling_lines(c: dict | None) -> list[str]:
    if not c:
        return ["(bench/mpi_ceiling.json not found: run bench/mpi_ceiling.py for the ceiling)"]
    d = c["dgemm"]
    out = [f"The machine's ceiling (bench/mpi_ceiling.py, {c['started_utc']} UTC, load "
           f"average {c['load_average_at_start'][0]:.1f} at its start): one dgemm "
           f"(n = {c['dgemm_n']}) alone against two at once, 2 × t_alone / t_pair = "
           + ", ".join(_f(x["ceiling"]) for x in d) + " (best "
           + _f(c.get("ceiling", max(x["ceiling"] for x in d))) + ").", ""]
    for mesh, rounds in c.get("factorization", {}).items():
        for r in rounds:
            serial, par = r["np1"]["variants"], r["np2"]["variants"]
            ok = [k for k in par if _factored(serial[k]) and _factored(par[k])]
            out.append(f"* MUMPS factorization alone, {mesh} ({r['np1']['dofs']:,} DOFs), "
                       "serial → 2 ranks s (speed-up): "
                       + ", ".join(f"{k} {serial[k]['s']:.2f} → {par[k]['s']:.2f} "
                                   f"(×{serial[k]['s'] / par[k]['s']:.2f})" for k in ok)
                       + "".join(f"; {k}: no factor on 2 ranks" for k in par if k not in ok))
    return out + [""]


def _factored(row: dict) -> bool:
    """bench/mpi_ceiling.py's row made a factor (no INFOG(1) < 0, entries in it)."""
    return row.get("infog1", 0) >= 0 and row.get("factor_entries", 0) != 0


def mpi_section(m: dict | None) -> list[str]:
    if not m:
        return []
    out = ["## Serial against `mpirun -n 2` (issue 18, item 5)", "",
           "The largest 2D and 3D cases of the run, on one process and on two "
           "(`bench/run.py --mpi`), back to back. Speed-up = serial time / two-rank time; "
           "answers: max |u₂ − u₁| / max |u₁| over all nodes (likewise the contact pressure "
           "and each increment's normal force).", "",
           *_ceiling_lines(m.get("ceiling")),
           "| case | phase | serial s | 2 ranks s | speed-up |", "|---|---|---:|---:|---:|"]
    for r in m["cases"]:
        if "error" in r:
            out.append(f"| {r['name']} | failed: {r['error']} | | | |")
            continue
        for p in r["phases"]:
            out.append(f"| {r['name']} | {p['phase']} | {_f(p['serial_s'], 3)} | "
                       f"{_f(p['np2_s'], 3)} | {_f(p['speedup'])} |")
    out += ["", "The run: set-up plus ten increments, (set-up + 10 (c)) from the phases above. "
            "The whole case: the process's wall time, gmsh's meshing included (serial on rank 0 "
            "on both; its seconds beside it).", "",
            "| case | run (set-up + 10 increments) speed-up | whole case speed-up | meshing s "
            "serial / 2 ranks | max rel. diff. u | pressure | normal force | "
            "load average serial / 2 ranks |", "|---|---:|---:|---|---:|---:|---:|---|"]
    for r in m["cases"]:
        if "error" in r:
            continue
        d, la = r["max_rel_diff"], r["load_average"]
        out.append(f"| {r['name']} | {_f(run_speedup(r))} | {_f(r['wall_speedup'])} | "
                   f"{_f(r['serial'].get('mesh_s'), 1)} / {_f(r['np2'].get('mesh_s'), 1)} | "
                   f"{_e(d['u'])} | {_e(d['pressure'])} | {_e(d['normal_force'])} | "
                   f"{_f((la['serial'] or [None])[0], 1)} / {_f((la['np2'] or [None])[0], 1)} |")
    out += [""] + [f"* {r['name']}: two ranks ≥ ×1.5 on the run: {_met(run_speedup(r))}; on "
                   f"the increment alone: {_met(_phase(r, 'increment_s'))}"
                   for r in m["cases"] if "error" not in r]
    return out + [""]


def _phase(r: dict, key: str) -> float | None:
    return next((p["speedup"] for p in r["phases"] if p["key"] == key), None)


def _met(speedup: float | None, target: float = 1.5) -> str:
    if speedup is None:
        return "not measured"
    return f"×{speedup:.2f}, " + ("met" if speedup >= target else "**missed**")


def run_speedup(r: dict, increments: int = 10) -> float | None:
    """Serial over two ranks for set-up plus ``increments`` increments, formed from the
    measured phases: the case itself runs four increments, and (c) is their median."""
    t = {p["key"]: (p["serial_s"], p["np2_s"]) for p in r["phases"]}
    if "setup_s" not in t or "increment_s" not in t:
        return None
    one = t["setup_s"][0] + increments * t["increment_s"][0]
    two = t["setup_s"][1] + increments * t["increment_s"][1]
    return one / two if two else None


def _f(v, digits=2):
    return "—" if v is None else f"{v:.{digits}f}"


def _case_table(cases: list[dict]) -> list[str]:
    out = ["| case | DOFs | contact DOFs | pairs | (a) factorization s | (b) F* + W s | "
           "(c) increment ms | (d) back-subst. ms | local solve ms | (b)/(a) | (c)/(d) | "
           "local/(d) | peak MB factorization / contact | memory ratio | "
           "contact solve / linear solve |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for c in cases:
        if "error" in c:
            out.append(f"| {c['name']} | failed: {c['error']} |" + " |" * 13)
            continue
        out.append(
            f"| {c['name']} | {c['dofs']:,} | {c['contact_dofs']:,} | {c['pairs']:,} | "
            f"{_f(c['factorization_s'])} | {_f(c['fstar_w_s'])} | {_f(c['increment_s'] * 1e3, 1)}"
            f" | {_f(c['backsolve_s'] * 1e3, 1)} | {_f(c['contact_solve_s'] * 1e3, 2)} | "
            f"{_f(c['fstar_w_over_factorization'])} | {_f(c['step_over_backsolve'])} | "
            f"{_f(c['contact_solve_over_backsolve'])} | {c['factorization_peak_mb']:.0f} / "
            f"{c['contact_peak_mb']:.0f} | {_f(c['memory_over_factorization'])} | "
            f"{_f(c['contact_over_linear_solve'])} |")
    return out


def _split_table(cases: list[dict]) -> list[str]:
    out = ["| case | ordering plain / Schur | plain factor entries | Schur factor entries | "
           "factorization with Schur s | Schur extraction s | Cholesky of the blocks s | W s (route per body) | "
           "set-up s | first increment s | (c) − 2(d) − local solve ms | linear solve s | "
           "local solver (iterations) | case wall / CPU s | load average |",
           "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---|"]
    for c in cases:
        if "error" in c:
            continue
        lin, con = c["linear"], c["contact"]
        last = con["increments"][-1]
        out.append(
            f"| {c['name']} | {lin['mumps_ordering']} / {con['mumps_ordering']} | "
            f"{lin['factor_entries'] / 1e6:.1f}M | {con['factor_entries'] / 1e6:.1f}M | "
            f"{_f(con['factorization_s'])} | {_f(con['schur_s'])} | {_f(con['inverse_s'])} | "
            f"{_f(con['delassus_s'], 3)} ({', '.join(con.get('delassus_routes', [])) or '—'}) | "
            f"{_f(con['setup_s'])} | "
            f"{_f(con['first_increment_s'])} | "
            f"{_f((c['increment_s'] - 2 * c['backsolve_s'] - c['contact_solve_s']) * 1e3, 1)} | "
            f"{_f(lin['solve_s'])} | "
            f"{last['solver']} ({last['iterations']}) | {c['wall_s']:.0f} / "
            f"{_f(c.get('process_cpu_s'), 0)} | "
            + " → ".join(f"{x:.1f}" for x in c.get("load_average", [])) + " |")
    return out


def _target_table(rows: list[dict]) -> list[str]:
    if not rows:
        return ["No case of this run is large enough for the targets (≥ 200k DOFs in 2D, "
                "≥ 100k in 3D)."]
    out = ["| case | target | value | result |", "|---|---|---:|---|"]
    for r in rows:
        verdict = "met" if r["met"] else f"**missed by {r['miss_pct']:.1f}%**"
        note = f" ({r['note']})" if r["note"] else ""
        out.append(f"| {r['case']} | {r['target']} | {r['value']:.2f} | {verdict}{note} |")
    return out


def _why(rows: list[dict], cases: list[dict]) -> list[str]:
    """Each miss split into its parts, from the same case's numbers."""
    by_name = {c["name"]: c for c in cases}
    out = []
    for r in rows:
        if r["met"]:
            continue
        c = by_name[r["case"]]
        lin, con = c["linear"], c["contact"]
        if r["target"].startswith("(b)"):
            out.append(
                f"* {c['name']}, (b)/(a) = {r['value']:.2f}: the factorization with the Schur "
                f"complement took {con['factorization_s']:.1f} s ({con['mumps_ordering']}, "
                f"{con['factor_entries'] / 1e6:.1f}M entries) against the plain one's "
                f"{lin['factorization_s']:.1f} s ({lin['mumps_ordering']}, "
                f"{lin['factor_entries'] / 1e6:.1f}M entries); on top of it the Schur "
                f"complement's extraction {con['schur_s']:.1f} s, the Cholesky factors of its "
                f"blocks {con['inverse_s']:.1f} s (n_c = {con['contact_dofs']:,}) and W "
                f"{con['delassus_s']:.2f} s (per body: "
                f"{', '.join(con.get('delassus_routes', [])) or '—'}; the inverse route's "
                f"dpotri is part of W).")
        elif r["target"].startswith("(c)"):
            split = c.get("split_increment", False)
            solves = 1 if split else 2
            rest = c["increment_s"] - solves * c["backsolve_s"] - c["contact_solve_s"]
            how = ("one back-substitution split around the contact solve (condensation "
                   "before, expansion after"
                   if split else "two back-substitutions (")
            out.append(
                f"* {c['name']}, (c)/(d) = {r['value']:.2f}: an increment is {how}"
                f"{'; ' if split else ''}{solves * c['backsolve_s'] * 1e3:.0f} ms), the local "
                f"contact solve with its products by F* ({c['contact_solve_s'] * 1e3:.0f} ms) "
                f"and the rest (load assembly, "
                f"gathers, write-back: {rest * 1e3:.0f} ms by difference"
                + (", i.e. within the timings' noise" if rest < 0 else "") + ").")
        else:
            out.append(f"* {c['name']}, peak memory ratio {r['value']:.2f}: contact phase "
                       f"{c['contact_peak_mb']:.0f} MB against {c['factorization_peak_mb']:.0f} MB"
                       f"; dense F* and W {con['dense_mb']:.0f} MB.")
    return out


def _package_version(res: dict, key: str) -> str:
    """The Debian version of the first loaded library whose file name holds ``key``."""
    for lib in res.get("libraries", []):
        if key in lib["path"].rsplit("/", 1)[-1] and lib["package"]:
            return lib["package"].split()[-1]
    return "?"


def markdown(res: dict) -> str:
    m, v = res["machine"], res.get("versions", {})
    fc = res["flexcontact"]
    libs = "\n".join(f"  - `{x['path']}`" + (f" ({x['package']})" if x["package"] else "")
                     for x in res.get("libraries", []))
    lines = [
        "# Bench results",
        "",
        f"Written by `{res['command']}` (bench/README.md), started {res['started_utc']} UTC, "
        f"{res['total_s'] / 60:.1f} min in all. **Every ratio below comes from this one run** "
        "on a shared machine: the times carry its noise (load average "
        f"{m['load_average_at_start'][0]:.1f} at the start); the ratios of the same case are "
        "measured minutes apart in one process.",
        "",
        f"* Machine: {m['cpu']}, {m['cores']} cores ({m['usable_cores']} usable), "
        f"{m['memory_gb']} GB",
        f"* flexcontact {v.get('flexcontact', '?')}, commit `{fc['commit'][:12]}`"
        + (" (with uncommitted changes)" if fc["dirty"] else ""),
        f"* DOLFINx {v.get('dolfinx', '?')}, PETSc {v.get('petsc', '?')}, MUMPS "
        f"{_package_version(res, 'mumps')}, OpenBLAS/BLAS {_package_version(res, 'blas')}, "
        f"petsc4py {v.get('petsc4py', '?')}, Python {v.get('python', '?')}",
        "* Libraries loaded by the cases (MUMPS, METIS, PETSc, BLAS/LAPACK):",
        libs,
        "",
        "## Definitions",
        "",
        "Each case is one process on a Hertz mesh (`meshes/hertz2d.py` plane strain, "
        "`meshes/hertz3d.py` quarter model; steel on steel, μ = 0.3), one serial rank. "
        "(a) one plain MUMPS factorization of K (analysis with flexcontact's ordering, "
        "`ordering=\"auto\"`, and numerical factorization, no Schur complement); (b) F* "
        "(the factorization with the Schur complement on the contact DOFs, its extraction "
        "and the Cholesky factor of each body's block) and W = B F* Bᵀ (per body by the "
        "cheaper of the inverse and the triangular route, docs/architecture.md §7); (c) one load increment after set-up (median of "
        "increments 2–4 of a ramp of the approach to a²/R, no output written); (d) one "
        "back-substitution with the stored factor (median of one before each increment and 5 "
        "after them); local solve: the kernel's "
        "contact step alone inside (c). Peak memory: the process's peak resident set from "
        "the start of each phase (linear solve; contact set-up and increments), the freed "
        "heap handed back before each, meshing "
        "excluded. Contact solve / linear solve: (set-up + first increment) over assembly + "
        "factorization + load + one back-substitution of the same mesh without contact "
        "(the method's limit is 1).",
        "",
        "## Cases",
        "",
        *_case_table(res["cases"]),
        "",
        "Where the time goes:",
        "",
        *_split_table(res["cases"]),
        "",
        "## Targets (issue 18, item 2) on the large meshes",
        "",
        *_target_table(res.get("targets", [])),
        "",
    ]
    why = _why(res.get("targets", []), res["cases"])
    if why:
        lines += ["Where each miss comes from (same run):", "", *why, ""]
    lines += mpi_section(res.get("mpi"))
    if res.get("notes"):
        lines += ["## Notes", "", *res["notes"], ""]
    failed = [c for c in res["cases"] if "error" in c]
    for c in failed:
        lines += [f"Case {c['name']} failed ({c['error']}):", "", "```",
                  c.get("log_tail", ""), "```", ""]
    return "\n".join(lines)
