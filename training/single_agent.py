"""One role of ``surveillance_v1`` as a Gymnasium env, the other played by a fixed Policy.

:class:`SingleAgentEnv` wraps :func:`envs.surveillance_v1.parallel_env` so that SB3 (or
any single-agent learner) trains the pursuer or the evader against a fixed opponent: a
registered policy name (``"evader/straight"``), a ``ROLE/sb3:PATH`` model zip, or any
object with the Policy protocol. SuperSuit's vector envs would need both agents to share
spaces; here only the learner's spaces are exposed.

Seeding: ``reset(seed=s)`` reseeds ``self.np_random`` (Gymnasium's generator, built from
``SeedSequence(s)``); every episode then draws from it, in a fixed order, one seed for the
env, one for the start sampler and one for the opponent. The same seed therefore gives
the same episodes, and later resets without a seed continue the same stream.

The opponent is given the observation it asks for, as :func:`strategies.runner.run_episode`
gives it (the same :class:`~strategies.runner.Observer`): opponents that read the
``"state"`` observation (every analytic policy) still play when the learner sees
``"lidar"``: they receive ``env.state()`` (the ``"state"`` vector) and a copy of the
config with ``observation="state"``, so they are as strong as in a ``"state"`` env; a
learned model gets the observation it was trained on (its provenance's), whatever the
learner sees.

A learner trained with analytic features (``DaggerConfig.features``) reads more than any
env observation: pass its :class:`~strategies.policies.learner_inputs.LearnerInputs` as
``inputs`` and the learner's observation is built from the state by them, the same code as
in the DAgger rollout and in :class:`~strategies.policies.learned.SB3Policy`, so PPO
fine-tunes (or evaluates) such a model on the input it was fitted on and plays with.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from envs import surveillance_v1
from envs.errors import InvalidConfigError
from envs.surveillance.env import EVADER, PURSUER
from strategies.policies import Policy, make_policy
from strategies.policies.base import check_role
from strategies.policies.learner_inputs import LearnerInputs
from strategies.policies.model_files import model_policy_name
from strategies.policies.starts import START_KINDS, sample_start
from strategies.runner import Observer, observation_options

__all__ = ["AGENT_OF_ROLE", "START_CHOICES", "SingleAgentEnv", "make_opponent", "sb3_params"]

AGENT_OF_ROLE = {"pursuer": PURSUER, "evader": EVADER}
"""The env's agent name of each role."""

START_CHOICES = ("env", *START_KINDS)
"""``"env"``: the env's own random start; ``"valid"``/``"safe"``: ``sample_start``."""

_SEED_BOUND = 2**31 - 1
_OBSERVATION_KEYS = ("observation", "n_rays", "lidar_range")


def _other(role: str) -> str:
    return "evader" if role == "pursuer" else "pursuer"


def sb3_params(name: str) -> dict[str, Any]:
    """Extra ``make_policy`` parameters for a ``ROLE/sb3:PATH`` name: the algorithm.

    ``SB3Policy`` reads the algorithm from the zip, which cannot tell PPO from A2C (both
    save ``common.policies.ActorCriticPolicy``); the ``provenance.json`` that
    :func:`training.train` writes beside every model names it. Other names: ``{}``.
    """
    kind = name.partition("/")[2]
    if not kind.startswith("sb3:"):
        return {}
    prov = Path(kind[len("sb3:") :]).parent / "provenance.json"
    try:
        algo = json.loads(prov.read_text()).get("algo")
    except (OSError, ValueError):
        return {}
    return {"algo": str(algo).upper()} if algo else {}


