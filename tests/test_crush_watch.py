"""The chatter watch of a crushing front (crush_watch.py) on flag sequences made by hand."""
import numpy as np
import pytest

from flexcontact.crush_watch import (CHATTER_MIN_FLIPS, CrushChatterWatch,
                                     CrushingChatterWarning)


def test_a_pair_flipping_every_step_is_warned_of_once():
    """Four closed pairs, one flipping between its cap and below it each step: one flip a
    step from the third step on; the warning comes when the flips reach CHATTER_MIN_FLIPS
    and a tenth of the capped pair-steps, and only once."""
    w = CrushChatterWatch()
    closed = np.ones(4, bool)
    texts = []
    with pytest.warns(CrushingChatterWarning) as caught:
        for k in range(40):
            capped = np.array([k % 2 == 0, True, False, False])
            texts.append(w.observe(k + 1, capped, closed))
    assert w.flips == 38
    warned_at = [k for k, t in enumerate(texts) if t is not None]
    assert warned_at == [CHATTER_MIN_FLIPS + 1]
    assert len(caught) == 1 and "theta=0.55" in str(caught[0].message)


def test_a_steady_front_and_an_opening_pair_are_not_chatter():
    """Pairs that stay at their cap, or leave it for good, or open, never flip."""
    w = CrushChatterWatch()
    for k in range(50):
        capped = np.array([True, k < 20, False])
        closed = np.array([True, True, k % 2 == 0])   # the third opens and closes
        assert w.observe(k + 1, capped, closed) is None
    assert w.flips == 0


def test_re_pairing_forgets_the_history():
    """After a re-pairing the flags are of other pairs: a change of their number restarts
    the history, so a flip needs three steps of the new pairs."""
    w = CrushChatterWatch()
    w.observe(1, np.array([True, True]), np.ones(2, bool))
    w.observe(2, np.array([False, False]), np.ones(2, bool))
    w.observe(3, np.array([True, True, True]), np.ones(3, bool))
    assert w.flips == 0
    w.observe(4, np.array([False, True, True]), np.ones(3, bool))
    w.observe(5, np.array([True, True, True]), np.ones(3, bool))
    assert w.flips == 1
