"""The public API: classification, labels and samples of starts, summaries, the cache,
the pictures, and bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from envs.errors import (
    InvalidConfigError,
    InvalidPlacementError,
    MemoryBudgetError,
    NoStartError,
)
from envs.geometry import kernel_for
from envs.surveillance.config import EnvConfig
from strategies.referee import (
    GameSpec,
    Resolution,
    cached_evader_bound,
    cached_pursuer_bound,
    label_starts,
    referee_for,
    solve,
)
from strategies.referee.cache import cache_path
from tests.strategies.referee.conftest import RADIUS, open_room, spec

# rho = 0.5 and 0.9 on purpose: the pursuer bound's own warning is tested in test_vacuity
pytestmark = pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")


def test_classify_and_label_starts(open_slow, corridor_half):
    assert open_slow.classify((2.5, 4.0), (2.5, 2.5)) == "pursuer"
    assert corridor_half.classify((-2.2, 0.0), (-0.9, 0.0)) == "evader"
    # not a start of the game: surveillance does not hold there
    with pytest.raises(InvalidPlacementError, match=r"distance 5.65685 outside \[l_min"):
        open_slow.classify((0.5, 0.5), (4.5, 4.5))
    with pytest.raises(InvalidPlacementError, match="occluded"):
        corridor_half.classify((-0.5, 0.0), (0.5, 1.5))
    starts = [{"pursuer": (2.5, 4.0), "evader": (2.5, 2.5)},
              {"pursuer": (-2.2, 0.0), "evader": (-0.9, 0.0)}]  # fmt: skip
    assert label_starts(corridor_half, starts)[1] == "evader"
    assert label_starts(open_slow, starts[:1]) == ["pursuer"]


@pytest.mark.parametrize(
    ("bad", "match"),
    [
        ((np.nan, 1.0), "pursuer"),
        (("a", "b"), "pursuer"),
        ((1.0, 2.0, 3.0), "pursuer"),
    ],
)
def test_classify_rejects_bad_points(open_slow, bad, match):
    with pytest.raises(InvalidConfigError, match=match):
        open_slow.classify(bad, (2.0, 2.0))


def test_label_starts_rejects_malformed_starts(open_slow):
    with pytest.raises(InvalidConfigError, match="start 0"):
        label_starts(open_slow, [((1, 1), (2, 2))])
    with pytest.raises(InvalidConfigError, match="start 1"):
        label_starts(open_slow, [{"pursuer": (2.5, 4.0), "evader": (2.5, 2.5)}, {"p": 1}])


@pytest.mark.parametrize("kind", ["pursuer", "evader"])
def test_sample_starts_are_valid_labelled_and_reproducible(kind, open_slow, corridor_half):
    ref = open_slow if kind == "pursuer" else corridor_half
    a = ref.sample_starts(12, np.random.default_rng(3), kind=kind)
    b = ref.sample_starts(12, np.random.default_rng(3), kind=kind)
    assert a == b and len(a) == 12
    ker = kernel_for(ref.spec.map)
    for s in a:
        p, e = np.array(s["pursuer"]), np.array(s["evader"])
        assert ref.spec.l_min <= np.hypot(*(p - e)) <= ref.spec.l_max
        assert ker.line_of_sight(p, e)
        assert (ref.spec.map.distance_to_walls(np.stack([p, e])) >= RADIUS).all()
        assert ref.classify(p, e) == kind  # the jittered player stays certified
    # the certified player sits on its lattice, the other was moved off it
    lat = (ref.pursuer if kind == "pursuer" else ref.evader).lattice
    mine = np.array([s[kind] for s in a])
    assert (lat.point_index(lat.cell_of(mine)) >= 0).all()


def test_sample_starts_errors(open_slow):
    rng = np.random.default_rng(0)
    with pytest.raises(InvalidConfigError, match="no 'evader'-labelled start") as err:
        open_slow.sample_starts(1, rng, kind="evader")
    assert "says nothing" not in str(err.value)
    with pytest.raises(InvalidConfigError, match="kind = 'both'"):
        open_slow.sample_starts(1, rng, kind="both")
    with pytest.raises(InvalidConfigError, match="n = -1"):
        open_slow.sample_starts(-1, rng)


def test_sample_starts_beyond_the_memory_budget_are_refused_before_drawing(open_slow, monkeypatch):
    # 1e12 starts died in numpy's MemoryError ("Unable to allocate 7.28 TiB"), and a
    # number that fits in RAM but not in the budget was drawn whatever the budget
    rng = np.random.default_rng(0)
    monkeypatch.delenv("SURVEIL_MEMORY_BUDGET", raising=False)
    with pytest.raises(MemoryBudgetError, match=r"n = 1000000000000 starts would take") as err:
        open_slow.sample_starts(10**12, rng, kind="unknown")
    assert "this machine has" in str(err.value)  # no budget advice that no RAM can meet
    monkeypatch.setenv("SURVEIL_MEMORY_BUDGET", "1MB")
    with pytest.raises(MemoryBudgetError, match=r"n = 10000 starts .* draw at most 1953") as err:
        open_slow.sample_starts(10_000, rng, kind="unknown")
    assert "SURVEIL_MEMORY_BUDGET=1GB in the environment" in str(err.value)
    assert len(open_slow.sample_starts(1953, rng, kind="unknown")) == 1953


def test_sample_starts_says_when_no_pursuer_start_says_nothing(corridor_half):
    # rho = 0.5: the pursuer bound is vacuous, and the error says so rather than suggest
    # that no start is winnable for the pursuer
    with pytest.raises(InvalidConfigError, match="no 'pursuer'-labelled start") as err:
        corridor_half.sample_starts(1, np.random.default_rng(0), kind="pursuer")
    assert "which says nothing about the game: pursuer bound at rho = 0.5" in str(err.value)


def test_summary_reports_fractions_sizes_and_timings(open_slow):
    s = open_slow.summary()
    assert s["pursuer"] + s["evader"] + s["gap"] == pytest.approx(1.0)
    assert s["starts"] == len(open_slow.lattice_starts())
    for key in ("pursuer_bound", "evader_bound"):
        assert s[key]["states"] > 0 and s[key]["iterations"] >= 1
        assert set(s[key]["seconds"]) == {"build", "solve"}


def test_referee_for_an_env_config_plays_in_whole_env_steps(tmp_path):
    cfg = EnvConfig(map=open_room(), l_min=1.0, l_max=2.0, v_evader=0.9, body_radius=RADIUS,
                    dt=0.15)  # fmt: skip
    ref = referee_for(cfg, 8, pursuer_coarse=2, evader_coarse=4, cache_dir=tmp_path)
    for bound in (ref.pursuer, ref.evader):
        k = bound.res.tau / 0.15
        assert abs(k - round(k)) < 1e-9
    assert ref.spec == GameSpec.from_config(cfg)


def test_solve_rejects_bad_input():
    with pytest.raises(InvalidConfigError, match="expected a GameSpec"):
        solve(open_room(), 10)
    with pytest.raises(InvalidConfigError, match="cells_per_lmin"):
        solve(spec(open_room(), 0.5), -3)


def test_cache_round_trip_and_corruption(tmp_path):
    s = spec(open_room(4.0), 1.5)
    res = Resolution.for_role(s, "evader", 8, coarse=4)
    first = cached_evader_bound(s, res, cache_dir=tmp_path)
    path = cache_path("evader", s, res, tmp_path)
    assert path.exists()
    again = cached_evader_bound(s, res, cache_dir=tmp_path)
    assert np.array_equal(first.rank, again.rank) and again.seconds == first.seconds
    # a corrupted file is ignored and rewritten
    path.write_bytes(path.read_bytes()[:100])
    third = cached_evader_bound(s, res, cache_dir=tmp_path)
    assert np.array_equal(first.win, third.win)
    assert cached_evader_bound(s, res, cache_dir=tmp_path).seconds == third.seconds
    # another game or resolution never hits that file
    assert cache_path("evader", spec(open_room(4.0), 1.4), res, tmp_path) != path
    assert cache_path("pursuer", s, res, tmp_path) != path
    assert cache_path("evader", s, Resolution(res.cell, res.coarse, res.tau * 2), tmp_path) != path


def test_cache_rejects_a_file_whose_arrays_were_altered(tmp_path):
    import json
    import zipfile

    s = spec(open_room(4.0), 0.2)
    res = Resolution.for_role(s, "pursuer", 8, coarse=4)
    bound = cached_pursuer_bound(s, res, cache_dir=tmp_path)
    path = cache_path("pursuer", s, res, tmp_path)
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["win"] = ~arrays["win"]  # same key, tampered content
    with zipfile.ZipFile(path, "w") as z:
        for name, a in arrays.items():
            with z.open(name + ".npy", "w") as fh:
                np.lib.format.write_array(fh, a)
    meta = json.loads(bytes(arrays["__meta__"]).decode())
    assert meta["key"]["game"]["map"] == s.map.digest
    reloaded = cached_pursuer_bound(s, res, cache_dir=tmp_path)
    assert np.array_equal(reloaded.win, bound.win)  # recomputed, not the tampered copy


def test_draw_referee_renders_the_panels(corridor_half, tmp_path):
    pytest.importorskip("matplotlib")
    from strategies.referee.draw import COLORS, draw_referee, draw_starts, evader_fractions

    fig = draw_referee(corridor_half, path=tmp_path / "ref.png")
    assert (tmp_path / "ref.png").stat().st_size > 10_000
    assert len(fig.axes) == 4
    _pts, fr, counts = evader_fractions(corridor_half)
    assert np.allclose(fr.sum(axis=1)[counts > 0], 1.0)
    ax = draw_starts(corridor_half, (-0.9, 0.0))
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    starts = corridor_half.lattice_starts()
    mine = np.all(np.isclose(starts.evader, (-0.9, 0.0), atol=0.2), axis=1)
    assert any(lab.startswith("evader") for lab in labels) and mine.any()
    assert set(COLORS) == {"pursuer", "evader", "unknown"}


@pytest.mark.parametrize("l_max", [4.0, 2.2])
def test_coarsest_with_starts_is_where_the_lattice_starts_begin(l_max):
    """At coarse resolutions both lattices have spacing 2 h (h = l_min / cpl), so the
    first start is at a spacing of l_max: cpl = 2 l_min / l_max. Checked against the
    solved referee's own lattice starts one scan step below and at the value found."""
    from strategies.referee.referee import COARSEST_SCAN_STEP, coarsest_with_starts

    cfg = EnvConfig(map="corridor", l_min=2.0, l_max=l_max)
    game = GameSpec.from_config(cfg)
    fit = coarsest_with_starts(game, dt=cfg.dt)
    assert 2 * 2.0 / l_max <= fit < 2 * 2.0 / l_max * COARSEST_SCAN_STEP
    assert len(referee_for(cfg, fit, cache=False).lattice_starts()) > 0
    with pytest.raises(NoStartError, match="hold no start"):  # was a referee with 0 starts
        referee_for(cfg, fit / COARSEST_SCAN_STEP, cache=False)


