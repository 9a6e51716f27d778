"""The certificates in the env: the referee's own strategies, played episode by episode
against every registered opponent, win wherever the referee says they do."""

from __future__ import annotations

import numpy as np
import pytest

from envs.errors import InvalidConfigError
from envs.surveillance.config import EnvConfig
from strategies.policies.base import BasePolicy
from strategies.policies.registry import make_policy, policy_names
from strategies.referee import RefereeEvader, RefereePursuer
from strategies.referee.policy import env_steps_per_referee_step
from tests.strategies.referee.conftest import DT, RADIUS, play, play_spec

# rho = 0.5 on purpose: the pursuer bound's own warning is tested in test_vacuity
pytestmark = pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")


def _registered(role: str) -> list[str]:
    """The registered policies of ``role`` but the referee's own, which these tests add
    with the fixture's solved bound (the registered one would solve the game again)."""
    return [n for n in policy_names(role) if not n.endswith("/referee")]


def _starts(ref, kind, n, seed):
    return ref.sample_starts(n, np.random.default_rng(seed), kind=kind)


def _opponents(role, ref):
    """Every registered policy of ``role``, plus the referee's own heuristic (a charger
    for the evader, a range keeper for the pursuer) on uncertified states."""
    names = [make_policy(n) for n in _registered(role)]
    extra = RefereeEvader(ref.evader) if role == "evader" else RefereePursuer(ref.pursuer)
    return [*names, extra]


def escapes_in_certified_time(ref, starts) -> None:
    """Assert the referee's evader, from each of ``starts`` (certified for the evader),
    breaks surveillance within the certified time against every registered pursuer and
    the referee's own, every step certified."""
    k = env_steps_per_referee_step(ref.evader.res.tau, DT)
    for start in starts:
        bound = ref.escape_time(start["pursuer"], start["evader"])
        assert bound is not None
        for pursuer in _opponents("pursuer", ref):
            evader = RefereeEvader(ref.evader)
            horizon = round(bound / DT) + k
            winner, steps, _cause = play(ref, pursuer, evader, start, max_cycles=horizon)
            assert winner == "evader", (start, pursuer.name, steps)
            assert steps * DT <= bound + 1e-9, (start, pursuer.name, steps, bound)
            assert evader.uncertified_steps == 0


def test_referee_pursuer_holds_from_certified_starts_against_every_evader(open_slow):
    for start in _starts(open_slow, "pursuer", 3, seed=1):
        for evader in _opponents("evader", open_slow):
            pursuer = RefereePursuer(open_slow.pursuer)
            winner, steps, cause = play(open_slow, pursuer, evader, start, max_cycles=200)
            assert winner == "pursuer", (start, evader.name, steps, cause)
            assert pursuer.uncertified_steps == 0, (start, evader.name)


@pytest.mark.filterwarnings("ignore::envs.errors.RhoAboveOneWarning")  # rho = 1.5: on purpose
@pytest.mark.parametrize("fixture", ["corridor_half", "open_fast"])
def test_referee_evader_escapes_in_the_certified_time_against_every_pursuer(fixture, request):
    ref = request.getfixturevalue(fixture)
    escapes_in_certified_time(ref, _starts(ref, "evader", 3, seed=2))


class _RankLog(RefereeEvader):
    """A referee evader that records the certified bound at each of its referee steps."""

    def _reset(self):
        super()._reset()
        self.bounds = []

    def _plan(self, snap):
        got = self.bound.plan(snap.pursuer, snap.evader)
        self.bounds.append(None if got is None else got[1])
        return None if got is None else got[0]


def test_referee_evader_makes_progress_every_step(corridor_half):
    """The certified number of steps left drops by one every referee step: the float32
    positions the policy reads do not cost it its full-length moves (they did)."""
    for start in _starts(corridor_half, "evader", 2, seed=4):
        for name in ("pursuer/greedy", "pursuer/decomposition"):
            evader = _RankLog(corridor_half.evader)
            winner, _, _ = play(corridor_half, make_policy(name), evader, start, 300)
            assert winner == "evader"
            b = evader.bounds
            assert None not in b and b == list(range(b[0], b[0] - len(b), -1)), b


def test_referee_policies_refuse_a_different_game(open_slow):
    pursuer = RefereePursuer(open_slow.pursuer)
    other = EnvConfig(map=open_slow.spec.map, l_min=1.0, l_max=2.5, v_evader=0.2,
                      body_radius=RADIUS)  # fmt: skip
    with pytest.raises(InvalidConfigError, match="l_max"):
        pursuer.reset(role="pursuer", map=other.map, config=other, seed=0)
    odd = EnvConfig(map=open_slow.spec.map, l_min=1.0, l_max=2.0, v_evader=0.2, dt=0.07,
                    body_radius=RADIUS)  # fmt: skip
    with pytest.raises(InvalidConfigError, match="whole number of env steps"):
        pursuer.reset(role="pursuer", map=odd.map, config=odd, seed=0)
    with pytest.raises(InvalidConfigError, match="expected a PursuerBound"):
        RefereePursuer(open_slow.evader)


