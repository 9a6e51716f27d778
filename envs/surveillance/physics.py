"""The pymunk world: static walls and two velocity-driven disc bodies.

Each agent is a small disc (radius ``body_radius``) whose centre is the point the
surveillance rules talk about. Walls are zero-radius static segments, one per wall
edge of the :class:`~envs.maps.Map`. Every step the commanded velocities (already
clipped to the speed bounds by the env) are imposed at the start of the step, so

* in open space a body moves exactly ``v * dt`` per step (no damping, no gravity, no
  acceleration limit: the commanded velocity *is* the velocity);
* against a wall the contact solver removes the normal component, so bodies slide
  (friction and elasticity are zero) for the rest of the step; the next step imposes
  the command afresh;
* the substep count is chosen so that a body moves at most
  :data:`MAX_SUBSTEP_TRAVEL` body radii per substep, which keeps a disc from
  tunnelling through a zero-thickness wall and keeps its centre in free space.

The two bodies share a non-zero collision group, so they pass through each other: the
game has no capture and the rod length may go to zero only through a rule violation,
which the rules report as ``"too_close"``.

The space is rebuilt by :meth:`World.reset`, so an episode replays bit-identically
from its seed and actions (Chipmunk caches contacts between steps; a fresh space
forgets them).
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from envs.errors import InvalidConfigError
from envs.maps import Map

__all__ = ["MAX_SUBSTEPS", "MAX_SUBSTEP_TRAVEL", "World", "check_step", "substeps_for"]

MAX_SUBSTEP_TRAVEL = 0.5
"""Largest distance a body may travel in one substep, as a fraction of its radius.

