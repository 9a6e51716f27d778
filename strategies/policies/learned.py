"""Learned policies: a stable-baselines3 model zip behind the Policy protocol.

``make_policy("pursuer/sb3:models/ppo_pursuer.zip")`` builds an :class:`SB3Policy`; the
zip is loaded on the first :meth:`~SB3Policy.reset` (stable-baselines3 and torch are
imported only then). The algorithm is read from the zip's metadata unless given.

**Only load model files you trust.** A stable-baselines3 zip holds pickled Python
objects (and SB3 unpickles them on load): a crafted model file runs arbitrary code on
the machine that loads it, as any pickle does. The models shipped in ``training/zoo``
come with this repository; treat a model from elsewhere like a program from elsewhere.

When a ``provenance.json`` written by :mod:`training` sits beside the zip, the policy
checks it on load: a model trained as a pursuer refuses to play the evader (and the
reverse), and the observation the model was trained on (``state`` or ``lidar`` with its
rays and range) is what the shared runner gives it (:attr:`SB3Policy.observation_options`).
A model trained with analytic features (``features`` in its DAgger config) reads the
state and builds its input as in training
(:class:`~strategies.policies.learner_inputs.LearnerInputs`).
"""

from __future__ import annotations

import json
import warnings
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError, InvalidObservationError, SurveilValueError
from strategies.policies.base import BasePolicy
from strategies.policies.learner_inputs import LearnerInputs, check_features
from strategies.policies.model_files import check_model_input, read_provenance
from strategies.policies.observe import finite_observation

__all__ = [
    "SB3_ALGORITHMS",
    "SB3_PARAMS",
    "SB3Policy",
    "UnseenMapWarning",
    "UnseenParametersWarning",
    "check_algo",
    "learner_inputs_spec",
    "maps_trained_on",
    "trained_map_digests",
    "trained_observation",
    "unseen_map_message",
    "unseen_parameters",
    "unseen_parameters_message",
]

SB3_ALGORITHMS = ("A2C", "DDPG", "PPO", "SAC", "TD3")
"""Algorithms :class:`SB3Policy` can load (continuous actions)."""

SB3_PARAMS = ("algo", "deterministic", "inputs")
"""The parameters a model takes as a policy (``--pursuer-params``, a spec's entry)."""


_PLAY_ONLY = {"lr_schedule": 0.0, "learning_rate": 0.0, "clip_range": 0.0}
"""SB3 ``custom_objects`` for a model that only acts (its training schedules unused)."""


class UnseenMapWarning(UserWarning):
    """A model that sees map coordinates plays a map it was not trained on."""


class UnseenParametersWarning(UserWarning):
    """A model plays a game whose speeds or ranges differ, up to scale, from the ones it
    was trained at (its ``provenance.json``'s ``env_config``)."""


_GAME_RATIOS = (
    ("rho = v_evader / v_pursuer", lambda c: c["v_evader"] / c["v_pursuer"],
     lambda c: f"{c['v_evader']:g} / {c['v_pursuer']:g}"),
    ("l_max / l_min", lambda c: c["l_max"] / c["l_min"],
     lambda c: f"{c['l_max']:g} / {c['l_min']:g}"),
    ("the pursuer's step in L_min, v_pursuer * dt / l_min",
     lambda c: c["v_pursuer"] * c["dt"] / c["l_min"],
     lambda c: f"{c['v_pursuer']:g} * {c['dt']:g} / {c['l_min']:g}"),
)  # fmt: skip
"""The numbers that fix a game up to scale (name, value, how it is made): a map scaled
with its ranges and speeds (``NAME~xS``) is the same game, so only these are compared."""

_RATIO_RTOL = 1e-6
"""Relative difference below which two ratios are the same (rounding of the inputs)."""

_GAME_KEYS = ("l_min", "l_max", "v_pursuer", "v_evader", "dt")


def unseen_parameters(provenance: Mapping[str, Any] | None, game: Any) -> str | None:
    """What differs, up to scale, between the game a model was trained at (its
    provenance's ``env_config``) and ``game`` (an ``EnvConfig``, or a mapping of its
    parameters): ``"rho = v_evader / v_pursuer: 0.5 in training (0.5 / 1), 0.8 here (0.8
    / 1)"``, the differing ratios joined by ``"; "``; ``None`` when none differs or the
    provenance records no game (an older one)."""
    trained = (provenance or {}).get("env_config") or {}
    try:
        was = {k: float(trained[k]) for k in _GAME_KEYS}
    except (KeyError, TypeError, ValueError):  # an older provenance: nothing to compare
        return None
    read = game.get if isinstance(game, Mapping) else lambda k: getattr(game, k)
    now = {k: float(read(k)) for k in _GAME_KEYS}
    differ = [
        f"{name}: {value(was):.4g} in training ({how(was)}), {value(now):.4g} here ({how(now)})"
        for name, value, how in _GAME_RATIOS
        if abs(value(now) - value(was)) > _RATIO_RTOL * abs(value(was))
    ]
    return "; ".join(differ) or None


