"""The frozen, validated configuration of a ``surveillance_v1`` environment.

The factories (:func:`envs.surveillance.env.parallel_env` and friends) take flat keyword
arguments and normalise them into one :class:`EnvConfig`; every later computation reads
that object, never the raw arguments. Bad values raise
:class:`~envs.errors.InvalidConfigError` naming the value and the expected range.
"""

from __future__ import annotations

import dataclasses
import difflib
import inspect
import os
import sys
import warnings
from dataclasses import dataclass
from typing import Any

from envs import validation as v
from envs.errors import InvalidConfigError, NarrowBandWarning, RhoAboveOneWarning
from envs.maps import Map, load_map
from envs.maps.io import BODY_RADIUS, recommended_parameters
from envs.maps.io import GLOBAL_DEFAULTS as _GLOBAL_DEFAULTS

__all__ = [
    "GLOBAL_DEFAULTS",
    "MAP_PARAMETERS",
    "MAX_RAYS",
    "OBSERVATION_KINDS",
    "RENDER_MODES",
    "REWARD_KINDS",
    "EnvConfig",
    "bind_env_arguments",
    "env_parameters",
    "env_signature",
    "map_recommendations",
    "resolve_map",
]

OBSERVATION_KINDS = ("state", "lidar", "lidar_track")
"""``"state"``: the full normalised state; ``"lidar"``: egocentric ray distances;
``"lidar_track"``: the lidar plus the tracked other agent's velocity."""

REWARD_KINDS = ("zero_sum", "sparse")
"""See :mod:`envs.surveillance.rules` for both reward schemes."""

RENDER_MODES = ("human", "rgb_array")
"""Render modes the env supports (``None`` renders nothing)."""

MAX_RAYS = 4096
"""Upper bound of ``n_rays`` (a lidar of 1e9 rays would exhaust memory before failing)."""


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


MAP_PARAMETERS = ("l_min", "l_max", "v_pursuer", "v_evader")
"""The parameters a built-in map recommends (``envs.maps.builtin_info(name).params()``)."""

GLOBAL_DEFAULTS = _GLOBAL_DEFAULTS
"""Values of :data:`MAP_PARAMETERS` for a Map object, a random map or a map file whose
metadata recommends none."""


def map_recommendations(value: Any) -> dict[str, float]:
    """The recommended :data:`MAP_PARAMETERS` for the map argument ``value``.

    A built-in map *named by a string* brings its own (``envs.maps.builtin_info``), and so
    does a map file named by its path: the ``l_min``, ``l_max``, ``v_pursuer``,
    ``v_evader`` and ``body_radius`` its ``metadata`` gives, the first four defaulting to
    :data:`GLOBAL_DEFAULTS` (``envs.maps.io.file_parameters``). Either is scaled by S when
    the name transforms it (``NAME~xS...``: lengths, speeds and the agents'
    ``body_radius`` scale alike, so the game is the same up to the similarity). A
    :class:`Map` object, a random map or a file recommending nothing gets
    :data:`GLOBAL_DEFAULTS`.

    Examples:
        >>> map_recommendations("corridor")
        {'l_min': 2.0, 'l_max': 4.0, 'v_pursuer': 1.0, 'v_evader': 0.5}
        >>> map_recommendations("corridor~x10rot0.3")
        {'l_min': 20.0, 'l_max': 40.0, 'v_pursuer': 10.0, 'v_evader': 5.0, 'body_radius': 1.0}
    """
    params = recommended_parameters(value)
    return dict(GLOBAL_DEFAULTS) if params is None else params


