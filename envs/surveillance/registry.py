"""Registration with PettingZoo's registry (``pettingzoo.register``, PettingZoo >= 1.27).

The ids are ``surveil/surveillance-v0`` in both the ``"parallel"`` and the ``"aec"``
registries (PettingZoo normalises ``surveillance_v0`` to ``surveillance-v0``), so::

    import pettingzoo, envs.surveillance_v0
    env = pettingzoo.make("parallel", "surveil/surveillance_v0", map="two_rooms")

An unversioned id (``surveil/surveillance``) resolves to the highest version.
"""

from __future__ import annotations

from pettingzoo import aec_registry, parallel_registry, register

__all__ = ["ENV_ID", "register_envs"]

ENV_ID = "surveil/surveillance-v0"
"""The versioned registry id of :mod:`envs.surveillance_v0`."""


def register_envs() -> None:
    """Register every version of the env once (idempotent: no override warning)."""
    if ENV_ID not in parallel_registry:
        register("parallel", ENV_ID, entry_point="envs.surveillance_v0:parallel_env")
    if ENV_ID not in aec_registry:
        register("aec", ENV_ID, entry_point="envs.surveillance_v0:env")
