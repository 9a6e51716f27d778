"""Input checks shared by the control modules.

Every check raises a project exception (a subclass of :class:`ValueError`) whose message
names the argument, shows its value and says what was expected.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from envs.errors import InfeasibleError, SurveilValueError

__all__ = [
    "as_finite_array",
    "branch_sign",
    "check_evasion_rho",
    "finite",
    "nonnegative",
    "positive",
    "vector2",
]


def finite(name: str, value: Any) -> float:
    """Return ``value`` as a float, or raise if it is not a finite real number."""
    try:
        out = float(value)
    except (TypeError, ValueError) as exc:
        raise SurveilValueError(f"{name} = {value!r}: expected a finite real number") from exc
    if not math.isfinite(out):
        raise SurveilValueError(f"{name} = {value!r}: expected a finite real number")
    return out


def positive(name: str, value: Any) -> float:
    """Return ``value`` as a float, or raise unless it is finite and > 0."""
    out = finite(name, value)
    if out <= 0.0:
        raise SurveilValueError(f"{name} = {value!r}: expected a finite number > 0")
    return out


def nonnegative(name: str, value: Any) -> float:
    """Return ``value`` as a float, or raise unless it is finite and >= 0."""
    out = finite(name, value)
    if out < 0.0:
        raise SurveilValueError(f"{name} = {value!r}: expected a finite number >= 0")
    return out


def as_finite_array(name: str, value: Any) -> np.ndarray:
    """Return ``value`` as a float array, or raise if any entry is NaN or infinite."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise SurveilValueError(f"{name} = {value!r}: expected real numbers") from exc
    if not np.all(np.isfinite(arr)):
        raise SurveilValueError(f"{name} = {value!r}: expected finite values (no NaN or inf)")
    return arr


def vector2(name: str, value: Any) -> np.ndarray:
    """Return ``value`` as a finite array whose last axis has length 2 (points, velocities)."""
    arr = as_finite_array(name, value)
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise SurveilValueError(
            f"{name} has shape {arr.shape}: expected a 2-vector or an array of shape (..., 2)"
        )
    return arr


def branch_sign(branch: Any) -> int:
    """Map a rotation branch to its sign: ``"+"``/``+1`` (θ̇⁺, CCW) or ``"-"``/``-1`` (θ̇⁻, CW)."""
    if branch in ("+", 1):
        return 1
    if branch in ("-", -1):
        return -1
    raise SurveilValueError(
        f"branch = {branch!r}: expected '+' (theta_dot+, counter-clockwise) "
        "or '-' (theta_dot-, clockwise)"
    )


def check_evasion_rho(rho: Any) -> float:
    """Check the speed ratio for the optimal-evasion problem of Sec. 6: 0 < rho < 1.

    Raises:
        SurveilValueError: rho is NaN, infinite or <= 0 (the evader cannot move).
        InfeasibleError: rho >= 1. At rho = 1 the rate θ̇⁺ vanishes for every heading with
            sin(alpha - theta) >= 0 (erratum E1) and the reduced extremal equation divides by
            1 - rho^2; for rho > 1 the evader escapes trivially (paper, footnote 4).
    """
    r = positive("rho", rho)
    if r >= 1.0:
        raise InfeasibleError(
            f"rho = {rho!r}: optimal evasion (Sec. 6) needs 0 < rho < 1; for rho >= 1 the "
            "evader escapes trivially by moving away from the pursuer (footnote 4, E1)"
        )
    return r