@dataclass(frozen=True)
class EnvConfig:
    """Every parameter of a surveillance episode, validated once.

    This dataclass is the one source of the env's arguments: the signatures of
    ``parallel_env``, ``raw_env`` and ``env`` are derived from its fields
    (:func:`env_parameters`), and so is the list of ``[env]`` keys a training config
    accepts.

    Attributes:
        map: the world (a :class:`Map`; a built-in name or a file path is resolved with
            :func:`envs.maps.load_map`).
        l_min: L_min, the sensor's minimum range (> 0). ``None``: the map's
            recommendation (see :func:`map_recommendations`); the same for ``l_max``,
            ``v_pursuer`` and ``v_evader``.
        l_max: L_max, the sensor's maximum range (> l_min). A band narrower than two
            evader steps (l_max - l_min < 2 v_evader dt) is legal but warned about: no
            pursuer can be sure to hold it (:class:`~envs.errors.NarrowBandWarning`).
        v_pursuer: V_p, the pursuer's speed bound (> 0).
        v_evader: V_e, the evader's speed bound (> 0); rho = V_e / V_p. rho > 1 is legal
            but warned about: the evader then wins by charging (Sec. 5).
        dt: duration of one env step (> 0, and large enough that each speed bound times
            dt exceeds the rounding of the map's coordinates: a step moves a body).
        max_cycles: steps before the episode is truncated (>= 1).
        observation: ``"state"``, ``"lidar"`` or ``"lidar_track"`` (see :mod:`.observations`).
        n_rays: lidar rays per agent (in [1, MAX_RAYS]; used by the lidar kinds only).
        lidar_range: range at which lidar rays saturate (> 0); ``None`` means ``l_max``.
        reward: ``"zero_sum"`` or ``"sparse"`` (see :mod:`.rules`).
        body_radius: radius of both agents' discs, in (0, l_min / 2). ``None``:
            :data:`envs.maps.io.BODY_RADIUS` (0.1), times S on a transformed built-in
            ``NAME~xS...`` (so that game is the built-in's up to the similarity).
        spawn_margin_steps: random starts survive any actions for at least this many
            steps (>= 0; see ``parallel_env.reset``).
        render_mode: ``None``, ``"human"`` or ``"rgb_array"``.
    """

    map: Map | str | os.PathLike[str] = "corridor"
    l_min: float | None = None
    l_max: float | None = None
    v_pursuer: float | None = None
    v_evader: float | None = None
    dt: float = 0.1
    max_cycles: int = 500
    observation: str = "state"
    n_rays: int = 32
    lidar_range: float | None = None
    reward: str = "zero_sum"
    body_radius: float | None = None
    spawn_margin_steps: int = 3
    render_mode: str | None = None

    def __post_init__(self) -> None:
        put = lambda name, value: object.__setattr__(self, name, value)
        recommended = map_recommendations(self.map)
        put("map", resolve_map(self.map))
        for name in MAP_PARAMETERS:
            value = getattr(self, name)
            put(name, recommended[name] if value is None else v.positive(name, value))
        if self.l_max <= self.l_min:
            raise InvalidConfigError(
                f"l_max = {self.l_max!r}: expected a value > l_min = {self.l_min!r}"
            )
        put("dt", v.positive("dt", self.dt))
        self._check_step_moves()
        put("max_cycles", v.integer("max_cycles", self.max_cycles, minimum=1))
        put("observation", v.choice("observation", self.observation, OBSERVATION_KINDS))
        put("n_rays", v.integer("n_rays", self.n_rays, minimum=1, maximum=MAX_RAYS))
        if self.lidar_range is not None:
            put("lidar_range", v.positive("lidar_range", self.lidar_range))
        put("reward", v.choice("reward", self.reward, REWARD_KINDS))
        if self.body_radius is None:  # the built-ins' body, scaled with a transformed one
            put("body_radius", recommended.get("body_radius", BODY_RADIUS))
        put("body_radius", v.positive("body_radius", self.body_radius))
        if self.body_radius >= 0.5 * self.l_min:
            raise InvalidConfigError(
                f"body_radius = {self.body_radius!r}: expected a value in "
                f"(0, l_min / 2 = {0.5 * self.l_min!r})"
            )
        put(
            "spawn_margin_steps",
            v.integer("spawn_margin_steps", self.spawn_margin_steps, minimum=0),
        )
        if self.render_mode is not None:
            put("render_mode", v.choice("render_mode", self.render_mode, RENDER_MODES))
        self._warn_if_unwinnable()

    def _warn_if_unwinnable(self) -> None:
        """Warn about a legal game no pursuer can be sure to win: rho > 1
        (:class:`~envs.errors.RhoAboveOneWarning`) or a range band narrower than two evader
        steps (:class:`~envs.errors.NarrowBandWarning`). Only for a config the env would
        build: every check above passed, and so does the physics' own
        (:func:`~envs.surveillance.physics.check_step`, which the env calls next), so a
        config about to be refused is refused without a warning first."""
        from envs.surveillance.physics import check_step  # pymunk: imported when needed

        try:
            check_step(self.map, self.dt, max(self.v_pursuer, self.v_evader), self.body_radius)
        except InvalidConfigError:
            return  # the env refuses it (its message says why); a warning would come first
        if self.v_evader > self.v_pursuer:
            warnings.warn(
                f"v_evader = {self.v_evader!r} > v_pursuer = {self.v_pursuer!r} (rho = "
                f"{self.v_evader / self.v_pursuer:.3g} > 1): the evader can always escape by "
                "running at the pursuer (Sec. 5 of the paper); legal, but no pursuer can win",
                RhoAboveOneWarning,
                stacklevel=_caller_stacklevel(),
            )
        band, steps = self.l_max - self.l_min, 2.0 * self.v_evader * self.dt
        if band < steps * (1.0 - 1e-9):  # exactly two steps (up to rounding) can be held
            warnings.warn(
                f"l_max - l_min = {band:.6g} < 2 v_evader dt = {steps:.6g} (l_min = "
                f"{self.l_min!r}, l_max = {self.l_max!r}, v_evader = {self.v_evader!r}, dt = "
                f"{self.dt!r}): within a step the evader can move v_evader dt toward or away "
                "from the pursuer whatever the pursuer does in it, and the two distances that "
                "leaves are 2 v_evader dt apart, so one is outside the band; legal, but no "
                "pursuer can be sure to hold it (expected l_max - l_min >= 2 v_evader dt: a "
                f"wider band, or dt <= {band / (2.0 * self.v_evader):.4g})",
                NarrowBandWarning,
                stacklevel=_caller_stacklevel(),
            )

    def _check_step_moves(self) -> None:
        """Refuse a step in which a body at full speed could not move: ``V dt`` at or below
        the rounding of the map's coordinates. There the position plus ``V dt`` is the
        position (the game is no game), a subnormal ``dt`` made ``1 / dt`` infinite (NaN
        velocities in every observation from step 1: dt = 1e-310), and an underflowing
        ``V dt`` divided by zero (the shooting evader's reset: dt = 5e-324)."""
        x0, y0, x1, y1 = self.map.bounds
        rounding = sys.float_info.epsilon * max(abs(x0), abs(y0), abs(x1), abs(y1))
        for name in ("v_pursuer", "v_evader"):
            speed = getattr(self, name)
            if speed * self.dt <= rounding:
                raise InvalidConfigError(
                    f"dt = {self.dt!r} with {name} = {speed!r}: a step of {name} dt = "
                    f"{speed * self.dt:.3g} would not move a body on map {self.map.name!r}, "
                    f"whose coordinates round by {rounding:.2g}; expected {name} dt > "
                    f"{rounding:.2g} (a larger dt or {name})"
                )

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
        record: dict[str, Any] = {"map": self.map.name, "map_digest": self.map.digest}
        for f in dataclasses.fields(self):
            if f.name != "map":
                record[f.name] = getattr(self, f.name)
        return record