def make_opponent(opponent: str | Policy, role: str) -> Policy:
    """Build the opponent of a learner playing ``role``.

    Args:
        opponent: a policy name (``"evader/straight"``, ``"evader/sb3:PATH"``), a model
            as users name one (``"zoo:NAME"``, a ``.zip`` path) or a Policy.
        role: the learner's role; the opponent must play the other one.

    Raises:
        InvalidConfigError: the opponent is of the wrong type or plays the learner's role.
        UnknownNameError: the name is not registered.
    """
    check_role(role)
    want = _other(role)
    if isinstance(opponent, str):
        # a model as play, evaluate and tournaments take it: zoo:NAME or a .zip
        name = model_policy_name(opponent, want, f"opponent = {opponent!r}")
        if name.partition("/")[0] != want:
            raise InvalidConfigError(
                f"opponent: {'an' if role == 'evader' else 'a'} {role} learner needs "
                f"{'an' if want == 'evader' else 'a'} {want!r} policy ('{want}/KIND', "
                f"'zoo:NAME' or a model .zip), got {opponent!r}"
            )
        return make_policy(name, **sb3_params(name))
    if isinstance(opponent, Policy):
        roles = getattr(opponent, "roles", (want,))
        if want not in roles:
            raise InvalidConfigError(
                f"opponent: policy {opponent.name!r} plays {tuple(roles)}, not {want!r}"
            )
        return opponent
    raise InvalidConfigError(
        f"opponent: expected a policy name or a Policy, got {type(opponent).__name__} {opponent!r}"
    )


