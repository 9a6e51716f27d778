"""Small worlds for the referee's tests, and their solved referees (built once per session)."""

from __future__ import annotations

import pytest

from envs.maps import Map
from strategies.referee import GameSpec, solve

L_MIN, L_MAX, RADIUS = 1.0, 2.0, 0.05
DT = 0.1
"""The env step the solved referees are built for (their tau is a whole number of it)."""


def open_room(size: float = 5.0) -> Map:
    """A convex square room: no occlusion is possible."""
    return Map([(0, 0), (size, 0), (size, size), (0, size)], name=f"open{size:g}")


def dead_end() -> Map:
    """A 5 x 5 room with a dead-end corridor 0.5 wide (< L_min) and 2.5 deep (> L_max)."""
    return Map(
        [(0, -2.5), (5, -2.5), (5, 2.5), (0, 2.5), (0, 0.25), (-2.5, 0.25), (-2.5, -0.25),
         (0, -0.25)],
        name="dead_end",
    )  # fmt: skip


def spec(world: Map, rho: float, **kw) -> GameSpec:
    return GameSpec(world, L_MIN, L_MAX, 1.0, rho, body_radius=RADIUS, **kw)


@pytest.fixture(scope="session")
def open_slow():
    """Open 5 x 5 room, rho = 0.2: the pursuer wins almost everywhere."""
    return solve(spec(open_room(), 0.2), 15, pursuer_coarse=4, evader_coarse=2, dt=DT,
                 cache=False)  # fmt: skip


@pytest.fixture(scope="session")
def open_fast():
    """Open 5 x 5 room, rho = 1.5: the evader wins everywhere (it charges)."""
    return solve(spec(open_room(), 1.5), 10, pursuer_coarse=2, evader_coarse=4, dt=DT,
                 cache=False)  # fmt: skip


@pytest.fixture(scope="session")
def corridor_half():
    """The dead end at rho = 0.5: a pursuer behind the evader in the corridor is lost."""
    return solve(spec(dead_end(), 0.5), 12, pursuer_coarse=4, evader_coarse=4, dt=DT,
                 cache=False)  # fmt: skip


def play(ref, pursuer, evader, start, max_cycles: int, seed: int = 0):
    """:func:`play_spec` on the referee's game."""
    return play_spec(ref.spec, pursuer, evader, start, max_cycles, seed)


def play_spec(s, pursuer, evader, start, max_cycles: int, seed: int = 0):
    """One env episode of the referee's game between two policies from ``start``, through
    the shared episode runner.

    Returns:
        ``(winner, steps, cause)``: ``"evader"`` with the step surveillance broke at and
        why, or ``"pursuer"`` when it held to ``max_cycles``.
    """
    from strategies.runner import run_episode

    overrides = {"l_min": s.l_min, "l_max": s.l_max, "v_pursuer": s.v_pursuer,
                 "v_evader": s.v_evader, "body_radius": RADIUS, "dt": DT}  # fmt: skip
    r = run_episode(s.map, pursuer, evader, seed, max_cycles=max_cycles, overrides=overrides,
                    start=start)  # fmt: skip
    return r.winner, r.steps, r.cause
