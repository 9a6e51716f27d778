"""One module, one rule: checks of user input shared by every layer.

Every check returns the value normalised (a ``float``, an ``int``, a tuple...) or raises
:class:`~envs.errors.InvalidConfigError` (a :class:`ValueError`) with a one-line message
that names the value, says what was expected and, when ``where`` is given, where the value
came from (a file, a CLI flag, a config section)::

    corridor.toml [env]: l_min = -1: expected a finite number > 0

**What is a number.** A real number is a Python ``int`` or ``float`` or a numpy integer or
floating scalar, finite unless stated otherwise. ``bool`` is *not* a number (``True`` would
silently mean 1), strings are not numbers (``"1"`` must be parsed by the caller that knows
it came from text), and neither are ``None``, complex numbers or containers. An integer is
an ``int`` or numpy integer (not a float with an integral value, not a bool).

Examples:
    >>> positive("l_min", 2)
    2.0
    >>> integer("seeds", 3, minimum=1)
    3
    >>> positive("l_min", True)
    Traceback (most recent call last):
    ...
    envs.errors.InvalidConfigError: l_min = True: expected a finite number > 0, got bool
"""

from __future__ import annotations

import math
import re
import tempfile
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError

__all__ = [
    "DuplicateKeyError",
    "boolean",
    "choice",
    "finite_array",
    "integer",
    "is_integer",
    "is_real",
    "json_pairs_once",
    "mapping",
    "nonnegative",
    "point",
    "points",
    "positive",
    "real",
    "shown",
    "string",
    "unit_interval",
]


def _where(name: str, where: str | None) -> str:
    return f"{where}: {name}" if where else name


def shown(value: Any, limit: int = 80) -> str:
    """``repr(value)`` on one line (a numpy array's repr spans lines), cut to ``limit``."""
    text = re.sub(r"\s*\n\s*", " ", repr(value))
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _fail(name: str, value: Any, expected: str, where: str | None) -> InvalidConfigError:
    kind = type(value).__name__
    shown_ = shown(value)
    suffix = (
        "" if isinstance(value, (int, float)) and not isinstance(value, bool) else f", got {kind}"
    )
    return InvalidConfigError(f"{_where(name, where)} = {shown_}: expected {expected}{suffix}")


def is_real(value: Any) -> bool:
    """True for a Python or numpy real scalar (int or float), False for bool and all else.

    A 0-d numpy array of integer or float dtype counts as a numpy scalar.
    """
    if isinstance(value, (bool, np.bool_)):
        return False
    if isinstance(value, (int, float, np.integer, np.floating)):
        return True
    return isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf"


def _float(value: Any) -> float:
    """``float(value)`` of a real scalar; an integer beyond a float's range (a JSON
    ``1`` followed by 400 zeros) is +-inf, so the checks below refuse it as not finite
    instead of raising OverflowError."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def is_integer(value: Any) -> bool:
    """True for a Python or numpy integer scalar (not bool)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def real(
    name: str,
    value: Any,
    *,
    where: str | None = None,
    minimum: float | None = None,
    maximum: float | None = None,
    allow_inf: bool = False,
) -> float:
    """``value`` as a float: a real number (finite unless ``allow_inf``) in [minimum, maximum].

    Raises:
        InvalidConfigError: naming ``name`` (and ``where``), the value and the range.
    """
    lo = "" if minimum is None else f" >= {minimum:g}"
    hi = "" if maximum is None else f" <= {maximum:g}"
    expected = "a finite number" if not allow_inf else "a number"
    expected += lo + ("," if lo and hi else "") + hi
    if not is_real(value):
        raise _fail(name, value, expected, where)
    v = _float(value)
    if math.isnan(v) or (not allow_inf and math.isinf(v)):
        raise _fail(name, value, expected, where)
    if (minimum is not None and v < minimum) or (maximum is not None and v > maximum):
        raise _fail(name, value, expected, where)
    return v


