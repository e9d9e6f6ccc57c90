"""A sample of the robustness campaign (bench/campaign.py runs the whole of it).

Random local problems with a known solution (tests/random_problems.py), four classes, 2D and
3D, μ from 0 to 2. The default chain must never return an answer that breaks the contact laws,
never a NaN, and must solve every problem that one of its solvers alone solves (or Siconos'
NSN_AC, where Siconos is installed).
"""
import numpy as np
import pytest

from random_problems import CLASSES, SOLVERS, run_flexcontact, run_siconos, sample

TOLERANCE = 1e-10
PROBLEMS = sample(seed=2026, count=96, sizes=(1, 40))


def _siconos_available():
    try:
        import siconos.numerics  # noqa: F401
        return True
    except ImportError:
        return False


@pytest.fixture(scope="module")
def outcomes():
    return [{s: run_flexcontact(p, s, TOLERANCE) for s in SOLVERS} for p in PROBLEMS]


def test_the_sample_covers_every_class_in_2d_and_3d():
    assert {(p.kind, p.dim) for p in PROBLEMS} == {(k, d) for k in CLASSES for d in (2, 3)}
    assert max(p.mu.max() for p in PROBLEMS) > 1.5


def test_no_solver_claims_a_wrong_answer_or_returns_nan(outcomes):
    bad = [(p.name, o.solver, o.residual) for p, row in zip(PROBLEMS, outcomes)
           for o in row.values() if o.wrong or (o.claimed and not o.finite)]
    assert not bad


def test_the_chain_solves_what_any_of_its_solvers_solves(outcomes):
    lost = [(p.name, {s: f"{o.residual:.1e}" for s, o in row.items()})
            for p, row in zip(PROBLEMS, outcomes)
            if not row["chain"].solved and any(o.solved for o in row.values())]
    assert not lost
    # The sample is not trivial: the chain solves most of it, and not every solver alone does.
    solved = np.mean([row["chain"].solved for row in outcomes])
    assert solved >= 0.9, solved


@pytest.mark.skipif(not _siconos_available(), reason="Siconos is not installed (Debian 13 has "
                    "no python3-siconos)")
def test_the_chain_solves_what_siconos_nsn_ac_solves(outcomes):
    lost = []
    for p, row in zip(PROBLEMS, outcomes):
        if p.dim == 3 and not row["chain"].solved:
            s = run_siconos(p, TOLERANCE)
            if s.solved:
                lost.append((p.name, s.residual, row["chain"].residual))
    assert not lost
