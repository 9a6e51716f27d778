"""Registration with PettingZoo's registry (``pettingzoo.register``, PettingZoo >= 1.27).

The ids are ``surveil/surveillance-v0`` and ``surveil/surveillance-v1`` in both the
``"parallel"`` and the ``"aec"`` registries (PettingZoo normalises ``surveillance_v1`` to
``surveillance-v1``), so::

    import pettingzoo, envs.surveillance_v1
    env = pettingzoo.make("parallel", "surveil/surveillance_v1", map="two_rooms")

An unversioned id (``surveil/surveillance``) resolves to the highest version.
"""

from __future__ import annotations

from pettingzoo import aec_registry, parallel_registry, register

__all__ = ["ENV_ID", "ENV_IDS", "register_envs"]

ENV_IDS = {0: "surveil/surveillance-v0", 1: "surveil/surveillance-v1"}
"""The versioned registry id of each version (:mod:`envs.surveillance_v0`, ``_v1``)."""

ENV_ID = ENV_IDS[max(ENV_IDS)]
"""The id of the current version."""


def register_envs() -> None:
    """Register every version of the env once (idempotent: no override warning)."""
    for version, env_id in ENV_IDS.items():
        module = f"envs.surveillance_v{version}"
        if env_id not in parallel_registry:
            register("parallel", env_id, entry_point=f"{module}:parallel_env")
        if env_id not in aec_registry:
            register("aec", env_id, entry_point=f"{module}:env")
