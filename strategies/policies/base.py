"""The one Policy protocol shared by analytic, baseline and learned policies.

A policy is reset once per episode with its role, the static map and the env's config,
then maps observations to actions. Analytic policies read the env's ``"state"``
observation by field name (``envs.surveillance.observations.decode_state``) and the static
map; they never see the physics engine. Every policy owns one seeded
``np.random.Generator``; the same seed gives the same actions bit for bit.

Actions are the env's normalised velocity commands: a desired velocity ``v`` (world
units per second) becomes ``v / V_max`` clipped to the unit disk, so a policy never asks
for more than its speed bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from envs import validation
from envs.errors import InvalidActionError, InvalidConfigError

__all__ = [
    "MAX_RAYS",
    "ROLES",
    "ActPredictor",
    "BasePolicy",
    "Policy",
    "Snapshot",
    "check_role",
    "count_param",
    "distance_ceiling",
    "distance_target",
    "flag_param",
    "nonnegative_param",
    "positive_param",
    "unit",
]

ROLES = ("pursuer", "evader")
"""The two roles, in the env's agent order."""

MAX_RAYS = 4096
"""Upper bound of a policy's probe-ray count (see :func:`count_param`)."""


def check_role(role: str) -> str:
    """Return ``role`` if it is ``"pursuer"`` or ``"evader"``, else raise.

    Raises:
        InvalidConfigError: naming the bad role.
    """
    return validation.choice("role", role, ROLES)


def positive_param(name: str, value: Any) -> float:
    """A policy parameter as a float; raise unless it is a finite number > 0.

    Bools and strings are not numbers (:mod:`envs.validation`): ``True`` does not mean 1.
    """
    return validation.positive(name, value)


def nonnegative_param(name: str, value: Any) -> float:
    """A policy parameter as a float; raise unless it is a finite number >= 0."""
    return validation.nonnegative(name, value)


def count_param(name: str, value: Any, minimum: int, maximum: int) -> int:
    """A policy parameter that sizes an array (rays, bins, samples) as an int.

    Bounded above so that a typo such as ``rays: 1000000000`` fails at once with a message
    instead of exhausting memory when the policy allocates.

    Raises:
        InvalidConfigError: not an integer (bools and floats are refused) or out of range.
    """
    return validation.integer(name, value, minimum=minimum, maximum=maximum)


def flag_param(name: str, value: Any) -> bool:
    """A policy parameter that is a switch: only ``True`` or ``False`` (never ``"no"``)."""
    return validation.boolean(name, value)


def distance_target(config: Any) -> float:
    """The distance a pursuer holds: L_min plus a buffer against one step of reaction lag,
    at most the middle of the range band ``[L_min, L_max]``.

    Policies see the evader's velocity of the *previous* step, so a sudden dash toward
    the pursuer closes up to ``V_e dt`` before it reacts; twice that, plus 1 % of L_min,
    keeps L above L_min (the env's ``"too_close"``). A dash away opens it as fast
    (``"too_far"``), so where the band is narrower than twice the buffer (``L_max -
    L_min < 4 V_e dt + 0.02 L_min``) the target is the band's middle, the same buffer
    both ways: L_min plus the buffer lay beyond the middle, and beyond L_max itself
    where the band was narrower than one buffer (L_min 2, L_max 2.2, V_e 1, dt 0.1:
    2.22; the decomposition pursuer lost all 16 of its episodes there ``"too_far"``
    within 1-20 steps, and wins 10 from the middle).
    Such a band is legal (the env asks only ``L_max > L_min``) but no pursuer can be
    sure to hold it: one step of the evader covers ``V_e dt`` of it.
    """
    low = config.l_min + 2.0 * config.v_evader * config.dt + 0.01 * config.l_min
    return min(low, 0.5 * (config.l_min + config.l_max))


def rounded_length(length: float) -> float:
    """A rod length as the policies' safety tables take it (and their caches key it):
    rounded to 6 decimals, so that float noise in ``L_min + body_radius`` does not make
    another table, or to 6 significant digits where that is finer (below 0.1: on a map
    scaled by 1e-7, L_min 2e-7, 6 decimals made the length 0 and every reset raised
    ``safety_table: L = 0.0``; at 1e-5 they kept one digit of it)."""
    return round(length, 6) if length >= 0.1 else float(f"{length:.6g}")


