"""
# Surveillance (finite sensor range)

| Import               | `from envs import surveillance_v1`                          |
|----------------------|-------------------------------------------------------------|
| Registry ids         | `surveil/surveillance-v1` (`"parallel"` and `"aec"`)        |
| Actions              | Continuous                                                  |
| Parallel API         | Yes (native); AEC by `parallel_to_aec`                      |
| Agents               | `agents = ["pursuer_0", "evader_0"]`                        |
| Action shape         | (2,)                                                        |
| Action values        | Box(-1, 1, (2,), float32): velocity / speed bound           |
| Observation shape    | `"state"`: (13,); `"lidar"`: (n_rays + 6,); `"lidar_track"`: +2 |
| Observation values   | float32 Box, finite bounds (see `observations.py`)          |
| State shape          | (13,), the `"state"` observation                            |

A pursuer must keep an evader in sight in a polygonal world (Murrieta-Cid et al., IJRR
2007). Surveillance holds while the segment pursuer-evader (the rod) touches no wall and
`l_min <= |P - E| <= l_max`. The check is continuous in time: the rod is swept along the
path each agent's disc centre follows within a step (linear, unless a wall stops or
deflects the disc: then along the path the physics made, substep by substep), and a rod
that sweeps across an obstacle corner between two frames breaks surveillance even if
both frames are clear. The evader wins the moment
surveillance breaks (the episode *terminates* for both agents); the pursuer wins if it
holds for `max_cycles` steps (the episode is *truncated*).

Both agents are discs of radius `body_radius` simulated with pymunk: static walls, no
collision between the two agents, velocity commands, sliding along walls, no
tunnelling, and the disc centres (the rod's ends) never leave free space.

### Actions

A (2,) velocity in units of the agent's speed bound (`v_pursuer`, `v_evader`). Finite
values outside [-1, 1] are clipped to the Box and then onto the unit disc (the bound is
on the speed, so a Box corner does not give sqrt(2) times the bound); NaN or inf raise
`InvalidActionError` naming the agent, as does a wrong shape or a missing action.

### Observations

`observation="state"`: the full state, identical for both agents, laid out as
`envs.surveillance.observations.STATE_LAYOUT`: positions (map bounds onto [-1, 1]),
realised velocities (/ speed bound), (cos theta, sin theta) with theta the direction from
evader to pursuer, distance / l_max, the visibility bit, steps / max_cycles. Decode with
`envs.surveillance.decode_state(obs, env.config)`.

`observation="lidar"`: `n_rays` egocentric ray distances / lidar range, the other
agent's relative position / l_max (zeros and a 0 mask bit when surveillance does not
hold), the agent's realised velocity, the visibility bit, the time fraction
(`envs.surveillance.lidar_layout(n_rays)`).

`observation="lidar_track"`: the lidar plus the other agent's realised velocity / its speed
bound, after the relative position (zeros when surveillance does not hold), as a tracker
locked on the target reports it (`lidar_layout(n_rays, track=True)`). Added in v0 without
changing the other kinds.

### Rewards

`reward="zero_sum"`: pursuer +1/max_cycles per step with surveillance held throughout,
-1 on escape; `reward="sparse"`: -1 on escape, +1 at the horizon if surveillance held.
The evader always receives the negation. `info` carries `reward_surveillance`,
`reward_escape` and `reward_horizon`.

### Infos

Every step: `surveillance` (held throughout the step), `distance`, `theta`, `step`,
`time`. When surveillance breaks: `cause` (`"occluded"`, `"too_far"`, `"too_close"`),
`feature` (the occluding wall feature as described by `Map.describe`, else None),
`break_time` (fraction of the step in [0, 1]) and `break_at` (absolute time).

### Starts

`reset(options={"pursuer": (x, y), "evader": (x, y)})` places the agents exactly
(`InvalidPlacementError` names the positions and the reason otherwise). Other keys are
left to wrappers; one close to those two (`"pursuer_0"`, `"Evader"`) warns
(`UnknownOptionWarning`: a misspelt placement would give a random start without a
word). Without a placement the start is drawn with the env's generator: evader uniform,
theta uniform, L uniform in `[l_min + m, l_max - m]`, rejected until both discs fit in
free space, the pursuer sees the evader and no convex obstacle corner is near the rod, so
that a random start survives any actions for `spawn_margin_steps` steps.

### Arguments

``` python
surveillance_v1.parallel_env(map="corridor", l_min=None, l_max=None, v_pursuer=None,
    v_evader=None, dt=0.1, max_cycles=500, observation="state", n_rays=32,
    lidar_range=None, reward="zero_sum", body_radius=None, spawn_margin_steps=3,
    render_mode=None)
```

The three factories share one signature, derived from the fields of
`envs.surveillance.config.EnvConfig` (`inspect.signature` shows it); a misspelt option is
a `TypeError` that suggests the closest name.

`map`: a `Map`, a built-in name (`envs.maps.builtin_names()`) or a map file path.

`l_min`, `l_max`: the sensor range, 0 < l_min < l_max. A band narrower than two evader
steps (l_max - l_min < 2 v_evader dt) is legal but raises a `NarrowBandWarning`: within a
step the evader can move v_evader dt toward or away from the pursuer whatever the pursuer
does in it, so no pursuer can be sure to hold the band. It and `RhoAboveOneWarning` (both
in `envs.errors`, filterable by class) come only for a config the env builds: one refused
by another check or by the physics' step check is refused without a warning first.

`v_pursuer`, `v_evader`: speed bounds (> 0); rho = v_evader / v_pursuer. rho > 1 is legal
but raises a `RhoAboveOneWarning`: escape is then trivial for the evader (Sec. 5).

`None` for `l_min`, `l_max`, `v_pursuer` or `v_evader` takes the value the map recommends:
a built-in map named by a string brings its own (`envs.maps.builtin_info(name).params()`),
and a map file named by its path the `l_min`, `l_max`, `v_pursuer`, `v_evader` and
`body_radius` its `metadata` gives (`envs.maps.io.file_parameters`; before 2026-11 such
files got the defaults below), each times S for a transformed one
(`NAME~xS[rotR][off(X,Y)]`, see `envs.maps.load_map`); a `Map` object, a random map or a
file recommending nothing gets L_min = 2, L_max = 4, V_p = 1, V_e = 0.5. Explicit
arguments always win. Every built-in map recommends these same values today (a test says
so): changing a built-in's recommendation changes this version's behaviour and needs a
new version.

`dt`: step duration. `max_cycles`: steps before truncation.

`observation`: `"state"`, `"lidar"` or `"lidar_track"`. `n_rays` (at most 4096),
`lidar_range` (default `l_max`): lidar.

`reward`: `"zero_sum"` or `"sparse"`.

`body_radius`: disc radius, in (0, l_min / 2). `None`: 0.1, times S on a transformed
built-in `NAME~xS...` (so that its game is the built-in's up to the similarity).

`spawn_margin_steps`: how many steps a random start survives whatever the actions.

`render_mode`: `None`, `"human"` or `"rgb_array"`.

`step()` before `reset()` or after the episode ended raises `EpisodeStateError`, as does
`render()` (with a render mode) before the first `reset()`; loop `while env.agents:`.

`copy.deepcopy(env)` mid-episode gives an env that continues the episode independently,
bit for bit as the original would (a lookahead); `pickle` rebuilds the env from its
arguments (EzPickle), so an unpickled env starts unreset.

### Version History

* v1: a step in which a wall stopped or deflected a body is swept along the path
  the physics made, substep by substep, instead of the chord between the step's two
  frames: v0 missed breaks there (the rod blocked mid-step while both frames are clear)
  and timed others late (dt = 10 on the corridor, a pursuer stopped by a wall after
  0.4 s: range break at 1.85 s, the truth 1.2 s). And a step is one physics substep
  only while a body pressed into a wall stays within half a radius of it (twice the
  substep's travel plus Chipmunk's slop), else two: with one substep of up to half a
  radius, v0 let a body pressed into a wall settle at twice that overlap, so at
  dt = 0.05 with the defaults (or body_radius 0.2 at dt = 0.1) a pursuer driven into a
  wall passed through it and left the map. The arguments, spaces, rewards and starts
  are v0's. Amended within v1 (2026-11, not bumped): a map file named by its path
  brings the `l_min`, `l_max`, `v_pursuer`, `v_evader` and `body_radius` its `metadata`
  recommends, as a built-in does (before, map files got the global defaults and their
  metadata was documented as ignored). Only files whose metadata gives these keys play
  otherwise; no shipped map, benchmark, model or result uses one, a tournament's run id
  names a file's recommendations (so stored runs never mix the two) and `surveil train`
  refuses to resume a run whose maps now resolve otherwise.
* v0: initial release (continuous-time surveillance check, state and lidar
  observations, zero-sum and sparse rewards). Retired: :mod:`envs.surveillance_v0`
  stays importable so that v0 results replay.
"""

from __future__ import annotations

from envs.surveillance.env import env, parallel_env, raw_env
from envs.surveillance.registry import ENV_IDS, register_envs

__all__ = ["ENV_ID", "env", "parallel_env", "raw_env"]

ENV_ID = ENV_IDS[1]
"""The versioned registry id."""

register_envs()
