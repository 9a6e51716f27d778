"""Guarantees stated in the env card, checked over many random cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from envs import surveillance_v1
from envs.maps import builtin_names
from envs.surveillance.physics import MAX_SUBSTEP_TRAVEL, World
from tests.envs.surveillance._worlds import pillar_room, spiky_room

P, E = "pursuer_0", "evader_0"

_SPIKY = spiky_room()
_velocity = st.tuples(st.floats(-1.0, 1.0, allow_nan=False), st.floats(-1.0, 1.0, allow_nan=False))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    commands=st.lists(st.tuples(_velocity, _velocity), min_size=1, max_size=60),
    start=st.sampled_from(
        [((3.0, 4.0), (8.5, 1.5)), ((0.5, 1.2), (9.5, 5.5)), ((6.3, 5.5), (5.9, 5.5))]
    ),
)
def test_disc_centres_stay_in_free_space_for_any_commands(commands, start) -> None:
    r = 0.05
    world = World(_SPIKY, r, 0.2, 2.0)
    world.reset(np.array(start[0]), np.array(start[1]))
    pts = []
    for vp, ve in commands:
        # full-speed commands press the discs into walls, spikes and the slit
        p, e = world.step((2.0 * vp[0], 2.0 * vp[1]), ve)
        pts += [p, e]
    pts = np.array(pts)
    assert _SPIKY.contains(pts).all()
    assert _SPIKY.distance_to_walls(pts).min() >= r * (1 - MAX_SUBSTEP_TRAVEL)


@pytest.mark.parametrize("map_name", ["pillars", "maze", "corridor"])
def test_random_starts_survive_spawn_margin_steps_whatever_the_actions(map_name: str) -> None:
    """The adversary may pick any actions: a random start still lasts k steps."""
    k = 3
    env = surveillance_v1.parallel_env(map=map_name, spawn_margin_steps=k, max_cycles=k + 1)
    rng = np.random.default_rng(0)
    for seed in range(25):
        env.reset(seed=seed)
        for _ in range(k):
            # extreme actions: full speed in random directions
            ang = rng.uniform(0, 2 * math.pi, 2)
            _, _, term, _, infos = env.step(
                {
                    P: np.array([math.cos(ang[0]), math.sin(ang[0])]),
                    E: np.array([math.cos(ang[1]), math.sin(ang[1])]),
                }
            )
            assert not term[P], (seed, infos[P])


def test_every_builtin_map_gives_random_starts_with_the_defaults() -> None:
    for name in builtin_names():
        env = surveillance_v1.parallel_env(map=name)
        _, infos = env.reset(seed=0)
        assert infos[P]["surveillance"] is True, name
        p, e = env.world.positions()
        assert env.map.contains(np.array([p, e])).all()


def test_impossible_random_start_raises_a_clear_error() -> None:
    from envs.errors import InfeasibleError

    # two discs 0.1 from the walls of a 10 x 10 room are at most 9.8 sqrt(2) = 13.86 apart
    env = surveillance_v1.parallel_env(map=pillar_room(), l_min=14.0, l_max=14.1)
    with pytest.raises(
        InfeasibleError, match=r"random start: map 'test_pillar' cannot hold the rod: .*13.86"
    ):
        env.reset(seed=0)


def _first_unreported_block(module, map_name: str, seed: int) -> int | None:
    """Headings held 10 steps of dt = 1 (the bodies slide along walls for many substeps);
    a shadow World replays the same commands and shapely checks the rod at every substep:
    the first step in which the rod was blocked or out of range at a substep (by more than
    1e-6) while the env did not end the episode, else None."""
    env = module.parallel_env(map=map_name, dt=1.0, max_cycles=200)
    env.reset(seed=seed)
    cfg = env.config
    shadow = World(cfg.map, cfg.body_radius, cfg.dt, max(cfg.v_pursuer, cfg.v_evader))
    shadow.reset(np.array(env._pursuer), np.array(env._evader))
    free = cfg.map.free_region
    rng = np.random.default_rng(seed)
    k = 0
    while env.agents:
        if k % 10 == 0:
            heading = {a: rng.uniform(-1, 1, 2) for a in env.agents}
        vp, ve = env._command(P, heading[P]), env._command(E, heading[E])
        _, _, term, _, _ = env.step(heading)
        shadow._pursuer.velocity, shadow._evader.velocity = vp, ve
        broken = False
        for _ in range(shadow.n_substeps):
            shadow.space.step(shadow.substep_dt)
            p, e = shadow._pursuer.position, shadow._evader.position
            d = math.dist(p, e)
            outside = shapely.LineString([p, e]).difference(free).length
            broken |= outside > 1e-6 or not cfg.l_min - 1e-6 <= d <= cfg.l_max + 1e-6
        if broken and not term[P]:
            return k
        k += 1
    return None


@pytest.mark.parametrize(("map_name", "seeds"), [("pillars", range(28, 33)), ("maze", range(5, 9))])
def test_a_rod_blocked_within_a_contact_step_ends_the_episode(map_name, seeds) -> None:
    """The env card's continuous check, against shapely at every physics substep, in steps
    where walls stop and deflect the bodies. v0 swept such a step's chord and missed these
    breaks (pillars seed 30 at step 5, maze seed 7 at step 3; a benchmark's wall-hugging
    evaders met them at dt = 0.1 too); v1 sweeps the substeps."""
    from envs import surveillance_v0

    for seed in seeds:
        assert _first_unreported_block(surveillance_v1, map_name, seed) is None, seed
    missed = [_first_unreported_block(surveillance_v0, map_name, s) for s in seeds]
    assert any(k is not None for k in missed)
