"""What the referee solves: the game (:class:`GameSpec`) and how finely (:class:`Resolution`).

Both are frozen, validated dataclasses (``envs.validation``); bad values raise
:class:`~envs.errors.InvalidConfigError` naming the value. Their :meth:`key` is the
material of cache keys (the map enters by its wall digest).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from envs import validation as V
from envs.errors import InvalidConfigError
from envs.maps import Map

__all__ = ["MARGIN_REL", "MAX_CELLS_PER_LMIN", "GameSpec", "Resolution", "check_cells_per_lmin"]

MARGIN_REL = 1e-6
"""Safety margin of every robust test, relative to the map's scale.

It absorbs the kernel's contact tolerance (``REL_LENGTH_TOL``, 1000 times smaller) and
the float32 rounding of positions in the env's ``"state"`` observation, which is what a
referee policy reads its position from.
"""


MAX_CELLS_PER_LMIN = 1e12
"""The finest resolution a solve or an estimate takes. A solve's states grow as the
fourth power of it (about 1e43 million on the corner world at 1e12, refused by the memory
budget in a second); from about 1e70 its size estimate overflowed a float (1e100: an
OverflowError, 1e300: a ZeroDivisionError, tracebacks)."""


def check_cells_per_lmin(value: Any, name: str = "cells_per_lmin") -> float:
    """``value`` as a float in ``(0, MAX_CELLS_PER_LMIN]``.

    Raises:
        InvalidConfigError: it is not a finite number > 0, or it is above
            :data:`MAX_CELLS_PER_LMIN`, naming it.
    """
    cpl = V.positive(name, value)
    if cpl > MAX_CELLS_PER_LMIN:
        raise InvalidConfigError(
            f"{name} = {value!r}: expected at most {MAX_CELLS_PER_LMIN:g} (a solve's states "
            "grow as its fourth power: far beyond any memory there already)"
        )
    return cpl


def _check_map(value: Any, where: str | None) -> Map:
    if not isinstance(value, Map):
        raise InvalidConfigError(
            f"{where + ': ' if where else ''}map = {value!r}: expected an envs.maps.Map, "
            f"got {type(value).__name__}"
        )
    return value


@dataclass(frozen=True)
class GameSpec:
    """The bounded-speed surveillance game (paper, Secs. 2 and 5) on one map.

    The pursuer P and the evader E are points moving at speeds at most ``v_pursuer`` and
    ``v_evader`` in the map's free region F. Surveillance holds while
    ``l_min <= |P - E| <= l_max`` and the segment P-E (the rod) touches no wall; the evader
    wins the moment it breaks, the pursuer if it never does.

    Attributes:
        map: the world.
        l_min: L_min > 0.
        l_max: L_max > l_min.
        v_pursuer: V_p > 0.
        v_evader: V_e > 0 (rho = V_e / V_p).
        body_radius: clearance the *certified* player keeps from every wall on its
            lattice points and along its moves: the env's disc radius, so a referee policy
            never touches a wall and moves exactly as planned. In (0, l_min / 2), as the
            env's: the two discs must not overlap at L_min.
        opponent_clearance: the opponent is assumed to stay at least this far (> 0) from
            the walls; ``None`` means ``body_radius / 2``, what the env's physics
            guarantees for a disc of ``body_radius`` pressed against a wall (a substep
            travels at most half a radius, ``envs.surveillance.physics``).
    """

    map: Map
    l_min: float
    l_max: float
    v_pursuer: float = 1.0
    v_evader: float = 0.5
    body_radius: float = 0.1
    opponent_clearance: float | None = None
    where: str | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        put = lambda name, value: object.__setattr__(self, name, value)
        w = self.where
        put("map", _check_map(self.map, w))
        put("l_min", V.positive("l_min", self.l_min, where=w))
        put("l_max", V.positive("l_max", self.l_max, where=w))
        if self.l_max <= self.l_min:
            raise InvalidConfigError(
                f"{w + ': ' if w else ''}l_max = {self.l_max!r}: expected a number > "
                f"l_min = {self.l_min!r}"
            )
        put("v_pursuer", V.positive("v_pursuer", self.v_pursuer, where=w))
        put("v_evader", V.positive("v_evader", self.v_evader, where=w))
        put("body_radius", V.positive("body_radius", self.body_radius, where=w))
        if self.body_radius >= 0.5 * self.l_min:  # as EnvConfig refuses it
            raise InvalidConfigError(
                f"{w + ': ' if w else ''}body_radius = {self.body_radius!r}: expected a value "
                f"in (0, l_min / 2 = {0.5 * self.l_min!r}) (two bodies of that radius "
                "overlap at L_min)"
            )
        if self.opponent_clearance is None:
            put("opponent_clearance", 0.5 * self.body_radius)
        else:
            put(
                "opponent_clearance",
                V.positive("opponent_clearance", self.opponent_clearance, where=w),
            )

    @classmethod
    def from_config(cls, config: Any, **overrides: Any) -> GameSpec:
        """The game an env plays: ``map, l_min, l_max, v_pursuer, v_evader, body_radius``
        read from an ``EnvConfig`` (or anything with those attributes), then ``overrides``.
        """
        values = {
            k: getattr(config, k)
            for k in ("map", "l_min", "l_max", "v_pursuer", "v_evader", "body_radius")
        }
        values.update(overrides)
        return cls(**values)

    @property
    def rho(self) -> float:
        """rho = V_e / V_p."""
        return self.v_evader / self.v_pursuer

    @property
    def margin(self) -> float:
        """Absolute margin of the robust tests (:data:`MARGIN_REL` times the map scale)."""
        return MARGIN_REL * self.map.scale

    def speed(self, role: str) -> float:
        """Speed bound of ``"pursuer"`` or ``"evader"``."""
        return self.v_pursuer if role == "pursuer" else self.v_evader

    def key(self) -> dict[str, Any]:
        """Cache-key material: the map's digest and every parameter, exactly (float.hex)."""
        return {
            "map": self.map.digest,
            **{
                k: float(getattr(self, k)).hex()
                for k in (
                    "l_min",
                    "l_max",
                    "v_pursuer",
                    "v_evader",
                    "body_radius",
                    "opponent_clearance",
                )
            },
        }


