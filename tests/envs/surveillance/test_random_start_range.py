"""Random starts with a sensor range far beyond the map: L is drawn below the map's diameter."""

from __future__ import annotations

import numpy as np
import pytest

from envs import surveillance_v0
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
    env = surveillance_v0.parallel_env(map="two_rooms", l_max=l_max)
    for seed in range(5):
        _, infos = env.reset(seed=seed)
        assert infos["pursuer_0"]["surveillance"]
        assert 2.0 < infos["pursuer_0"]["distance"] <= env.map.diameter


def test_l_min_beyond_the_map_names_the_diameter() -> None:
    env = surveillance_v0.parallel_env(map="corridor", l_min=50.0, l_max=60.0, body_radius=0.1)
    with pytest.raises(InfeasibleError, match=r"no two points 50.45 apart \(its diameter is 16.9"):
        env.reset(seed=0)
