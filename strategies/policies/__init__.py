"""Policies for both roles behind one protocol, and the registry that names them.

``make_policy("pursuer/decomposition")`` builds a policy; ``policy_names()`` lists them.
Every policy has ``reset(*, role, map, config, seed)``, ``act(observation)`` and the
SB3-compatible ``predict(observation, state, episode_start, deterministic)``.
"""

from strategies.policies.base import ROLES, BasePolicy, Policy, Snapshot
from strategies.policies.registry import (
    PolicySpec,
    describe_policy,
    make_policy,
    policy_names,
    policy_spec,
    register_policy,
)

__all__ = [
    "ROLES",
    "BasePolicy",
    "Policy",
    "PolicySpec",
    "Snapshot",
    "describe_policy",
    "make_policy",
    "policy_names",
    "policy_spec",
    "register_policy",
]