class SingleAgentEnv(gym.Env):
    """The surveillance game seen by one role; a fixed Policy plays the other.

    Args:
        role: ``"pursuer"`` or ``"evader"``, the role the learner plays.
        opponent: the other role's policy: a name for
            :func:`strategies.policies.make_policy`, a Policy object, or a mixture
            (anything with ``select(seed) -> Policy``, e.g.
            :class:`training.pool.OpponentPool`) from which each episode draws one.
        map: the world (a :class:`Map`, a built-in name, a map file path or a
            ``random:SEED`` name), or a list of worlds: each episode is played on one
            drawn uniformly from this env's generator. A built-in named by a string
            brings its recommended ranges and speeds unless ``env_kwargs`` sets them,
            and observations are normalised by each world's own ranges.
        start: ``"env"`` (the env's random start), ``"valid"`` or ``"safe"``
            (:func:`strategies.policies.starts.sample_start`).
        render_mode: ``None``, ``"human"`` or ``"rgb_array"``.
        inputs: the learner's input built from the state (a
            :class:`~strategies.policies.learner_inputs.LearnerInputs`, e.g. of a model
            trained with analytic features) instead of the env's observation; its
            ``observation`` options replace ``env_kwargs``' observation. The features are
            built once per map (from the features' expert parameters) and reset every
            episode.
        **env_kwargs: the other arguments of :func:`envs.surveillance_v1.parallel_env`
            (``max_cycles``, ``observation``, ``v_evader``...).

    Rewards are the learner's env rewards, ``terminated`` means surveillance broke and
    ``truncated`` that the horizon was reached. ``info`` is the env's info of the
    learner's agent (surveillance, distance, theta, step, time; cause, feature and
    break time on escape; reward components).

    Raises:
        InvalidConfigError: bad role, opponent, start or env argument (naming it).
    """

    metadata: ClassVar[dict[str, Any]] = {
        "render_modes": ["human", "rgb_array"],
        "render_fps": 10,
    }

    def __init__(
        self,
        role: str,
        opponent: Any,
        map: Any = "corridor",
        *,
        start: str = "env",
        render_mode: str | None = None,
        inputs: LearnerInputs | None = None,
        **env_kwargs: Any,
    ) -> None:
        self.role = check_role(role)
        if inputs is not None and not isinstance(inputs, LearnerInputs):
            raise InvalidConfigError(
                f"inputs: expected a LearnerInputs or None, got {type(inputs).__name__} {inputs!r}"
            )
        if inputs is not None:  # the env computes the state; the inputs encode it
            env_kwargs = {k: v for k, v in env_kwargs.items() if k not in _OBSERVATION_KEYS}
        if start not in START_CHOICES:
            raise InvalidConfigError(f"start: expected one of {START_CHOICES}, got {start!r}")
        self.start = start
        self.pool = opponent if hasattr(opponent, "select") else None
        if self.pool is not None and getattr(self.pool, "role", _other(role)) != _other(role):
            raise InvalidConfigError(
                f"opponent: a {role} learner needs a pool of {_other(role)} policies, "
                f"got {self.pool!r}"
            )
        self.opponent = (
            self.pool.select(0) if self.pool is not None else make_opponent(opponent, role)
        )
        self.opponent_role = _other(role)
        self.agent = AGENT_OF_ROLE[role]
        self.opponent_agent = AGENT_OF_ROLE[self.opponent_role]
        maps = list(map) if isinstance(map, (list, tuple)) else [map]
        if not maps:
            raise InvalidConfigError("map: expected a map or a non-empty list of maps, got []")
        self.envs = []
        for world in maps:
            try:
                self.envs.append(
                    surveillance_v1.parallel_env(map=world, render_mode=render_mode, **env_kwargs)
                )
            except TypeError as exc:  # a misspelt env argument
                raise InvalidConfigError(f"env: {exc}") from exc
        self._select(0)
        self.render_mode = self.env.render_mode
        self.metadata = {**type(self).metadata, "render_fps": 1.0 / self.config.dt}
        self.observation_space = _union_space(
            [e.observation_space(self.agent) for e in self.envs], maps
        )
        self._inputs: list[LearnerInputs] = []
        if inputs is not None:
            # one per map: the features' tables are built once per map, not per episode
            self._inputs = [
                LearnerInputs(inputs.observation, inputs.features, inputs.expert_params)
                for _ in self.envs
            ]
            # the space of the observation the inputs encode (lidar: the same on every map)
            base = surveillance_v1.parallel_env(map=maps[0], **env_kwargs, **inputs.observation)
            self.observation_space = inputs.space(base.observation_space(self.agent))
            base.close()
        self.action_space = self.env.action_space(self.agent)
        self._opponent_obs: np.ndarray | None = None

    def _select(self, i: int) -> None:
        """Play the next episode on map ``i`` (of the list given)."""
        self._map_index = i
        self.env = self.envs[i]
        self.config = self.env.config
        self._bind_opponent()

    def _bind_opponent(self) -> None:
        # the observation the opponent asks for, as run_episode gives it: the "state"
        # vector for an analytic one even when the learner sees lidar, the observation a
        # model was trained on (lidar_track with 32 rays for the zoo's generalists)
        self._opponent_options = observation_options(self.opponent) or {}
        self._observer = Observer(self.env, self.opponent_role, self._opponent_options)

    # ------------------------------------------------------------------ episode
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode.

        Args:
            seed: reseeds this env's generator (and through it the env, the start
                sampler and the opponent); ``None`` continues the current stream.
            options: ``{"pursuer": (x, y), "evader": (x, y)}`` places the agents exactly,
                bypassing the start sampler.

        Returns:
            The learner's observation and info.
        """
        # a refused reset (a placement the env refuses) leaves this env as it was: its
        # generator, map and opponent are put back, and the opponent, reset only once the
        # env has accepted the start, keeps the episode under way
        rng = self._np_random
        kept = (
            rng,
            self._np_random_seed,
            None if rng is None else rng.bit_generator.state,
            {k: self.__dict__[k] for k in self._EPISODE_CHOICES},
        )
        try:
            return self._reset(seed, options)
        except Exception:
            self._np_random, self._np_random_seed = kept[0], kept[1]
            if rng is not None:
                rng.bit_generator.state = kept[2]
            self.__dict__.update(kept[3])
            raise

    _EPISODE_CHOICES = (
        "_map_index",
        "env",
        "config",
        "opponent",
        "_opponent_options",
        "_observer",
    )
    """What :meth:`reset` chooses before the env accepts the start (put back if it refuses)."""

    def _reset(
        self, seed: int | None, options: dict[str, Any] | None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        env_seed, start_seed, opp_seed = (
            int(s) for s in self.np_random.integers(_SEED_BOUND, size=3)
        )
        if len(self.envs) > 1:  # a draw only when there is a choice: one-map streams unchanged
            self._select(int(self.np_random.integers(len(self.envs))))
        if self.pool is not None:
            self.opponent = self.pool.select(int(self.np_random.integers(_SEED_BOUND)))
            self._bind_opponent()
        if options and ("pursuer" in options or "evader" in options):
            placement = dict(options)
        elif self.start == "env":
            placement = None
        else:
            judge = self.config  # the start sampler's judge reads the state
            if judge.observation != "state":
                judge = dataclasses.replace(judge, observation="state")
            placement = sample_start(judge, np.random.default_rng(start_seed), kind=self.start)
        # a new observer each episode (a lidar track differentiates positions over steps)
        self._observer = Observer(self.env, self.opponent_role, self._opponent_options)
        obs, infos = self.env.reset(seed=env_seed, options=placement)
        self.opponent.reset(
            role=self.opponent_role,
            map=self.config.map,
            config=self._observer.config,
            seed=opp_seed,
        )
        self._steps = 0
        self._opponent_obs = self._opponent_view(obs, infos)
        if self._inputs:
            self._inputs[self._map_index].reset(self.config, self.role)
        return self._learner_view(obs), dict(infos[self.agent])

    def _learner_view(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        if self._inputs:
            return self._inputs[self._map_index](self.env.state())
        return obs[self.agent]

    def _opponent_view(self, obs: dict[str, np.ndarray], infos: dict[str, Any]) -> np.ndarray:
        visible = bool(infos[PURSUER].get("surveillance", True))
        return self._observer(obs, visible, self._steps)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Play the learner's ``action`` and the opponent's reply for one step.

        Args:
            action: the learner's (2,) action (finite values outside [-1, 1] are clipped
                by the env; NaN or inf raise ``InvalidActionError``).

        Returns:
            ``(observation, reward, terminated, truncated, info)`` of the learner.

        Raises:
            InvalidConfigError: called before ``reset`` or after the episode ended.
        """
        if self._opponent_obs is None or not self.env.agents:
            raise InvalidConfigError("step: call reset() first; the episode is over")
        reply = self.opponent.act(self._opponent_obs)
        obs, rewards, terms, truncs, infos = self.env.step(
            {self.agent: action, self.opponent_agent: reply}
        )
        terminated = bool(terms[self.agent])
        truncated = bool(truncs[self.agent])
        self._steps += 1
        done = terminated or truncated
        self._opponent_obs = None if done else self._opponent_view(obs, infos)
        return (
            self._learner_view(obs),
            float(rewards[self.agent]),
            terminated,
            truncated,
            dict(infos[self.agent]),
        )

    def render(self) -> np.ndarray | None:
        """The env's frame (``"rgb_array"``) or window (``"human"``)."""
        return self.env.render()

    def close(self) -> None:
        """Close the envs' renderers (idempotent)."""
        for env in self.envs:
            env.close()


def _union_space(spaces: list[gym.spaces.Box], maps: list[Any]) -> gym.spaces.Box:
    """One Box holding the observations of every map (bounds may differ: ``"state"``)."""
    first = spaces[0]
    for world, space in zip(maps[1:], spaces[1:], strict=True):
        if space.shape != first.shape:
            raise InvalidConfigError(
                f"map: {world!r} gives observations of shape {space.shape}, the first map "
                f"{first.shape}; maps trained together need one observation shape"
            )
    if len(spaces) == 1:
        return first
    low = np.minimum.reduce([s.low for s in spaces])
    high = np.maximum.reduce([s.high for s in spaces])
    return gym.spaces.Box(low=low, high=high, dtype=first.dtype)