def distance_ceiling(config: Any) -> float:
    """The longest distance a pursuer aims at: L_max less the buffer
    :func:`distance_target` keeps above L_min (its mirror below L_max), or the band's
    middle where the two buffers overlap."""
    return max(distance_target(config), config.l_min + config.l_max - distance_target(config))


def unit(v: np.ndarray) -> np.ndarray:
    """Return ``v / |v|`` (the zero vector stays zero)."""
    n = math.hypot(float(v[0]), float(v[1]))
    return v / n if n > 0 else np.zeros(2)


@dataclass(frozen=True)
class Snapshot:
    """What an analytic policy knows at one step, in world units.

    Attributes:
        evader: evader position E = (x, y).
        pursuer: pursuer position P.
        evader_velocity: estimate of the evader's current velocity.
        pursuer_velocity: estimate of the pursuer's current velocity.
        time: episode time in seconds (steps times dt).
    """

    evader: np.ndarray
    pursuer: np.ndarray
    evader_velocity: np.ndarray
    pursuer_velocity: np.ndarray
    time: float

    @property
    def rod(self) -> np.ndarray:
        """The vector P - E."""
        return self.pursuer - self.evader

    @property
    def L(self) -> float:
        """Surveillance distance |P - E|."""
        d = self.rod
        return math.hypot(float(d[0]), float(d[1]))

    @property
    def theta(self) -> float:
        """Rod orientation, the direction from evader to pursuer (eq. 1)."""
        d = self.rod
        return math.atan2(float(d[1]), float(d[0]))


@runtime_checkable
class Policy(Protocol):
    """Anything that plays one role of the surveillance game.

    ``predict`` makes every policy an SB3 ``PolicyPredictor``.
    """

    name: str
    role: str | None

    def reset(self, *, role: str, map: Any, config: Any, seed: int | None = None) -> None:
        """Start an episode as ``role`` on ``map`` with the env's ``config``."""

    def act(self, observation: np.ndarray) -> np.ndarray:
        """Return the action (float32, shape (2,), in [-1, 1]) for one observation."""

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """SB3-compatible adapter around :meth:`act`."""


class ActPredictor:
    """Mixin: SB3's ``PolicyPredictor.predict`` from the class's own ``act``, one
    observation at a time (the class defines ``act``; :class:`BasePolicy` and
    :class:`strategies.mixed.MixedPolicy` take it).
    """

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """SB3 ``PolicyPredictor`` adapter: batched (n, obs) or single observations.

        Returns:
            ``(actions, None)`` with actions of shape (2,) or (n, 2).
        """
        obs = np.asarray(observation)
        if obs.ndim == 2:
            return np.stack([self.act(o) for o in obs]), None
        return self.act(obs), None