def unseen_parameters_message(label: str, differ: str, *, games: int = 1) -> str:
    """The :class:`UnseenParametersWarning` of model ``label`` at ``games`` games where
    ``differ`` (:func:`unseen_parameters`, or several joined)."""
    what, how = ("a game", "this one") if games == 1 else (f"{games} games", "these")
    return (
        f"{label}: this model plays {what} it was not trained at: {differ}. Up to scale "
        "only these numbers matter (a map scaled with its ranges and speeds, NAME~xS, is "
        f"the same game); how it plays {how} is unmeasured"
    )


def maps_trained_on(provenance: Mapping[str, Any] | None) -> list[Any]:
    """The maps a model that sees map coordinates (observation ``"state"``) was trained
    on, as its config names them; empty for any other model (a lidar one sees no
    coordinates) or a provenance that names none."""
    prov = provenance or {}
    if (prov.get("env_config") or {}).get("observation") != "state":
        return []
    cfg = prov.get("config") or {}
    return list(cfg.get("maps") or ([cfg["map"]] if cfg.get("map") else []))


def trained_map_digests(provenance: Mapping[str, Any] | None) -> set[str]:
    """Geometry digests of the maps of :func:`maps_trained_on`, as they load now (those
    that do not load, e.g. a file moved since, are left out), and the one the provenance
    recorded. By geometry, not by name: a map file is named by its path in the config and
    by its own name on the map, and a user's map called "l_hall" is not the l_hall
    trained on."""
    from envs.maps import load_map

    found = {((provenance or {}).get("env_config") or {}).get("map_digest")}
    for name in maps_trained_on(provenance):
        try:
            found.add(load_map(str(name)).digest)
        except (ValueError, OSError):
            pass
    return {d for d in found if d}


def unseen_map_message(label: str, trained: list[Any], here: list[str]) -> str:
    """The :class:`UnseenMapWarning` of model ``label``, trained on ``trained``, playing
    the maps named ``here``, which it has not seen."""
    plays = f"{here[0]!r}, a map" if len(here) == 1 else f"{', '.join(map(repr, here))}, maps"
    return (
        f"{label}: this model sees map coordinates (observation 'state') and was trained "
        f"on {', '.join(map(str, trained))}; it plays {plays} it has not seen"
    )


