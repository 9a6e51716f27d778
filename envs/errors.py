"""Project exceptions.

Every error a user can trigger with bad input is a :class:`SurveilValueError`, which
subclasses :class:`ValueError`, so ``except ValueError`` keeps working. Messages name
the offending value and say what was expected.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

__all__ = [
    "EpisodeStateError",
    "InfeasibleError",
    "InvalidActionError",
    "InvalidConfigError",
    "InvalidMapError",
    "InvalidObservationError",
    "InvalidPlacementError",
    "LongRunWarning",
    "MemoryBudgetError",
    "NarrowBandWarning",
    "NoStartError",
    "OutputError",
    "OversubscribedWarning",
    "RelaxedStartWarning",
    "RhoAboveOneWarning",
    "SurveilValueError",
    "UnknownNameError",
    "UnknownOptionWarning",
    "VacuousBoundWarning",
]


class SurveilValueError(ValueError):
    """Base class of every project exception caused by bad input."""


class InvalidMapError(SurveilValueError):
    """A map polygon is not simple, degenerate, outside the boundary or overlapping."""


class InvalidConfigError(SurveilValueError):
    """An environment, policy or tournament configuration value is out of range."""


class OutputError(SurveilValueError):
    """A file could not be written whole (a full disk, a quota, a file-size limit): the
    message names the file and the reason, and the file is as it was before (an earlier
    version kept, or none made; :func:`envs.files.written_whole`)."""


class InvalidPlacementError(SurveilValueError):
    """Requested start positions do not form a valid surveillance configuration."""


class InvalidActionError(SurveilValueError):
    """An action is not finite or has the wrong shape."""


class InvalidObservationError(SurveilValueError):
    """An observation given to a policy has the wrong shape or is not finite."""


class EpisodeStateError(SurveilValueError, RuntimeError):
    """A call out of order: ``step()`` before ``reset()`` or after the episode ended.

    Also a :class:`RuntimeError`, the conventional type of a call in the wrong state.
    """


class InfeasibleError(SurveilValueError):
    """A requested computation has no solution for the given parameters."""


class MemoryBudgetError(InfeasibleError):
    """A solve refused before it starts: its estimated peak memory exceeds the budget
    (the referee's solves, the estimate, the hindsight's grid).

    The message names the knobs by the names of the function that refused
    (``cells_per_lmin``, ``memory_budget=``); a command line, a benchmark or a policy
    that sets them under other names re-raises :meth:`named` with its own (``surveil
    referee --cells-per-lmin``, ``unseen_worlds.py --referee CPL``), so the user reads
    what they can change where they are.

    Args:
        template: the message, with :data:`KNOB` where the resolution's knob goes and
            :data:`BUDGET` where the budget's.
        knob: the resolution's knob (``"cells_per_lmin"``).
        budget: how to raise the budget, a format string with ``{size}``.
        size: the budget that would fit (``"4GB"``).
    """

    KNOB = "\x00knob\x00"
    BUDGET = "\x00budget\x00"
    PYTHON_BUDGET = "memory_budget='{size}' or $SURVEIL_MEMORY_BUDGET"
    """How a Python caller raises the budget."""
    ENV_BUDGET = "SURVEIL_MEMORY_BUDGET={size} in the environment"
    """How a command line (or a policy, which has no budget argument) raises it."""

    def __init__(self, template: str, knob: str = "", budget: str = PYTHON_BUDGET, size: str = ""):
        super().__init__(template, knob, budget, size)  # pickles (pool workers) by its args

    def __str__(self) -> str:
        template, knob, budget, size = self.args
        return template.replace(self.KNOB, knob).replace(self.BUDGET, budget.format(size=size))

    @classmethod
    @contextlib.contextmanager
    def naming(cls, knob: str, budget: str = ENV_BUDGET) -> Iterator[None]:
        """Within it, a MemoryBudgetError is re-raised :meth:`named` ``knob`` and ``budget``
        (by default ``$SURVEIL_MEMORY_BUDGET``: a command line has no ``memory_budget=``)."""
        try:
            yield
        except cls as exc:
            raise exc.named(knob, budget) from None

    def named(self, knob: str | None = None, budget: str | None = None) -> MemoryBudgetError:
        """The same error with the knobs named as the caller's user sets them."""
        template, k, b, size = self.args
        return type(self)(
            template, k if knob is None else knob, b if budget is None else budget, size
        )


class NoStartError(InfeasibleError, InvalidConfigError):
    """A referee resolution whose lattices hold no start (no lattice point clear of the
    walls, or no pair of them in range and in sight): a solve there would certify nothing,
    so it is refused rather than returned empty. An :class:`InfeasibleError` (scripts that
    label starts say "not solved" and go on to the next world, as for the memory budget)
    and an :class:`InvalidConfigError` (the resolution is the caller's to change).

    As in :class:`MemoryBudgetError`, the message names the resolution's knob by the name
    of the function that refused (``cells_per_lmin``); a command line or a policy that
    sets it under another name re-raises :meth:`named` with its own.

    Args:
        template: the message, with :data:`KNOB` where the knob's name goes.
        knob: the knob's name.
    """

    KNOB = "\x00knob\x00"

    def __init__(self, template: str, knob: str = "cells_per_lmin"):
        super().__init__(template, knob)  # pickles (pool workers) by its args

    def __str__(self) -> str:
        template, knob = self.args
        return template.replace(self.KNOB, knob)

    def named(self, knob: str) -> NoStartError:
        """The same error with the knob named as the caller's user sets it."""
        return type(self)(self.args[0], knob)


class UnknownNameError(SurveilValueError, KeyError):
    """A name (map, policy, observation kind...) is not registered."""

    def __str__(self) -> str:  # KeyError would repr() the message
        return str(self.args[0]) if self.args else ""


class RhoAboveOneWarning(UserWarning):
    """V_e > V_p: legal, but escape is trivial for the evader (Sec. 5 of the paper)."""


class NarrowBandWarning(UserWarning):
    """``L_max - L_min < 2 V_e dt``: legal, but no pursuer can be sure to hold the range
    band. Policies choose a step's velocities together, so within a step the evader can
    move ``V_e dt`` toward or away from the pursuer whatever the pursuer does; the two
    distances that leaves differ by ``2 V_e dt``, more than the band holds, so one of them
    is outside it."""


class OversubscribedWarning(UserWarning):
    """More worker processes asked for than the CPUs can run (``--workers 1000`` on two
    cores): legal, and played as asked, but no faster than one a CPU and heavier."""


class RelaxedStartWarning(UserWarning):
    """A "safe" start drawn with fewer guarantees than the name promises: no proposal in a
    safe cell was admissible or left room to retreat (rho near 1), so one in a safe cell
    only was drawn, as at rho >= 1 (:mod:`strategies.policies.starts`)."""


class LongRunWarning(UserWarning):
    """A computation estimated, before it starts, to run longer than its module's limit
    (the hindsight's grids: :data:`strategies.referee.hindsight.LONG_SECONDS`); the
    message gives the estimate and the knobs that shorten it."""


class UnknownOptionWarning(UserWarning):
    """A ``reset`` option the env does not read whose name is close to one it does
    (``"pursuer_0"``, ``"evader "``): most likely a misspelt placement, which would
    otherwise be lost without a word (:func:`envs.surveillance.placement.check_option_keys`)."""


class VacuousBoundWarning(UserWarning):
    """A referee bound that certifies nothing, or that is in the regime where it was measured
    to certify nothing: its 0 % means "unknown", not a win for the other player
    (:mod:`strategies.referee.pursuer_bound`)."""
