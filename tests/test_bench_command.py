"""The bench command (bench/run.py) on its tiny case: the structure of results.json, its
ratios as the quotients of the recorded times, the case's sizes from the mesh's formulas.
No time is asserted (speed targets live in bench/)."""
import importlib.util
import json
import math
import sys

from conftest import ROOT


def _run_module():
    spec = importlib.util.spec_from_file_location("bench_run", ROOT / "bench" / "run.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_run"] = module
    spec.loader.exec_module(module)
    return module


def test_bench_command_tiny(tmp_path):
    run = _run_module()
    run.main(["--cases", "2d_tiny", "--out", str(tmp_path)])
    res = json.loads((tmp_path / "results.json").read_text())
    assert (tmp_path / "RESULTS.md").read_text().startswith("# Bench results")
    for key in ("cpu", "cores", "memory_gb"):
        assert res["machine"][key]
    assert len(res["flexcontact"]["commit"]) == 40
    assert {"dolfinx", "petsc"} <= set(res["versions"])
    assert any("mumps" in lib["path"] for lib in res["libraries"])
    (case,) = res["cases"]
    assert "error" not in case, case.get("log_tail")
    # hertz2d: zone half-width w = 1.25 a, spacing h = a/10 → n = ceil(w/h) segments a side,
    # 2n + 1 nodes on each surface, one pair per slave node, 2 DOFs per node on both.
    n = math.ceil(1.25 * 10 - 1e-9)
    assert case["pairs"] == 2 * n + 1
    assert case["contact_dofs"] == 2 * 2 * (2 * n + 1)
    rel = 1e-12
    assert math.isclose(case["fstar_w_over_factorization"],
                        case["fstar_w_s"] / case["factorization_s"], rel_tol=rel)
    assert math.isclose(case["step_over_backsolve"],
                        case["increment_s"] / case["backsolve_s"], rel_tol=rel)
    assert math.isclose(case["memory_over_factorization"],
                        case["contact_peak_mb"] / case["factorization_peak_mb"], rel_tol=rel)
    con = case["contact"]
    assert math.isclose(case["fstar_w_s"], con["flexibility_s"] + con["delassus_s"], rel_tol=rel)
    # the approach grows with every increment: so does the contact force
    forces = [r["normal_force"] for r in con["increments"]]
    assert len(forces) == 4 and all(b > a > 0 for a, b in zip(forces, forces[1:]))
    assert all(r["residual"] < 1e-8 for r in con["increments"])
    assert case["linear"]["ordering"] == con["ordering"]  # the same ordering for (a) and (b)


def test_bench_mpi_section_tiny(tmp_path):
    """`--mpi-only` on the tiny 2D case: serial and `mpirun -n 2` give the same answer (u and
    pressure at every node, the normal forces) to round-off; the speed-ups are the
    quotients of the recorded phase times."""
    run = _run_module()
    run.main(["--mpi-only", "--mpi-cases", "2d_tiny", "--out", str(tmp_path)])
    res = json.loads((tmp_path / "results.json").read_text())
    assert res["cases"] == []
    (row,) = res["mpi"]["cases"]
    assert "error" not in row, row.get("error")
    assert row["serial"]["ranks"] == 1 and row["np2"]["ranks"] == 2
    assert row["np2"]["contact"]["method"] == "schur"
    for key in ("u", "pressure", "normal_force"):
        assert row["max_rel_diff"][key] is not None and row["max_rel_diff"][key] < 1e-10, key
    for p in row["phases"]:
        assert math.isclose(p["speedup"], p["serial_s"] / p["np2_s"], rel_tol=1e-12)
    # the run (set-up + 10 increments) from the same phase times
    t = {p["key"]: p for p in row["phases"]}
    one = t["setup_s"]["serial_s"] + 10 * t["increment_s"]["serial_s"]
    two = t["setup_s"]["np2_s"] + 10 * t["increment_s"]["np2_s"]
    assert math.isclose(run.report.run_speedup(row), one / two, rel_tol=1e-12)
    text = (tmp_path / "RESULTS.md").read_text()
    assert "Serial against `mpirun -n 2`" in text
    assert "run (set-up + 10 increments) speed-up" in text