def env_parameters() -> dict[str, Any]:
    """The env's arguments in signature order, each with its default (``EnvConfig``'s fields).

    ``None`` for ``l_min``, ``l_max``, ``v_pursuer`` and ``v_evader`` means the map's
    recommendation (:func:`map_recommendations`).

    Examples:
        >>> list(env_parameters())[:3]
        ['map', 'l_min', 'l_max']
    """
    return {f.name: f.default for f in dataclasses.fields(EnvConfig)}


def env_signature(return_annotation: Any = inspect.Signature.empty) -> inspect.Signature:
    """The keyword signature of the env factories, derived from :class:`EnvConfig`."""
    sig = inspect.signature(EnvConfig)
    return sig.replace(return_annotation=return_annotation)


def bind_env_arguments(factory: str, args: tuple, kwargs: dict[str, Any]) -> dict[str, Any]:
    """The arguments given to the env factory ``factory`` as keywords (defaults not filled).

    Raises:
        TypeError: an unknown (misspelt) or repeated argument, or too many positional
            ones; the message names it, suggests the closest argument and lists them all.
    """
    try:
        bound = env_signature().bind(*args, **kwargs)
    except TypeError as exc:
        names = list(env_parameters())
        unknown = [k for k in kwargs if k not in names]
        hint = ""
        if unknown:
            close = difflib.get_close_matches(unknown[0], names, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
        raise TypeError(f"{factory}(): {exc}{hint} (arguments: {', '.join(names)})") from None
    return dict(bound.arguments)


def _caller_stacklevel() -> int:
    """``stacklevel`` that points a warning at the first frame outside ``envs.surveillance``."""
    frame = sys._getframe(1)
    level = 1
    while frame is not None and (
        frame.f_code.co_filename == "<string>"  # the __init__ that dataclasses generate
        or frame.f_globals.get("__name__", "").startswith(("envs.surveillance", "pettingzoo"))
    ):
        frame = frame.f_back
        level += 1
    return level
