"""Policies that play the referee's certified strategies in the env.

A referee policy recomputes its plan every referee step (``tau``, a whole number of env
steps): it reads both real positions, asks its bound for a certified straight move to a
lattice point (:meth:`PursuerBound.plan`, :meth:`EvaderBound.plan`) and drives there at
constant velocity, re-aiming at the target each env step so that float32 observations do
not make it drift. From a start its bound certifies, it cannot lose (pursuer) or fail to
break surveillance within the certified number of steps (evader), whatever the opponent
does: that is what the tests check, episode by episode, against every registered opponent.

Off certified states it falls back to a simple heuristic, decided every env step (the
pursuer keeps the distance at the middle of the sensor range, the evader charges the
pursuer) and records that it did, in ``uncertified_steps``.

Built without a bound (``make_policy("evader/referee", cells_per_lmin=16)``), a policy
solves the bound it plays at reset, at that resolution and with its ``tau`` a whole number
of env steps (:func:`strategies.referee.referee.solve_role`; cached on disk, so only the
first episode on a world pays). Where its lattice misses a map's narrow passages, reset
raises :class:`~envs.errors.NoStartError` naming the policy, the map and the next
``cells_per_lmin`` whose lattices hold a start.
"""

from __future__ import annotations

import math

import numpy as np

from envs.errors import InvalidConfigError, MemoryBudgetError, NoStartError
from strategies.policies.base import BasePolicy, Snapshot, unit
from strategies.referee.evader_bound import EvaderBound
from strategies.referee.pursuer_bound import PursuerBound
from strategies.referee.spec import check_cells_per_lmin

__all__ = ["RefereeEvader", "RefereePursuer", "env_steps_per_referee_step"]


def env_steps_per_referee_step(tau: float, dt: float) -> int:
    """The whole number of env steps in one referee step.

    Raises:
        InvalidConfigError: ``tau`` is not a multiple of ``dt`` (to 1e-9 relative).
    """
    k = max(1, round(tau / dt))
    if abs(k * dt - tau) > 1e-9 * max(tau, dt):
        raise InvalidConfigError(
            f"referee step tau = {tau!r} is not a whole number of env steps dt = {dt!r}; "
            "build the resolution with Resolution.for_role(..., dt=dt)"
        )
    return k


_SOLVED: dict = {}
"""The bounds solved in this process, by (game, resolution, dt, role): episodes on the
same world reuse them instead of reloading the disk cache at every reset. A resolution
whose lattice has no point keeps its :class:`~envs.errors.NoStartError`, so the next
episodes are refused at once (a tournament records each as an error)."""


def _solved(config, cells_per_lmin: float, role: str):
    """The bound ``role`` plays in the env's game, solved or loaded once per process (the
    other bound is not needed: it was solved too, half of the reset's time, before)."""
    from strategies.referee.referee import solve_role
    from strategies.referee.spec import GameSpec

    spec = GameSpec.from_config(config)
    key = (spec, float(cells_per_lmin), float(config.dt), role)
    bound = _SOLVED.get(key)
    if bound is None:
        try:
            bound = solve_role(spec, role, cells_per_lmin, dt=config.dt)
        except NoStartError as exc:
            bound = exc
        if len(_SOLVED) >= 8:
            _SOLVED.pop(next(iter(_SOLVED)))
        _SOLVED[key] = bound
    if isinstance(bound, NoStartError):
        raise NoStartError(*bound.args)
    return bound


