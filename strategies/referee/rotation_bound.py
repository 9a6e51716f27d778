"""A bound on the rod's turn alone: could any pursuer keep the rod clear of the walls?

Against a known *open-loop* evader path E(t) (:func:`.hindsight.record_evader_path`) the
rod's orientation theta must stay, at every instant, among the orientations whose rod is
clear; and theta turns no faster than the pursuer's speed allows (eq. 5, with ``u`` the
rod's direction and ``c = cross(u, v_E)`` the evader's motion across it)::

    theta' = (cross(u, v_P) - c) / L  in  [(-V_p - c) / L_min, (V_p - c) / L_min]

for any pursuer velocity ``|v_P| <= V_p`` and any ``L >= L_min`` (where ``V_p - c`` is
negative the fastest counter-clockwise turn is slower still, so the bound caps it at 0).
That is a reachability question on the circle of orientations: the set of orientations a
pursuer could have at step k, grown by the fastest turn each way over the step, minus the
orientations that are certainly blocked at step k + 1. When it empties at t_k, no pursuer
kept surveillance past t_k against this path: the evader's win is **certain**. Every
approximation favours the pursuer (an over-approximation, like the optimistic grid of
:mod:`.hindsight`):

* the pursuer's position, its clearance from the walls and ``L_max`` are ignored; all of
  ``V_p`` goes across the rod and ``L`` is ``L_min`` when that turns it fastest;
* the orientations are bins; a bin is grown from its whole arc, and the evader's motion
  across the rod is bounded over the step by a Lipschitz slack (``c`` changes by at most
  ``V_e`` times the angle turned in the step plus the bin's width, the evader's speed
  taken as at least its bound ``V_e``);
* a bin is removed only at the frames, and only when the rod of length ``L_min`` from
  ``E`` meets a wall over its whole arc: a longer rod contains that one. The blocked arcs
  are exact: each wall edge clipped to the disc of radius ``L_min`` round ``E`` blocks the
  arc between the clipped ends.

The env checks ``L >= L_min`` continuously over a step (its sweep), so the rate bound holds
at every instant of it; where the evader's motion within a step is not the chord of the
path (a wall deflected it), the rod's net turn still differs from the chord's by no more
than the Lipschitz slack, for the evader's displacement is the chord's and, with
``V_p > V_e``, ``V_p - c > 0`` throughout (at ``rho >= 1`` the cap at 0 is a chord-only
approximation). The sign of ``c`` is checked against the closed form of an orbit round a
disc, the slack against the integrated turn of a rod held at ``L_min`` over one step,
which the rate at the step's start alone falls short of
(``tests/strategies/referee/test_rotation_bound.py``).

Where the evader circles an obstacle small enough, the obstacle's shadow (its blocked arc)
turns with it faster than any rod can turn on the average, and the set empties
(issue 13: the orbit of a 3.0-long hull on ``rand:polygons:3007`` at rho 0.5 by 20.5 s,
where the hindsight's optimistic grid at cell 0.02 never empties). It costs about a
second per 100 frames at the default 7200 bins, on one core, with no memory to speak of.
"""

from __future__ import annotations

import math

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError

__all__ = ["blocked_bins", "rotation_bound"]


def blocked_bins(world, evader: np.ndarray, length: float, bins: int) -> np.ndarray:
    """``(bins,)`` bool: the orientation bins (bin ``i`` covers ``[i, i + 1) 2 pi / bins``)
    whose rod of ``length`` from ``evader`` meets a wall of ``world`` over the whole bin."""
    bw = 2.0 * math.pi / bins
    f = world.edge_start - evader[None, :]
    d = world.edge_dir
    b = np.einsum("ej,ej->e", f, d)
    disc = b * b - (np.einsum("ej,ej->e", f, f) - length * length)
    hit = disc >= 0.0
    root = np.sqrt(np.where(hit, disc, 0.0))
    s0 = np.maximum(0.0, -b - root)
    s1 = np.minimum(world.edge_length, -b + root)
    hit &= s0 <= s1
    p0 = f[hit] + s0[hit, None] * d[hit]
    p1 = f[hit] + s1[hit, None] * d[hit]
    t0 = np.arctan2(p0[:, 1], p0[:, 0])
    span = np.remainder(np.arctan2(p1[:, 1], p1[:, 0]) - t0 + math.pi, 2.0 * math.pi) - math.pi
    lo = np.mod(np.where(span >= 0.0, t0, t0 + span), 2.0 * math.pi)
    hi = lo + np.abs(span)
    # split the arcs that wrap past 2 pi, then merge them in order
    wrap = hi > 2.0 * math.pi
    los = np.concatenate([lo, np.zeros(int(wrap.sum()))])
    his = np.concatenate([np.minimum(hi, 2.0 * math.pi), hi[wrap] - 2.0 * math.pi])
    out = np.zeros(bins, dtype=bool)
    order = np.argsort(los, kind="stable")
    cur_lo = cur_hi = None
    for a, z in zip(los[order], his[order], strict=True):
        if cur_hi is not None and a <= cur_hi + 1e-12:
            cur_hi = max(cur_hi, z)
            continue
        if cur_hi is not None:
            _cover(out, cur_lo, cur_hi, bw)
        cur_lo, cur_hi = a, z
    if cur_hi is not None:
        _cover(out, cur_lo, cur_hi, bw)
    return out


