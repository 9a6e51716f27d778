"""Project exceptions.

Every error a user can trigger with bad input is a :class:`SurveilValueError`, which
subclasses :class:`ValueError`, so ``except ValueError`` keeps working. Messages name
the offending value and say what was expected.
"""

from __future__ import annotations

__all__ = [
    "EpisodeStateError",
    "InfeasibleError",
    "InvalidActionError",
    "InvalidConfigError",
    "InvalidMapError",
    "InvalidObservationError",
    "InvalidPlacementError",
    "RhoAboveOneWarning",
    "SurveilValueError",
    "UnknownNameError",
    "VacuousBoundWarning",
]


class SurveilValueError(ValueError):
    """Base class of every project exception caused by bad input."""


class InvalidMapError(SurveilValueError):
    """A map polygon is not simple, degenerate, outside the boundary or overlapping."""


class InvalidConfigError(SurveilValueError):
    """An environment, policy or tournament configuration value is out of range."""


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


class UnknownNameError(SurveilValueError, KeyError):
    """A name (map, policy, observation kind...) is not registered."""

    def __str__(self) -> str:  # KeyError would repr() the message
        return str(self.args[0]) if self.args else ""


class RhoAboveOneWarning(UserWarning):
    """V_e > V_p: legal, but escape is trivial for the evader (Sec. 5 of the paper)."""


class VacuousBoundWarning(UserWarning):
    """A referee bound that certifies nothing, or that is in the regime where it was measured
    to certify nothing: its 0 % means "unknown", not a win for the other player
    (:mod:`strategies.referee.pursuer_bound`)."""