def positive(name: str, value: Any, *, where: str | None = None) -> float:
    """``value`` as a float, finite and > 0."""
    if not is_real(value) or not math.isfinite(_float(value)) or _float(value) <= 0:
        raise _fail(name, value, "a finite number > 0", where)
    return float(value)


def nonnegative(name: str, value: Any, *, where: str | None = None) -> float:
    """``value`` as a float, finite and >= 0."""
    if not is_real(value) or not math.isfinite(_float(value)) or _float(value) < 0:
        raise _fail(name, value, "a finite number >= 0", where)
    return float(value)


def unit_interval(name: str, value: Any, *, where: str | None = None, open: bool = True) -> float:
    """``value`` as a float in (0, 1) (``open=True``) or [0, 1]."""
    expected = "a number in (0, 1)" if open else "a number in [0, 1]"
    if not is_real(value):
        raise _fail(name, value, expected, where)
    v = _float(value)
    ok = (0.0 < v < 1.0) if open else (0.0 <= v <= 1.0)
    if not ok:
        raise _fail(name, value, expected, where)
    return v


def integer(
    name: str,
    value: Any,
    *,
    minimum: int | None = None,
    maximum: int | None = None,
    where: str | None = None,
) -> int:
    """``value`` as an int in [minimum, maximum] (bools and floats are refused)."""
    if minimum is not None and maximum is not None:
        expected = f"an integer in [{minimum}, {maximum}]"
    elif minimum is not None:
        expected = f"an integer >= {minimum}"
    elif maximum is not None:
        expected = f"an integer <= {maximum}"
    else:
        expected = "an integer"
    if not is_integer(value):
        raise _fail(name, value, expected, where)
    v = int(value)
    if (minimum is not None and v < minimum) or (maximum is not None and v > maximum):
        raise _fail(name, value, expected, where)
    return v


def boolean(name: str, value: Any, *, where: str | None = None) -> bool:
    """``value`` as a bool: only ``True``/``False`` (numpy bools too), never ``"no"`` or 1."""
    if not isinstance(value, (bool, np.bool_)):
        raise _fail(name, value, "true or false", where)
    return bool(value)


def string(name: str, value: Any, *, where: str | None = None, nonempty: bool = True) -> str:
    """``value`` as a str (non-empty unless ``nonempty=False``)."""
    if not isinstance(value, str) or (nonempty and not value):
        raise _fail(name, value, "a non-empty string" if nonempty else "a string", where)
    return value


def _same_kind(a: Any, b: Any) -> bool:
    """Whether ``a`` and ``b`` may be compared as options: both strings (numpy's too), both
    integers (numpy's too, :func:`is_integer`), both bools, or else of one type."""
    if isinstance(a, str) or isinstance(b, str):
        return isinstance(a, str) and isinstance(b, str)
    if is_integer(a) or is_integer(b):
        return is_integer(a) and is_integer(b)
    if isinstance(a, (bool, np.bool_)) or isinstance(b, (bool, np.bool_)):
        return isinstance(a, (bool, np.bool_)) and isinstance(b, (bool, np.bool_))
    return type(a) is type(b)


def choice(name: str, value: Any, options: Iterable[Any], *, where: str | None = None) -> Any:
    """The option equal to ``value`` (compared with ``==``; bools never match ints, a
    numpy string or integer matches the option it equals and the option is returned, so
    no numpy type leaks into a config)."""
    opts = list(options)
    for o in opts:
        if _same_kind(o, value) and o == value:
            return o
    raise InvalidConfigError(
        f"{_where(name, where)} = {value!r}: expected one of {', '.join(map(repr, opts))}"
    )


def mapping(name: str, value: Any, *, where: str | None = None) -> dict[str, Any]:
    """``value`` as a dict with string keys (a JSON object, a TOML table)."""
    if not isinstance(value, Mapping) or not all(isinstance(k, str) for k in value):
        raise _fail(name, value, "a table/object of name = value pairs", where)
    return dict(value)


