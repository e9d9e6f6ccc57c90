"""A dam model file (dam/model_file.py, `python3 -m flexcontact dam prepare / what-if`): the
dam factored once, saved, and a scenario answered in a new process without factoring it —
the same answer as the evaluator that factored it (1e-10; measured 1e-14). Bad models are
refused by name and nothing is overwritten."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from mpi4py import MPI

from conftest import ROOT
from flexcontact.dam import DamScenario
from flexcontact.dam import model_file
from flexcontact.dam.reuse import ScenarioEvaluator, sweep_time_step_s
from flexcontact.errors import InputError, SavedFileError

BASE = DamScenario(mesh_size_far_m=6.0, mesh_size_impact_m=0.4)
LEVELS = (BASE.water_level_m - 1.0, BASE.water_level_m)
DT = sweep_time_step_s([BASE])
ASKED = {"log_speed_m_s": 2.5, "log_pitch_deg": 12.0, "water_level_m": 26.5}
OUTPUTS = ("peak_force_N_per_m", "peak_force_filtered_N_per_m", "impulse_N_s_per_m",
           "heel_stress_impact_Pa", "toe_stress_impact_Pa", "peak_tensile_stress_Pa",
           "contact_duration_s", "log_velocity_after_m_s")


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    path = tmp_path_factory.mktemp("models") / "dam"
    manifest = model_file.prepare(BASE, DT, LEVELS, path, progress=lambda *a: None)
    return path, manifest


def cli(*args):
    env = dict(os.environ, PYTHONPATH=str(ROOT / "dolfinx_ext" / "python"))
    return subprocess.run([sys.executable, "-m", "flexcontact", "dam", *map(str, args)],
                          capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)


def what_if_json(path, asked: dict) -> dict:
    """The --json answer of `dam what-if` in a new process, asked ``asked`` as options."""
    r = cli("what-if", path, *[a for k, v in asked.items()
                               for a in ("--" + k.replace("_", "-"), v)], "--json")
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_what_if_in_a_new_process_equals_the_factoring_evaluator(model):
    path, manifest = model
    assert manifest["counts"]["factorizations"] == {"dam_stage1": 1, "dam_stage2": 1, "log": 0}
    # The 2D section's Ŵ is kept as the split factor's arrays, K as MUMPS's files.
    assert manifest["factors"]["stage2"]["kind"] == model_file.SPLIT
    assert "kind" not in manifest["factors"]["stage1"]
    got = what_if_json(path, ASKED)
    ref = ScenarioEvaluator(BASE, DT, LEVELS, MPI.COMM_SELF).evaluate(BASE.replace(**ASKED))
    for key in OUTPUTS:
        assert got["outputs"][key] == pytest.approx(ref[key], rel=1e-10), key
    c = got["counts"]
    # Nothing of the dam factored: both factors restored, the response functions read.
    assert c["factorizations"]["dam_stage1"] == c["factorizations"]["dam_stage2"] == 0
    assert c["restorations"] == {"dam_stage1": 1, "dam_stage2": 1}
    assert c["back_substitutions"]["dam_response"] == 0
    assert c["factorizations"]["log"] == 1          # the log is built on the spot
    # 26.5 m is inside the range but not stored: one back-substitution of K.
    assert c["back_substitutions"]["dam_stage1"] == 1


def test_a_scenario_outside_the_model_is_refused_by_name(model):
    path, _ = model
    r = cli("what-if", path, "--water-level-m", 20.0)
    assert r.returncode == 2 and "water_level_m=20.0" in r.stderr and "range" in r.stderr
    ev = model_file.load(path)
    with pytest.raises(InputError, match="dam_height_m"):
        ev.check(BASE.replace(dam_height_m=31.0))


def _copy(path, dest):
    dest.mkdir()
    for p in path.iterdir():
        (dest / p.name).write_bytes(p.read_bytes())
    return dest


@pytest.mark.parametrize("damage, words", [
    ("truncate", "truncated"), ("alter", "altered"), ("remove", "missing"),
    ("format", "format 99"), ("inputs", "edited"), ("manifest", "not readable JSON")])
def test_a_damaged_model_is_refused_by_name(model, tmp_path, damage, words):
    path, _ = model
    d = _copy(path, tmp_path / "m")
    arrays = d / "arrays.npz"
    manifest = json.loads((d / "manifest.json").read_text())
    if damage == "truncate":
        arrays.write_bytes(arrays.read_bytes()[:100])
    elif damage == "alter":
        data = bytearray(arrays.read_bytes())
        data[-10] ^= 1
        arrays.write_bytes(bytes(data))
    elif damage == "remove":
        arrays.unlink()
    elif damage == "format":
        manifest["format"] = 99
    elif damage == "inputs":
        manifest["inputs"]["dt_s"] *= 2
    elif damage == "manifest":
        (d / "manifest.json").write_text('{"format": 1, "inpu')
    if damage in ("format", "inputs"):
        (d / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(SavedFileError, match=words):
        model_file.load(d)
    with pytest.raises(SavedFileError, match="not a dam model"):
        model_file.load(tmp_path)


def test_prepare_is_atomic(model, tmp_path, monkeypatch):
    """A prepare that fails leaves the previous model as it was and no partial directory;
    one that succeeds replaces it whole."""
    path, _ = model
    d = _copy(path, tmp_path / "m")
    before = {p.name: p.read_bytes() for p in d.iterdir()}

    def fail(*a, **k):
        raise RuntimeError("disk full")
    monkeypatch.setattr(model_file.saved_factor, "save_factor", fail)
    with pytest.raises(RuntimeError, match="disk full"):
        model_file.prepare(BASE, DT, LEVELS, d, progress=lambda *a: None)
    assert {p.name: p.read_bytes() for p in d.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m"]


def test_inputs_that_changed_are_named(model):
    _, manifest = model
    model_file.check_inputs(manifest, BASE, DT)
    with pytest.raises(SavedFileError, match="crest_width_m=6.0"):
        model_file.check_inputs(manifest, BASE.replace(crest_width_m=6.0))
    with pytest.raises(SavedFileError, match="dt_s"):
        model_file.check_inputs(manifest, BASE, DT / 2)


BASE_3D = DamScenario(dim=3, mesh_size_far_m=6.0, mesh_size_impact_m=0.4)
ASKED_3D = {"log_speed_m_s": 3.0, "log_yaw_deg": 10.0, "log_across_m": 6.5}


def test_a_3d_model_answers_in_a_new_process_as_the_factoring_evaluator(tmp_path):
    """The 3D block: prepare (keeping the base's log), then what-if in a new process with a
    yaw and a place across the block; the same answer as the evaluator that factored the
    dam and the log (1e-10), the dam's factors and the log's restored, none made, Ŵ with its
    Schur split; a log leaving the saved patch is refused by name."""
    dt = sweep_time_step_s([BASE_3D])
    levels = (BASE_3D.water_level_m, BASE_3D.water_level_m)
    path = tmp_path / "dam3d"
    manifest = model_file.prepare(BASE_3D, dt, levels, path, lags=0, progress=lambda *a: None,
                                  logs=[BASE_3D])
    assert manifest["inputs"]["patch_y_m"][0] > 0.0
    assert manifest["factors"]["stage2"]["kind"] == "schur"  # MUMPS's files, split kept
    assert len(manifest["logs"]) == 1
    got = what_if_json(path, ASKED_3D)
    own = ScenarioEvaluator(BASE_3D, dt, levels, MPI.COMM_SELF)
    ref = own.evaluate(BASE_3D.replace(**ASKED_3D))
    for key in OUTPUTS:
        assert got["outputs"][key] == pytest.approx(ref[key], rel=1e-10), key
    c = got["counts"]
    assert c["factorizations"] == {"dam_stage1": 0, "dam_stage2": 0, "log": 0}
    assert c["restorations"] == {"dam_stage1": 1, "dam_stage2": 1, "log": 1}
    # The restored Ŵ kept its Schur split: a contact step is one condensation and one
    # expansion of the dam, as with its own factor, not two whole solves.
    assert c["back_substitutions"]["dam_stage2"] == own.counts()["back_substitutions"]["dam_stage2"]
    r = cli("what-if", path, "--log-across-m", 13.0)
    assert r.returncode == 2 and "face patch" in r.stderr, r.stderr


def test_a_format_4_model_whose_log_is_held_dense_still_loads(tmp_path):
    """A small log is kept as its sparse split factor (format 5); a model of format 4 held
    it as dense blocks, and still loads and answers the same (1e-10: two factorizations
    of one SPD matrix)."""
    from flexcontact.dense_factor import DenseFactor
    path = tmp_path / "dam"
    manifest = model_file.prepare(BASE, DT, LEVELS, path, lags=0, progress=lambda *a: None,
                                  logs=[BASE])
    (entry,) = manifest["logs"]
    assert entry["kind"] == model_file.SPLIT
    now = what_if_json(path, ASKED)
    # The same model as format 4 wrote it: the log's dense blocks in arrays.npz, no kind.
    p = entry["prefix"] + "f_"
    own = ScenarioEvaluator(BASE, DT, LEVELS, MPI.COMM_SELF).logs.get(BASE)
    with np.load(path / "arrays.npz") as z:
        arrays = {k: z[k] for k in z.files if not k.startswith(p)}
    arrays.update(DenseFactor(own.W_hat, own.front_dofs).arrays(p))
    np.savez(path / "arrays.npz", **arrays)
    old = json.loads((path / "manifest.json").read_text())
    old["format"] = 4
    del old["logs"][0]["kind"]
    old["files"]["arrays.npz"] = model_file._file_entry(path / "arrays.npz")
    (path / "manifest.json").write_text(json.dumps(old))
    got = what_if_json(path, ASKED)
    assert got["counts"]["factorizations"]["log"] == 0
    assert got["counts"]["restorations"]["log"] == now["counts"]["restorations"]["log"] == 1
    for key in OUTPUTS:
        assert got["outputs"][key] == pytest.approx(now["outputs"][key], rel=1e-10), key


BASE_FINE_LOG = DamScenario(mesh_size_far_m=6.0, mesh_size_impact_m=0.4,
                            mesh_size_contact_m=0.0125, contact_zone_m=0.35,
                            log_end_crushes=True)


def test_a_large_log_is_kept_and_restored_when_asked(tmp_path):
    """A log above the dense limit (its crushed patch refined: 1,980 DOFs) is kept as its
    own arrays, MUMPS's Schur factor and its plain factor (its flight after the contact): a
    what-if in a new process restores both instead of meshing and factoring it, and answers
    as the evaluator that factored it (1e-10). Flying on the Schur factor's full solves
    instead (a format-3 model, which still loads) gives the same answer (1e-10). A model
    whose log factor file is gone is refused naming the file."""
    dt = sweep_time_step_s([BASE_FINE_LOG])
    levels = (BASE_FINE_LOG.water_level_m,) * 2
    path = tmp_path / "dam"
    manifest = model_file.prepare(BASE_FINE_LOG, dt, levels, path, progress=lambda *a: None,
                                  logs=[BASE_FINE_LOG])
    (entry,) = manifest["logs"]
    assert entry["factor"]["kind"] == "schur" and entry["arrays"] in manifest["files"]
    assert "kind" not in entry["flight_factor"]  # a plain factor
    assert manifest["counts"]["factorizations"]["log"] == 2  # counted where they were made
    asked = {"log_speed_m_s": 3.0, "log_pitch_deg": 12.0}
    got = what_if_json(path, asked)
    own = ScenarioEvaluator(BASE_FINE_LOG, dt, levels, MPI.COMM_SELF)
    ref = own.evaluate(BASE_FINE_LOG.replace(**asked))
    assert own.logs.get(BASE_FINE_LOG).factor_kind == "mumps_schur"
    for key in OUTPUTS:
        assert got["outputs"][key] == pytest.approx(ref[key], rel=1e-10), key
    c = got["counts"]
    assert c["factorizations"]["log"] == 0 and c["restorations"]["log"] == 2
    # The flight after the contact on the Schur factor's full solves: the same answer.
    assert ref["dam_steps_convolved"] > 0  # the log flew alone after the contact
    log = own.logs.get(BASE_FINE_LOG)
    solves = log.back_substitutions
    log.flight_factor = None
    schur = own.evaluate(BASE_FINE_LOG.replace(**asked))
    assert log.back_substitutions - solves == ref["log_back_substitutions"]
    for key in OUTPUTS:
        assert schur[key] == pytest.approx(ref[key], rel=1e-10), key
    # A format-3 model (no plain log factor) still loads, and its log flies that way.
    mpath = path / "manifest.json"
    now = mpath.read_text()
    old = json.loads(now)
    old["format"] = 3
    del old["logs"][0]["flight_factor"]
    mpath.write_text(json.dumps(old))
    got3 = what_if_json(path, asked)
    assert got3["counts"]["restorations"]["log"] == 1
    for key in OUTPUTS:
        assert got3["outputs"][key] == pytest.approx(ref[key], rel=1e-10), key
    mpath.write_text(now)
    # A scenario of another log reads none of the large log's files.
    ev = model_file.load(path)
    ev.evaluate(BASE_FINE_LOG.replace(log_length_m=8.0))
    assert ev.counts()["restorations"].get("log", 0) == 0
    assert ev.counts()["factorizations"]["log"] == 2  # its Schur and its plain factor
    # Its files are hashed when read, not at every load: an altered arrays file is named
    # by the scenario that reads it, while another log's scenario still answers.
    arrays = path / entry["arrays"]
    data = bytearray(arrays.read_bytes())
    data[-10] ^= 1
    arrays.write_bytes(bytes(data))
    ev = model_file.load(path)
    ev.evaluate(BASE_FINE_LOG.replace(log_length_m=8.0))
    with pytest.raises(SavedFileError, match=f"{entry['arrays']}: its SHA-256 differs"):
        ev.evaluate(BASE_FINE_LOG.replace(**asked))
    lost = next(n for n in entry["factor"]["files"] if n.endswith(".mumps"))
    (path / lost).unlink()
    with pytest.raises(SavedFileError, match=f"{lost}: missing"):
        model_file.load(path)


def test_every_what_if_option_says_what_it_is_and_its_unit():
    """`dam what-if --help` explains each scenario input it takes, and each is a field of
    DamScenario or the wood's density (a renamed field would otherwise leave a dead
    option)."""
    import dataclasses
    from flexcontact.dam.cli import WHAT_IF_HELP, WHAT_IF_INPUTS
    assert set(WHAT_IF_HELP) == set(WHAT_IF_INPUTS)
    fields = {f.name for f in dataclasses.fields(DamScenario)}
    assert set(WHAT_IF_INPUTS) - fields <= {"wood_density_kg_m3"}  # DamScenario.wood's
    r = cli("what-if", "--help")
    assert r.returncode == 0, r.stderr
    text = " ".join(r.stdout.split())   # argparse wraps the help lines
    for name in WHAT_IF_INPUTS:
        assert "--" + name.replace("_", "-") in text, name
        assert " ".join(WHAT_IF_HELP[name].split()) in text, name
    for unit in ("m/s", "degrees", "kg/m³", ", Pa", ", m"):
        assert unit in text, unit
