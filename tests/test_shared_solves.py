"""Runs that share their solves (flexcontact/shared_solves.py): several generators driven in
lockstep give each what it gets alone (round-off: MUMPS's blocked kernels for several
columns), with one call per factor and round; a run that fails between its condensation and
its expansion leaves the others right; a factor holding one pending condensation is never
shared. Then the dam evaluator's evaluate_many on the 3D block against evaluate, one
scenario at a time."""
import numpy as np
import pytest
from petsc4py import PETSc

from test_saved_factor import SCHUR_DOFS, matrix, vec
from flexcontact import _cpp
from flexcontact.errors import InputError
from flexcontact.shared_solves import (Condense, Expand, Solve, Together, serve_alone,
                                       serve_together)
from flexcontact.split_factor import SplitFactor


@pytest.fixture(scope="module")
def factors():
    A, M = matrix(shift=0.05)
    _, schur, _ = _cpp.flexibility(M, SCHUR_DOFS, "schur", "auto", False, False)
    plain = _cpp.SavedFactor(M)
    return A, schur, plain, M


def run(schur, plain, n, seed, fail=False):
    """Two coupled steps of a body on the Schur factor (condense, then expand the contact
    values a kernel would give: here half the condensed ones), a plain solve between, and
    a second body's plain solve beside the first step's condensation."""
    rng = np.random.default_rng(seed)
    y1, y2, z = vec(np.zeros(n)), vec(np.zeros(n)), vec(np.zeros(n))
    c1, _ = yield [Condense(schur, vec(rng.standard_normal(n))),
                   Solve(plain, vec(rng.standard_normal(n)), z)]
    if fail:
        raise ValueError(f"run {seed} failed between its condensation and its expansion")
    yield [Expand(schur, 0.5 * c1, y1)]
    yield [Solve(plain, vec(rng.standard_normal(n)), y2)]
    (c2,) = yield [Condense(schur, vec(y1.array + y2.array))]
    y3 = vec(np.zeros(n))
    yield [Expand(schur, 0.25 * c2, y3)]
    return np.concatenate([c1, z.array, y1.array, y2.array, c2, y3.array])


def test_runs_together_get_what_they_get_alone_with_one_call_per_factor(factors):
    A, schur, plain, _ = factors
    n = A.shape[0]
    alone = [serve_alone(run(schur, plain, n, seed)) for seed in range(3)]
    stats = Together()
    together = serve_together([run(schur, plain, n, seed) for seed in range(3)], stats)
    for a, t in zip(alone, together):
        assert np.abs(t - a).max() <= 1e-13 * np.abs(a).max()
    assert stats.calls == {"condense": 2, "expand": 2, "solve": 2, "product": 0}
    assert stats.columns == {"condense": 6, "expand": 6, "solve": 6, "product": 0}


def with_block(schur, block, n, seed):
    """A condensation that asks for its product with the body's F̂ block as well."""
    rng = np.random.default_rng(seed)
    y = vec(np.zeros(n))
    ((c, Fc),) = yield [Condense(schur, vec(rng.standard_normal(n)), block)]
    yield [Expand(schur, c, y)]
    return c, Fc, y.array.copy()


def test_runs_sharing_a_block_share_its_product(factors):
    A, schur, _, _ = factors
    n = A.shape[0]
    rng = np.random.default_rng(4)
    G = rng.standard_normal((SCHUR_DOFS.size,) * 2)
    block = _cpp.DenseBlock(np.asfortranarray(G @ G.T))
    alone = [serve_alone(with_block(schur, block, n, seed)) for seed in range(3)]
    stats = Together()
    together = serve_together([with_block(schur, block, n, seed) for seed in range(3)], stats)
    for (c, Fc, y), (ct, Fct, yt) in zip(alone, together):
        # F̂ b̃ by the block, alone and with the others' columns
        assert np.abs(Fc - (G @ G.T) @ c).max() <= 1e-12 * np.abs(Fc).max()
        assert np.abs(Fct - Fc).max() <= 1e-12 * np.abs(Fc).max()
        assert np.abs(yt - y).max() <= 1e-12 * np.abs(y).max()
    assert stats.calls["product"] == 1 and stats.columns["product"] == 3