@dataclass(frozen=True)
class Resolution:
    """How finely the referee discretises the game.

    Attributes:
        cell: side h of the square cells that locate the *opponent* (> 0).
        coarse: the certified player lives on the lattice of spacing ``coarse * cell``
            (an integer >= 1; a sub-lattice of the cell centres).
        tau: duration of one referee step, in the game's time units (> 0). The certified
            player moves along straight lattice vectors of length <= V tau.
        sweep_pieces: the pursuer-bound sweep test splits each step into this many pieces
            (>= 1): more pieces, a tighter test, more work.
    """

    cell: float
    coarse: int = 4
    tau: float = 0.5
    sweep_pieces: int = 2
    where: str | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        put = lambda name, value: object.__setattr__(self, name, value)
        w = self.where
        put("cell", V.positive("cell", self.cell, where=w))
        put("coarse", V.integer("coarse", self.coarse, minimum=1, where=w))
        put("tau", V.positive("tau", self.tau, where=w))
        put("sweep_pieces", V.integer("sweep_pieces", self.sweep_pieces, minimum=1, where=w))

    @property
    def spacing(self) -> float:
        """Spacing of the certified player's lattice, ``coarse * cell``."""
        return self.coarse * self.cell

    @property
    def cell_radius(self) -> float:
        """delta = h / sqrt(2): a cell lies in the disc of this radius about its centre."""
        return self.cell / math.sqrt(2.0)

    def key(self) -> dict[str, Any]:
        """Cache-key material (exact floats)."""
        return {
            "cell": float(self.cell).hex(),
            "coarse": int(self.coarse),
            "tau": float(self.tau).hex(),
            "sweep_pieces": int(self.sweep_pieces),
        }

    @classmethod
    def for_role(
        cls,
        spec: GameSpec,
        role: str,
        cells_per_lmin: float = 24.0,
        *,
        coarse: int = 4,
        steps: float = 2.0,
        sweep_pieces: int = 2,
        dt: float | None = None,
    ) -> Resolution:
        """A resolution scaled to the game, for certifying ``role``.

        ``cell = l_min / cells_per_lmin``; the certified lattice is ``coarse`` cells apart;
        ``tau`` lets the certified player cover ``steps`` lattice spacings per step (so
        its moves are the lattice vectors in a disc of ``steps`` spacings).

        Args:
            spec: the game.
            role: ``"pursuer"`` (the pursuer bound certifies pursuer wins) or ``"evader"``.
            cells_per_lmin: opponent cells per L_min (> 0): the main resolution knob.
            coarse: cells per spacing of the certified lattice (>= 1).
            steps: spacings the certified player covers per step (>= 1).
            sweep_pieces: see :class:`Resolution`.
            dt: when given (an env's step), ``tau`` is rounded up to a whole number of
                ``dt``, so referee policies can play the result in that env.

        Examples:
            >>> from envs.maps import Map
            >>> room = Map([(0, 0), (10, 0), (10, 10), (0, 10)])
            >>> spec = GameSpec(room, l_min=2.0, l_max=4.0, v_pursuer=1.0, v_evader=0.5)
            >>> res = Resolution.for_role(spec, "pursuer", 20, coarse=4, steps=2)
            >>> res.cell, res.spacing, res.tau
            (0.1, 0.4, 0.8)
        """
        V.choice("role", role, ("pursuer", "evader"))
        cpl = check_cells_per_lmin(cells_per_lmin)
        st = V.real("steps", steps, minimum=1.0)
        co = V.integer("coarse", coarse, minimum=1)
        h = spec.l_min / cpl
        tau = st * co * h / spec.speed(role)
        if dt is not None:
            step = V.positive("dt", dt)
            tau = max(1, math.ceil(tau / step - 1e-9)) * step
        return cls(cell=h, coarse=co, tau=tau, sweep_pieces=sweep_pieces)
