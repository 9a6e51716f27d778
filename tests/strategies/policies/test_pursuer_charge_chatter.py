"""The decomposition pursuer's charge test holds against a walk the rod chatters across
(issue 13, holds-bench pillars).

A straight evader walks a fixed heading about 60 deg off the rod, right at the charge
test (its velocity along the rod above half its speed). On aeb694f the orbit keeper turned
the rod hard one way whenever the test passed, the test failed on the next step, the
decomposition's turn brought the rod back, and the test passed again: the rod stood
still between 95.8 and 100.5 deg while the range fell, too close at 11.9 s. The test now
keeps the charge (to 70 deg off the rod) once it re-enters with the rod and the evader's
heading standing still, and only then: a herder's heading turns with the rod.
"""

from __future__ import annotations

import importlib
import math
from pathlib import Path
from types import SimpleNamespace

import pytest

from strategies.runner import run_episode
from tests.strategies.policies.conftest import decomposition_pursuer


@pytest.fixture
def holds(monkeypatch):
    """The pursuer-holds benchmark module (benchmarks/pursuer_holds.py)."""
    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[3] / "benchmarks"))
    return importlib.import_module("pursuer_holds")


def test_the_pillars_straight_walk_at_the_charge_test_is_held(holds):
    """holds-bench: pillars as is, rho 0.5, evader/straight, seed 7 (lost by too_close
    at 11.87 s on aeb694f)."""
    variant = next(v for v in holds.VARIANTS if v[0] == "as is")
    m, params = holds._game("pillars", variant, 0.5, None)
    r = run_episode(m, "pursuer/decomposition", holds._evader("evader/straight"), 7,
                    max_cycles=600, overrides=params, start="safe")  # fmt: skip
    assert r.winner == "pursuer", r.summary()


def _run(steps):
    """Feed the charge test (rod orientation, evader heading) pairs, in degrees, at speed
    0.5 (the angle off the rod is their difference) of a fresh decomposition pursuer in
    the open room; the test's answers."""
    p = decomposition_pursuer()
    out = []
    for theta, heading in steps:
        h = math.radians(heading)
        snap = SimpleNamespace(theta=math.radians(theta))
        out.append(p._charge_test(snap, 0.5 * math.cos(h), 0.5 * math.sin(h), 0.5))
    return out


def test_a_chatter_across_a_fixed_heading_keeps_the_charge():
    # heading 0; the rod at 61 deg off it (no charge), 59 (charge), 62, 62.5 (the
    # orbit keeper's turn undone), 59.2 (re-entered, rod within 2 deg of the last
    # entry): armed, so 64 and 69 stay charging, 71 leaves
    seq = [(61, 0), (59, 0), (62, 0), (62.5, 0), (59.2, 0), (64, 0), (69, 0), (71, 0), (63, 0)]
    assert _run(seq) == [False, True, False, False, True, True, True, False, False]


def test_one_entry_alone_does_not_keep_the_charge():
    assert _run([(61, 0), (59, 0), (62, 0), (64, 0)]) == [False, True, False, False]


def test_a_heading_that_turns_with_the_rod_does_not_arm_it():
    # the same angles off the rod as above (61, 59, 62, 62.5, 59.2, 64) and the rod back
    # within 2 deg at the second entry, but the heading swung by 2 deg in between (a
    # herder's heading turns with the rod)
    seq = [(61, 0), (59, 0), (64, 2), (63.5, 1), (59.7, 0.5), (64.5, 0.5)]
    assert _run(seq) == [False, True, False, False, True, False]


def test_a_rod_that_moved_between_entries_does_not_arm_it():
    seq = [(61, 0), (59, 0), (62, 0), (55, 0), (66, 0)]
    assert _run(seq) == [False, True, False, True, False]


def test_the_charge_held_ends_when_the_heading_turns():
    # armed as in the fixed-heading chatter, then the heading turns 2 deg: the charge
    # held at 64 deg off the rod ends (a herder's heading turns with the held turn)
    seq = [(61, 0), (59, 0), (62, 0), (62.5, 0), (59.2, 0), (66, 2)]
    assert _run(seq) == [False, True, False, False, True, False]


def test_a_heading_that_drifts_like_a_herders_does_not_arm_it():
    # the chatter of the first test (the angles off the rod 61, 59, 62, 62.3, 59, then
    # 64), but the heading drifts 0.8 deg between the entries, the rod with it: a
    # herder's smallest drift between two entries in the sets is 0.71 deg (a walker that
    # holds its heading: 0.00), so it does not arm and 64 deg is no charge
    seq = [(61, 0), (59, 0), (62.3, 0.3), (62.9, 0.6), (59.8, 0.8), (64.8, 0.8)]
    assert _run(seq) == [False, True, False, False, True, False]
