"""Tournament statistics against closed forms and known generating parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import expit

from analysis.tournament import statistics as st


def _row(p, e, winner, seed, m="m", status="ok", escape=None, cause=None):
    return {
        "map": m,
        "variant": "",
        "start": "safe",
        "pursuer": p,
        "evader": e,
        "winner": winner,
        "seed": seed,
        "status": status,
        "escape_time": escape,
        "cause": cause,
        "blame": None,
    }


def test_cells_count_held_rates_escapes_and_forfeits():
    rows = [_row("P", "E", "pursuer", s) for s in range(3)]
    rows += [_row("P", "E", "evader", 3, escape=2.0, cause="occluded")]
    rows += [_row("P", "E", "evader", 4, escape=4.0, cause="too_far")]
    rows += [{**_row("P", "E", "pursuer", 5, status="forfeit"), "blame": "evader"}]
    rows += [_row("P", "E", None, 6, status="error")]
    (c,) = st.cells(rows)
    assert (c.n, c.held, c.errors) == (6, 4, 1)
    assert (c.lo, c.hi) == pytest.approx(st.wilson_interval(4, 6))
    assert c.escape_mean == pytest.approx(3.0)
    assert c.causes == {"occluded": 1, "too_far": 1, "forfeit": 1}
    assert c.forfeits == {"pursuer": 0, "evader": 1}


def test_games_of_payoff_matrices():
    rows = []
    # rates: P1 vs E1 = 1, P1 vs E2 = 0, P2 vs E1 = 0, P2 vs E2 = 1 (matching pennies)
    for s in range(4):
        rows += [_row("P1", "E1", "pursuer", s), _row("P1", "E2", "evader", s, escape=1.0)]
        rows += [_row("P2", "E1", "evader", s, escape=1.0), _row("P2", "E2", "pursuer", s)]
    (m,) = st.payoff_matrices(st.cells(rows))
    assert m.complete and m.rate.tolist() == [[1.0, 0.0], [0.0, 1.0]]
    (g,) = st.games([m])
    assert g.value == pytest.approx(0.5)
    assert g.pursuers == pytest.approx({"P1": 0.5, "P2": 0.5})
    assert g.pursuer_exploitability == pytest.approx({"P1": 0.5, "P2": 0.5})


def test_bradley_terry_recovers_known_strengths():
    rng = np.random.default_rng(0)
    a = np.array([1.5, 0.0, -1.0])
    b = np.array([0.8, -0.6])
    rows, seed = [], 0
    for i, pa in enumerate(a):
        for j, eb in enumerate(b):
            for _ in range(400):
                held = rng.random() < expit(pa - eb)
                rows.append(_row(f"P{i}", f"E{j}", "pursuer" if held else "evader", seed))
                seed += 1
    ratings = {(r.role, r.label): r for r in st.ratings(rows)}
    centre = np.concatenate([a, b]).mean()
    for i, pa in enumerate(a):
        r = ratings[("pursuer", f"P{i}")]
        assert r.lo < pa - centre < r.hi and abs(r.strength - (pa - centre)) < 0.25
    for j, eb in enumerate(b):
        r = ratings[("evader", f"E{j}")]
        assert r.lo < eb - centre < r.hi
    boot = st.ratings(rows, method="bootstrap", n_resamples=60)
    assert {r.label: round(r.strength, 9) for r in boot} == {
        r.label: round(r.strength, 9) for r in ratings.values()
    }


def test_mcnemar_exact_and_holm():
    rows = []
    # on 12 shared starts: A holds and B fails on 8, B holds and A fails on 1, both hold on 3
    outcomes = [(1, 0)] * 8 + [(0, 1)] + [(1, 1)] * 3
    for s, (a, b) in enumerate(outcomes):
        rows.append(_row("A", "E", "pursuer" if a else "evader", s, escape=1.0))
        rows.append(_row("B", "E", "pursuer" if b else "evader", s, escape=1.0))
    (cmp,) = [c for c in st.paired_comparisons(rows) if c.role == "pursuer"]
    assert (cmp.pairs, cmp.a_only, cmp.b_only) == (12, 8, 1)
    assert cmp.p_value == pytest.approx(2 * (9 + 1) / 2**9)  # two-sided exact binomial
    tests = [st.PairedComparison("pursuer", "a", "b", 1, 0, 0, p) for p in (0.01, 0.04, 0.03)]
    assert [t.p_holm for t in st._holm(tests)] == pytest.approx([0.03, 0.06, 0.06])


def test_sprt_and_intervals():
    assert st.sprt(12, 0) == "a better" and st.sprt(0, 12) == "not better"
    assert st.sprt(3, 2) == "undecided"
    assert math.isnan(st.t_mean_interval([])[0])
    lo, hi = st.wilson_interval(8, 10)
    assert (lo, hi) == pytest.approx((0.4901625, 0.9433178), abs=1e-6)