def finite_array(
    name: str, value: Any, *, shape: tuple[int | None, ...] | None = None, where: str | None = None
) -> np.ndarray:
    """``value`` as a float64 array of finite real numbers, of ``shape`` if given
    (``None`` entries match any length). A float64 array is returned as is (no copy)."""
    what = "real numbers" if shape is None else f"an array of shape {_shape(shape)}"
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError) as exc:  # ragged nested lists
        raise _fail(name, value, what, where) from exc
    if arr.dtype.kind not in "iuf" or (
        isinstance(value, (list, tuple)) and _contains_bool(value)  # numpy reads True as 1
    ):
        raise _fail(name, value, what if shape is None else what + " of real numbers", where)
    arr = arr.astype(np.float64, copy=False)
    if shape is not None and (
        arr.ndim != len(shape)
        or any(s is not None and s != n for s, n in zip(shape, arr.shape, strict=False))
    ):
        raise InvalidConfigError(
            f"{_where(name, where)}: expected shape {_shape(shape)}, got shape {arr.shape}"
        )
    finite = np.isfinite(arr)
    if not finite.all():
        bad = np.argwhere(~finite)[0]
        at = int(bad[0]) if len(bad) == 1 else tuple(int(i) for i in bad)
        raise InvalidConfigError(
            f"{_where(name, where)} = {shown(value)}: expected finite values, got "
            f"{arr[tuple(bad)]} at index {at}"
        )
    return arr


def point(name: str, value: Any, *, where: str | None = None) -> np.ndarray:
    """``value`` as a finite float (x, y) array."""
    return finite_array(name, value, shape=(2,), where=where)


def points(name: str, value: Any, *, where: str | None = None) -> np.ndarray:
    """``value`` as a finite float array whose last axis has length 2: one (x, y) of shape
    (2,) or many of shape (..., 2) (points, velocities)."""
    arr = finite_array(name, value, where=where)
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise InvalidConfigError(
            f"{_where(name, where)}: expected shape (2,) or (..., 2), got shape {arr.shape}"
        )
    return arr


def _contains_bool(value: list | tuple) -> bool:
    return any(
        isinstance(v, (bool, np.bool_)) or (isinstance(v, (list, tuple)) and _contains_bool(v))
        for v in value
    )


def _shape(shape: tuple[int | None, ...]) -> str:
    return (
        "("
        + ", ".join("n" if s is None else str(s) for s in shape)
        + ("," if len(shape) == 1 else "")
        + ")"
    )


class DuplicateKeyError(Exception):
    """A JSON object gives ``key`` twice (raised by :func:`json_pairs_once`; callers word
    the message, naming where the JSON came from)."""

    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


def json_pairs_once(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``json.loads(..., object_pairs_hook=json_pairs_once)``: a JSON object's dict, refusing
    a key given twice (:class:`DuplicateKeyError`) where ``json`` keeps the last silently."""
    obj: dict[str, Any] = {}
    for key, value in pairs:
        if key in obj:
            raise DuplicateKeyError(key)
        obj[key] = value
    return obj


def writable_directory(name: str, text: str, alternative: str = "") -> None:
    """Refuse a directory to be made or written that is a file or lies under one, or that
    could not be made or written (its nearest existing folder takes no new file), making
    nothing: without the check a report or a training run failed only at its first write,
    after the work ("DIR: Permission denied", "x.json: File exists"), naming no flag.
    ``alternative`` is added to the message (e.g. "(or --no-report)")."""
    path = Path(text)
    blocker = next((p for p in (path, *path.parents) if p.exists() and not p.is_dir()), None)
    more = f" {alternative}" if alternative else ""
    if blocker is not None:
        raise InvalidConfigError(
            f"{name} = {text!r}: {str(blocker)!r} is a file, expected a directory{more}"
        )
    nearest = next((p for p in (path, *path.parents) if p.is_dir()), Path("."))
    try:
        with tempfile.TemporaryFile(dir=nearest):
            pass  # a file can be made there (os.access lies to root and on some mounts)
    except OSError as exc:
        raise InvalidConfigError(
            f"{name} = {text!r}: cannot write in {str(nearest)!r} "
            f"({exc.strerror or type(exc).__name__}); expected a directory you can write{more}"
        ) from None
