"""The surveillance environment: config, physics, rules, observations, env, renderer.

Import the versioned module :mod:`envs.surveillance_v1` in user code; this package is
its unversioned implementation.
"""

from envs.surveillance.config import EnvConfig
from envs.surveillance.observations import STATE_LAYOUT, StateView, decode_state, lidar_layout

__all__ = ["STATE_LAYOUT", "EnvConfig", "StateView", "decode_state", "lidar_layout"]
