"""What the two solved bounds share: their lattice, moves, tables and the cache round trip."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from strategies.referee.lattice import Lattice
from strategies.referee.spec import GameSpec, Resolution

__all__ = ["SolvedBound"]


@dataclass
class SolvedBound:
    """Base of :class:`~strategies.referee.pursuer_bound.PursuerBound` and
    :class:`~strategies.referee.evader_bound.EvaderBound`.

    Subclasses declare ``role`` (the certified player) and ``tables`` (the per-state
    arrays they solve, with their dtypes) and add those fields plus ``iterations`` and
    ``seconds``.

    Attributes:
        spec: the game.
        res: the resolution.
        lattice: cells and the certified player's lattice.
        vectors: (n_moves, 2) the certified player's moves in cells (row 0: standing still).
        targets: (n_points, n_moves) point reached by each move, -1 if not allowed.
    """

    role: ClassVar[str] = ""
    tables: ClassVar[dict[str, Any]] = {}

    spec: GameSpec
    res: Resolution
    lattice: Lattice
    vectors: np.ndarray
    targets: np.ndarray

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The solved arrays (for the on-disk cache); the rest is rebuilt from spec/res."""
        seconds = getattr(self, "seconds", {})
        return {
            **{name: getattr(self, name) for name in self.tables},
            "iterations": np.array(getattr(self, "iterations", 0)),
            "seconds": np.array([seconds.get("build", 0.0), seconds.get("solve", 0.0)]),
        }

    @classmethod
    def from_arrays(cls, spec: GameSpec, res: Resolution, arrays):
        """Rebuild a bound from :meth:`to_arrays` output (the lattice is recomputed).

        Raises:
            ValueError: an array does not have the shape this game and resolution give.
        """
        lat = Lattice(spec, res, cls.role)
        vectors, targets = lat.moves(spec.speed(cls.role) * res.tau)
        shape = (lat.n_points, lat.W, lat.W)
        for name in cls.tables:
            if arrays[name].shape != shape:
                raise ValueError(
                    f"cached {cls.role} bound: {name} has shape {arrays[name].shape}, "
                    f"expected {shape}"
                )
        sec = arrays["seconds"]
        return cls(
            spec=spec,
            res=res,
            lattice=lat,
            vectors=vectors,
            targets=targets,
            **{name: arrays[name].astype(dtype) for name, dtype in cls.tables.items()},
            iterations=int(arrays["iterations"]),
            seconds={"build": float(sec[0]), "solve": float(sec[1])},
        )
