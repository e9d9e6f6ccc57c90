"""flexcontact against real peers: same mesh, same load, same accuracy; total times.

    /usr/bin/python3 bench/peers.py [--full]     # writes bench/peers.json, prints a table
    /usr/bin/python3 bench/peers.py --cases hertz3d    # these cases again, merged into it

Peers (see bench/README.md):

* GetFEM (Debian's python3-getfem), nodal Alart–Curnier contact between the two bodies of
  the Hertz meshes (demos/hertz2d.py, demos/hertz3d.py), frictionless in one load step and
  with friction μ = 0.3 over 20 increments (bench/peers_getfem.py); skipped, and said so,
  where GetFEM is not installed;
* a penalty contact against a rigid obstacle written by hand in UFL and solved by PETSc
  SNES inside DOLFINx, frictionless, against flexcontact's rigid targets on the meshes of
  demos/rigid_cylinder.py and demos/sphere_on_plane.py (bench/peers_snes.py);
* one plain linear-elastic solve on each mesh (assembly, MUMPS factorization,
  back-substitution), the floor of any contact solve.

Each case: the approach δ that gives Hertz's load for a = R/10 is found first (a trial
flexcontact run, which also compiles the forms); then every code solves from the mesh to
the answer at that δ, timed whole. a, p0 and P are measured the same way for all
(bench/peers_cases.py) and compared with flexcontact's: a, p0 within 0.5 %, P within 1 %.
Serial only.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import peers_flexcontact as pf  # noqa: E402
import peers_getfem as pg  # noqa: E402
import peers_snes as ps  # noqa: E402
from peers_cases import MU_FRICTION, agreement, build_case, measure  # noqa: E402
from flexcontact.info import describe  # noqa: E402

INCREMENTS = 20
# (dim, kind, refine, loadings): the 3D Hertz mesh at about 60k DOFs (hertz3d --refine 1).
DEFAULT = [(2, "hertz", 1, ("single", "incremental")), (2, "rigid", 1, ("single", "incremental")),
           (3, "hertz", 1, ("single", "incremental")), (3, "rigid", 1, ("single", "incremental"))]
FULL = [(2, "hertz", 3, ("single", "incremental")), (2, "rigid", 3, ("single", "incremental")),
        (3, "hertz", 1, ("single", "incremental")), (3, "rigid", 1, ("single", "incremental"))]


def _entry(case, out, ref=None) -> dict:
    m = measure(case, out["x"], out["fn"])
    e = {**m, "time_s": out["time_s"],
         **{k: v for k, v in out.items() if k not in ("x", "fn", "time_s")}}
    if ref is not None:
        e["vs_flexcontact"] = agreement(ref, m)
    return e


def _peer(case, ref, solve, *args) -> dict:
    """A peer's record; a peer that does not converge is recorded as such, not fatal."""
    try:
        return _entry(case, solve(case, *args), ref)
    except RuntimeError as e:
        return {"skipped": f"did not converge: {e}"}


def run_case(dim: int, kind: str, refine: int, loadings) -> dict:
    """Every code on one mesh; returns the JSON record of the case."""
    t0 = time.perf_counter()
    started = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    load = os.getloadavg()[0]
    case = build_case(dim, kind, refine)
    delta = pf.calibrate(case)
    rec = {"case": case.name, "dim": dim, "kind": kind, "refine": refine, "dofs": case.dofs(),
           "slave_nodes": len(case.areas), "h_contact_m": case.geo["h_contact"],
           "approach_m": delta, "started": started, "loadings": {}}
    rec["linear_solve"] = {f: pf.linear_solve(case, delta, f) for f in ("lu", "cholesky")}
    rec["linear_solve_s"] = min(v["time_s"] for v in rec["linear_solve"].values())
    for loading in loadings:
        n = 1 if loading == "single" else INCREMENTS
        mu = 0.0 if (loading == "single" or kind == "rigid") else MU_FRICTION
        fc = pf.solve(case, delta, n, mu)
        ref = measure(case, fc["x"], fc["fn"])
        row = {"increments": n, "mu": mu, "flexcontact": _entry(case, fc)}
        if kind == "hertz":
            if pg.available():
                row["getfem"] = _peer(case, ref, pg.solve, delta, n, mu)
            else:
                row["getfem"] = {"skipped": "python3-getfem is not installed"}
        else:
            row["snes_penalty"] = _peer(case, ref, ps.solve, delta, n)
        for name in ("getfem", "snes_penalty"):
            if name in row and "time_s" in row[name]:
                row[name]["time_over_flexcontact"] = row[name]["time_s"] / fc["time_s"]
        rec["loadings"][loading] = row
    single = rec["loadings"].get("single")
    if single:
        rec["flexcontact_over_linear_solve"] = (single["flexcontact"]["time_s"]
                                                / rec["linear_solve_s"])
    rec["case_s"] = time.perf_counter() - t0
    rec["load_average"] = [load, os.getloadavg()[0]]
    return rec