def test_a_block_reads_its_array_in_place():
    """A model's W_face or W_front is hundreds of MB: the block reads a Fortran-ordered float64
    array where it is, makes it read-only and keeps it alive; any other array is copied once;
    a bad shape is named."""
    G = np.random.default_rng(5).standard_normal((40, 40))
    F = np.asfortranarray(G @ G.T)
    block = _cpp.DenseBlock(F)
    view = block.matrix
    assert np.shares_memory(view, F) and not F.flags.writeable and not view.flags.writeable
    X = np.zeros((40, 2))
    X[3, 0], X[:, 1] = 1.0, 0.5
    expected = (G @ G.T) @ X
    del F, block
    assert np.abs(view - G @ G.T).max() == 0.0  # the view keeps block and values alive
    C = np.ascontiguousarray(G)
    copied = _cpp.DenseBlock(C)
    assert not np.shares_memory(copied.matrix, C) and C.flags.writeable
    assert np.array_equal(copied.matrix, C) and not copied.symmetric
    assert np.abs(_cpp.DenseBlock(view).product(X) - expected).max() <= 1e-12 * np.abs(expected).max()
    with pytest.raises(InputError, match=r"square 2-D array, got shape \(3, 4\)"):
        _cpp.DenseBlock(np.zeros((3, 4)))


def test_a_run_failing_between_condensation_and_expansion_leaves_the_others_right(factors):
    A, schur, plain, _ = factors
    n = A.shape[0]
    alone = [serve_alone(run(schur, plain, n, seed)) for seed in (0, 2)]
    out = serve_together([run(schur, plain, n, 0), run(schur, plain, n, 1, fail=True),
                          run(schur, plain, n, 2)])
    assert isinstance(out[1], ValueError) and "run 1 failed" in str(out[1])
    for a, t in zip(alone, (out[0], out[2])):
        assert np.abs(t - a).max() <= 1e-13 * np.abs(a).max()


def test_a_factor_with_one_pending_condensation_is_not_shared(factors):
    A, _, plain, M = factors
    n = A.shape[0]
    split = SplitFactor(M, SCHUR_DOFS)
    assert np.abs(serve_together([run(split, plain, n, 0)])[0]
                  - serve_alone(run(split, plain, n, 0))).max() == 0.0
    with pytest.raises(RuntimeError, match="2 runs condense on one factor that holds a single "
                                           "pending condensation"):
        serve_together([run(split, plain, n, 0), run(split, plain, n, 1)])


# ---- the 3D dam block: evaluate_many against evaluate ----------------------------------------

SHARED_TOL = 1e-6
"""Relative: the same runs with the dam's and the log's solves made for several scenarios at
once, which differ by round-off, amplified where a step's index set or a pair at its cap
comes out otherwise. Measured here: 1.6e-9 at most (the log's final rotation, a small
difference of large displacements), 2e-10 for the others. Over 200 scenarios of
bench/sweep_1000_3d_crushing.toml, 192 agreed to 1e-9 in every output and the largest
differences were 1.7e-6 (the log's rotation) and 6.8e-7 (the peak principal stress)."""


@pytest.fixture(scope="module")
def block():
    pytest.importorskip("flexcontact.dam.reuse")
    from flexcontact.dam.reuse import ScenarioEvaluator
    from flexcontact.dam.scenario import DamScenario
    # The 3D sweep's mesh: the log at 0.2 m is factored by MUMPS (a Schur factor that
    # shares), not held as a split factor.
    base = DamScenario(dim=3, mesh_size_far_m=6.0, mesh_size_impact_m=0.4, mesh_size_log_m=0.2,
                       log_end_crushes=True, mesh_size_contact_m=0.05, contact_zone_m=0.35,
                       contact_layer_m=0.05)
    return ScenarioEvaluator(base, water_levels_m=(base.water_level_m,) * 2)