class BasePolicy(ActPredictor):
    """Shared plumbing: role checks, seeded RNG, observation decoding, action scaling.

    Subclasses set ``roles`` (the roles they can play) and implement
    :meth:`_decide`, which receives a :class:`Snapshot` and returns the desired velocity
    in world units; or override :meth:`act` entirely (learned policies).

    Args:
        name: registry name, for reports.
    """

    roles: tuple[str, ...] = ROLES
    uses_state: bool = True

    def __init__(self, *, name: str | None = None) -> None:
        self.name = name or type(self).__name__
        self.role: str | None = None
        self.map = None
        self.config = None
        self.rng = np.random.default_rng()
        self._prev: tuple[np.ndarray, np.ndarray] | None = None
        self._steps = 0

    # ----------------------------------------------------------------- protocol
    def reset(self, *, role: str, map: Any, config: Any, seed: int | None = None) -> None:
        """Start an episode.

        Args:
            role: ``"pursuer"`` or ``"evader"``.
            map: the static :class:`~envs.maps.Map`.
            config: the env's ``EnvConfig`` (speed bounds, L range, dt, observation kind).
            seed: seeds this policy's own RNG (``None``: fresh entropy).

        Raises:
            InvalidConfigError: the role is unknown or this policy cannot play it, the
                map is no :class:`~envs.maps.Map`, the config no ``EnvConfig``, the seed
                no integer >= 0, or the env does not give the ``"state"`` observation an
                analytic policy needs. A refused reset (this or any error of the
                policy's own set-up) leaves the policy un-reset: :meth:`act` then asks
                for a reset instead of playing the previous episode's state.
        """
        from envs.maps import Map
        from envs.surveillance.config import EnvConfig

        where = f"policy {self.name!r}: reset"
        check_role(role)
        if role not in self.roles:
            raise InvalidConfigError(
                f"policy {self.name!r} plays {self.roles}, cannot play {role!r}"
            )
        if not isinstance(map, Map):
            raise InvalidConfigError(
                f"{where}: map = {map!r}: expected the env's Map (env.config.map)"
            )
        if not isinstance(config, EnvConfig):
            raise InvalidConfigError(
                f"{where}: config = {config!r}: expected the env's EnvConfig (env.config)"
            )
        if seed is not None:  # numpy's own refusal named no argument
            seed = validation.integer("seed", seed, minimum=0, where=where)
        if self.uses_state and getattr(config, "observation", "state") != "state":
            raise InvalidConfigError(
                f"policy {self.name!r} reads the 'state' observation, but the env gives "
                f"{config.observation!r}; build the env with observation='state'"
            )
        self.role = role
        self.map = map
        self.config = config
        self.rng = np.random.default_rng(seed)
        self._prev = None
        self._steps = 0
        try:
            self._reset()
        except BaseException:
            self.role = None  # half set up: act() must not play on (AttributeError deep in)
            raise

    def act(self, observation: np.ndarray) -> np.ndarray:
        """Return the normalised action for one observation.

        Raises:
            InvalidConfigError: called before :meth:`reset`.
            InvalidObservationError: the observation is not a finite ``"state"`` vector.
        """
        if self.role is None:
            raise InvalidConfigError(f"policy {self.name!r}: call reset() before act()")
        snap = self._snapshot(observation)
        velocity = np.asarray(self._decide(snap), dtype=float)
        self._steps += 1
        return self.velocity_to_action(velocity)

    # ----------------------------------------------------------------- helpers
    @property
    def v_max(self) -> float:
        """This role's speed bound."""
        return float(self.config.v_pursuer if self.role == "pursuer" else self.config.v_evader)

    def velocity_to_action(self, velocity: np.ndarray) -> np.ndarray:
        """Scale a world velocity to the action box, clipped to the unit disk."""
        a = np.asarray(velocity, dtype=float) / self.v_max
        n = math.hypot(float(a[0]), float(a[1]))
        if not math.isfinite(n):
            raise InvalidActionError(f"policy {self.name!r} produced velocity {velocity!r}")
        if n > 1.0:
            a = a / n
        return a.astype(np.float32)

    def _snapshot(self, observation: np.ndarray) -> Snapshot:
        from strategies.policies.observe import read_state

        e, p, ve, vp = read_state(observation, self.config)
        dt = float(self.config.dt)
        if ve is None or vp is None:
            # no velocities in the observation: finite differences of the last two steps
            if self._prev is None:
                est_e, est_p = np.zeros(2), np.zeros(2)
            else:
                est_e = (e - self._prev[0]) / dt
                est_p = (p - self._prev[1]) / dt
            ve = est_e if ve is None else ve
            vp = est_p if vp is None else vp
        self._prev = (e, p)
        return Snapshot(e, p, ve, vp, self._steps * dt)

    # ----------------------------------------------------------------- subclass hooks
    def _reset(self) -> None:
        """Per-episode set-up after the common reset (precompute from the map here)."""

    def _decide(self, snap: Snapshot) -> np.ndarray:
        """Return the desired velocity in world units."""
        raise NotImplementedError(f"{type(self).__name__} must implement _decide()")

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r}, role={self.role!r})"