def _algo_from_zip(path: Path) -> str:
    """The algorithm name recorded in an SB3 zip (its policy class's module path)."""
    try:
        with zipfile.ZipFile(path) as zf:
            data = json.loads(zf.read("data"))
    except (OSError, KeyError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
        raise InvalidConfigError(f"{path}: not a stable-baselines3 model zip ({exc})") from exc
    text = json.dumps(data.get("policy_class", ""))
    for algo in SB3_ALGORITHMS:
        if f"stable_baselines3.{algo.lower()}." in text:
            return algo
    if "stable_baselines3.common.policies" in text:
        # PPO and A2C both save the shared ActorCriticPolicy; only PPO stores clip_range
        return "PPO" if "clip_range" in data else "A2C"
    raise InvalidConfigError(
        f"{path}: cannot tell the algorithm from the zip; pass algo= one of {SB3_ALGORITHMS}"
    )


_ALGO_FAMILIES = ({"PPO", "A2C"}, {"TD3", "DDPG"}, {"SAC"})
"""Algorithms that load one another's zips (they save the same policy class)."""


def check_algo(algo: str, path: str | Path) -> str:
    """``algo`` upper-cased, if it is an SB3 algorithm that can load the zip at ``path``.

    A zip that does not say which algorithm saved it is not refused here (loading it
    will tell). ``algo = "SAC"`` for a PPO zip failed only as the model loaded, in every
    match of a tournament entry.

    Raises:
        InvalidConfigError: an unknown algorithm, or one that cannot load the zip's.
    """
    name = algo.upper()
    if name not in SB3_ALGORITHMS:
        raise InvalidConfigError(f"algo = {algo!r}: expected one of {list(SB3_ALGORITHMS)}")
    try:
        saved = _algo_from_zip(Path(path))
    except InvalidConfigError:
        return name
    if not any(name in family and saved in family for family in _ALGO_FAMILIES):
        raise InvalidConfigError(
            f"algo = {algo!r}: {path} was saved by {saved}, which {name} cannot load; "
            f"give algo = {saved!r}, or no algo (it is read from the zip)"
        )
    return name


class SB3Policy(BasePolicy):
    """A trained stable-baselines3 model playing one role.

    Args:
        path: the model zip.
        role: the role the model was trained for.
        algo: ``"PPO"``, ``"SAC"``... (``None``: read from the zip).
        deterministic: use the deterministic action.
        inputs: how to build the model's input from the state, for a model trained with
            analytic features (:func:`learner_inputs_spec`); ``None``: from the
            ``provenance.json`` beside the zip (a copy of the zip without it, e.g. a
            tournament's, needs this passed).
    """

    uses_state = False

    def __init__(
        self,
        path: str | Path,
        *,
        role: str,
        algo: str | None = None,
        deterministic: bool = True,
        name: str | None = None,
        inputs: Mapping[str, Any] | None = None,
    ) -> None:
        super().__init__(name=name or f"{role}/sb3:{path}")
        self.path = Path(path)
        self.roles = (role,)
        if algo is not None and algo.upper() not in SB3_ALGORITHMS:
            raise InvalidConfigError(f"algo must be one of {SB3_ALGORITHMS}, got {algo!r}")
        self.algo = algo.upper() if algo else None
        # bool("no") is True: a string or a number was taken for its truth
        self.deterministic = validation.boolean("deterministic", deterministic, where=self.name)
        self.model: Any = None
        self._warned: set[str] = set()
        self._digests: set[str] | None = None
        self._fits: set[tuple[str, int]] = set()  # observations found to fit the model
        self.provenance = read_provenance(self.path)
        trained = None if self.provenance is None else self.provenance.get("role")
        if trained is not None and trained != role:
            raise InvalidConfigError(
                f"{self.name}: this model was trained as the {trained} (its provenance.json "
                f"says role = {trained!r}); it cannot play the {role}"
            )
        if inputs is None:
            inputs = learner_inputs_spec(self.provenance)
        self._inputs = None if inputs is None else self._learner_inputs(inputs)
        if self._inputs is not None:
            self.uses_state = True  # the runner gives it the state; act() builds the input

    @property
    def inputs(self) -> LearnerInputs | None:
        """How the model's input is built from the state (a model trained with analytic
        features), or ``None`` for a model that reads the env's own observation."""
        return self._inputs

    def _learner_inputs(self, inputs: Mapping[str, Any]) -> LearnerInputs:
        """The input builder of a model trained with analytic features (see
        :func:`learner_inputs_spec`)."""
        where = f"{self.name}: inputs"
        if not isinstance(inputs, Mapping) or not inputs.get("features"):
            raise InvalidConfigError(
                f"{where} = {inputs!r}: expected a mapping with 'features' (a list of names), "
                "'observation', 'expert' and 'expert_params' (see learner_inputs_spec)"
            )
        features = check_features(
            inputs["features"], role=self.roles[0], expert=inputs.get("expert"), where=where
        )
        return LearnerInputs(inputs.get("observation"), features, inputs.get("expert_params"))

    @property
    def observation_options(self) -> dict[str, Any] | None:
        """The observation the runner should give the model (from its provenance), if
        known: the one it was trained on, or the state for a model with analytic
        features (it builds its input from the state, as in training)."""
        if self._inputs is not None:
            return {"observation": "state"}
        return trained_observation(self.provenance)

    def load(self) -> None:
        """Load the model file, once (the first :meth:`reset` does it otherwise, on the
        episode's clock: a tournament worker loads its models before its first match).

        Raises:
            InvalidConfigError: no model file, or one stable-baselines3 cannot load,
                naming the file.
        """
        if self.model is None:
            if not self.path.is_file():
                raise InvalidConfigError(f"{self.name}: no model file at {self.path}")
            import stable_baselines3

            algo = self.algo or _algo_from_zip(self.path)
            try:
                # playing needs no schedules: replacing them skips unpickling the saved
                # lambdas, which fails with a warning across Python/SB3 versions
                self.model = getattr(stable_baselines3, algo).load(
                    str(self.path), device="cpu", custom_objects=_PLAY_ONLY
                )
            except Exception as exc:  # a damaged zip: say which file, in one line
                raise InvalidConfigError(
                    f"{self.name}: cannot load the model file {self.path} "
                    f"({type(exc).__name__}: {exc})"
                ) from exc

    def check_observation(self, config: Any) -> None:
        """Refuse a game whose observation (``config``'s, as the runner resets this
        policy with it) has another shape than the model's input, before the model loads:
        it would fail its first :meth:`act` (a model without its provenance.json is given
        the env's own observation). A model of analytic features is not checked here (it
        builds its input from the state; :meth:`act` checks what it builds).

        Raises:
            InvalidConfigError: naming the model, its input shape and the one given.
        """
        given = {"observation": config.observation, "n_rays": config.n_rays}
        seen = (given["observation"], given["n_rays"])
        if self._inputs is not None or seen in self._fits or not self.path.is_file():
            return  # no file: load() says so
        check_model_input(
            self.path,
            [given],
            self.name,
            given_by="the game's",
            then="it would fail its first step; give it the observation it was trained "
            "on (the env's observation and n_rays), or put the provenance.json its "
            "training wrote beside it (the runner then gives it that observation)",
        )
        self._fits.add(seen)  # the zip is read once, not at every reset

    def _reset(self) -> None:
        self.check_observation(self.config)
        self.load()
        seed = int(self.rng.integers(2**31 - 1))
        self.model.set_random_seed(seed)
        if self._inputs is not None:
            self._inputs.reset(self.config, self.role)
        self._warn_unseen_map()
        self._warn_unseen_parameters()

    def _warn_unseen_parameters(self) -> None:
        """Warn (once per game) when the game's speed ratio, range ratio or step differs
        from the one the model was trained at: it never saw that game, whatever the map
        (a lidar generalist too)."""
        key = unseen_parameters(self.provenance, self.config)
        if key is None or key in self._warned:
            return
        self._warned.add(key)
        warnings.warn(
            unseen_parameters_message(self.name, key), UnseenParametersWarning, stacklevel=3
        )

    def _warn_unseen_map(self) -> None:
        """Warn (once per map) when a model that sees map coordinates plays a map it did
        not train on: a ``"state"`` observation places both agents in the map's bounds,
        so what it learned belongs to its training maps (a map specialist)."""
        trained = maps_trained_on(self.provenance)
        here = getattr(self.map, "name", None)
        if not trained or here is None or here in self._warned:
            return
        digest = getattr(self.map, "digest", None)
        if (here in trained) if digest is None else (digest in self._trained_digests()):
            return
        self._warned.add(here)
        warnings.warn(
            unseen_map_message(self.name, trained, [here]), UnseenMapWarning, stacklevel=3
        )

    def _trained_digests(self) -> set[str]:
        """:func:`trained_map_digests`, computed once."""
        if self._digests is None:
            self._digests = trained_map_digests(self.provenance)
        return self._digests

    def act(self, observation: np.ndarray) -> np.ndarray:
        """The model's action for one observation, clipped to [-1, 1].

        Raises:
            InvalidObservationError: the observation is not an array of finite real
                numbers, or its shape is not the one the model was trained on (another
                observation kind or ray count; for a model of analytic features, no
                ``"state"`` vector).
        """
        if self.role is None:
            raise InvalidConfigError(f"policy {self.name!r}: call reset() before act()")
        # NaN was torch's or int()'s ValueError
        finite_observation(observation, f"{self.name}: observation")
        obs = np.asarray(observation)
        if self._inputs is not None:
            try:
                obs = self._inputs(obs)
            except SurveilValueError:
                raise
            except ValueError as exc:  # decode_state's shape check, as analytic policies say it
                raise InvalidObservationError(f"{self.name}: observation: {exc}") from exc
        want = self.model.observation_space.shape
        if obs.shape != want:
            raise InvalidObservationError(
                f"{self.name}: observation of shape {obs.shape}, but the model was trained "
                f"on shape {want} (observation options {self.observation_options})"
            )
        action, _ = self.model.predict(obs, deterministic=self.deterministic)
        return np.clip(np.asarray(action, dtype=np.float32), -1.0, 1.0)


def trained_observation(provenance: Mapping[str, Any] | None) -> dict[str, Any] | None:
    """The env observation options a model was trained with, from its provenance."""
    env = (provenance or {}).get("env_config") or {}
    if "observation" not in env:
        return None
    opts = {"observation": env["observation"]}
    if env["observation"] != "state":
        opts["n_rays"] = env.get("n_rays", 32)
        if env.get("lidar_range") is not None:
            opts["lidar_range"] = env["lidar_range"]
    return opts


def learner_inputs_spec(provenance: Mapping[str, Any] | None) -> dict[str, Any] | None:
    """The ``inputs`` of a model trained with analytic features, from its provenance.

    ``{"observation": ..., "features": [...], "expert": ..., "expert_params": {...}}``
    (JSON-ready), or ``None`` for a model that reads the env's own observation.
    """
    cfg = (provenance or {}).get("config") or {}
    if not cfg.get("features"):
        return None
    return {
        "observation": trained_observation(provenance),
        "features": list(cfg["features"]),
        "expert": cfg.get("expert"),
        "expert_params": dict(cfg.get("expert_params") or {}),
    }
