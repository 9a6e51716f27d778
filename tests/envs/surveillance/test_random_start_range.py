"""Random starts with a sensor range far beyond the map: L is drawn below the map's diameter."""

from __future__ import annotations

import numpy as np
import pytest

from envs import surveillance_v1
from envs.errors import InfeasibleError
from envs.maps import builtin_map, builtin_names, random_map


@pytest.mark.parametrize("world", [*builtin_names(), "random"])
def test_diameter_is_the_largest_vertex_distance(world) -> None:
    m = random_map(5, n_vertices=30) if world == "random" else builtin_map(world)
    b = m.rings[0]
    brute = max(np.linalg.norm(p - q) for p in b for q in b)
    assert m.diameter == pytest.approx(brute, rel=1e-12)


@pytest.mark.parametrize("l_max", [1e3, 1e6, 1e12])
def test_a_huge_l_max_still_starts(l_max) -> None:
    env = surveillance_v1.parallel_env(map="two_rooms", l_max=l_max)
    for seed in range(5):
        _, infos = env.reset(seed=seed)
        assert infos["pursuer_0"]["surveillance"]
        assert 2.0 < infos["pursuer_0"]["distance"] <= env.map.diameter


def test_l_min_beyond_the_map_names_the_diameter() -> None:
    env = surveillance_v1.parallel_env(map="corridor", l_min=50.0, l_max=60.0, body_radius=0.1)
    with pytest.raises(InfeasibleError, match=r"no two points 50.45 apart \(its diameter is 16.9"):
        env.reset(seed=0)


def _room(w: float, h: float, name: str):
    from envs.maps import Map

    return Map([(0, 0), (w, 0), (w, h), (0, h)], name=name)


@pytest.mark.parametrize("kind", ["valid", "safe"])
def test_a_map_too_small_for_the_bodies_says_so_up_front(kind) -> None:
    """A 1 mm map cannot hold a disc of radius 0.1: said at once, not after 25,600 tries."""
    from envs.surveillance.config import EnvConfig
    from strategies.policies.starts import sample_start

    cfg = EnvConfig(map=_room(0.001, 0.001, "mm"), l_min=2.0, l_max=4.0)
    with pytest.raises(InfeasibleError, match=r"map 'mm' cannot hold an agent: no point .* "
                       r"body_radius = 0.1 from the walls"):  # fmt: skip
        sample_start(cfg, np.random.default_rng(0), kind=kind)


def test_a_map_too_narrow_for_the_rod_says_so_up_front() -> None:
    """A 1 x 0.3 room holds the bodies (0.1) and has a diameter of 1.04, but no two points
    0.1 from its walls are more than 0.81 apart: the shortest rod a start may have (l_min
    0.45 plus the spawn margin 0.45) cannot fit."""
    env = surveillance_v1.parallel_env(
        map=_room(1.0, 0.3, "slot"), l_min=0.45, l_max=3.0, body_radius=0.1
    )
    with pytest.raises(InfeasibleError, match=r"map 'slot' cannot hold the rod: .* L = 0.9 "
                       r"apart \(at most 0.806"):  # fmt: skip
        env.reset(seed=0)


def test_a_round_room_s_start_check_takes_no_square_of_its_vertices_in_memory() -> None:
    """An 8,000-gon room: the check that a rod fits (the env's first random start) built all
    8,000^2 pairs of its region's hull at once, 1.5 GB (20,000 vertices: 9.6 GB)."""
    import tracemalloc

    from envs.maps import Map
    from envs.surveillance.placement import check_room

    t = 2 * np.pi * np.arange(8000) / 8000
    room = Map(np.stack([5 + 5 * np.cos(t), 5 + 5 * np.sin(t)], axis=1), name="round8000")
    tracemalloc.start()
    try:
        check_room(room, 0.1, 9.75)  # fits: the region 0.1 in is 9.8 across
        with pytest.raises(InfeasibleError, match=r"cannot hold the rod: .* \(at most 9.8\)"):
            check_room(room, 0.1, 9.9)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100e6, peak


def test_a_random_start_the_margins_rule_out_names_their_factors():
    """pettingzoo's api_test on the maze at dt = 2 (helper-114): 'rod clearance 6 from
    convex vertices); lower spawn_margin_steps or body_radius', without saying that the 6
    is spawn_margin_steps x speed x dt (a dt the user had just set), as the safe start's
    message does."""
    env = surveillance_v1.parallel_env(map="maze", dt=2.0)
    with pytest.raises(InfeasibleError, match=r"rod clearance 6 from convex vertices = "
                       r"spawn_margin_steps 3 x the faster speed 1 x dt 2\); lower "
                       r"spawn_margin_steps, dt or body_radius"):  # fmt: skip
        env.reset(seed=0)
    surveillance_v1.parallel_env(map="maze", dt=2.0, spawn_margin_steps=0).reset(seed=0)
