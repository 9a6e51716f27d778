"""The pymunk world: exact motion in open space, sliding, no tunnelling, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from envs import surveillance_v1
from envs.errors import InvalidConfigError
from envs.surveillance.physics import MAX_SUBSTEP_TRAVEL, World, substeps_for
from tests.envs.surveillance._worlds import open_room, pillar_room, spiky_room


@pytest.mark.parametrize(
    ("speed", "dt", "radius", "expected"),
    [(1.0, 0.1, 0.1, 2), (1.0, 0.1, 0.05, 4), (0.1, 0.1, 0.1, 1), (3.0, 0.2, 0.1, 12)],
)
def test_substeps_keep_travel_below_a_fraction_of_the_radius(speed, dt, radius, expected) -> None:
    n = substeps_for(speed, dt, radius)
    assert n == expected
    assert speed * dt / n <= MAX_SUBSTEP_TRAVEL * radius * (1 + 1e-12)
    assert n == 1 or speed * dt / (n - 1) > MAX_SUBSTEP_TRAVEL * radius


def test_open_space_motion_is_exactly_the_command() -> None:
    world = World(open_room(), 0.1, 0.1, 1.0)
    p, e = np.array([2.0, 3.0]), np.array([7.0, 6.0])
    world.reset(p, e)
    rng = np.random.default_rng(0)
    for _ in range(30):
        vp = tuple(rng.uniform(-0.7, 0.7, 2))
        ve = tuple(rng.uniform(-0.35, 0.35, 2))
        p1, e1 = world.step(vp, ve)
        assert np.allclose(p1, p + 0.1 * np.array(vp), atol=1e-12, rtol=0)
        assert np.allclose(e1, e + 0.1 * np.array(ve), atol=1e-12, rtol=0)
        p, e = np.array(p1), np.array(e1)


def test_a_body_pushed_into_a_wall_slides_with_the_tangential_part() -> None:
    world = World(open_room(), 0.1, 0.1, 1.0)
    world.reset(np.array([5.0, 0.1]), np.array([5.0, 5.0]))  # pursuer resting on the floor
    x = 5.0
    for _ in range(20):
        (px, py), _ = world.step((0.6, -0.8), (0.0, 0.0))
        assert px == pytest.approx(x + 0.06, abs=1e-9)  # the tangential component only
        assert 0.1 - 0.1 * MAX_SUBSTEP_TRAVEL <= py <= 0.1 + 1e-9  # overlap < a substep
        x = px


def test_bodies_pass_through_each_other() -> None:
    world = World(open_room(), 0.1, 0.1, 1.0)
    world.reset(np.array([4.0, 5.0]), np.array([4.5, 5.0]))
    for _ in range(10):
        p, e = world.step((1.0, 0.0), (-1.0, 0.0))
    assert p == pytest.approx((5.0, 5.0)) and e == pytest.approx((3.5, 5.0))


@pytest.mark.parametrize("seed", range(4))
def test_centres_never_leave_free_space_among_narrow_features(seed: int) -> None:
    """Random, wall-seeking commands on saw teeth, needles and a slit: no tunnelling."""
    world_map = spiky_room()
    r = 0.05
    world = World(world_map, r, 0.1, 2.0)
    rng = np.random.default_rng(seed)
    p, e = np.array([3.0, 4.0]), np.array([8.5, 1.5])
    world.reset(p, e)
    centres = []
    heading = rng.uniform(0, 2 * math.pi, 2)
    for step in range(600):
        if step % 15 == 0:  # hold a heading for a while, so bodies press into walls
            heading = rng.uniform(0, 2 * math.pi, 2)
        speed = rng.uniform(0.5, 1.0, 2) * (2.0, 1.0)
        vp = (speed[0] * math.cos(heading[0]), speed[0] * math.sin(heading[0]))
        ve = (speed[1] * math.cos(heading[1]), speed[1] * math.sin(heading[1]))
        p1, e1 = world.step(vp, ve)
        # never faster than commanded (no solver kick)
        assert math.dist(p1, p) <= 2.0 * 0.1 * (1 + 1e-9) + 0.01 * r
        assert math.dist(e1, e) <= 1.0 * 0.1 * (1 + 1e-9) + 0.01 * r
        p, e = p1, e1
        centres += [p1, e1]
    pts = np.array(centres)
    assert world_map.contains(pts).all()
    # the disc overlaps a wall by less than one substep's travel
    assert world_map.distance_to_walls(pts).min() >= r * (1 - MAX_SUBSTEP_TRAVEL)
    # and the bodies did reach the walls (the test exercises contacts)
    assert world_map.distance_to_walls(pts).min() <= r * 1.01


def test_rebuilt_space_replays_bit_identically() -> None:
    world_map = pillar_room()
    rng = np.random.default_rng(3)
    commands = rng.uniform(-1, 1, (200, 4))
    runs = []
    for _ in range(2):
        world = World(world_map, 0.1, 0.1, 1.0)
        for _ in range(2):  # the second reset of the same World must replay too
            world.reset(np.array([3.5, 5.0]), np.array([6.5, 2.0]))
            runs.append([world.step(tuple(c[:2]), tuple(0.5 * c[2:])) for c in commands])
    assert runs[0] == runs[1] == runs[2] == runs[3]


def test_step_before_reset_is_an_error() -> None:
    with pytest.raises(RuntimeError, match=r"before World\.reset"):
        World(open_room(), 0.1, 0.1, 1.0).step((0.0, 0.0), (0.0, 0.0))


@pytest.mark.parametrize(("over", "speed"), [({"dt": 100.0}, 1.0), ({"v_pursuer": 1e6}, 1e6)])
@pytest.mark.filterwarnings("ignore::envs.errors.NarrowBandWarning")  # dt 14: on purpose
def test_a_step_that_crosses_the_map_is_refused(over, speed) -> None:
    """v_pursuer = 1e6 hung (2e6 physics substeps a step); dt = 100 timed the break of a
    pursuer and evader running apart at 12.6 s instead of 0.58 s (both stopped by the
    walls long before the step's end, the sweep taking their motion as linear); the start
    margins also covered the map ("no valid start found on map 'corridor'")."""
    from envs import surveillance_v0

    world = open_room()  # 10 x 10: diameter 14.14
    with pytest.raises(InvalidConfigError, match=(
        rf"^dt = {over.get('dt', 0.1)!r} with max\(v_pursuer, v_evader\) = {speed!r}: a body "
        r"would cross map 'test_open' \(diameter 14.14\) in one step; .* i\.e\. dt <= "
    )):  # fmt: skip
        surveillance_v0.parallel_env(map=world, l_min=2.0, l_max=4.0, v_evader=0.5, **over)
    env = surveillance_v0.parallel_env(map=world, l_min=2.0, l_max=4.0, v_evader=0.5, dt=14.0)
    env.close()  # a step within the map's diameter is the user's choice


@pytest.mark.parametrize("radius", [1e-12, 1e-300, 5e-324])
def test_a_step_of_too_many_substeps_is_refused(radius) -> None:
    """``surveil play --config '{"body_radius": 1e-12}'`` hung: 2e11 physics substeps a
    step (a body moves at most half its radius a substep). Refused beyond MAX_SUBSTEPS,
    naming the smallest radius that fits, which builds. The subnormal 5e-324 (half of it
    is 0.0) raised ZeroDivisionError from the env's constructor instead."""
    from envs.surveillance.physics import MAX_SUBSTEPS

    refused = (
        rf"^body_radius = {radius!r} with max\(v_pursuer, v_evader\) dt = 0.1: a step would "
        r"take (?:[\d.e+]+|inf) physics substeps .* more than 100,000 .* expected body_radius "
        r">= 2e-06"
    )
    with pytest.raises(InvalidConfigError, match=refused):
        World(open_room(), radius, 0.1, 1.0)
    with pytest.raises(InvalidConfigError, match=refused):  # through the env's config
        surveillance_v1.parallel_env(map=open_room(), body_radius=radius)
    assert World(open_room(), 2e-6, 0.1, 1.0).n_substeps == MAX_SUBSTEPS


def test_the_trace_holds_each_substep_of_a_step_with_a_contact() -> None:
    world = World(open_room(), 0.1, 0.1, 1.0)  # 2 substeps of 0.05 s
    world.reset(np.array([5.0, 5.0]), np.array([3.0, 5.0]))
    trace: list = []
    world.step((1.0, 0.0), (0.0, -0.5), trace)
    assert trace == []  # no wall touched: the chord is the path
    world.reset(np.array([9.82, 5.0]), np.array([3.0, 5.0]))  # the wall at x = 10
    p, e = world.step((1.0, 0.0), (0.0, -0.5), trace)
    assert len(trace) == world.n_substeps == 2
    assert trace[-1] == (p, e)  # the second substep touched the wall
    assert np.allclose(trace[0][0], (9.87, 5.0)) and np.allclose(trace[0][1], (3.0, 4.975))


@pytest.mark.parametrize(("dt", "speed"), [(0.1, 1.0), (0.37, 1.7), (1.0, 1.0)])
def test_the_trace_is_the_positions_read_after_each_substep(dt, speed) -> None:
    """Until a contact the trace computes p += v h instead of reading the bodies (a read
    costs about 1 us); bit for bit what Chipmunk did, through runs along the walls."""
    world_map = pillar_room()
    a, b = World(world_map, 0.1, dt, speed), World(world_map, 0.1, dt, speed)
    start = (np.array([2.0, 2.0]), np.array([4.0, 6.0]))
    a.reset(*start)
    b.reset(*start)
    rng = np.random.default_rng(3)
    touched = 0
    for k in range(600):
        if k % 25 == 0:  # a heading kept long enough to slide along a wall
            hp, he = rng.uniform(-math.pi, math.pi, 2)
        vp = (speed * math.cos(hp), speed * math.sin(hp))
        ve = (0.5 * math.cos(he), 0.5 * math.sin(he))
        trace: list = []
        p0, e0 = a.positions()
        a.step(vp, ve, trace)
        b._pursuer.velocity, b._evader.velocity = vp, ve
        read = []
        for _ in range(b.n_substeps):
            b.space.step(b.substep_dt)
            p, e = b._pursuer.position, b._evader.position
            read.append(((p.x, p.y), (e.x, e.y)))
        assert trace in ([], read), k  # empty: no contact, the chord is the path
        if not trace:
            h = np.arange(1, b.n_substeps + 1)[:, None] * b.substep_dt
            assert np.allclose([r[0] for r in read], np.add(p0, h * vp), rtol=0, atol=1e-12)
            assert np.allclose([r[1] for r in read], np.add(e0, h * ve), rtol=0, atol=1e-12)
        touched += bool(trace)
    assert 0 < touched < 600  # both kinds of step were met


@pytest.mark.parametrize("dt", [10.0, 1.0, 0.1])
@pytest.mark.filterwarnings("ignore::envs.errors.NarrowBandWarning")  # dt 10: on purpose
def test_a_break_after_a_body_stopped_at_a_wall_is_timed_on_its_path(dt) -> None:
    """Pursuer and evader run apart along the corridor world's room (x in [0, 10]): the
    pursuer, at x = 9.5 with radius 0.1, stops at the wall after 0.4 s (L = 3.6), the
    evader recedes at 0.5, so the range breaks at t = 1.2 s exactly. The sweep took each
    step's motion as linear, so at dt = 10 it said 1.85 s (the chord from 9.5 to 9.9
    over the whole step). Now within one substep's travel (r / 2 = 0.05 of wall
    penetration, the physics' own, 0.1 s at the evader's 0.5) of the truth; a step
    without contact keeps the single sweep. v0, retired, keeps the chord."""
    from envs import surveillance_v0

    def break_at(module) -> float:
        env = module.parallel_env(map="corridor", dt=dt, spawn_margin_steps=0)
        env.reset(seed=0, options={"pursuer": (9.5, 0.0), "evader": (6.5, 0.0)})
        info: dict = {}
        while env.agents:
            _, _, _, _, infos = env.step({"pursuer_0": [1.0, 0.0], "evader_0": [-1.0, 0.0]})
            info = infos["pursuer_0"]
        env.close()
        assert info["cause"] == "too_far"
        return info["break_at"]

    assert 1.2 - 0.1 - 1e-9 <= break_at(surveillance_v1) <= 1.2 + 1e-9
    if dt == 10.0:  # v0's chord: 3 + 0.5 t + 0.04 t = 4 at t = 1.85
        assert break_at(surveillance_v0) == pytest.approx(1.0 / 0.54)


@pytest.mark.parametrize(
    ("speed", "dt", "radius"),
    [(1.0, 0.05, 0.1), (1.0, 0.04, 0.1), (1.0, 0.03, 0.1), (1.0, 0.0245, 0.1), (1.0, 0.01, 0.1),
     (0.5, 0.1, 0.1), (1.0, 0.1, 0.2), (3.0, 0.1, 0.1)],
)  # fmt: skip
@pytest.mark.parametrize("heading", [(-1.0, 0.0), (-math.sqrt(0.5), -math.sqrt(0.5))])
def test_a_body_pressed_into_a_wall_keeps_its_centre_half_a_radius_inside(
    speed: float, dt: float, radius: float, heading: tuple[float, float]
) -> None:
    """Driven into a wall (or a corner) step after step, the disc overlaps it by at most
    half its radius, also with one substep a step. With one substep the overlap settled
    at twice a substep's travel: at dt = 0.05 (defaults) the body passed through the wall
    and left the map; v0 keeps that rule, so that its results replay."""
    world = World(open_room(), radius, dt, speed)
    world.reset(np.array([1.0, 1.0]), np.array([5.0, 5.0]))
    velocity = (speed * heading[0], speed * heading[1])
    centres = [world.step(velocity, (0.0, 0.0))[0] for _ in range(round(3.0 / dt))]
    pts = np.array(centres)
    assert open_room().contains(pts).all()
    assert open_room().distance_to_walls(pts).min() >= radius * (1 - MAX_SUBSTEP_TRAVEL) - 1e-12
    assert open_room().distance_to_walls(pts[-1:]).min() <= radius  # it did press
    if speed * dt <= MAX_SUBSTEP_TRAVEL * radius:  # one substep in v0: the old rule
        assert World(open_room(), radius, dt, speed, v0_substeps=True).n_substeps == 1