def test_registered_referee_policies_solve_their_game_at_reset(tmp_path, monkeypatch):
    """``make_policy("evader/referee")`` solves the env's game when reset (cached on disk and
    in the process) and plays it: from a start its bound certifies, it wins."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    from strategies.referee import policy as referee_policy
    from tests.strategies.referee.conftest import dead_end, spec

    monkeypatch.setattr(referee_policy, "_SOLVED", {})
    s = spec(dead_end(), 0.5)
    evader = make_policy("evader/referee", cells_per_lmin=12)
    winner, _steps, _ = play_spec(s, make_policy("pursuer/greedy"), evader,
                                 {"pursuer": (-2.2, 0.0), "evader": (-0.9, 0.0)}, 300)  # fmt: skip
    assert winner == "evader" and evader.uncertified_steps == 0
    assert evader.certified_steps is not None
    assert any((tmp_path / "referee").iterdir())
    assert len(referee_policy._SOLVED) == 1
    with pytest.raises(InvalidConfigError, match="cells_per_lmin = 0"):
        make_policy("pursuer/referee", cells_per_lmin=0)


@pytest.mark.parametrize("role", ["pursuer", "evader"])
def test_a_referee_policy_solves_only_the_bound_it_plays(role, tmp_path, monkeypatch):
    """Issue 13 leftover: ``pursuer/referee`` solved both bounds at reset (the evader bound
    too, about half the reset: corner at 16 cells per L_min, 1.58 s cold). Now the
    other bound's solver is never called, and the bound played is the one solve() gives
    (its evader fallback included: the dead end's default evader lattice certifies next to
    nothing, and the retry is solved too)."""
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    from strategies.referee import policy as referee_policy
    from strategies.referee import referee as referee_module
    from tests.strategies.referee.conftest import dead_end, spec

    monkeypatch.setattr(referee_policy, "_SOLVED", {})
    calls = []

    def counted(kind):
        real = getattr(referee_module, f"solve_{kind}_bound")
        return lambda *a, **kw: calls.append(kind) or real(*a, **kw)

    for kind in ("pursuer", "evader"):
        monkeypatch.setattr(referee_module, f"solve_{kind}_bound", counted(kind))
    s = spec(dead_end(), 0.5)
    cfg = EnvConfig(map=s.map, l_min=s.l_min, l_max=s.l_max, v_pursuer=s.v_pursuer,
                    v_evader=s.v_evader, body_radius=RADIUS, dt=DT)  # fmt: skip
    pol = make_policy(f"{role}/referee", cells_per_lmin=12)
    pol.reset(role=role, map=cfg.map, config=cfg, seed=0)
    mine = ["evader", "evader"] if role == "evader" else ["pursuer"]  # default, retry
    assert calls == mine
    ref = referee_module.solve(s, 12, dt=DT, cache_dir=tmp_path)  # the other from scratch
    assert calls == mine + (["pursuer"] if role == "evader" else ["evader", "evader"])
    mine = ref.pursuer if role == "pursuer" else ref.evader
    assert pol.bound.res == mine.res and np.array_equal(pol.bound.win, mine.win)


class _Still(BasePolicy):
    """An evader that never moves."""

    def _decide(self, snap):
        return np.zeros(2)


def test_the_referee_pursuers_range_keeper_keeps_the_range_off_certified_states():
    """Off certified states the pursuer keeps L at the middle of the sensor range. Its
    heuristic was decided once per referee step (tau = 1.5 s on the corridor) and held: at
    V_p for the whole step it overshot the middle by up to V_p tau, so L swung between 2.45
    and 3.95 against an evader that never moves, and every charging evader (toward_away,
    shooting) won "too_close" at t = 2.3 s. Decided every env step it settles at 3."""
    from strategies.runner import run_episode

    pursuer = make_policy("pursuer/referee")
    r = run_episode("corridor", pursuer, _Still(name="evader/still"), seed=0, max_cycles=60)
    assert pursuer.uncertified_steps > 0  # the heuristic played
    L = np.linalg.norm(r.trajectory[:, 0] - r.trajectory[:, 1], axis=1)
    mid = 0.5 * (r.config.l_min + r.config.l_max)
    assert r.winner == "pursuer"
    assert np.all(np.abs(L[20:] - mid) < 0.05), L.round(2)