def _cover(out: np.ndarray, lo: float, hi: float, bw: float) -> None:
    """Mark the bins lying wholly inside ``[lo, hi]``."""
    i0 = math.ceil(lo / bw - 1e-9)
    i1 = math.floor(hi / bw + 1e-9)
    if i1 > i0:
        out[i0:i1] = True


def rotation_bound(config, path, pursuer_start, *, bins: int = 7200) -> float | None:
    """The time by which the rod certainly meets a wall against the evader's ``path``.

    Args:
        config: the env's :class:`~envs.surveillance.config.EnvConfig` (map, speeds,
            ``l_min``, ``dt``).
        path: the evader's path, ``(n + 1, 2)`` centres one frame (``config.dt``) apart
            (:attr:`.hindsight.EvaderPath.positions`).
        pursuer_start: ``(2,)`` the pursuer's start.
        bins: orientation bins (at least 8).

    Returns:
        The first frame time at which no orientation is left (no pursuer holds past it
        against this path), or ``None`` if some is left at every frame (nothing proven).

    Raises:
        InvalidConfigError: a malformed ``path``, ``pursuer_start`` or ``bins``.
    """
    bins = validation.integer("bins", bins, minimum=8)
    path = validation.finite_array("path", path, shape=(None, 2))
    start = validation.point("pursuer_start", pursuer_start)
    if len(path) < 2:
        raise InvalidConfigError(
            f"path: {len(path)} frame(s), expected at least 2 (a path over a step)"
        )
    world, dt = config.map, float(config.dt)
    vp, ve, lmin = float(config.v_pursuer), float(config.v_evader), float(config.l_min)
    bw = 2.0 * math.pi / bins
    th = (np.arange(bins) + 0.5) * bw
    ux, uy = np.cos(th), np.sin(th)
    rod = start - path[0]
    theta0 = math.atan2(float(rod[1]), float(rod[0])) % (2.0 * math.pi)
    held = np.zeros(bins, dtype=bool)
    held[int(theta0 / bw) % bins] = True
    idx = np.arange(bins)
    for k in range(len(path) - 1):
        v = (path[k + 1] - path[k]) / dt
        speed = max(math.hypot(float(v[0]), float(v[1])), ve)
        c = ux * float(v[1]) - uy * float(v[0])  # the evader's motion across the rod
        slack = speed * (dt * (vp + speed) / lmin + bw)  # c over the step and the bin
        ccw = dt * np.maximum(vp - c + slack, 0.0) / lmin + bw
        cw = dt * np.maximum(vp + c + slack, 0.0) / lmin + bw
        i = idx[held]
        first = i - np.ceil(cw[i] / bw).astype(np.int64)
        last = i + np.ceil(ccw[i] / bw).astype(np.int64)
        grown = np.zeros(bins, dtype=bool)
        if np.any(last - first + 1 >= bins):
            grown[:] = True
        else:  # mark first..last (mod bins) through a difference array over three turns
            diff = np.zeros(3 * bins + 1, dtype=np.int64)
            np.add.at(diff, first + bins, 1)
            np.add.at(diff, last + bins + 1, -1)
            grown = (np.cumsum(diff[:-1]).reshape(3, bins) > 0).any(axis=0)
        held = grown & ~blocked_bins(world, path[k + 1], lmin, bins)
        if not held.any():
            return (k + 1) * dt
    return None
