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
import types
import typing
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from envs import validation
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
        types: the declared type of each parameter (``float``, ``int``, ``bool``, ``str``,
            or ``None`` when the annotation says nothing checkable), and whether ``None``
            is allowed; :func:`make_policy` checks given values against it.
    """

    name: str
    factory: Callable[..., BasePolicy]
    description: str
    params: dict[str, Any] = field(default_factory=dict)
    types: dict[str, tuple[type | None, bool]] = field(default_factory=dict, repr=False)

    @property
    def role(self) -> str:
        """The role this name plays."""
        return self.name.split("/", 1)[0]


_REGISTRY: dict[str, PolicySpec] = {}


_FACTORY_SHAPE = (
    "a class or function called as factory(name=NAME, **params), e.g. a BasePolicy "
    "subclass with def __init__(self, *, name=None, gain: float = 1.0)"
)


def register_policy(name: str, factory: Callable[..., BasePolicy], description: str) -> None:
    """Register ``factory`` under ``name`` (``ROLE/KIND``).

    :func:`make_policy` calls ``factory(name=NAME, **params)``: the factory takes ``name``
    by keyword (or ``**kwargs``), and its parameters are its keyword-only ones, each with a
    default (their annotations or defaults give the types :func:`make_policy` checks).

    Raises:
        InvalidConfigError: malformed or duplicate name; a factory that is not callable,
            does not take ``name=``, or has a parameter without a default (it could not be
            built by name).
    """
    name = validation.string("policy name", name)
    role, _, kind = name.partition("/")
    if role not in ROLES or not kind or SB3_PREFIX in kind:
        raise InvalidConfigError(
            f"policy name must be 'pursuer/KIND' or 'evader/KIND', got {name!r}"
        )
    if name in _REGISTRY:
        raise InvalidConfigError(f"policy {name!r} is already registered")
    if not callable(factory):
        raise InvalidConfigError(
            f"policy {name!r}: factory = {factory!r}: expected {_FACTORY_SHAPE}"
        )
    try:
        sig = inspect.signature(factory, eval_str=True)
    except (NameError, TypeError):  # an annotation that cannot be evaluated here
        sig = inspect.signature(factory)
    _check_factory(name, factory, sig)
    keyword = [p for k, p in sig.parameters.items() if p.kind is p.KEYWORD_ONLY and k != "name"]
    params = {p.name: p.default for p in keyword}
    kinds = {p.name: _declared_type(p) for p in keyword}
    _REGISTRY[name] = PolicySpec(name, factory, description, params, kinds)


def _check_factory(name: str, factory: Any, sig: inspect.Signature) -> None:
    """Refuse a factory that :func:`make_policy` could not call (see :func:`register_policy`):
    it was registered, and every ``make_policy(name)`` then raised a bare ``TypeError``."""
    ps = sig.parameters.values()
    takes_name = any(p.kind is p.VAR_KEYWORD for p in ps) or (
        "name" in sig.parameters
        and sig.parameters["name"].kind is not inspect.Parameter.POSITIONAL_ONLY
    )
    required = [
        p.name
        for p in ps
        if p.default is p.empty
        and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
        and p.name != "name"
    ]
    if not takes_name or required:
        why = (
            "does not take name=" if not takes_name else f"parameter(s) {required} have no default"
        )
        raise InvalidConfigError(
            f"policy {name!r}: factory {getattr(factory, '__qualname__', factory)}{sig} {why}; "
            f"expected {_FACTORY_SHAPE}"
        )


_CHECKABLE = (bool, int, float, str)


def _declared_type(param: inspect.Parameter) -> tuple[type | None, bool]:
    """``(type, none_allowed)`` of a factory parameter from its annotation or default."""
    ann = param.annotation
    none_ok = param.default is None
    if isinstance(ann, (types.UnionType,)) or typing.get_origin(ann) is typing.Union:
        args = typing.get_args(ann)
        none_ok = none_ok or type(None) in args
        rest = [a for a in args if a is not type(None)]
        ann = rest[0] if len(rest) == 1 else None
    if ann is inspect.Parameter.empty or isinstance(ann, str):
        default = param.default
        ann = type(default) if default is not None and default is not param.empty else None
    return (ann if ann in _CHECKABLE else None), none_ok


def _checked_param(policy: str, key: str, value: Any, declared: tuple[type | None, bool]) -> Any:
    """``value`` checked against the declared type of parameter ``key`` (one rule for all
    policies: :mod:`envs.validation`; bools and strings are not numbers, ``"no"`` is not a
    bool). The policy checks its own ranges afterwards."""
    kind, none_ok = declared
    where = f"policy {policy!r}"
    if value is None and none_ok:
        return None
    if kind is bool:
        return validation.boolean(key, value, where=where)
    if kind is int:
        validation.integer(key, value, where=where)
    elif kind is float:  # the policy converts: its range messages then show the value given
        validation.real(key, value, where=where)
    elif kind is str:
        validation.string(key, value, where=where)
    if value is None:
        raise InvalidConfigError(f"{where}: {key} = None: expected a value")
    return value


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
        InvalidConfigError: the name is not a string, or a parameter is unknown, of the
            wrong type (``{"shoot": "no"}``, ``{"n_bins": True}``, ``{"gain": None}``)
            or out of range.
    """
    name = validation.string("policy name", name)
    role, _, kind = name.partition("/")
    if kind.startswith(SB3_PREFIX) and role in ROLES:
        from strategies.policies.learned import SB3_PARAMS, SB3Policy

        unknown = sorted(set(params) - set(SB3_PARAMS))
        if unknown:  # was SB3Policy's TypeError (a traceback), 'role' and 'name' too
            raise InvalidConfigError(
                f"policy {name!r} has no parameter(s) {unknown}; a model's parameters are "
                f"{list(SB3_PARAMS)}"
            )
        return SB3Policy(kind[len(SB3_PREFIX) :], role=role, name=name, **params)
    spec = policy_spec(name)
    unknown = sorted(set(params) - set(spec.params))
    if unknown:
        raise InvalidConfigError(
            f"policy {name!r} has no parameter(s) {unknown}; its parameters are "
            f"{sorted(spec.params)}"
        )
    checked = {k: _checked_param(name, k, v, spec.types[k]) for k, v in params.items()}
    try:
        policy = spec.factory(name=name, **checked)
    except InvalidConfigError as exc:  # the policy's own range checks: say which policy
        if str(exc).startswith(f"policy {name!r}"):
            raise
        raise InvalidConfigError(f"policy {name!r}: {exc}") from None
    if not (callable(getattr(policy, "reset", None)) and callable(getattr(policy, "act", None))):
        raise InvalidConfigError(
            f"policy {name!r}: its factory returned {type(policy).__name__} {policy!r:.60}, "
            "not a policy (expected reset() and act() methods, e.g. a BasePolicy subclass)"
        )
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
