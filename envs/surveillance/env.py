"""The PettingZoo adapter: ``parallel_env`` (native), ``raw_env`` and ``env`` (AEC).

The env card (agents, spaces, arguments, version history) is the docstring of
:mod:`envs.surveillance_v1`; this module holds the implementation of every version:
:class:`parallel_env` is the latest (v1) and :class:`parallel_env_v0` the retired v0,
which differs only in how a step in which a wall bent a body's path is swept
(:meth:`parallel_env._sweep`).
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
import math
import warnings
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
from gymnasium.spaces import Box
from gymnasium.utils import EzPickle, seeding
from pettingzoo import AECEnv, ParallelEnv
from pettingzoo.utils.conversions import parallel_to_aec_wrapper
from pettingzoo.utils.wrappers import OrderEnforcingWrapper

from envs import validation
from envs.errors import (
    EpisodeStateError,
    InfeasibleError,
    InvalidActionError,
    InvalidPlacementError,
    UnknownNameError,
)
from envs.geometry import Kernel, kernel_for
from envs.maps import Map
from envs.surveillance import rules
from envs.surveillance.config import (
    RENDER_MODES,
    EnvConfig,
    bind_env_arguments,
    env_signature,
)
from envs.surveillance.observations import (
    LidarEncoder,
    StateEncoder,
    lidar_space,
    state_space,
)
from envs.surveillance.physics import World
from envs.surveillance.placement import check_option_keys, random_start, validate_placement
from envs.tolerances import REL_LENGTH_TOL

__all__ = [
    "AGENTS",
    "EVADER",
    "PURSUER",
    "env",
    "env_v0",
    "parallel_env",
    "parallel_env_v0",
    "raw_env",
    "raw_env_v0",
]

PURSUER = "pursuer_0"
EVADER = "evader_0"
AGENTS = (PURSUER, EVADER)
TRAIL_LENGTH = 200
"""Past positions kept per agent for the renderer's trails."""


def _kernel(world: Map) -> Kernel:
    """The cached kernel of ``world``, provided its wall indices match ``world``'s.

    ``kernel_for`` caches by digest, and equal digests do not imply equal vertex
    numbering (the digest ignores where each ring starts), while the features the
    kernel reports index the arrays of the map it was built from.
    """
    k = kernel_for(world)
    if k.map is world or np.array_equal(k.map.vertices, world.vertices):
        return k
    return Kernel(world)