class _RefereePolicy(BasePolicy):
    """Shared plumbing: step counting, target following, the certified flag."""

    role_name = ""
    bound_type: type = object

    def __init__(self, bound=None, *, cells_per_lmin: float = 16.0, name: str | None = None):
        super().__init__(name=name or f"{self.role_name}/referee")
        if bound is not None and not isinstance(bound, self.bound_type):
            raise InvalidConfigError(
                f"{type(self).__name__}: expected a {self.bound_type.__name__}, got "
                f"{type(bound).__name__}"
            )
        self.roles = (self.role_name,)
        self.bound = bound
        self._solve = bound is None
        self.cells_per_lmin = check_cells_per_lmin(cells_per_lmin)
        self._k = 1
        self._target: np.ndarray | None = None
        self.uncertified_steps = 0
        self.referee_steps = 0

    def _reset(self) -> None:
        cfg = self.config
        if self._solve:
            # a policy has no memory_budget argument; its users set cells_per_lmin
            try:
                with MemoryBudgetError.naming(f"{self.name!r} with cells_per_lmin"):
                    self.bound = _solved(cfg, self.cells_per_lmin, self.role_name)
            except NoStartError as exc:  # a map whose passages its lattice misses: it said
                # "no lattice point ... of map 'ring'; try another resolution", naming no
                # policy, parameter or resolution
                raise NoStartError(f"policy {self.name!r}: {exc.args[0]}", *exc.args[1:]) from None
        spec = self.bound.spec
        for attr in ("l_min", "l_max", "v_pursuer", "v_evader"):
            if not math.isclose(getattr(cfg, attr), getattr(spec, attr), rel_tol=1e-12):
                raise InvalidConfigError(
                    f"policy {self.name!r}: the env's {attr} = {getattr(cfg, attr)!r} differs "
                    f"from the solved game's {getattr(spec, attr)!r}"
                )
        if self.map.digest != spec.map.digest:
            raise InvalidConfigError(
                f"policy {self.name!r}: the env's map {self.map.name!r} is not the solved map "
                f"{spec.map.name!r}"
            )
        if cfg.body_radius > spec.body_radius * (1 + 1e-12):
            raise InvalidConfigError(
                f"policy {self.name!r}: the env's body_radius = {cfg.body_radius!r} exceeds "
                f"the solved clearance {spec.body_radius!r}"
            )
        self._k = env_steps_per_referee_step(self.bound.res.tau, cfg.dt)
        self._target = None
        self.uncertified_steps = 0
        self.referee_steps = 0

    def _decide(self, snap: Snapshot) -> np.ndarray:
        phase = self._steps % self._k
        mine = snap.pursuer if self.role == "pursuer" else snap.evader
        if phase == 0:
            self.referee_steps += 1
            self._target = self._plan(snap)
            if self._target is None:
                self.uncertified_steps += 1
        if self._target is None:
            # off certified states the heuristic answers every env step: held for a whole
            # referee step, the pursuer's range keeper ran at V_p for tau and overshot
            # the range by up to V_p tau (corridor: out of range in 2.3 s, whoever the evader)
            return self._heuristic(snap)
        remaining = (self._k - phase) * float(self.config.dt)
        return (self._target - mine) / remaining

    def _plan(self, snap: Snapshot) -> np.ndarray | None:
        raise NotImplementedError

    def _heuristic(self, snap: Snapshot) -> np.ndarray:
        raise NotImplementedError


class RefereePursuer(_RefereePolicy):
    """Plays the pursuer bound's certified strategy.

    Args:
        bound: a solved :class:`PursuerBound` of the env's game (same map, range and
            speeds; its ``tau`` a whole number of env steps); None: solve the env's game
            at reset.
        cells_per_lmin: the resolution of that solve.
        name: registry-style name.
    """

    role_name = "pursuer"
    bound_type = PursuerBound

    def _plan(self, snap: Snapshot) -> np.ndarray | None:
        return self.bound.plan(snap.pursuer, snap.evader)

    def _heuristic(self, snap: Snapshot) -> np.ndarray:
        spec = self.bound.spec
        mid = 0.5 * (spec.l_min + spec.l_max)
        rod = snap.pursuer - snap.evader
        return unit(rod) * (mid - snap.L) / float(self.config.dt)


class RefereeEvader(_RefereePolicy):
    """Plays the evader bound's certified strategy.

    Args:
        bound: a solved :class:`EvaderBound` of the env's game; None: solve the env's
            game at reset.
        cells_per_lmin: the resolution of that solve.
        name: registry-style name.

    Attributes:
        certified_steps: when the first referee step was certified, the bound on the
            referee steps it needed to break surveillance (None otherwise).
    """

    role_name = "evader"
    bound_type = EvaderBound

    def __init__(self, bound=None, *, cells_per_lmin: float = 16.0, name: str | None = None):
        super().__init__(bound, cells_per_lmin=cells_per_lmin, name=name)
        self.certified_steps: int | None = None

    def _reset(self) -> None:
        super()._reset()
        self.certified_steps = None

    def _plan(self, snap: Snapshot) -> np.ndarray | None:
        got = self.bound.plan(snap.pursuer, snap.evader)
        if got is None:
            return None
        if self.referee_steps == 1:
            self.certified_steps = got[1]
        return got[0]

    def _heuristic(self, snap: Snapshot) -> np.ndarray:
        return unit(snap.pursuer - snap.evader) * self.bound.spec.v_evader
