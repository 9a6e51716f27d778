"""Table features (issue 9): recomputed from the table by a plain walk over the bins, and
the direction they favour is the one the decomposition pursuer turns."""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs.surveillance.observations import StateEncoder
from strategies.policies.base import Snapshot
from strategies.policies.table_features import FLOOR, TableFeatures
from strategies.runner import build_env

PARAMS = {"range_margin": 0.3, "distance_gain": 6.0}  # the generalist recipe's expert


@pytest.fixture(scope="module", params=["corridor", "l_hall"])
def feats(request):
    return TableFeatures(build_env(request.param, {}).config, **PARAMS)


def _states(feats, n, seed=0):
    """States with the evader at random free points and the rod at random angles."""
    c = feats.config
    enc = StateEncoder(c)
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = c.map.bounds
    out = []
    while len(out) < n:
        e = rng.uniform((xmin, ymin), (xmax, ymax))
        if feats.pursuer.table.rows(e[None])[0] < 0:  # the nearest grid node is not free
            continue
        th = rng.uniform(-math.pi, math.pi)
        L = feats.pursuer.L_target
        p = e + L * np.array([math.cos(th), math.sin(th)])
        ve = rng.uniform(-0.5, 0.5, 2) * c.v_evader
        out.append((enc.encode(tuple(p), (0.0, 0.0), tuple(e), tuple(ve), True, 0), e, p, ve))
    return out


def _walk(free, b0, sign, blocked):
    """Candidate steps one way round, bin by bin."""
    nb = len(free)
    k = 1 if sign < 0 or blocked else 0
    if blocked:  # crossed: the blocked bins before the first free one
        while k < nb and not free[(b0 + sign * k) % nb]:
            k += 1
    steps = []
    while k < nb and free[(b0 + sign * k) % nb]:
        steps.append(k)
        k += 1
    return steps


def test_features_match_a_walk_over_the_table(feats):
    p = feats.pursuer
    tab = p.table
    nb = tab.n_bins
    for state, e, pos, _ in _states(feats, 150):
        got = feats(state)
        row = tab.row(e)
        free = tab.free[row]
        b0 = tab.bin_of(math.atan2(pos[1] - e[1], pos[0] - e[0]))
        value = p.orientation_values(e)
        blocked = not free[b0] and free.any()
        want = []
        for sign in (1, -1):
            best, at = None, 0
            for k in _walk(free, b0, sign, blocked):
                s = value[(b0 + sign * k) % nb] - p.hysteresis * k * tab.bin_width / p.omega
                s /= math.pi / p.omega
                if best is None or s > best:
                    best, at = s, k
            want += (
                [FLOOR, 0.0]
                if best is None
                else [min(max(best, FLOOR), 1.5), min(at / (nb / 2), 1.0)]
            )
        np.testing.assert_allclose(got[:4], want, atol=1e-5)
        assert got[4] == np.sign(round(want[0] - want[2], 9)) or abs(want[0] - want[2]) < 1e-6


def test_the_favoured_direction_is_the_pursuers_turn(feats):
    p = feats.pursuer
    turned = 0
    for state, e, pos, ve in _states(feats, 150, seed=1):
        f = feats(state)
        p.last_target = None
        rot, _ = p._target(Snapshot(e, pos, ve, np.zeros(2), 0.0))
        if f[4] == 0.0:
            continue
        if f[4] > 0 and f[1] == 0.0:  # the current bin wins: no turn
            assert rot == 0.0
        else:
            assert np.sign(rot) == f[4]
            turned += 1
    assert turned > 30  # the sample does make it choose a way round