def test_a_long_solve_warns_before_it_starts_and_not_from_the_cache(tmp_path, monkeypatch):
    """A referee policy solves at its first reset: a solve estimated beyond
    LONG_SOLVE_SECONDS says so (with the estimate) before it starts; a cached bound does not."""
    import strategies.referee.referee as referee_module
    from envs.errors import LongRunWarning
    from strategies.referee._budget import bound_size

    s = spec(open_room(4.0), 1.5)
    res = Resolution.for_role(s, "evader", 8, coarse=4)
    estimate = bound_size(s, res, "evader").seconds
    monkeypatch.setattr(referee_module, "LONG_SOLVE_SECONDS", 0.5 * estimate)
    with pytest.warns(LongRunWarning, match=r"evader bound of map 'open4'.*estimated to take"):
        cached_evader_bound(s, res, cache_dir=tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LongRunWarning)
        cached_evader_bound(s, res, cache_dir=tmp_path)  # from the cache: no word
    monkeypatch.setattr(referee_module, "LONG_SOLVE_SECONDS", 2.0 * estimate)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LongRunWarning)
        cached_evader_bound(s, res, cache=False)  # below the limit: no word


def test_a_solve_the_budget_refuses_is_not_announced_as_long(monkeypatch):
    """The memory refusal comes alone, not after an announcement of its time."""
    import strategies.referee.referee as referee_module
    from envs.errors import LongRunWarning, MemoryBudgetError

    monkeypatch.setattr(referee_module, "LONG_SOLVE_SECONDS", 0.0)
    s = spec(open_room(4.0), 1.5)
    res = Resolution.for_role(s, "evader", 8, coarse=4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LongRunWarning)
        with pytest.raises(MemoryBudgetError):
            cached_evader_bound(s, res, cache=False, memory_budget="1MB")
