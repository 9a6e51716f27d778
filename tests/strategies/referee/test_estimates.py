"""The referee's estimate: the plain discrete game, checked against the sound bounds."""

from __future__ import annotations

import numpy as np
import pytest

from envs.errors import InvalidConfigError
from envs.maps import Map
from strategies.referee import ESTIMATE_LABELS, GameSpec, estimate
from strategies.referee.estimates import _clear_states, _discretise, _fan_blocked

from .conftest import dead_end, open_room, spec


def test_estimate_agrees_with_the_pursuer_bound(open_slow):
    """Open 5 x 5 room, rho = 0.2: of the starts the sound pursuer bound certifies, the
    estimate calls >= 95 % pursuer wins and at most 0.1 % evader wins.

    Tolerance: the estimate snaps each player to its own (coarser) lattice, which can
    move a start by up to a cell; the 16 of 106,952 certified starts it calls evader
    wins have the pursuer 0.05 from a wall and the evader 1.075 in front of it, which
    snaps to a distance of 1.0 = L_min with the wall behind (lost in the discrete game).
    The contested 3 % are starts the two resolutions or orders disagree on.
    """
    starts = open_slow.lattice_starts()
    won = starts.label == "pursuer"
    assert won.sum() > 100_000
    est = estimate(spec(open_room(), 0.2), cpls=(6, 8), steps=4, cache=False)
    labels = est.labels(starts.pursuer[won], starts.evader[won])
    assert np.mean(labels == "pursuer") >= 0.95
    assert np.mean(labels == "evader") <= 0.001


@pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")  # its pursuer side
def test_estimate_agrees_with_the_evader_bound(corridor_half):
    """The dead end at rho = 0.5: every start the sound evader bound certifies (the pursuer
    behind the evader in the corridor) is an evader win in every solution."""
    starts = corridor_half.lattice_starts()
    won = starts.label == "evader"
    assert won.sum() >= 10
    est = estimate(spec(dead_end(), 0.5), cpls=(4, 5), cache=False)
    assert set(est.labels(starts.pursuer[won], starts.evader[won])) == {"evader"}
    # and the estimate is not "evader" everywhere: the informed pursuer holds the room
    assert all(s.summary()["evader_first"] > 0.9 for s in est.solutions)


def test_a_rod_cannot_sweep_over_an_obstacle_within_a_move():
    """The evader stands at (5, 7); the pursuer moves from (4, 3) to (6, 3). Both end rods
    pass beside a small pillar at (5, 5), the rods in between cross it: the move is blocked
    (and a move that keeps the pillar outside the swept triangle is not)."""
    pillar = [(4.9, 4.9), (5.1, 4.9), (5.1, 5.1), (4.9, 5.1)]
    world = Map([(0, 0), (10, 0), (10, 10), (0, 10)], [pillar], name="pin")
    s = GameSpec(world, 2.0, 5.0, 1.0, 0.5, body_radius=0.1)
    _, lat, _, _ = _discretise(s, 4, 4, 16)  # h = 0.5: the points below are on the lattice
    clear = _clear_states(lat, s, 0.0, 5.0)
    moves = np.array([[0, 0], [4, 0], [0, -4]])  # stay, 2 m to the right, 2 m down
    blocked = _fan_blocked(lat, clear, moves, "pursuer")
    k = int(lat.point_index(lat.cell_of(np.array([[4.0, 3.0]])))[0])
    a, b = lat.window_cell(k, lat.cell_of(np.array([[5.0, 7.0]])))[0]
    flat = np.ravel_multi_index((k, a, b), clear.shape)
    assert clear.flat[flat]  # the start rod is clear
    assert flat in set(blocked[1].tolist())  # moving right sweeps over the pillar
    assert flat not in set(blocked[2].tolist())  # moving down does not


def test_estimate_api_labels_cache_and_bad_input(tmp_path):
    s = spec(open_room(), 1.5)
    first = estimate(s, cpls=(3, 4), cache_dir=tmp_path)
    assert first.cpls == (3.0, 4.0)
    # the same step tau, the finer lattice's moves snap differently
    assert [s.steps for s in first.solutions] == pytest.approx([4.0, 16 / 3])
    assert first.solutions[0].tau == pytest.approx(first.solutions[1].tau)
    assert any((tmp_path / "referee").iterdir())
    again = estimate(s, cpls=(4, 3), cache_dir=tmp_path)  # loaded, same arrays
    for x, y in zip(first.solutions, again.solutions, strict=True):
        assert np.array_equal(x.evader_first, y.evader_first)
        assert np.array_equal(x.pursuer_first, y.pursuer_first)
    summary = first.summary()
    assert summary["evader"] == 1.0  # rho = 1.5: the evader charges, everywhere
    assert set(summary) >= {"starts", *ESTIMATE_LABELS, "solutions"}
    assert first.classify((2.5, 4.0), (2.5, 2.5)) == "evader"
    with pytest.raises(InvalidConfigError, match="cpls = \\(4, 4\\)"):
        estimate(s, cpls=(4, 4))
    with pytest.raises(InvalidConfigError, match="cpls"):
        estimate(s, cpls=(4, -1))
    with pytest.raises(InvalidConfigError, match="steps = \\(4,\\): expected one number"):
        estimate(s, cpls=(3, 4), steps=(4,))
    with pytest.raises(InvalidConfigError, match="expected a GameSpec"):
        estimate(open_room(), cpls=(3, 4))
