"""The memory budget every estimated computation is checked against, and the machine's RAM.

Decompositions (:mod:`strategies.cspace`), the referee's solves (:mod:`strategies.referee`),
the policies' lazy tables and a tournament's plan all refuse, before they start, work
estimated to need more memory than the budget: ``memory_budget=`` where the call takes
one, else ``$SURVEIL_MEMORY_BUDGET`` (bytes, or a number with a unit: ``"1.5GB"``,
``"800MB"``, ``"2GiB"``), else half the machine's physical memory.

Examples:
    >>> memory_budget("1.5GB"), memory_budget(2**20), memory_budget("2 MiB")
    (1500000000.0, 1048576.0, 2097152.0)
    >>> physical_memory() > 0
    True
"""

from __future__ import annotations

import os
import re

from envs.errors import InvalidConfigError

__all__ = ["byte_size", "memory_budget", "physical_memory"]

_UNITS = {"": 1, "b": 1, "kb": 1e3, "mb": 1e6, "gb": 1e9, "kib": 2**10, "mib": 2**20, "gib": 2**30}


def physical_memory() -> float:
    """The machine's physical memory in bytes (8 GB where the system does not say)."""
    try:
        return float(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return 8e9


def memory_budget(value: object = None) -> float:
    """The memory budget in bytes: ``value``, ``$SURVEIL_MEMORY_BUDGET`` or half the RAM.

    Raises:
        InvalidConfigError: for a budget that is not a positive size.
    """
    where = "memory_budget"
    if value is None:
        value = os.environ.get("SURVEIL_MEMORY_BUDGET")
        where = "$SURVEIL_MEMORY_BUDGET"
        if value is None or value == "":
            return 0.5 * physical_memory()
    if isinstance(value, bool):
        raise InvalidConfigError(f"{where} = {value!r}: expected a size in bytes or '2GB'")
    if isinstance(value, (int, float)):
        size = float(value)
    else:
        m = re.fullmatch(r"\s*([0-9.]+(?:e[+-]?[0-9]+)?)\s*([kmg]i?b|b)?\s*", str(value), re.I)
        if not m:
            raise InvalidConfigError(f"{where} = {value!r}: expected a size in bytes or '2GB'")
        size = float(m.group(1)) * _UNITS[(m.group(2) or "").lower()]
    if not size > 0 or size != size or size == float("inf"):
        raise InvalidConfigError(f"{where} = {value!r}: expected a finite size > 0")
    return size


def byte_size(n: float) -> str:
    """``n`` bytes for a message: ``"50 MB"``, ``"1.5 GB"``, ``"4.8e+14 GB"`` (not the
    ``"0.1 GB"`` a fixed one decimal of GB gave a 50 MB budget).

    Examples:
        >>> byte_size(50e6), byte_size(1.5e9), byte_size(4.8e23)
        ('50 MB', '1.5 GB', '4.8e+14 GB')
    """
    if n >= 1e13:  # 4.8e+14 GB, not 479908800287946.0 GB
        return f"{n / 1e9:.3g} GB"
    return f"{n / 1e9:.1f} GB" if n >= 1e9 else f"{n / 1e6:.0f} MB"
