"""Names for policies: ``"pursuer/decomposition"``, ``"evader/shooting"``, ``"pursuer/sb3:PATH"``.

A name is ``ROLE/KIND``. :func:`make_policy` builds a fresh policy with keyword
parameters; the CLI, tournament configs and training opponents all go through it. A
``ROLE/sb3:PATH`` name loads a stable-baselines3 model zip lazily (on first reset).

Examples:
    >>> "pursuer/greedy" in policy_names("pursuer")
    True
    >>> make_policy("evader/toward_away", mode="away").name
    'evader/toward_away'
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from envs.errors import InvalidConfigError, UnknownNameError
from strategies.policies.base import ROLES, BasePolicy, check_role

__all__ = [
    "PolicySpec",
    "describe_policy",
    "make_policy",
    "policy_names",
    "policy_spec",
    "register_policy",
]

SB3_PREFIX = "sb3:"


@dataclass(frozen=True)
class PolicySpec:
    """One registry entry.

    Attributes:
        name: ``ROLE/KIND``.
        factory: builds the policy from keyword parameters.
        description: one line for ``surveil`` listings.
        params: the factory's parameters and their defaults.
    """

    name: str
    factory: Callable[..., BasePolicy]
    description: str
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def role(self) -> str:
        """The role this name plays."""
        return self.name.split("/", 1)[0]


_REGISTRY: dict[str, PolicySpec] = {}


def register_policy(name: str, factory: Callable[..., BasePolicy], description: str) -> None:
    """Register ``factory`` under ``name`` (``ROLE/KIND``).

    Raises:
        InvalidConfigError: malformed or duplicate name.
    """
    role, _, kind = name.partition("/")
    if role not in ROLES or not kind or SB3_PREFIX in kind:
        raise InvalidConfigError(
            f"policy name must be 'pursuer/KIND' or 'evader/KIND', got {name!r}"
        )
    if name in _REGISTRY:
        raise InvalidConfigError(f"policy {name!r} is already registered")
    sig = inspect.signature(factory)
    params = {
        k: p.default for k, p in sig.parameters.items() if p.kind is p.KEYWORD_ONLY and k != "name"
    }
    _REGISTRY[name] = PolicySpec(name, factory, description, params)


def policy_names(role: str | None = None) -> list[str]:
    """Sorted registered names, optionally only those of one role."""
    _ensure_loaded()
    if role is not None:
        check_role(role)
    return sorted(n for n, s in _REGISTRY.items() if role is None or s.role == role)


def policy_spec(name: str) -> PolicySpec:
    """The registry entry of ``name``.

    Raises:
        UnknownNameError: listing the known names.
    """
    _ensure_loaded()
    try:
        return _REGISTRY[name]
    except KeyError:
        raise UnknownNameError(
            f"unknown policy {name!r}; known policies: {', '.join(policy_names())} "
            f"(or ROLE/{SB3_PREFIX}PATH for a stable-baselines3 model zip)"
        ) from None


def describe_policy(name: str) -> str:
    """One-line description of a registered policy, with its parameters."""
    spec = policy_spec(name)
    params = ", ".join(f"{k}={v!r}" for k, v in spec.params.items())
    return f"{spec.description} ({params})" if params else spec.description


def make_policy(name: str, **params: Any) -> BasePolicy:
    """Build a fresh policy by name.

    Args:
        name: ``ROLE/KIND`` from :func:`policy_names`, or ``ROLE/sb3:PATH``.
        **params: the policy's parameters (see :func:`describe_policy`).

    Raises:
        UnknownNameError: the name is not registered (the message lists the known ones).
        InvalidConfigError: a parameter is unknown or out of range.
    """
    role, _, kind = name.partition("/")
    if kind.startswith(SB3_PREFIX) and role in ROLES:
        from strategies.policies.learned import SB3Policy

        return SB3Policy(kind[len(SB3_PREFIX) :], role=role, name=name, **params)
    spec = policy_spec(name)
    unknown = sorted(set(params) - set(spec.params))
    if unknown:
        raise InvalidConfigError(
            f"policy {name!r} has no parameter(s) {unknown}; its parameters are "
            f"{sorted(spec.params)}"
        )
    policy = spec.factory(name=name, **params)
    policy.roles = (spec.role,)
    return policy


_LOADED = False


def _ensure_loaded() -> None:
    # the policy modules register themselves on import; import them once, lazily, so that
    # importing the registry alone stays cheap and free of import cycles
    global _LOADED
    if not _LOADED:
        _LOADED = True
        from strategies.policies import catalog  # noqa: F401
