"""Checks of the control modules' own domain rules.

Numbers, arrays and points are checked with :mod:`envs.validation` (one rule for what is
a number: bools and strings are not); this module holds only what is specific to the
theory of Secs. 5-6: the rotation branch and the speed ratio of the evasion problem.
"""

from __future__ import annotations

from typing import Any

from envs import validation
from envs.errors import InfeasibleError, InvalidConfigError

__all__ = ["branch_sign", "check_evasion_rho"]


def branch_sign(branch: Any) -> int:
    """Map a rotation branch to its sign: ``"+"``/``+1`` (θ̇⁺, CCW) or ``"-"``/``-1`` (θ̇⁻, CW)."""
    if isinstance(branch, str) and branch in ("+", "-"):
        return 1 if branch == "+" else -1
    if validation.is_integer(branch) and int(branch) in (1, -1):
        return int(branch)
    raise InvalidConfigError(
        f"branch = {branch!r}: expected '+' (theta_dot+, counter-clockwise) "
        "or '-' (theta_dot-, clockwise)"
    )


def check_evasion_rho(rho: Any) -> float:
    """Check the speed ratio for the optimal-evasion problem of Sec. 6: 0 < rho < 1.

    Raises:
        InvalidConfigError: rho is not a finite number > 0 (the evader cannot move).
        InfeasibleError: rho >= 1. At rho = 1 the rate θ̇⁺ vanishes for every heading with
            sin(alpha - theta) >= 0 (erratum E1) and the reduced extremal equation divides by
            1 - rho^2; for rho > 1 the evader escapes trivially (paper, footnote 4).
    """
    r = validation.positive("rho", rho)
    if r >= 1.0:
        raise InfeasibleError(
            f"rho = {rho!r}: optimal evasion (Sec. 6) needs 0 < rho < 1; for rho >= 1 the "
            "evader escapes trivially by moving away from the pursuer (footnote 4, E1)"
        )
    return r
