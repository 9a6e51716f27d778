"""The frozen, validated configuration of a ``surveillance_v0`` environment.

The factories (:func:`envs.surveillance.env.parallel_env` and friends) take flat keyword
arguments and normalise them into one :class:`EnvConfig`; every later computation reads
that object, never the raw arguments. Bad values raise
:class:`~envs.errors.InvalidConfigError` naming the value and the expected range.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError
from envs.maps import Map, load_map

__all__ = [
    "OBSERVATION_KINDS",
    "RENDER_MODES",
    "REWARD_KINDS",
    "EnvConfig",
    "resolve_map",
]

OBSERVATION_KINDS = ("state", "lidar")
"""``"state"``: the full normalised state; ``"lidar"``: egocentric ray distances."""

REWARD_KINDS = ("zero_sum", "sparse")
"""See :mod:`envs.surveillance.rules` for both reward schemes."""

RENDER_MODES = ("human", "rgb_array")
"""Render modes the env supports (``None`` renders nothing)."""


def resolve_map(value: Map | str | os.PathLike[str]) -> Map:
    """Return ``value`` as a :class:`Map`: a Map as is, a name or path via ``load_map``.

    Raises:
        InvalidConfigError: ``value`` is neither a Map, a string nor a path.
    """
    if isinstance(value, Map):
        return value
    if isinstance(value, (str, os.PathLike)):
        return load_map(value)
    raise InvalidConfigError(
        f"map: expected a Map, a built-in map name or a path to a map file, "
        f"got {type(value).__name__} {value!r}"
    )


def _real(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidConfigError(
            f"{name}: expected a real number, got {type(value).__name__} {value!r}"
        )
    value = float(value)
    if not math.isfinite(value):
        raise InvalidConfigError(f"{name}: expected a finite number, got {value!r}")
    return value


def _positive(name: str, value: Any) -> float:
    v = _real(name, value)
    if v <= 0:
        raise InvalidConfigError(f"{name}: expected a value > 0, got {value!r}")
    return v


def _integer(name: str, value: Any, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidConfigError(
            f"{name}: expected an integer >= {minimum}, got {type(value).__name__} {value!r}"
        )
    if int(value) < minimum:
        raise InvalidConfigError(f"{name}: expected an integer >= {minimum}, got {value!r}")
    return int(value)


def _choice(name: str, value: Any, options: tuple[str, ...]) -> str:
    if value not in options:
        raise InvalidConfigError(f"{name}: expected one of {list(options)}, got {value!r}")
    return str(value)


@dataclass(frozen=True)
class EnvConfig:
    """Every parameter of a surveillance episode, validated once.

    Attributes:
        map: the world (a :class:`Map`; a built-in name or a file path is resolved with
            :func:`envs.maps.load_map`).
        l_min: L_min, the sensor's minimum range (> 0).
        l_max: L_max, the sensor's maximum range (> l_min).
        v_pursuer: V_p, the pursuer's speed bound (> 0).
        v_evader: V_e, the evader's speed bound (> 0); rho = V_e / V_p.
        dt: duration of one env step (> 0).
        max_cycles: steps before the episode is truncated (>= 1).
        observation: ``"state"`` or ``"lidar"`` (see :mod:`.observations`).
        n_rays: lidar rays per agent (>= 1; used by ``"lidar"`` only).
        lidar_range: range at which lidar rays saturate (> 0); ``None`` means ``l_max``.
        reward: ``"zero_sum"`` or ``"sparse"`` (see :mod:`.rules`).
        body_radius: radius of both agents' discs, in (0, l_min / 2).
        spawn_margin_steps: random starts survive any actions for at least this many
            steps (>= 0; see ``parallel_env.reset``).
        render_mode: ``None``, ``"human"`` or ``"rgb_array"``.
    """

    map: Map
    l_min: float = 2.0
    l_max: float = 4.0
    v_pursuer: float = 1.0
    v_evader: float = 0.5
    dt: float = 0.1
    max_cycles: int = 500
    observation: str = "state"
    n_rays: int = 32
    lidar_range: float | None = None
    reward: str = "zero_sum"
    body_radius: float = 0.1
    spawn_margin_steps: int = 3
    render_mode: str | None = None

    def __post_init__(self) -> None:
        put = lambda name, value: object.__setattr__(self, name, value)
        put("map", resolve_map(self.map))
        put("l_min", _positive("l_min", self.l_min))
        put("l_max", _positive("l_max", self.l_max))
        if self.l_max <= self.l_min:
            raise InvalidConfigError(
                f"l_max: expected a value > l_min = {self.l_min!r}, got {self.l_max!r}"
            )
        put("v_pursuer", _positive("v_pursuer", self.v_pursuer))
        put("v_evader", _positive("v_evader", self.v_evader))
        put("dt", _positive("dt", self.dt))
        put("max_cycles", _integer("max_cycles", self.max_cycles, 1))
        put("observation", _choice("observation", self.observation, OBSERVATION_KINDS))
        put("n_rays", _integer("n_rays", self.n_rays, 1))
        if self.lidar_range is not None:
            put("lidar_range", _positive("lidar_range", self.lidar_range))
        put("reward", _choice("reward", self.reward, REWARD_KINDS))
        put("body_radius", _positive("body_radius", self.body_radius))
        if self.body_radius >= 0.5 * self.l_min:
            raise InvalidConfigError(
                f"body_radius: expected a value in (0, l_min / 2 = {0.5 * self.l_min!r}), "
                f"got {self.body_radius!r}"
            )
        put("spawn_margin_steps", _integer("spawn_margin_steps", self.spawn_margin_steps, 0))
        if self.render_mode is not None:
            put("render_mode", _choice("render_mode", self.render_mode, RENDER_MODES))

    # ---------------------------------------------------------------- derived values
    @property
    def rho(self) -> float:
        """rho = V_e / V_p, the speed ratio of the paper (Sec. 5)."""
        return self.v_evader / self.v_pursuer

    @property
    def lidar_max_range(self) -> float:
        """Range at which lidar rays saturate (``lidar_range`` or ``l_max``)."""
        return self.l_max if self.lidar_range is None else self.lidar_range

    def speed(self, role: str) -> float:
        """Speed bound of ``"pursuer"`` or ``"evader"``."""
        return self.v_pursuer if role == "pursuer" else self.v_evader

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready record of the configuration (the map by name and digest)."""
        return {
            "map": self.map.name,
            "map_digest": self.map.digest,
            "l_min": self.l_min,
            "l_max": self.l_max,
            "v_pursuer": self.v_pursuer,
            "v_evader": self.v_evader,
            "dt": self.dt,
            "max_cycles": self.max_cycles,
            "observation": self.observation,
            "n_rays": self.n_rays,
            "lidar_range": self.lidar_range,
            "reward": self.reward,
            "body_radius": self.body_radius,
            "spawn_margin_steps": self.spawn_margin_steps,
            "render_mode": self.render_mode,
        }
