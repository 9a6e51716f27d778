"""Progress of a long decomposition: a tqdm bar over its phases, and their timings.

A build goes through a fixed list of phases (:data:`PHASES`); each one's wall time is
recorded (``Decomposition.timings``). The bar is shown on standard error when asked
(``progress=True``), or by default when the build looks long (many candidate curves) and
standard error is a terminal (tqdm's own rule).
"""

from __future__ import annotations

import time

__all__ = ["PHASES", "Progress"]

PHASES = ("critical curves", "arrangement", "cells", "boundaries", "escapable cells")
"""The phases of a build, in order."""


class Progress:
    """Phase timer with an optional tqdm bar.

    Args:
        show: ``True`` (always), ``False`` (never) or ``None`` (tqdm decides: only on a
            terminal).
        label: a prefix for the bar, e.g. the map's name and L.
    """

    def __init__(self, show: bool | None, label: str = "decompose") -> None:
        self.timings: dict[str, float] = {}
        self._phase: str | None = None
        self._t0 = time.perf_counter()
        self._bar = None
        if show is not False:
            from tqdm import tqdm

            self._bar = tqdm(
                total=len(PHASES),
                desc=label,
                unit="phase",
                disable=None if show is None else False,
                leave=False,
            )

    def step(self, phase: str, **sizes: int) -> None:
        """Start ``phase`` (closing the previous one); ``sizes`` show on the bar."""
        self._close_phase()
        self._phase = phase
        if self._bar is not None:
            self._bar.set_postfix_str(
                phase + "".join(f", {v} {k}" for k, v in sizes.items()), refresh=True
            )

    def _close_phase(self) -> None:
        now = time.perf_counter()
        if self._phase is not None:
            self.timings[self._phase] = now - self._t0
            if self._bar is not None:
                self._bar.update(1)
        self._t0 = now

    def close(self) -> dict[str, float]:
        """Finish; returns the phase timings in seconds."""
        self._close_phase()
        self._phase = None
        if self._bar is not None:
            self._bar.close()
        return dict(self.timings)