def machine() -> dict:
    """flexcontact.info's record of the stack, plus the processor and GetFEM's version."""
    info = dict(describe(), processor=platform.processor())
    if pg.available():
        info["getfem"] = getattr(pg.gf, "__version__", "5.4 (Debian python3-getfem)")
    return info


def run(full: bool = False, names=None) -> dict:
    """Run every case (the default set, or the larger ``full`` one; only those named in
    ``names``, e.g. ["hertz3d"], if given) and return the record that ``bench/peers.json``
    holds."""
    t0 = time.perf_counter()
    chosen = [c for c in (FULL if full else DEFAULT)
              if names is None or f"{c[1]}{c[0]}d" in names]
    if names is not None and not chosen:
        raise ValueError(f"--cases {' '.join(names)}: no such case in the "
                         f"{'full' if full else 'default'} set (hertz2d, rigid2d, hertz3d, "
                         "rigid3d)")
    cases = [run_case(*c) for c in chosen]
    return {"machine": machine(), "full": full, "increments": INCREMENTS,
            "mu_friction": MU_FRICTION, "snes_kappa_factor_E_over_h": ps.KAPPA_FACTOR,
            "getfem_available": pg.available(), "cases": cases,
            "total_s": time.perf_counter() - t0}


def table(result: dict) -> str:
    lines = [f"{'case':9} {'DOFs':>7} {'loading':12} {'code':13} {'time s':>8} {'/flexc':>7} "
             f"{'a mm':>8} {'p0 GPa':>8} {'P':>11} {'Δa %':>7} {'Δp0 %':>7} {'ΔP %':>7}"]
    for c in result["cases"]:
        for loading, row in c["loadings"].items():
            for code in ("flexcontact", "getfem", "snes_penalty"):
                e = row.get(code)
                if e is None:
                    continue
                if "skipped" in e:
                    lines.append(f"{c['case']:9} {c['dofs']:7d} {loading:12} {code:13} "
                                 f"skipped: {e['skipped']}")
                    continue
                v = e.get("vs_flexcontact", {})
                d = [f"{100 * v[k]:7.3f}" if k in v else f"{'':7}"
                     for k in ("a_rel", "p0_rel", "P_rel")]
                lines.append(f"{c['case']:9} {c['dofs']:7d} {loading:12} {code:13} "
                             f"{e['time_s']:8.2f} {e.get('time_over_flexcontact', 1.0):7.2f} "
                             f"{1e3 * e['a_m']:8.4f} {1e-9 * e['p0_Pa']:8.4f} {e['P']:11.4e} "
                             + " ".join(d))
        if "flexcontact_over_linear_solve" in c:
            lines.append(f"{c['case']:9} {c['dofs']:7d} flexcontact single step / one linear "
                         f"solve: "
                         f"{c['flexcontact_over_linear_solve']:.2f}"
                         f" (LU {c['linear_solve']['lu']['time_s']:.2f} s, Cholesky "
                         f"{c['linear_solve']['cholesky']['time_s']:.2f} s)")
    return "\n".join(lines)


def merge(old: dict, new: dict) -> dict:
    """``old`` (a peers.json) with the cases of ``new`` replaced or added; ``runs`` lists
    which cases each run wrote and how long it took."""
    fresh = {c["case"]: c for c in new["cases"]}
    runs = old.get("runs") or [{"cases": [c["case"] for c in old["cases"]],
                                "full": old.get("full", False), "total_s": old["total_s"]}]
    cases = [fresh.pop(c["case"], c) for c in old["cases"]] + list(fresh.values())
    runs = runs + [{"cases": [c["case"] for c in new["cases"]], "full": new["full"],
                    "total_s": new["total_s"]}]
    return {**new, "cases": cases, "runs": runs}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--full", action="store_true",
                        help="the 2D meshes at --refine 3")
    parser.add_argument("--out", default=str(HERE / "peers.json"), help="JSON file to write")
    parser.add_argument("--cases", nargs="+", metavar="NAME",
                        help="only these cases (hertz2d rigid2d hertz3d rigid3d), merged into "
                             "the existing --out file")
    args = parser.parse_args()
    if not pg.available():
        print("GetFEM (python3-getfem) is missing: its comparisons are skipped", flush=True)
    result = run(args.full, args.cases)
    out = Path(args.out)
    if args.cases and out.exists():
        result = merge(json.loads(out.read_text()), result)
    out.write_text(json.dumps(result, indent=1, default=float))
    print(table(result))
    print(f"written {args.out} ({result['total_s']:.0f} s)")


if __name__ == "__main__":
    main()