def test_the_3d_block_evaluates_scenarios_side_by_side_as_one_by_one(block):
    ev = block
    base = ev.base
    scenarios = [base.replace(log_yaw_deg=-10.0, log_speed_m_s=1.5),
                 base.replace(log_across_m=4.0),  # off the face patch: fails alone
                 base.replace(log_yaw_deg=10.0, log_speed_m_s=3.0),
                 base.replace(log_across_m=8.0, log_pitch_deg=5.0)]
    before = ev.counts()["back_substitutions"]
    many = ev.evaluate_many(scenarios)
    middle = ev.counts()["back_substitutions"]
    assert "patch_y_m" in str(many[1]) and "log_yaw_deg=0.0" in str(many[1])
    ones = [ev.evaluate(s) for s in scenarios[::2] + scenarios[3:]]
    after = ev.counts()["back_substitutions"]
    # Every column of a shared call is counted: the same counts either way.
    for key in ("dam_stage2", "log"):
        assert middle[key] - before[key] == after[key] - middle[key], key
    assert type(ev.dam.factor).__name__ == "DistributedSchur"
    assert ev.together.calls["condense"] < ev.together.columns["condense"]
    # One copy of each model's block: W_face and W_front are the kernel blocks' own values.
    assert np.shares_memory(ev.dam.W_face, ev.dam.face_block.matrix)
    log = ev.log_model(base)
    assert np.shares_memory(log.W_front, log.front_block.matrix)
    for m, o in zip([many[0], many[2], many[3]], ones):
        # The impulse on the face is the log's loss of momentum (a conservation law, exact
        # whatever the order of the sums).
        assert abs(m["impulse_N_s_per_m"] + m["log_momentum_change_N_s_per_m"]) \
            <= 1e-9 * m["impulse_N_s_per_m"]
        for k in ("steps", "contact_episodes", "dam_back_substitutions",
                  "log_back_substitutions"):
            assert m[k] == o[k], (k, m[k], o[k])
        for k, v in o.items():
            if k == "evaluate_s" or not isinstance(v, float) or np.isnan(v):
                continue
            assert abs(m[k] - v) <= SHARED_TOL * abs(v), (k, m[k], v)


FHAT_TOL = 1e-8
"""Relative: the kernel holding the models' F̂ blocks (the products made outside it, W_eff's
columns fetched for the pairs that close) against F̂ and W_eff formed whole; the same
arithmetic in another order. Measured here: 1.3e-10 at most (the log's final rotation),
1e-11 for the others."""


def test_the_shared_blocks_give_the_dense_kernels_answers(block):
    ev = block
    base = ev.base
    scenarios = [base.replace(log_yaw_deg=-10.0, log_speed_m_s=1.5),
                 base.replace(log_across_m=8.0, log_pitch_deg=5.0)]
    from flexcontact.dam.coupled_step import holds_shared_blocks
    assert holds_shared_blocks(ev.fhat, ev.dam)  # the 3D block's default
    try:
        ev.fhat = "dense"
        dense = [ev.evaluate(s) for s in scenarios]
    finally:
        ev.fhat = "auto"
    shared = [ev.evaluate(s) for s in scenarios]
    for d, s in zip(dense, shared):
        assert d["peak_force_N_per_m"] > 0.0
        for k in ("steps", "contact_episodes", "dam_back_substitutions",
                  "log_back_substitutions"):
            assert s[k] == d[k], (k, s[k], d[k])
        for k, v in d.items():
            if k == "evaluate_s" or not isinstance(v, float) or np.isnan(v) or v == 0.0:
                continue
            assert abs(s[k] - v) <= FHAT_TOL * abs(v), (k, s[k], v)


def _first_request_seen(run, seen: list, dam):
    """``run``'s requests passed on unchanged; the response functions' lags at its first."""
    ops = next(run)
    seen.append(dam.responses().lags)
    while True:
        answers = yield ops
        try:
            ops = run.send(answers)
        except StopIteration as stop:
            return stop.value


def test_a_run_tabulates_its_response_functions_before_its_first_request(block):
    """A run that convolves longer than the lags tabulated so far extends them with the
    dam's factor. Beside other runs, that extension must come before the run's first
    request: made when it finished, it fell between another run's condensation and its
    expansion on the dam, and the batch stopped with "expand_many: no condense_many since
    the last expansion or solve" (16 scenarios of bench/sweep_1000_3d_crushing.toml side
    by side on an evaluator without a model file)."""
    from flexcontact.dam.coupled_step import impact_run, run_steps
    ev = block
    lags = ev.dam.responses().lags
    # A slower log approaches for longer: the first speed whose run outlasts the lags.
    s = next(s for s in (ev.base.replace(log_speed_m_s=v) for v in (0.5, 0.35, 0.25, 0.18))
             if run_steps(s, ev.dam) > lags)
    n = run_steps(s, ev.dam)
    seen: list = []
    run = impact_run(ev.dam, ev.log_model(s), s, ev.dam.static_state(s.water_level_m))
    out = serve_alone(_first_request_seen(run, seen, ev.dam))
    assert seen[0] >= n > lags
    assert out["steps"] == n and out["dam_steps_convolved"] > 0