class parallel_env(ParallelEnv, EzPickle):
    """Visibility-based surveillance with a finite sensor range, as a ParallelEnv.

    See :mod:`envs.surveillance_v1` for the env card; every argument is a field of
    :class:`~envs.surveillance.config.EnvConfig`.
    """

    metadata: ClassVar[dict[str, Any]] = {
        "name": "surveillance_v1",
        "render_modes": list(RENDER_MODES),
        "is_parallelizable": True,
        "render_fps": 10,
    }
    sweep_path: ClassVar[bool] = True
    """Sweep a step in which a wall stopped or deflected a body along the path the physics
    made (v1); False sweeps every step's chord, as v0 did."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        # the signature is EnvConfig's (set below the class): one source for the arguments
        given = bind_env_arguments("parallel_env", args, kwargs)
        EzPickle.__init__(self, **given)
        cfg = EnvConfig(**given)
        self.config = cfg
        self.render_mode = cfg.render_mode
        self.metadata = {**type(self).metadata, "render_fps": 1.0 / cfg.dt}
        self.possible_agents = list(AGENTS)
        self.agents: list[str] = []
        self.map = cfg.map
        self.kernel = _kernel(cfg.map)
        self.world = World(
            cfg.map,
            cfg.body_radius,
            cfg.dt,
            max(cfg.v_pursuer, cfg.v_evader),
            v0_substeps=not self.sweep_path,  # v0's physics too, so that v0 replays
        )
        self._state_encoder = StateEncoder(cfg)
        self.state_space = state_space(cfg)
        if cfg.observation == "state":
            self._observation_spaces = {a: state_space(cfg) for a in AGENTS}
            self._lidar = None
        else:
            self._observation_spaces = {a: lidar_space(cfg) for a in AGENTS}
            self._lidar = {
                PURSUER: LidarEncoder(cfg, "pursuer", self.kernel),
                EVADER: LidarEncoder(cfg, "evader", self.kernel),
            }
        self._action_spaces = {a: Box(-1.0, 1.0, (2,), dtype=np.float32) for a in AGENTS}
        self._speed = {PURSUER: cfg.v_pursuer, EVADER: cfg.v_evader}
        self._inv_dt = 1.0 / cfg.dt
        # a step whose end is this close to the commanded one moved linearly (_sweep)
        self._linear_tol = REL_LENGTH_TOL * cfg.map.diameter
        self._surveillance_reward = rules.reward_components(
            cfg.reward, escaped=False, truncated=False, max_cycles=cfg.max_cycles
        )
        self.np_random, self._np_random_seed = seeding.np_random(None)
        self._step = 0
        self._pursuer = (0.0, 0.0)
        self._evader = (0.0, 0.0)
        self._vp = (0.0, 0.0)
        self._ve = (0.0, 0.0)
        self._visible = False
        self._last_event = None
        self._ended_at: str | None = None  # why the last episode ended; None before reset
        self._trail: tuple[list, list] = ([], [])
        self._renderer = None

    def __deepcopy__(self, memo: dict) -> parallel_env:
        """A copy that carries the episode on: positions, the pymunk world (contacts and
        all, so a contact step continues as in the original), the step count and the
        generator; stepping both with the same actions gives the same results bit for
        bit. The map, its kernel and the config are immutable and shared; a window is
        not copied (the copy opens its own on ``render()``).

        ``pickle`` still rebuilds the env from its arguments (EzPickle, as vector envs
        and process pools expect): an unpickled env starts unreset. Without this method
        ``copy.deepcopy`` did the same, so a copy taken mid-episode (a lookahead) raised
        "step() before reset()".
        """
        cls = type(self)
        new = cls.__new__(cls)
        memo[id(self)] = new
        for shared in (self.config, self.map, self.kernel):
            memo[id(shared)] = shared
        for key, value in self.__dict__.items():
            new.__dict__[key] = None if key == "_renderer" else copy.deepcopy(value, memo)
        return new

    def __copy__(self) -> parallel_env:
        """``copy.copy`` is :meth:`__deepcopy__`: a shallow copy would share the pymunk
        world and the generator (a step of one would move the other), and EzPickle's
        default rebuilt an unreset env, so a copy taken mid-episode raised "step()
        before reset()"."""
        return copy.deepcopy(self)

    # ------------------------------------------------------------------ spaces
    def observation_space(self, agent: str) -> Box:
        """The observation Box of ``agent`` (the same object on every call)."""
        return self._space(self._observation_spaces, agent)

    def action_space(self, agent: str) -> Box:
        """The action Box(-1, 1, (2,)) of ``agent`` (the same object on every call)."""
        return self._space(self._action_spaces, agent)

    def _space(self, spaces: dict, agent: str) -> Box:
        try:
            return spaces[agent]
        except (KeyError, TypeError):  # TypeError: an unhashable name
            raise UnknownNameError(
                f"agent = {agent!r}: expected one of {self.possible_agents}"
            ) from None

    # ------------------------------------------------------------------ episode
    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, dict[str, Any]]]:
        """Start an episode.

        A refused reset (any error below) changes nothing: not the generator, not the
        episode under way.

        Args:
            seed: reseeds ``self.np_random`` when not ``None``.
            options: ``{"pursuer": (x, y), "evader": (x, y)}`` places the agents exactly
                (validated: both in free space with body clearance, within range, with
                line of sight); without them the start is drawn at random (see
                :func:`envs.surveillance.placement.random_start`). Other keys are left
                to wrappers, which pass their own options through; one whose name is
                close to a placement key (``"pursuer_0"``) warns
                (:class:`~envs.errors.UnknownOptionWarning`).

        Returns:
            Observations and infos of both agents.

        Raises:
            InvalidConfigError: ``seed`` is not None or an integer >= 0.
            InvalidPlacementError: ``options`` is not a dict, or the requested placement is
                not a valid surveillance configuration; the message names the positions
                and the reason.
            InfeasibleError: no random start exists (see ``random_start``).
        """
        if seed is not None:
            seed = validation.integer("seed", seed, minimum=0, where="reset")
        if options is not None and not isinstance(options, Mapping):
            raise InvalidPlacementError(
                "reset: options must be None or a dict such as {'pursuer': (x, y), "
                f"'evader': (x, y)}}, got {type(options).__name__} {options!r}"
            )
        cfg = self.config
        if options:
            check_option_keys(options, stacklevel=2)
        # the generator is replaced only once the start stands: a refused reset (a
        # placement that is not valid, no random start) leaves the env as it was, so
        # the next reset() plays the episode it would have played without the refused one
        rng, rng_seed = (
            (self.np_random, self._np_random_seed) if seed is None else seeding.np_random(int(seed))
        )
        if options and ("pursuer" in options or "evader" in options):
            p, e = validate_placement(
                cfg, self.kernel, options.get("pursuer"), options.get("evader")
            )
        else:
            state = rng.bit_generator.state
            try:
                p, e = random_start(cfg, self.kernel, rng)
            except InfeasibleError:
                rng.bit_generator.state = state  # the draws of a refused reset never happened
                raise
        self.np_random, self._np_random_seed = rng, rng_seed
        self.world.reset(p, e)
        self._pursuer = (float(p[0]), float(p[1]))
        self._evader = (float(e[0]), float(e[1]))
        self._vp = (0.0, 0.0)
        self._ve = (0.0, 0.0)
        self._step = 0
        self._last_event = None
        self._ended_at = ""
        self._trail = ([self._pursuer], [self._evader])
        self.agents = list(AGENTS)
        status = rules.surveillance_status(
            self.kernel, self._pursuer, self._evader, cfg.l_min, cfg.l_max
        )
        self._visible = status.holds
        info = self._base_info(status.holds, status.distance)
        observations = self._observations()
        if self.render_mode == "human":
            self.render()
        return observations, {PURSUER: info, EVADER: dict(info)}

    def _command(self, agent: str, action: Any) -> tuple[float, float]:
        """Validate, clip and scale one action into a velocity (see the env card)."""
        if type(action) is np.ndarray and action.shape == (2,) and action.dtype.kind == "f":
            x, y = action.tolist()  # the common case, without a conversion to float64
        else:
            try:
                a = np.asarray(action)
                if a.dtype.kind not in "iuf":  # no strings, booleans, complex or objects
                    raise TypeError(f"dtype {a.dtype}")
                if isinstance(action, (list, tuple)) and any(
                    isinstance(v, (bool, np.bool_)) for v in action
                ):  # numpy reads [True, 0.5] as [1.0, 0.5]: a bool is not a number
                    raise TypeError("a bool")
                a = a.astype(np.float64)
            except (TypeError, ValueError) as exc:
                raise InvalidActionError(
                    f"{agent}: expected an action of shape (2,) with finite values, got "
                    f"{validation.shown(action)}"
                ) from exc
            if a.shape != (2,):
                raise InvalidActionError(
                    f"{agent}: expected an action of shape (2,), got shape {a.shape}"
                )
            x, y = a.tolist()
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InvalidActionError(f"{agent}: action must be finite, got {[x, y]}")
        # clip to the Box, then onto the unit disc: the speed bound is on |v|, and the
        # Box corners would otherwise allow sqrt(2) times the bound
        x = -1.0 if x < -1.0 else (1.0 if x > 1.0 else x)
        y = -1.0 if y < -1.0 else (1.0 if y > 1.0 else y)
        n2 = x * x + y * y
        scale = self._speed[agent]
        if n2 > 1.0:
            scale /= math.sqrt(n2)
        return (x * scale, y * scale)

    def _sweep(self, p0, e0, p1, e1, vp, ve, trace: list | None) -> Any:
        """The step's first break (:meth:`Kernel.sweep`), timed on the motion the physics
        made. The sweep takes each body's motion as linear; it is, unless a wall stopped
        or deflected a body within the step. Then the chord p0 -> p1 is not the path: at
        dt = 10 on the corridor a pursuer stopped by the wall after 0.4 s had its range
        break timed at 1.85 s instead of 1.2 s. So such a step is swept substep by substep
        (each substep's motion is linear: Chipmunk integrates positions at the commanded
        velocity, then corrects the contact), its time the substep's plus the fraction.
        The step starts clear (reset validated it, a broken step ends the episode), and so
        does each substep after one without a break. v0 (``trace`` None) sweeps the chord.
        """
        cfg = self.config
        if trace is not None and len(trace) > 1:  # a contact within the step (World.step)
            dt = cfg.dt
            moved = abs(p1[0] - p0[0] - vp[0] * dt) + abs(p1[1] - p0[1] - vp[1] * dt)
            moved += abs(e1[0] - e0[0] - ve[0] * dt) + abs(e1[1] - e0[1] - ve[1] * dt)
            if moved > self._linear_tol:
                n = len(trace)
                pa, ea = p0, e0
                for k, (pb, eb) in enumerate(trace):
                    event = self.kernel.sweep(
                        pa, ea, pb, eb, cfg.l_min, cfg.l_max, start_clear=True
                    )
                    if event is not None:
                        return dataclasses.replace(event, time=(k + event.time) / n)
                    pa, ea = pb, eb
                return None
        return self.kernel.sweep(p0, e0, p1, e1, cfg.l_min, cfg.l_max, start_clear=True)

    def step(self, actions: dict[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        """Advance both agents by ``dt`` and check surveillance continuously over the step.

        Args:
            actions: one action per live agent, each a (2,) velocity in units of the
                agent's speed bound. Finite values outside [-1, 1] are clipped to the Box
                and then onto the unit disc; NaN or inf raise.

        Returns:
            ``(observations, rewards, terminations, truncations, infos)`` for the agents
            live at the start of the step. After the episode ends ``agents`` is empty.

        Raises:
            EpisodeStateError: ``step()`` before ``reset()`` or after the episode ended
                (loop ``while env.agents:``).
            InvalidActionError: ``actions`` is not a dict, or an action is missing, not
                numeric, of the wrong shape, or not finite.
            UnknownNameError: ``actions`` has a key that is not an agent's name.
        """
        if not self.agents:
            if self._ended_at is None:
                raise EpisodeStateError("step() before reset(): call reset(seed=...) first")
            raise EpisodeStateError(
                f"step() after the episode ended at step {self._step} ({self._ended_at}): "
                "call reset() to start a new episode"
            )
        if type(actions) is not dict and not isinstance(actions, Mapping):
            raise InvalidActionError(
                f"step: expected a dict of actions keyed by agent, got "
                f"{type(actions).__name__} {actions!r}"
            )
        if PURSUER not in actions or EVADER not in actions:
            missing = [a for a in AGENTS if a not in actions]
            raise InvalidActionError(
                f"step: missing actions for {missing}; got keys {sorted(actions)}"
            )
        if len(actions) > 2:  # a misspelt agent would otherwise be ignored silently
            unknown = sorted((a for a in actions if a not in AGENTS), key=repr)
            raise UnknownNameError(
                f"step: actions for unknown agent(s) {unknown}; the agents are {list(AGENTS)}"
            )
        cfg = self.config
        vp = self._command(PURSUER, actions[PURSUER])
        ve = self._command(EVADER, actions[EVADER])
        p0, e0 = self._pursuer, self._evader
        trace: list | None = [] if self.sweep_path else None
        p1, e1 = self.world.step(vp, ve, trace)
        event = self._sweep(p0, e0, p1, e1, vp, ve, trace)
        self._step += 1
        inv_dt = self._inv_dt
        self._vp = ((p1[0] - p0[0]) * inv_dt, (p1[1] - p0[1]) * inv_dt)
        self._ve = ((e1[0] - e0[0]) * inv_dt, (e1[1] - e0[1]) * inv_dt)
        self._pursuer, self._evader = p1, e1
        escaped = event is not None
        trunc = (not escaped) and self._step >= cfg.max_cycles
        if escaped or trunc:
            comp = rules.reward_components(
                cfg.reward, escaped=escaped, truncated=trunc, max_cycles=cfg.max_cycles
            )
        else:
            comp = self._surveillance_reward
        distance = math.hypot(p1[0] - e1[0], p1[1] - e1[1])
        if escaped:
            # the rod may clear the obstacle again by the end of the step
            self._visible = rules.surveillance_status(
                self.kernel, p1, e1, cfg.l_min, cfg.l_max
            ).holds
        else:
            self._visible = True
        self._last_event = event
        trail_p, trail_e = self._trail
        trail_p.append(p1)
        trail_e.append(e1)
        if len(trail_p) > TRAIL_LENGTH:
            del trail_p[0], trail_e[0]

        info_p = self._base_info(not escaped, distance)
        if escaped:
            info_p["cause"] = event.cause
            info_p["feature"] = None if event.feature is None else self.map.describe(event.feature)
            info_p["break_time"] = float(event.time)
            info_p["break_at"] = (self._step - 1 + float(event.time)) * cfg.dt
        info_e = dict(info_p)
        r = comp.total
        info_p["reward_surveillance"] = comp.surveillance
        info_p["reward_escape"] = comp.escape
        info_p["reward_horizon"] = comp.horizon
        info_e["reward_surveillance"] = -comp.surveillance
        info_e["reward_escape"] = -comp.escape
        info_e["reward_horizon"] = -comp.horizon

        observations = self._observations()
        rewards = {PURSUER: r, EVADER: -r}
        terminations = {PURSUER: escaped, EVADER: escaped}
        truncations = {PURSUER: trunc, EVADER: trunc}
        infos = {PURSUER: info_p, EVADER: info_e}
        if escaped or trunc:
            self.agents = []
            self._ended_at = (
                f"the evader escaped: {event.cause}" if escaped else "max_cycles reached"
            )
        if self.render_mode == "human":
            self.render()
        return observations, rewards, terminations, truncations, infos

    def _base_info(self, surveillance: bool, distance: float) -> dict[str, Any]:
        p, e = self._pursuer, self._evader
        return {
            "surveillance": surveillance,
            "distance": distance,
            "theta": math.atan2(p[1] - e[1], p[0] - e[0]),
            "step": self._step,
            "time": self._step * self.config.dt,
        }

    def _observations(self) -> dict[str, np.ndarray]:
        if self._lidar is None:
            obs = self._state_encoder.encode(
                self._pursuer, self._vp, self._evader, self._ve, self._visible, self._step
            )
            return {PURSUER: obs, EVADER: obs.copy()}
        return {
            PURSUER: self._lidar[PURSUER].encode(
                self._pursuer, self._vp, self._evader, self._visible, self._step, self._ve
            ),
            EVADER: self._lidar[EVADER].encode(
                self._evader, self._ve, self._pursuer, self._visible, self._step, self._vp
            ),
        }

    def state(self) -> np.ndarray:
        """The global state (the ``"state"`` observation vector) for centralised critics.

        Raises:
            EpisodeStateError: before the first ``reset()`` (it returned the state of both
                agents at (0, 0), possibly inside a wall; the AEC env raises too).
        """
        if self._ended_at is None:
            raise EpisodeStateError("state() before reset(): call reset(seed=...) first")
        return self._state_encoder.encode(
            self._pursuer, self._vp, self._evader, self._ve, self._visible, self._step
        )

    # ------------------------------------------------------------------ rendering
    def snapshot(self):
        """A read-only snapshot of the world for renderers (no observation is read back)."""
        from envs.surveillance.render import Snapshot

        event = self._last_event
        return Snapshot(
            map=self.map,
            pursuer=self._pursuer,
            evader=self._evader,
            l_min=self.config.l_min,
            l_max=self.config.l_max,
            body_radius=self.config.body_radius,
            surveillance=event is None,
            cause=None if event is None else event.cause,
            feature=None if event is None else event.feature,
            step=self._step,
            time=self._step * self.config.dt,
            trail_pursuer=tuple(self._trail[0]),
            trail_evader=tuple(self._trail[1]),
        )

    def render(self) -> np.ndarray | None:
        """``"rgb_array"``: an HxWx3 uint8 frame; ``"human"``: draw to a window; ``None``:
        nothing (``None``, with a warning).

        Raises:
            EpisodeStateError: before the first ``reset()`` (there is no state to draw: it
                drew both agents at (0, 0), possibly inside a wall; the AEC env raises too).
        """
        if self.render_mode is None:  # as Gymnasium's and PettingZoo's envs: said, not silent
            warnings.warn(
                "render() with render_mode=None draws nothing and returns None; build the env "
                "with render_mode='rgb_array' (a frame) or 'human' (a window)",
                stacklevel=2,
            )
            return None
        if self._ended_at is None:
            raise EpisodeStateError("render() before reset(): call reset(seed=...) first")
        if self._renderer is None:
            from envs.surveillance.render import Renderer

            self._renderer = Renderer(
                self.map,
                human=self.render_mode == "human",
                fps=self.metadata["render_fps"],
                title=self.metadata["name"],
            )
        return self._renderer.draw(self.snapshot())

    def close(self) -> None:
        """Release the window, if any (idempotent)."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


parallel_env.__init__.__signature__ = env_signature(None).replace(  # type: ignore[attr-defined]
    parameters=[
        inspect.Parameter("self", inspect.Parameter.POSITIONAL_OR_KEYWORD),
        *env_signature().parameters.values(),
    ]
)


def _env_factory(fn):
    """Give a factory that forwards ``*args, **kwargs`` to ``parallel_env`` its signature.

    The PettingZoo way (``aec_wrapper_fn``) with the arguments kept introspectable:
    ``inspect.signature(raw_env)`` lists EnvConfig's fields, and a misspelt option is a
    ``TypeError`` raised by ``parallel_env``.
    """
    fn.__signature__ = env_signature(AECEnv)
    return fn


class _aec_wrapper(parallel_to_aec_wrapper):
    """PettingZoo's ``parallel_to_aec_wrapper``, checking each action on its agent's turn.

    The conversion only buffers an action until the last agent of the cycle has acted, so
    a NaN given by the pursuer was refused on the evader's turn, and stayed in the buffer:
    every later step raised the same error until a reset. Checked here (the parallel env's
    own check, :meth:`parallel_env._command`), a bad action is refused on the call that
    gave it and leaves the env as it was; a valid one goes through unchanged.
    """

    def step(self, action: Any) -> None:
        agent = self.agent_selection
        if not (self.terminations[agent] or self.truncations[agent]):
            self.env._command(agent, action)  # raises InvalidActionError naming the agent
        super().step(action)

    def observe(self, agent: str) -> Any:
        """``agent``'s observation; an unknown name is an :class:`UnknownNameError` naming
        the agents (the conversion's bare ``KeyError`` said only the name)."""
        if agent not in self.possible_agents:
            self.env._space(self.env._observation_spaces, agent)  # raises, naming them
        return super().observe(agent)


class _order_enforcing(OrderEnforcingWrapper):
    """PettingZoo's ``OrderEnforcingWrapper``, whose calls before ``reset()`` raised a bare
    ``AssertionError`` (gone under ``python -O``), raising the parallel env's
    :class:`EpisodeStateError` instead."""

    def _require_reset(self, call: str) -> None:
        if not self._has_reset:
            raise EpisodeStateError(f"{call}() before reset(): call reset(seed=...) first")

    def step(self, action: Any) -> None:
        self._require_reset("step")
        super().step(action)

    def observe(self, agent: str) -> Any:
        self._require_reset("observe")
        return super().observe(agent)

    def render(self) -> Any:
        self._require_reset("render")
        return super().render()

    def state(self) -> np.ndarray:
        self._require_reset("state")
        return super().state()

    def agent_iter(self, max_iter: int = 2**63) -> Any:
        self._require_reset("agent_iter")
        return super().agent_iter(max_iter)


def parallel_to_aec(par_env: parallel_env) -> AECEnv:
    """``pettingzoo.utils.conversions.parallel_to_aec`` with actions checked on their turn
    and calls before ``reset()`` refused with :class:`EpisodeStateError`."""
    return _order_enforcing(_aec_wrapper(par_env))


@_env_factory
def raw_env(*args: Any, **kwargs: Any) -> AECEnv:
    """The AEC version, by conversion of :class:`parallel_env` (same arguments)."""
    return parallel_to_aec(parallel_env(*args, **kwargs))


@_env_factory
def env(*args: Any, **kwargs: Any) -> AECEnv:
    """The AEC env with PettingZoo's standard wrappers for Box actions (same arguments).

    ``parallel_to_aec`` already applies ``OrderEnforcingWrapper`` (reset before step,
    no render before reset). ``ClipOutOfBoundsWrapper`` and ``AssertOutOfBoundsWrapper``
    are deliberately left out: the env clips finite out-of-Box actions itself and
    raises :class:`~envs.errors.InvalidActionError` on NaN or inf, whereas the former
    would log a warning per clipped action and turn NaN into a logger error, and the
    latter would reject the overshoot that analytic policies produce by rounding.
    """
    return raw_env(*args, **kwargs)


class parallel_env_v0(parallel_env):
    """The retired v0 of :class:`parallel_env` (:mod:`envs.surveillance_v0`): every step is
    swept along the chord between its two frames, also when a wall bent a body's path
    within it (a break there can be missed or timed late). Kept importable so that
    results recorded with v0 replay; new work uses v1.
    """

    metadata: ClassVar[dict[str, Any]] = {**parallel_env.metadata, "name": "surveillance_v0"}
    sweep_path: ClassVar[bool] = False


@_env_factory
def raw_env_v0(*args: Any, **kwargs: Any) -> AECEnv:
    """The AEC version of :class:`parallel_env_v0` (same arguments)."""
    return parallel_to_aec(parallel_env_v0(*args, **kwargs))


@_env_factory
def env_v0(*args: Any, **kwargs: Any) -> AECEnv:
    """The AEC env of v0, as :func:`env` is of v1 (same arguments)."""
    return raw_env_v0(*args, **kwargs)