A disc whose centre moves less than its radius per substep is detected touching a
wall before its centre can cross it. Positions are integrated before contacts are
solved, so a disc driven into a wall overlaps it by up to one substep's travel: half a
radius keeps the centre at least half a radius inside free space, with the fewest
substeps (each costs a ``Space.step``).
"""

MAX_SUBSTEPS = 100_000
"""Most physics substeps an env step may take. A substep (one ``Space.step`` of two discs)
costs about 1 us (measured: 0.99-1.07 us at 200 and 20,000 substeps a step, 3.3 us at 2),
so this is about 0.1 s of physics a step, a minute for a 600-step episode, against 7 us a
step at the defaults. ``body_radius = 1e-12`` asked for 2e11 substeps a step and hung."""

COLLISION_SLOP_FRACTION = 0.01
"""Overlap Chipmunk tolerates before pushing back, as a fraction of the body radius."""

_AGENT_GROUP = 1  # shapes in one non-zero group never collide with each other


def substeps_for(max_speed: float, dt: float, body_radius: float, *, v0: bool = False) -> int:
    """Number of physics substeps per env step so no body outruns its radius.

    The command is imposed at the start of each step, and Chipmunk removes half of an
    overlap a substep (``collision_bias``): a body pressed into a wall by a travel t a
    substep settles at an overlap of t (1/2)^(n-1) / (1 - (1/2)^n) with n substeps a
    step (the substeps after the first only slide). With n >= 2 that is at most 2t/3,
    a third of the radius; with n = 1 it is 2t, and at t = half a radius the centre
    reaches the wall and the body passes through it (dt = 0.05 at the defaults: a
    pursuer driven into the corridor's wall left the map). So one substep is taken
    only while 2t plus Chipmunk's slop (:data:`COLLISION_SLOP_FRACTION`) stays within
    ``MAX_SUBSTEP_TRAVEL * body_radius``, as with two or more, else two. ``v0`` keeps
    the retired env's rule (one substep up to ``MAX_SUBSTEP_TRAVEL * body_radius``), so
    that v0 replays.

    Args:
        max_speed: the larger of the two speed bounds.
        dt: env step duration.
        body_radius: disc radius of both agents.
        v0: the retired v0's rule.

    Returns:
        The smallest n >= 1 with ``max_speed * dt / n <= MAX_SUBSTEP_TRAVEL * body_radius``,
        and 2 when that is 1 but a pressed body would overlap a wall by more (unless v0).

    Examples:
        >>> substeps_for(1.0, 0.1, 0.1), substeps_for(1.0, 0.05, 0.1), substeps_for(1.0, 0.024, 0.1)
        (2, 2, 1)
        >>> substeps_for(1.0, 0.05, 0.1, v0=True)
        1
    """
    travel = max_speed * dt / (MAX_SUBSTEP_TRAVEL * body_radius)
    # the small relative slack keeps 4.000000000000001 from becoming 5
    n = max(1, math.ceil(travel * (1.0 - 1e-12)))
    one = (MAX_SUBSTEP_TRAVEL - COLLISION_SLOP_FRACTION) / (2.0 * MAX_SUBSTEP_TRAVEL)
    if n == 1 and not v0 and travel * (1.0 - 1e-12) > one:  # at defaults dt > 0.0245
        return 2
    return n


def check_step(
    world_map: Map, dt: float, max_speed: float, body_radius: float | None = None
) -> None:
    """Refuse a step in which a body could cross the map (``max_speed * dt`` beyond its
    diameter): the substeps grow as V dt (``v_pursuer = 1e6`` hung on 2e6 a step), and the
    sweep's linear motion within the step no longer follows bodies stopped by the walls
    (``dt = 100`` timed a break 20 times late). With ``body_radius``, also a step that
    needs more than :data:`MAX_SUBSTEPS` substeps (they grow as V dt / radius). Callers
    that validate a config before building an env (tournament specs) call it too.

    Raises:
        InvalidConfigError: naming dt, the speed and the largest dt that fits, or the
            radius, the substeps and the smallest radius that fits.
    """
    if max_speed * dt > world_map.diameter:
        raise InvalidConfigError(
            f"dt = {dt!r} with max(v_pursuer, v_evader) = {max_speed!r}: a body would "
            f"cross map {world_map.name!r} (diameter {world_map.diameter:.4g}) in one "
            "step; expected max(v_pursuer, v_evader) dt <= the map's diameter, i.e. "
            f"dt <= {world_map.diameter / max_speed:.4g}"
        )
    if body_radius is None:
        return
    travel = max_speed * dt
    reach = MAX_SUBSTEP_TRAVEL * body_radius  # 0.0 for the subnormal 5e-324: need is inf
    need = travel / reach if reach > 0.0 else math.inf  # inf for a radius of 1e-320
    if need * (1.0 - 1e-12) > MAX_SUBSTEPS:  # substeps_for's slack: 2e-06 fits exactly
        raise InvalidConfigError(
            f"body_radius = {body_radius!r} with max(v_pursuer, v_evader) dt = {travel:g}: "
            f"a step would take {need:.3g} physics substeps (a body moves at most "
            f"{MAX_SUBSTEP_TRAVEL:g} of its radius a substep, so as not to pass through a "
            f"wall), more than {MAX_SUBSTEPS:,} (about 0.1 s a step); expected body_radius "
            f">= {travel / (MAX_SUBSTEPS * MAX_SUBSTEP_TRAVEL):.3g}, or a smaller dt or speed"
        )


class World:
    """A pymunk space holding the map's walls and the pursuer and evader discs.

    Args:
        world_map: the map whose wall edges become static segments.
        body_radius: disc radius of both agents.
        dt: env step duration.
        max_speed: the larger speed bound, which fixes the substep count.
        v0_substeps: count the substeps as the retired v0 did (:func:`substeps_for`).

    Raises:
        InvalidConfigError: ``max_speed * dt`` exceeds the map's diameter, or the step
            needs more than :data:`MAX_SUBSTEPS` substeps.
    """

    def __init__(
        self,
        world_map: Map,
        body_radius: float,
        dt: float,
        max_speed: float,
        *,
        v0_substeps: bool = False,
    ) -> None:
        check_step(world_map, dt, max_speed, body_radius)
        self.map = world_map
        self.body_radius = float(body_radius)
        self.dt = float(dt)
        self.n_substeps = substeps_for(max_speed, dt, body_radius, v0=v0_substeps)
        self.substep_dt = self.dt / self.n_substeps
        # plain Python tuples: pymunk's constructors are faster on them than on arrays
        self._walls = [
            (tuple(map(float, a)), tuple(map(float, b)))
            for a, b in zip(world_map.edge_start, world_map.edge_end, strict=True)
        ]
        self.space: pymunk.Space | None = None
        self._pursuer: pymunk.Body | None = None
        self._evader: pymunk.Body | None = None

    def reset(self, pursuer: np.ndarray, evader: np.ndarray) -> None:
        """Build a fresh space with both bodies at rest at the given centres."""
        space = pymunk.Space(threaded=False)
        space.gravity = (0.0, 0.0)
        space.damping = 1.0  # fraction of velocity kept per second: no damping
        space.collision_slop = COLLISION_SLOP_FRACTION * self.body_radius
        # Chipmunk removes the fraction 1 - collision_bias**h of an overlap per substep
        # of length h; remove half of it each substep (the default is ~15% at h = 0.025)
        space.collision_bias = 0.5 ** (1.0 / self.substep_dt)
        static = space.static_body
        segments = []
        for a, b in self._walls:
            seg = pymunk.Segment(static, a, b, 0.0)
            seg.elasticity = 0.0
            seg.friction = 0.0
            segments.append(seg)
        space.add(*segments)
        self._pursuer = self._make_body(space, pursuer)
        self._evader = self._make_body(space, evader)
        # a contact in a substep (pre_solve: the shapes touch) marks the motion from then
        # on as the solver's, not the command's (see step's trace)
        space.on_collision(pre_solve=self._touching)
        self._hit = False  # a contact in the current substep
        self._carry = False  # one in the last substep of the previous step
        self._at = (self._pursuer.position, self._evader.position)
        self.space = space
        # the episode so far, for __deepcopy__: its start and each step's commands
        self._start = ((float(pursuer[0]), float(pursuer[1])), (float(evader[0]), float(evader[1])))
        self._commands: list = []

    def _touching(self, arbiter, space, data) -> None:
        self._hit = True

    def _make_body(self, space: pymunk.Space, centre: np.ndarray) -> pymunk.Body:
        body = pymunk.Body(1.0, math.inf)  # infinite moment: discs never spin
        body.position = (float(centre[0]), float(centre[1]))
        shape = pymunk.Circle(body, self.body_radius)
        shape.elasticity = 0.0
        shape.friction = 0.0
        shape.filter = pymunk.ShapeFilter(group=_AGENT_GROUP)
        space.add(body, shape)
        return body

    def step(
        self,
        pursuer_velocity: tuple[float, float],
        evader_velocity: tuple[float, float],
        trace: list | None = None,
    ) -> tuple[tuple[float, float], tuple[float, float]]:
        """Advance one env step with constant commanded velocities.

        Args:
            pursuer_velocity: commanded pursuer velocity (already within its bound).
            evader_velocity: commanded evader velocity (already within its bound).
            trace: if given, a list that receives the centres ``((px, py), (ex, ey))``
                after each substep (the last one is the step's end) when a body touched
                a wall within the step: the path the env's sweep follows. It stays empty
                when neither did (both moved by the command: the chord is the path).

        Returns:
            The new pursuer and evader centres as ``(x, y)`` tuples.
        """
        space, pb, eb = self.space, self._pursuer, self._evader
        if space is None or pb is None or eb is None:
            raise RuntimeError("World.step called before World.reset")
        # The command is set once per step. Chipmunk integrates positions before it
        # solves contacts, so a body pressed into a wall overlaps it by at most one
        # substep's travel before the solver removes the normal velocity; the rest of
        # the step it slides with the tangential part. Re-imposing the command every
        # substep would need a Python velocity callback per body and substep (it
        # doubled the step cost) or would discard the solver's correction and push
        # bodies through walls.
        self._commands.append((pursuer_velocity, evader_velocity, trace is not None))
        pb.velocity = pursuer_velocity
        eb.velocity = evader_velocity
        h = self.substep_dt
        n = self.n_substeps
        if trace is None:
            for _ in range(n):
                space.step(h)
        else:
            # Until a body touches a wall, Chipmunk moves it by exactly p += v h each
            # substep (no damping, no force, no bias velocity): such a step needs no
            # trace (the chord is the path), and in a step with a contact the substeps
            # before it are computed here, bit for bit, rather than read (a read costs
            # about 1 us). A contact in the last substep of the previous step leaves a
            # bias velocity for the first one of this step, so it counts as touching too.
            hit = self._carry
            k = 0  # substeps done
            self._hit = False
            if not hit:
                while k < n:
                    space.step(h)
                    k += 1
                    if self._hit:
                        hit = True
                        break
            if hit:
                (px, py), (ex, ey) = self._at
                pvx, pvy = pursuer_velocity
                evx, evy = evader_velocity
                for _ in range(k - 1):  # before the first contact: the command's motion
                    px, py = px + pvx * h, py + pvy * h
                    ex, ey = ex + evx * h, ey + evy * h
                    trace.append(((px, py), (ex, ey)))
                if k:  # the substep of the first contact (none when carried over)
                    p, e = pb.position, eb.position
                    trace.append(((p.x, p.y), (e.x, e.y)))
                for _ in range(n - k):
                    self._hit = False
                    space.step(h)
                    p, e = pb.position, eb.position
                    trace.append(((p.x, p.y), (e.x, e.y)))
        self._carry = trace is None or self._hit  # untraced: unknown, so assumed
        p = pb.position
        e = eb.position
        self._at = (p, e)
        return (p.x, p.y), (e.x, e.y)

    def __deepcopy__(self, memo: dict) -> World:
        """A world in the same state, rebuilt by replaying the episode's commands from its
        start (bit for bit: :meth:`reset` builds a fresh space). Copying the pymunk space
        instead loses what Chipmunk keeps between steps in contact (cached impulses, bias
        velocities): a copy taken against a wall drifted by 8e-3 within 15 steps.
        """
        new = World.__new__(World)
        memo[id(self)] = new
        new.__dict__.update(
            map=self.map,
            body_radius=self.body_radius,
            dt=self.dt,
            n_substeps=self.n_substeps,
            substep_dt=self.substep_dt,
            _walls=self._walls,
            space=None,
            _pursuer=None,
            _evader=None,
        )
        if self.space is not None:
            new.reset(*self._start)
            for pursuer_velocity, evader_velocity, traced in self._commands:
                new.step(pursuer_velocity, evader_velocity, [] if traced else None)
        return new

    def positions(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Current pursuer and evader centres."""
        if self._pursuer is None or self._evader is None:
            raise RuntimeError("World.positions called before World.reset")
        p = self._pursuer.position
        e = self._evader.position
        return (p.x, p.y), (e.x, e.y)
