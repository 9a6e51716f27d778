"""Observation layouts, spaces, encoders and the decoder analytic policies use.

Two kinds (``EnvConfig.observation``):

``"state"`` -- the full state, the same vector for both agents (the agent knows its
name, so no role bit), laid out as :data:`STATE_LAYOUT`:

=============== ========= ===============================================================
field           slice     normalisation
=============== ========= ===============================================================
pursuer_pos     0:2       map bounds onto [-1, 1]: ``2 (x - x_min) / (x_max - x_min) - 1``
pursuer_vel     2:4       realised mean velocity of the last step / V_p, clipped to [-1, 1]
evader_pos      4:6       as pursuer_pos
evader_vel      6:8       realised mean velocity of the last step / V_e, clipped to [-1, 1]
theta           8:10      (cos theta, sin theta), theta the direction from evader to pursuer
distance        10:11     |P - E| / L_max, in [0, diagonal / L_max]
visible         11:12     1.0 when surveillance holds at this instant, else 0.0
time            12:13     steps taken / max_cycles, in [0, 1]
=============== ========= ===============================================================

The realised velocity is (displacement over the last step) / dt: the commanded
velocity in open space, its tangential part along a wall. Contact correction can add a
displacement of the order of the collision slop, hence the clip. At reset both are 0.

``"lidar"`` -- egocentric and partial, :func:`lidar_layout`: ``n_rays`` ray distances
from the agent's centre at angles ``2 pi k / n_rays`` (world-aligned axes: a disc has no
heading) divided by the lidar range and saturating at 1; the other agent's position
relative to this one divided by L_max (zeros when not visible); the agent's own
realised velocity divided by its speed bound; the visibility bit (surveillance holds);
the time fraction. The relative vector is zero padded *and* masked by the explicit bit,
since a zero vector alone would be ambiguous.

``"lidar_track"`` -- the lidar plus what a tracker locked on the other agent reports:
its realised velocity divided by *its* speed bound (``other_vel``, after ``other_rel``;
zeros when not visible), :func:`lidar_layout` with ``track=True``. Still egocentric and
free of map coordinates, and it carries what the analytic policies act on (the
decomposition pursuer matches the evader's velocity, eq. 5), so a learner imitating them
can see it.

``state()`` (for centralised critics) is the ``"state"`` vector whatever the agents see.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from gymnasium.spaces import Box

from envs.surveillance.config import EnvConfig

__all__ = [
    "STATE_LAYOUT",
    "STATE_SIZE",
    "LidarEncoder",
    "StateEncoder",
    "StateView",
    "decode_state",
    "lidar_layout",
    "lidar_space",
    "observation_size",
    "state_space",
]

STATE_LAYOUT: dict[str, slice] = {
    "pursuer_pos": slice(0, 2),
    "pursuer_vel": slice(2, 4),
    "evader_pos": slice(4, 6),
    "evader_vel": slice(6, 8),
    "theta": slice(8, 10),
    "distance": slice(10, 11),
    "visible": slice(11, 12),
    "time": slice(12, 13),
}
"""Where each field lives in a ``"state"`` observation (and in ``state()``)."""

STATE_SIZE = 13


def lidar_layout(n_rays: int, track: bool = False) -> dict[str, slice]:
    """Where each field lives in a ``"lidar"`` (``"lidar_track"``: ``track``) observation.

    Examples:
        >>> lidar_layout(4)["other_rel"]
        slice(4, 6, None)
        >>> lidar_layout(4, track=True)["other_vel"], lidar_layout(4, track=True)["time"]
        (slice(6, 8, None), slice(11, 12, None))
    """
    n = int(n_rays)
    if track:
        return {
            "rays": slice(0, n),
            "other_rel": slice(n, n + 2),
            "other_vel": slice(n + 2, n + 4),
            "self_vel": slice(n + 4, n + 6),
            "visible": slice(n + 6, n + 7),
            "time": slice(n + 7, n + 8),
        }
    return {
        "rays": slice(0, n),
        "other_rel": slice(n, n + 2),
        "self_vel": slice(n + 2, n + 4),
        "visible": slice(n + 4, n + 5),
        "time": slice(n + 5, n + 6),
    }


def observation_size(observation: str, n_rays: int) -> int:
    """How many numbers an ``observation`` (``EnvConfig.observation``) of ``n_rays`` rays
    holds (``n_rays`` is not read for ``"state"``).

    Examples:
        >>> observation_size("state", 32), observation_size("lidar", 32)
        (13, 38)
        >>> observation_size("lidar_track", 32)
        40
    """
    if observation == "state":
        return STATE_SIZE
    return lidar_layout(n_rays, track=observation == "lidar_track")["time"].stop


def _max_distance_ratio(config: EnvConfig) -> float:
    xmin, ymin, xmax, ymax = config.map.bounds
    return math.hypot(xmax - xmin, ymax - ymin) / config.l_max


def state_space(config: EnvConfig) -> Box:
    """The Box of ``"state"`` observations (a new object each call: store it)."""
    low = np.full(STATE_SIZE, -1.0, dtype=np.float32)
    high = np.full(STATE_SIZE, 1.0, dtype=np.float32)
    for name in ("distance", "visible", "time"):
        low[STATE_LAYOUT[name]] = 0.0
    high[STATE_LAYOUT["distance"]] = np.float32(_max_distance_ratio(config)) * np.float32(
        1.0 + 1e-6
    )
    return Box(low=low, high=high, dtype=np.float32)


def lidar_space(config: EnvConfig) -> Box:
    """The Box of ``"lidar"`` / ``"lidar_track"`` observations (a new object each call)."""
    layout = lidar_layout(config.n_rays, track=config.observation == "lidar_track")
    size = observation_size(config.observation, config.n_rays)
    low = np.full(size, -1.0, dtype=np.float32)
    high = np.full(size, 1.0, dtype=np.float32)
    for name in ("rays", "visible", "time"):
        low[layout[name]] = 0.0
    return Box(low=low, high=high, dtype=np.float32)


def _clip1(x: float) -> float:
    return -1.0 if x < -1.0 else (1.0 if x > 1.0 else x)


@dataclass(frozen=True)
class StateView:
    """A ``"state"`` observation decoded into named, de-normalised fields.

    Attributes:
        pursuer_pos, evader_pos: positions in map coordinates, shape (2,).
        pursuer_vel, evader_vel: realised velocities over the last step, shape (2,).
        theta: direction from evader to pursuer (radians, in [-pi, pi]).
        distance: |P - E|.
        visible: surveillance holds at this instant.
        step: steps taken so far.
        time: ``step * dt``.
    """

    pursuer_pos: np.ndarray
    pursuer_vel: np.ndarray
    evader_pos: np.ndarray
    evader_vel: np.ndarray
    theta: float
    distance: float
    visible: bool
    step: int
    time: float


class StateEncoder:
    """Builds ``"state"`` vectors; normalisation constants are computed once.

    Args:
        config: the env configuration.
    """

    def __init__(self, config: EnvConfig) -> None:
        xmin, ymin, xmax, ymax = config.map.bounds
        self.cx = 0.5 * (xmin + xmax)
        self.cy = 0.5 * (ymin + ymax)
        self.sx = 2.0 / (xmax - xmin)
        self.sy = 2.0 / (ymax - ymin)
        self.inv_vp = 1.0 / config.v_pursuer
        self.inv_ve = 1.0 / config.v_evader
        self.inv_lmax = 1.0 / config.l_max
        self.inv_cycles = 1.0 / config.max_cycles

    def encode(
        self,
        p: tuple[float, float],
        vp: tuple[float, float],
        e: tuple[float, float],
        ve: tuple[float, float],
        visible: bool,
        step: int,
    ) -> np.ndarray:
        """The ``"state"`` vector for positions, realised velocities, visibility and step."""
        dx = p[0] - e[0]
        dy = p[1] - e[1]
        d = math.hypot(dx, dy)
        if d > 0.0:
            c, s = dx / d, dy / d
        else:  # the bodies do not collide with each other, so they may coincide
            c, s = 1.0, 0.0
        return np.array(
            (
                (p[0] - self.cx) * self.sx,
                (p[1] - self.cy) * self.sy,
                _clip1(vp[0] * self.inv_vp),
                _clip1(vp[1] * self.inv_vp),
                (e[0] - self.cx) * self.sx,
                (e[1] - self.cy) * self.sy,
                _clip1(ve[0] * self.inv_ve),
                _clip1(ve[1] * self.inv_ve),
                c,
                s,
                d * self.inv_lmax,
                1.0 if visible else 0.0,
                step * self.inv_cycles,
            ),
            dtype=np.float32,
        )


def decode_state(obs: np.ndarray, config: EnvConfig) -> StateView:
    """Decode a ``"state"`` observation (or ``state()``) into a :class:`StateView`.

    Args:
        obs: a vector laid out as :data:`STATE_LAYOUT`.
        config: the configuration of the env that produced it.

    Returns:
        The de-normalised fields (exact up to float32 rounding of the observation).
    """
    o = np.asarray(obs, dtype=np.float64)
    if o.shape != (STATE_SIZE,):
        raise ValueError(
            f"decode_state: expected a state vector of shape ({STATE_SIZE},), got {o.shape}"
        )
    # Python floats: the same IEEE operations in the same order as the vectorised form
    # (lo + (o + 1) * half), a few times faster on 13 numbers (analytic policies decode
    # every step)
    px, py, pvx, pvy, ex, ey, evx, evy, c, s, d, vis, t = o.tolist()
    xmin, ymin, xmax, ymax = config.map.bounds
    hx, hy = 0.5 * (xmax - xmin), 0.5 * (ymax - ymin)
    step = round(t * config.max_cycles)
    return StateView(
        pursuer_pos=np.array((xmin + (px + 1.0) * hx, ymin + (py + 1.0) * hy)),
        pursuer_vel=np.array((pvx * config.v_pursuer, pvy * config.v_pursuer)),
        evader_pos=np.array((xmin + (ex + 1.0) * hx, ymin + (ey + 1.0) * hy)),
        evader_vel=np.array((evx * config.v_evader, evy * config.v_evader)),
        theta=math.atan2(s, c),
        distance=d * config.l_max,
        visible=bool(vis >= 0.5),
        step=step,
        time=step * config.dt,
    )


class LidarEncoder:
    """Builds ``"lidar"`` (or ``"lidar_track"``, by ``config.observation``) vectors.

    Args:
        config: the env configuration.
        role: ``"pursuer"`` or ``"evader"`` (whose velocity bound normalises ``self_vel``).
        kernel: the geometry kernel, for ``ray_distances``.
    """

    def __init__(self, config: EnvConfig, role: str, kernel: object) -> None:
        self.kernel = kernel
        self.n = config.n_rays
        self.angles = 2.0 * np.pi * np.arange(self.n) / self.n
        self.angles.setflags(write=False)
        self.max_range = config.lidar_max_range
        self.inv_range = 1.0 / self.max_range
        self.inv_speed = 1.0 / config.speed(role)
        self.track = config.observation == "lidar_track"
        self.inv_other_speed = 1.0 / config.speed("evader" if role == "pursuer" else "pursuer")
        self.size = self.n + (8 if self.track else 6)
        self.inv_lmax = 1.0 / config.l_max
        self.inv_cycles = 1.0 / config.max_cycles

    def encode(
        self,
        me: tuple[float, float],
        my_vel: tuple[float, float],
        other: tuple[float, float],
        visible: bool,
        step: int,
        other_vel: tuple[float, float] = (0.0, 0.0),
    ) -> np.ndarray:
        """The vector of the agent at ``me`` looking for ``other`` (moving at ``other_vel``,
        read by ``"lidar_track"`` only)."""
        n = self.n
        out = np.empty(self.size, dtype=np.float32)
        rays = self.kernel.ray_distances(np.array(me), self.angles, self.max_range)
        np.minimum(np.asarray(rays) * self.inv_range, 1.0, out=out[:n], casting="unsafe")
        if visible:
            out[n] = _clip1((other[0] - me[0]) * self.inv_lmax)
            out[n + 1] = _clip1((other[1] - me[1]) * self.inv_lmax)
        else:
            out[n] = 0.0
            out[n + 1] = 0.0
        if self.track:
            if visible:
                out[n + 2] = _clip1(other_vel[0] * self.inv_other_speed)
                out[n + 3] = _clip1(other_vel[1] * self.inv_other_speed)
            else:
                out[n + 2] = 0.0
                out[n + 3] = 0.0
            n += 2
        out[n + 2] = _clip1(my_vel[0] * self.inv_speed)
        out[n + 3] = _clip1(my_vel[1] * self.inv_speed)
        out[n + 4] = 1.0 if visible else 0.0
        out[n + 5] = step * self.inv_cycles
        return out

    def encode_state(self, state: np.ndarray, state_config: EnvConfig, role: str) -> np.ndarray:
        """The lidar vector ``role`` would see in the state ``state``.

        For learners that see lidar while a teacher reads the ``"state"`` vector of the
        same instant (DAgger labels with an analytic expert): the rays are cast from the
        decoded position, the relative vector and the visibility bit come from the state,
        and ``self_vel`` is the state's velocity of ``role`` (both are the realised
        velocity over the speed bound, clipped). Equal to the env's own ``"lidar"``
        observation up to the float32 rounding of the positions in ``state``.

        Args:
            state: a ``"state"`` vector (:data:`STATE_LAYOUT`).
            state_config: the config of the env that produced it (its map bounds
                de-normalise the positions).
            role: ``"pursuer"`` or ``"evader"``: whose lidar.
        """
        view = decode_state(state, state_config)
        if role == "pursuer":
            me, other = view.pursuer_pos, view.evader_pos
            vel, ovel = view.pursuer_vel, view.evader_vel
        else:
            me, other = view.evader_pos, view.pursuer_pos
            vel, ovel = view.evader_vel, view.pursuer_vel
        return self.encode(
            (float(me[0]), float(me[1])),
            (float(vel[0]), float(vel[1])),
            (float(other[0]), float(other[1])),
            view.visible,
            view.step,
            (float(ovel[0]), float(ovel[1])),
        )
