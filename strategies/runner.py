"""The one episode loop: `surveil play`, tournaments, benchmarks and training all use it.

:func:`run_episode` builds a ``surveillance_v1`` parallel env from a map and env
overrides, draws (or takes) a start, seeds everything from one episode seed, plays two
policies against each other and returns an :class:`EpisodeResult`.

**Each policy gets the observation it was built for.** A policy says what it needs with
an ``observation_options`` attribute (or a method of that name): a mapping of the
observation fields of ``EnvConfig`` (:data:`OBSERVATION_OPTIONS`: ``observation``,
``n_rays``, ``lidar_range``), e.g. ``{"observation": "lidar", "n_rays": 32}`` for a
model trained on 32-ray lidar; ``None`` means "whatever the env gives". Without the
attribute, a policy with ``uses_state = True`` (every analytic policy, see
:class:`~strategies.policies.base.BasePolicy`) asks for ``{"observation": "state"}`` and
one with ``uses_state = False`` takes the env's own observation. The ``observations``
argument of :func:`run_episode` overrides both per role (a tournament spec may say
what a model was trained on). The env is built with the first non-state request (so it
encodes that one itself); a ``"state"`` request is served with ``env.state()`` (the same
encoder, bit for bit), and a second, different lidar request with the env's own
:class:`~envs.surveillance.observations.LidarEncoder` fed the exact positions and the
realised velocities (displacement / dt, as the env computes them). Each policy is reset
with the env's config carrying *its* observation settings.

**Seeding.** One episode seed, split with ``numpy.random.SeedSequence(seed).spawn(4)``
into the env's seed, the start sampler's, the pursuer's and the evader's (independent
streams): the same seed gives the same episode, bit for bit. A policy with a
``select(seed)`` method (a mixture, :class:`strategies.mixed.MixedPolicy`) first picks
the concrete policy of the episode with its role's seed.

**Failures.** An exception raised by a policy's ``act`` (or a non-``ValueError`` one from
its ``reset``), or an action the env refuses (NaN, inf, a wrong shape, not numbers: the
env's :class:`~envs.errors.InvalidActionError`), becomes a :class:`PolicyFailure` naming
the role, the policy and the step (the original exception is its ``__cause__``).
Configuration errors (``ValueError`` subclasses, see :mod:`envs.errors`) propagate
unchanged.

**Time limits are chess clocks.** ``time_limit`` is what each role may spend deciding in
the episode: its clock runs during its policy's ``reset`` and each of its ``act`` calls,
and only then. Building the env, drawing the start, making observations and stepping the
env are on no clock. The clock is read as each call returns, and a role whose clock has
passed the limit loses at once (:class:`EpisodeTimeout`, which blames that role whichever
side was slower overall). A call that raises past its clock is that timeout too, whatever
it raised, a configuration error included: a tournament worker's alarm interrupts a call
past its clock, and a policy may turn the interruption into an error of its own.
``on_clock(role, seconds_left)`` is told when a policy starts deciding and
``on_clock(None, None)`` when it stops (a tournament worker arms its alarm and tells its
driver from these).

Examples:
    >>> r = run_episode("open_room", "pursuer/greedy", "evader/straight", seed=3, max_cycles=20)
    >>> r.winner in ("pursuer", "evader"), r.trajectory.shape[1:]
    (True, (2, 2))
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from envs.errors import InvalidActionError, InvalidConfigError, MemoryBudgetError

__all__ = [
    "OBSERVATION_OPTIONS",
    "VALID_START",
    "EpisodeResult",
    "EpisodeTimeout",
    "Observer",
    "PolicyFailure",
    "Transition",
    "build_env",
    "check_observation_options",
    "episode_seeds",
    "map_parameters",
    "observation_options",
    "run_episode",
]

PURSUER, EVADER = "pursuer_0", "evader_0"
AGENT = {"pursuer": PURSUER, "evader": EVADER}
OBSERVATION_OPTIONS = ("observation", "n_rays", "lidar_range")
"""The ``EnvConfig`` fields that decide what an observation looks like."""

VALID_START = "start='valid'"
"""How a memory budget refusal of the safe start's judge names the way round it (a
command line renames it to its own flag)."""
_SEED_BOUND = 2**63


# --------------------------------------------------------------------------- failures
class PolicyFailure(RuntimeError):
    """A policy raised (or overran its time) during an episode: that role forfeits.

    Attributes:
        role: ``"pursuer"`` or ``"evader"``, the side at fault.
        policy: the policy's name.
        step: the env step at which it failed (``-1``: during reset).
        error: ``"TypeName: message"`` of the original exception.
    """

    def __init__(self, role: str, policy: str, step: int, error: str) -> None:
        where = "reset" if step < 0 else f"step {step}"
        super().__init__(f"{role} {policy!r} failed at {where}: {error}")
        self.role = role
        self.policy = policy
        self.step = step
        self.error = error

    def __reduce__(self):  # picklable across processes
        return (type(self), (self.role, self.policy, self.step, self.error))


class EpisodeTimeout(PolicyFailure):
    """``role``'s decision clock (its reset and acts) passed the episode's ``time_limit``."""


# --------------------------------------------------------------------------- records
@dataclass(frozen=True)
class Transition:
    """One env step as the ``on_step`` callback sees it.

    Attributes:
        step: index of the step (0 for the first).
        observations: ``{"pursuer": obs, "evader": obs}``, what each policy saw.
        state: the env's ``state()`` vector before the step (the ``"state"`` layout).
        actions: ``{"pursuer": action, "evader": action}`` the policies returned (float
            copies, so a policy reusing its buffer does not rewrite earlier records).
        info: the env's info of the pursuer after the step (surveillance, distance...).
        done: the episode ended with this step.
    """

    step: int
    observations: dict[str, np.ndarray]
    state: np.ndarray
    actions: dict[str, np.ndarray]
    info: dict[str, Any]
    done: bool


@dataclass
class EpisodeResult:
    """Outcome of one episode.

    Attributes:
        map: map name.
        map_digest: SHA-256 of the map's geometry (:attr:`envs.maps.Map.digest`).
        pursuer, evader: names of the policies that played (a mixture's pick).
        seed: the episode seed (env, start sampler and both policies derive from it).
        winner: ``"pursuer"`` (surveillance held to the horizon) or ``"evader"``.
        cause: why surveillance broke (``"occluded"``, ``"too_far"``, ``"too_close"``),
            ``None`` if it held.
        feature: the wall feature that occluded, as the map describes it, or ``None``.
        escape_time: time (s) at which surveillance broke, within the step; ``None`` if held.
        steps: env steps played.
        dt: step duration (s).
        start: ``{"pursuer": [x, y], "evader": [x, y]}``.
        start_kind: ``"safe"``, ``"valid"`` or ``"given"``.
        overrides: env config overrides used (besides the map's recommended parameters).
        observations: the observation settings each role was given.
        decide_seconds: mean wall-clock seconds per ``act`` call, per role (its
            ``reset`` is in ``reset_seconds``; a ``time_limit``'s clock counts both).
        decide_max: the longest ``act`` call, per role.
        reset_seconds: wall-clock seconds of the policy's ``reset``, per role.
        wall_seconds: wall-clock time of the whole episode.
        trajectory: (steps + 1, 2, 2) positions ``[pursuer, evader]`` per step, exact.
        map_obj: the :class:`Map` (for replays; not serialised).
        config: the env's ``EnvConfig`` (for replays; not serialised).
        frames: frames collected by ``record=True`` (``None`` otherwise; not serialised).
    """

    map: str
    map_digest: str
    pursuer: str
    evader: str
    seed: int
    winner: str
    cause: str | None
    feature: str | None
    escape_time: float | None
    steps: int
    dt: float
    start: dict[str, list[float]]
    start_kind: str
    overrides: dict[str, Any] = field(default_factory=dict)
    observations: dict[str, dict[str, Any]] = field(default_factory=dict)
    decide_seconds: dict[str, float] = field(default_factory=dict)
    decide_max: dict[str, float] = field(default_factory=dict)
    reset_seconds: dict[str, float] = field(default_factory=dict)
    wall_seconds: float = 0.0
    trajectory: np.ndarray | None = field(default=None, repr=False)
    map_obj: Any = field(default=None, repr=False)
    config: Any = field(default=None, repr=False)
    frames: list[np.ndarray] | None = field(default=None, repr=False)

    def summary(self) -> str:
        """One line: who won, why and when."""
        head = f"{self.map}: {self.pursuer} vs {self.evader} (seed {self.seed}): "
        if self.winner == "pursuer":
            return head + f"pursuer kept surveillance for all {self.steps} steps"
        return head + f"evader escaped at t = {self.escape_time:.3f} s ({self.cause})"

    def to_record(self) -> dict[str, Any]:
        """JSON-ready dict without trajectory, frames, map and config objects."""
        d = dataclasses.asdict(
            dataclasses.replace(self, trajectory=None, map_obj=None, config=None, frames=None)
        )
        for k in ("trajectory", "frames", "map_obj", "config"):
            d.pop(k)
        return d


# --------------------------------------------------------------------------- set-up
def map_parameters(map_: Any) -> tuple[Any, dict[str, float]]:
    """The :class:`Map` of ``map_`` and the recommended parameters of a built-in name.

    Args:
        map_: a map name (``envs.maps.load_map``), a map file path or a
            :class:`~envs.maps.Map`.

    Returns:
        ``(map, params)`` with ``params`` the built-in's ``l_min``, ``l_max``,
        ``v_pursuer`` and ``v_evader``, or those a map file's metadata recommends
        (:func:`envs.maps.io.recommended_parameters`), scaled for a transformed one
        (``NAME~xS...``); ``{}`` for random maps, Map objects and files recommending
        nothing: the env's defaults apply.
    """
    from envs.maps import Map, builtin_info, builtin_names, load_map
    from envs.maps.io import recommended_parameters

    if isinstance(map_, str) and map_ in builtin_names():
        return builtin_info(map_).map, builtin_info(map_).params()
    if (rec := recommended_parameters(map_)) is not None:
        return load_map(map_), rec
    if isinstance(map_, Map):
        return map_, {}
    from envs.surveillance.config import resolve_map

    return resolve_map(map_), {}


def build_env(
    map_: Any,
    overrides: Mapping[str, Any] | None = None,
    *,
    render_mode: str | None = None,
):
    """A ``surveillance_v1`` parallel env on ``map_``.

    A built-in map's (or a map file's) recommended ``l_min``, ``l_max`` and speeds apply
    unless ``overrides`` sets them.

    Raises:
        InvalidConfigError: an override is not an env argument or is out of range.
    """
    from envs import surveillance_v1

    world, kwargs = map_parameters(map_)
    kwargs.update(dict(overrides or {}))
    for bad in ("map", "render_mode"):
        if bad in kwargs:
            raise InvalidConfigError(f"env overrides: {bad!r} is set by the runner, not here")
    try:
        return surveillance_v1.parallel_env(map=world, render_mode=render_mode, **kwargs)
    except TypeError as exc:  # a misspelt env argument
        raise InvalidConfigError(f"env overrides: {exc}") from exc


def episode_seeds(seed: int) -> tuple[int, int, int, int]:
    """The env, start-sampler, pursuer and evader seeds of episode ``seed``."""
    from envs.validation import integer

    s = integer("seed", seed, minimum=0)
    ss = np.random.SeedSequence(s)
    return tuple(int(c.generate_state(1)[0]) for c in ss.spawn(4))  # type: ignore[return-value]


def observation_options(policy: Any) -> dict[str, Any] | None:
    """The observation settings ``policy`` needs (see the module docstring).

    Returns:
        A dict of :data:`OBSERVATION_OPTIONS` fields, or ``None`` for "the env's own".

    Raises:
        InvalidConfigError: the policy declares an unknown field or observation kind.
    """
    opts = getattr(policy, "observation_options", None)
    if callable(opts):
        opts = opts()
    if opts is None:
        return {"observation": "state"} if getattr(policy, "uses_state", True) else None
    return check_observation_options(opts, f"policy {getattr(policy, 'name', policy)!r}")


def check_observation_options(opts: Any, where: str) -> dict[str, Any]:
    """``opts`` as a dict of :data:`OBSERVATION_OPTIONS` with a known observation kind.

    Raises:
        InvalidConfigError: naming ``where``, the bad field or kind.
    """
    from envs.surveillance.config import OBSERVATION_KINDS

    if not isinstance(opts, Mapping):
        raise InvalidConfigError(
            f"{where}: observation options must be a mapping such as "
            f"{{'observation': 'lidar', 'n_rays': 32}}, got {opts!r}"
        )
    unknown = sorted(set(opts) - set(OBSERVATION_OPTIONS))
    if unknown:
        raise InvalidConfigError(
            f"{where}: observation options {unknown} are not among {list(OBSERVATION_OPTIONS)}"
        )
    kind = opts.get("observation")
    if kind not in OBSERVATION_KINDS:
        raise InvalidConfigError(
            f"{where}: observation = {kind!r}: expected one of {list(OBSERVATION_KINDS)}"
        )
    return dict(opts)


def _settings(config: Any, opts: Mapping[str, Any]) -> tuple:
    """What an observation looks like under ``config`` with ``opts`` applied."""
    kind = opts.get("observation", config.observation)
    if kind == "state":
        return ("state",)
    rays = opts.get("n_rays", config.n_rays)
    rng = opts.get("lidar_range", config.lidar_range)
    return (kind, int(rays), None if rng is None else float(rng))


class Observer:
    """Serves one role the observation it asked for from the env of the episode.

    Args:
        env: the episode's parallel env (built, not yet reset).
        role: ``"pursuer"`` or ``"evader"``.
        opts: the role's :data:`OBSERVATION_OPTIONS` (``{}``: the env's own).

    ``config`` is the env config to reset the role's policy with; calling it with the
    env's observations, whether the evader is in sight and the step gives the role's. A
    new one for each episode (a lidar track differentiates positions across steps).
    """

    def __init__(self, env: Any, role: str, opts: Mapping[str, Any]) -> None:
        cfg = env.config
        self.env = env
        self.agent = AGENT[role]
        mine = _settings(cfg, opts)
        self.config = cfg if mine == _settings(cfg, {}) else _replace(cfg, **opts)
        self.options = dict(zip(OBSERVATION_OPTIONS[: len(mine)], mine, strict=False))
        if mine == _settings(cfg, {}):
            self.mode = "env"
        elif mine == ("state",):
            self.mode = "state"
        else:
            from envs.surveillance.observations import LidarEncoder

            self.mode = "lidar"
            self.encoder = LidarEncoder(self.config, role, env.kernel)
            self.role = role
            self.inv_dt = 1.0 / cfg.dt
            self.prev: tuple | None = None

    def __call__(self, obs: dict[str, np.ndarray], visible: bool, step: int) -> np.ndarray:
        if self.mode == "env":
            return obs[self.agent]
        if self.mode == "state":
            return self.env.state()
        p, e = self.env.world.positions()
        if self.prev is None:
            vp = ve = (0.0, 0.0)
        else:  # the realised velocities, as the env computes them
            p0, e0 = self.prev
            vp = ((p[0] - p0[0]) * self.inv_dt, (p[1] - p0[1]) * self.inv_dt)
            ve = ((e[0] - e0[0]) * self.inv_dt, (e[1] - e0[1]) * self.inv_dt)
        self.prev = (p, e)
        if self.role == "pursuer":
            return self.encoder.encode(p, vp, e, visible, step, ve)
        return self.encoder.encode(e, ve, p, visible, step, vp)


def _make(policy: Any, role: str):
    from strategies.policies import Policy, make_policy
    from strategies.policies.model_files import is_model_reference, model_policy_name

    if isinstance(policy, str):
        given = policy
        if is_model_reference(policy):  # zoo:NAME or a model .zip, as surveil play takes them
            policy = model_policy_name(policy, role, f"{role}: model = {policy!r}")
        if policy.partition("/")[0] != role:
            raise InvalidConfigError(
                f"{role}: expected a '{role}/KIND' policy name, 'zoo:NAME' or a model .zip, "
                f"got {policy!r}"
            )
        made = make_policy(policy)
        if policy != given:  # records and errors name the model as the caller did
            made.name = given
        return made
    if isinstance(policy, Policy) or hasattr(policy, "select"):
        return policy
    raise InvalidConfigError(
        f"{role}: expected a policy name or a Policy, got {type(policy).__name__} {policy!r}"
    )


# --------------------------------------------------------------------------- the loop
def run_episode(
    map: Any,
    pursuer: Any,
    evader: Any,
    seed: int = 0,
    *,
    max_cycles: int | None = None,
    overrides: Mapping[str, Any] | None = None,
    start: str | Mapping[str, Any] = "safe",
    observations: Mapping[str, Mapping[str, Any] | None] | None = None,
    on_step: Callable[[Transition], None] | None = None,
    on_frame: Callable[[np.ndarray], None] | None = None,
    record: bool = False,
    time_limit: float | None = None,
    on_clock: Callable[[str | None, float | None], None] | None = None,
) -> EpisodeResult:
    """Play one episode between two policies.

    Args:
        map: built-in name, map file path or :class:`~envs.maps.Map`.
        pursuer, evader: registered names (``"pursuer/decomposition"``), shipped or
            saved models (``"zoo:NAME"``, a model ``.zip``: its ``provenance.json`` must
            not name the other role), policies, or mixtures (anything with
            ``select(seed) -> Policy``).
        seed: the episode seed (see the module docstring).
        max_cycles: episode horizon in steps (``None``: the overrides' or the default).
        overrides: env config overrides, e.g. ``{"v_evader": 0.8}``; a built-in map's
            recommended parameters apply to what they leave unset.
        start: ``"safe"`` (a non-escapable cell at L_min where one exists), ``"valid"``
            (any valid surveillance configuration), both drawn by
            :func:`strategies.policies.starts.sample_start`, or an explicit
            ``{"pursuer": (x, y), "evader": (x, y)}``.
        observations: per role (``"pursuer"``, ``"evader"``) observation options that
            override what the policy declares.
        on_step: called after every env step with a :class:`Transition`.
        on_frame: called with each rendered RGB frame (the env renders ``"rgb_array"``);
            frames are not kept, so a writer can stream them.
        record: also keep the frames in ``result.frames`` (memory grows with the episode).
        time_limit: wall-clock seconds each role may spend deciding in the episode (> 0):
            its ``reset`` and all its ``act`` calls (see the module docstring).
        on_clock: called with ``(role, seconds left on its clock)`` (``None`` without a
            limit) as a policy starts a ``reset`` or ``act``, and with ``(None, None)`` as
            it returns.

    Returns:
        The :class:`EpisodeResult`.

    Raises:
        PolicyFailure: a policy raised while playing, or returned an action the env
            refuses (its role forfeits).
        EpisodeTimeout: a role's decision clock passed ``time_limit`` (that role).
        InvalidConfigError: bad arguments (names, overrides, start, observations,
            time_limit).
    """
    from strategies.policies.starts import START_KINDS, sample_start

    t_start = time.perf_counter()
    clocks = _Clocks(time_limit, on_clock)
    if time_limit is not None:  # a bad limit is the caller's error, not a policy's forfeit
        from envs.validation import positive

        time_limit = positive("time_limit", time_limit)
    overrides = dict(_mapping("overrides", overrides, "{'v_evader': 0.8}"))
    if max_cycles is not None:
        overrides["max_cycles"] = max_cycles
    s_env, s_start, s_p, s_e = episode_seeds(seed)
    policies = {"pursuer": _make(pursuer, "pursuer"), "evader": _make(evader, "evader")}
    seeds = {"pursuer": s_p, "evader": s_e}
    for role, pol in policies.items():
        if hasattr(pol, "select"):  # a mixture: the concrete policy of this episode
            rng = np.random.default_rng(seeds[role])
            policies[role] = pol.select(int(rng.integers(_SEED_BOUND)))
            seeds[role] = int(rng.integers(_SEED_BOUND))
    requests = _requests(policies, overrides, observations)
    env_obs = next(
        (r for r in (requests["pursuer"], requests["evader"]) if r["observation"] != "state"),
        {"observation": "state"},
    )
    render = "rgb_array" if (on_frame is not None or record) else None
    env = build_env(map, {**overrides, **env_obs}, render_mode=render)
    try:
        config = env.config
        observers = {r: Observer(env, r, requests[r]) for r in policies}
        if isinstance(start, Mapping):
            placement, start_kind = dict(start), "given"
        elif start in START_KINDS:
            judge = config if config.observation == "state" else _state_config(config)
            with MemoryBudgetError.naming(VALID_START, MemoryBudgetError.ENV_BUDGET):
                placement = sample_start(judge, np.random.default_rng(s_start), kind=start)
            start_kind = start
        else:
            raise InvalidConfigError(
                f"start: expected one of {list(START_KINDS)} or "
                f"{{'pursuer': (x, y), 'evader': (x, y)}}, got {start!r}"
            )
        reset_seconds = {}
        for role, pol in policies.items():
            t0 = clocks.start(role)
            try:
                pol.reset(
                    role=role, map=config.map, config=observers[role].config, seed=seeds[role]
                )
            except MemoryBudgetError as exc:  # say whose parameter (the table's resolution)
                knob = exc.args[1]
                if not knob or _name(pol) in knob:
                    raise
                raise exc.named(f"{_name(pol)!r} with {knob}") from None
            except ValueError as exc:
                clocks.check(role, _name(pol), -1, t0, exc)
                raise
            except Exception as exc:
                clocks.check(role, _name(pol), -1, t0, exc)
                raise PolicyFailure(role, _name(pol), -1, _describe(exc)) from exc
            finally:
                reset_seconds[role] = clocks.stop(role, t0)
            clocks.check(role, _name(pol), -1)
        obs, infos = env.reset(seed=s_env, options=placement)
        frames: list[np.ndarray] | None = [] if record else None
        _emit_frame(env, on_frame, frames)
        traj = [env.world.positions()]
        spent = {"pursuer": 0.0, "evader": 0.0}
        slowest = {"pursuer": 0.0, "evader": 0.0}
        steps, cause, feature, escape = 0, None, None, None
        visible = bool(infos[PURSUER].get("surveillance", True))
        while env.agents:
            seen = {r: observers[r](obs, visible, steps) for r in policies}
            state = env.state() if on_step is not None else None
            actions = {}
            for role, pol in policies.items():
                t0 = clocks.start(role)
                try:
                    actions[role] = pol.act(seen[role])
                except Exception as exc:
                    clocks.check(role, _name(pol), steps, t0, exc)
                    raise PolicyFailure(role, _name(pol), steps, _describe(exc)) from exc
                finally:
                    dt = clocks.stop(role, t0)
                clocks.check(role, _name(pol), steps)
                try:  # an action the env refuses (NaN, wrong shape...) is the policy's fault
                    env._command(AGENT[role], actions[role])
                except InvalidActionError as exc:
                    raise PolicyFailure(role, _name(pol), steps, _describe(exc)) from exc
                spent[role] += dt
                slowest[role] = max(slowest[role], dt)
            obs, _, _, _, infos = env.step({AGENT[r]: a for r, a in actions.items()})
            info = infos[PURSUER]
            steps += 1
            traj.append(env.world.positions())
            _emit_frame(env, on_frame, frames)
            visible = bool(info.get("surveillance", True))
            if not visible:
                cause, feature = info.get("cause"), info.get("feature")
                escape = float(info["break_at"])
            if on_step is not None:  # copies: a policy may reuse its action's buffer
                taken = {r: np.array(a, dtype=float) for r, a in actions.items()}
                on_step(Transition(steps - 1, seen, state, taken, info, not env.agents))
    finally:
        env.close()
    return EpisodeResult(
        map=config.map.name,
        map_digest=config.map.digest,
        pursuer=_name(policies["pursuer"]),
        evader=_name(policies["evader"]),
        seed=int(seed),
        winner="evader" if cause is not None else "pursuer",
        cause=cause,
        feature=None if feature is None else str(feature),
        escape_time=escape,
        steps=steps,
        dt=config.dt,
        start={k: [float(v) for v in placement[k]] for k in ("pursuer", "evader")},
        start_kind=start_kind,
        overrides=overrides,
        observations={r: dict(o.options) for r, o in observers.items()},
        decide_seconds={k: v / max(steps, 1) for k, v in spent.items()},
        decide_max=dict(slowest),
        reset_seconds=reset_seconds,
        wall_seconds=time.perf_counter() - t_start,
        trajectory=np.asarray(traj, dtype=float),
        map_obj=config.map,
        config=config,
        frames=frames,
    )


class _Clocks:
    """The two roles' decision clocks of one episode (see the module docstring)."""

    def __init__(
        self, limit: float | None, watch: Callable[[str | None, float | None], None] | None
    ) -> None:
        self.limit = limit
        self.watch = watch
        self.spent = {"pursuer": 0.0, "evader": 0.0}

    def start(self, role: str) -> float:
        """Start ``role``'s clock (call :meth:`stop` with what it returns, however it ends)."""
        if self.watch is not None:
            self.watch(role, None if self.limit is None else self.limit - self.spent[role])
        return time.perf_counter()

    def stop(self, role: str, t0: float) -> float:
        """Stop ``role``'s clock started at ``t0``; the seconds it ran."""
        took = time.perf_counter() - t0
        self.spent[role] += took
        if self.watch is not None:
            self.watch(None, None)
        return took

    def check(
        self,
        role: str,
        policy: str,
        step: int,
        t0: float | None = None,
        raised: BaseException | None = None,
    ) -> None:
        """Raise :class:`EpisodeTimeout` if ``role``'s clock has passed the limit.

        ``t0`` and ``raised``: the call started at ``t0`` (its clock still running) raised
        ``raised``. Past the clock, that is the role's timeout whatever the call raised:
        a tournament worker's alarm interrupts a call past its clock, and a policy may
        turn that interruption into an error of its own (a model loader reports any
        failure of its load as a bad model file, an ``InvalidConfigError``)."""
        spent = self.spent[role] + (0.0 if t0 is None else time.perf_counter() - t0)
        if self.limit is None or spent <= self.limit:
            return
        other = "evader" if role == "pursuer" else "pursuer"
        then = "" if raised is None else f"; the call then raised {_describe(raised)}"
        timeout = EpisodeTimeout(
            role,
            policy,
            step,
            f"its clock ran out: {_seconds(spent)} s of decision time (reset and acts) "
            f"against the time limit of {self.limit:g} s per role (the {other}'s clock: "
            f"{_seconds(self.spent[other])} s){then}",
        )
        if raised is not None:
            raise timeout from raised
        raise timeout


def _requests(
    policies: dict[str, Any],
    overrides: Mapping[str, Any],
    explicit: Mapping[str, Mapping[str, Any] | None] | None,
) -> dict[str, dict[str, Any]]:
    explicit = dict(_mapping("observations", explicit, "{'pursuer': {'observation': 'lidar'}}"))
    unknown = sorted(set(explicit) - {"pursuer", "evader"})
    if unknown:
        raise InvalidConfigError(f"observations: keys must be 'pursuer' or 'evader', got {unknown}")
    default = {k: overrides[k] for k in OBSERVATION_OPTIONS if k in overrides}
    default.setdefault("observation", "state")
    out = {}
    for role, pol in policies.items():
        if explicit.get(role) is not None:
            req = check_observation_options(explicit[role], f"observations[{role!r}]")
        else:
            req = observation_options(pol)
        out[role] = dict(default) if req is None else req
    return out


def _mapping(name: str, value: Any, example: str) -> Mapping[str, Any]:
    """``value`` if it is a mapping (``None``: an empty one); a list or a string was
    dict()'s TypeError or ValueError ('dictionary update sequence element #0 ...')."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise InvalidConfigError(
            f"{name} = {value!r}: expected a mapping such as {example}, got {type(value).__name__}"
        )
    return value


def _replace(config: Any, **changes: Any) -> Any:
    """A copy of an env config with other observation settings (warned about already)."""
    import warnings

    from envs.errors import NarrowBandWarning, RhoAboveOneWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RhoAboveOneWarning)
        warnings.simplefilter("ignore", NarrowBandWarning)
        return dataclasses.replace(config, **changes)


def _state_config(config: Any) -> Any:
    return _replace(config, observation="state")


def _emit_frame(env: Any, sink: Callable | None, frames: list | None) -> None:
    if sink is None and frames is None:
        return
    frame = env.render()
    if sink is not None:
        sink(frame)
    if frames is not None:
        frames.append(frame)


def _name(policy: Any) -> str:
    return str(getattr(policy, "name", type(policy).__name__))


def _seconds(x: float) -> str:
    """``x`` seconds to two decimals, or two significant digits below 5 ms (a clock of a
    tiny time limit read '0.00 s ... against the time limit of 0.0001 s')."""
    return f"{x:.2f}" if x >= 0.005 else f"{x:.2g}"


def _describe(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0]}" if lines else type(exc).__name__
