"""
# Surveillance (finite sensor range), v0 (retired: use `surveillance_v1`)

| Import               | `from envs import surveillance_v0`                          |
|----------------------|-------------------------------------------------------------|
| Registry ids         | `surveil/surveillance-v0` (`"parallel"` and `"aec"`)        |
| Actions              | Continuous                                                  |
| Parallel API         | Yes (native); AEC by `parallel_to_aec`                      |
| Agents               | `agents = ["pursuer_0", "evader_0"]`                        |
| Action shape         | (2,)                                                        |
| Action values        | Box(-1, 1, (2,), float32): velocity / speed bound           |
| Observation shape    | `"state"`: (13,); `"lidar"`: (n_rays + 6,); `"lidar_track"`: +2 |
| Observation values   | float32 Box, finite bounds (see `observations.py`)          |
| State shape          | (13,), the `"state"` observation                            |

Every argument, space, reward, info and start is v1's: see the card of
:mod:`envs.surveillance_v1` (same signature: ``surveillance_v0.parallel_env(map="corridor",
...)``). The differences: v0's continuous check takes both agents to move linearly
within a step, so a step in which a wall stopped or deflected a body is swept along the
chord between its two frames (at dt = 10 on the corridor, a pursuer stopped by a wall
after 0.4 s had its range break timed at 1.85 s, the truth 1.2 s; at dt = 0.1 an
occlusion at a middle substep with both frames clear is missed), and it takes one
physics substep a step up to half a radius of travel, where a body pressed into a wall
can pass through it (dt = 0.05 at the defaults). v0 stays importable so that results
recorded with it replay.

### Version History

* v1: see :mod:`envs.surveillance_v1` (steps with a wall contact swept along the path).
* v0: initial release (continuous-time surveillance check, state and lidar
  observations, zero-sum and sparse rewards).
"""

from __future__ import annotations

from envs.surveillance.env import env_v0 as env
from envs.surveillance.env import parallel_env_v0 as parallel_env
from envs.surveillance.env import raw_env_v0 as raw_env
from envs.surveillance.registry import ENV_IDS, register_envs

__all__ = ["ENV_ID", "env", "parallel_env", "raw_env"]

ENV_ID = ENV_IDS[0]
"""The versioned registry id."""

register_envs()
