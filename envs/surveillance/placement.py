"""Start configurations: validation of requested placements and seeded random starts."""

from __future__ import annotations

import difflib
import math
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

from envs import validation
from envs.errors import (
    InfeasibleError,
    InvalidConfigError,
    InvalidPlacementError,
    UnknownOptionWarning,
)
from envs.surveillance import rules
from envs.surveillance.config import EnvConfig
from envs.tolerances import REL_LENGTH_TOL

__all__ = [
    "BATCH",
    "MAX_BATCHES",
    "PLACEMENT_KEYS",
    "check_option_keys",
    "check_room",
    "in_sensor_range",
    "random_start",
    "spawn_margins",
    "validate_placement",
]

BATCH = 256
"""Candidate start configurations drawn at once by :func:`random_start`."""

MAX_BATCHES = 64
"""Batches tried before :func:`random_start` gives up (16384 candidates)."""


PLACEMENT_KEYS = ("pursuer", "evader")
"""The ``reset`` options the env reads: the agents' start positions."""


def check_option_keys(options: Mapping[Any, Any], stacklevel: int = 2) -> None:
    """Warn about ``reset`` options whose name is close to a placement key but is not one.

    Other keys are left alone, as Gymnasium and PettingZoo envs do: wrappers pass their own
    options through ``reset``, and PettingZoo's ``api_test`` and ``parallel_api_test``
    reset with ``options={"options": 1}`` (refusing unknown keys would fail the official
    suites, and a warning on every unknown key would make them warn). A near miss
    (``"pursuer_0"``, the agent's name; ``"Evader"``; ``"persuer"``) is a placement lost
    without a word, the start then drawn at random: that one warns.

    Warns:
        UnknownOptionWarning: for each near miss, naming it and the key it resembles.
    """
    placed = any(k in options for k in PLACEMENT_KEYS)
    for key in options:
        if key in PLACEMENT_KEYS or not isinstance(key, str):
            continue
        close = difflib.get_close_matches(key.strip().lower(), PLACEMENT_KEYS, n=1, cutoff=0.6)
        if close:
            warnings.warn(
                f"reset: options key {key!r} is not read by the env (its keys are "
                f"{list(PLACEMENT_KEYS)}; other keys are left to wrappers): did you mean "
                f"{close[0]!r}?" + ("" if placed else " The start is drawn at random."),
                UnknownOptionWarning,
                stacklevel=stacklevel + 1,
            )


def _point(value: Any, who: str) -> np.ndarray:
    try:
        return validation.point(who, value)
    except InvalidConfigError as exc:
        raise InvalidPlacementError(str(exc)) from None


def _fmt(p: np.ndarray) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


def validate_placement(
    config: EnvConfig, kernel: Any, pursuer: Any, evader: Any
) -> tuple[np.ndarray, np.ndarray]:
    """Check a requested start and return it as two float arrays.

    Args:
        config: the env configuration (map, range, body radius).
        kernel: the map's geometry kernel.
        pursuer: requested pursuer centre (x, y).
        evader: requested evader centre (x, y).

    Returns:
        ``(pursuer, evader)`` as (2,) float arrays.

    Raises:
        InvalidPlacementError: a position is missing, not finite, outside free space or
            closer to a wall than the body radius, or the pair is out of range or
            occluded; the message names the positions and the reason.
    """
    if pursuer is None or evader is None:
        raise InvalidPlacementError(
            "placement: options must give both 'pursuer' and 'evader' positions, got "
            f"pursuer={pursuer!r}, evader={evader!r}"
        )
    m = config.map
    p = _point(pursuer, "pursuer")
    e = _point(evader, "evader")
    tol = REL_LENGTH_TOL * m.scale
    for who, q in (("pursuer", p), ("evader", e)):
        if not bool(m.contains(q[None])[0]):
            raise InvalidPlacementError(
                f"{who} position {_fmt(q)} is outside the free space of map {m.name!r}"
            )
        clearance = float(m.distance_to_walls(q[None])[0])
        if clearance < config.body_radius - tol:
            raise InvalidPlacementError(
                f"{who} position {_fmt(q)} is {clearance:.6g} from the nearest wall, closer "
                f"than the body radius {config.body_radius:g}"
            )
    status = rules.surveillance_status(kernel, tuple(p), tuple(e), config.l_min, config.l_max)
    pair = f"pursuer {_fmt(p)} and evader {_fmt(e)}"
    if status.cause in ("too_close", "too_far"):
        raise InvalidPlacementError(
            f"{pair} are out of range: distance {status.distance:.6g} is not in "
            f"[l_min, l_max] = [{config.l_min:g}, {config.l_max:g}] ({status.cause})"
        )
    if status.cause == "occluded":
        what = m.describe(status.feature) if status.feature is not None else "a wall"
        raise InvalidPlacementError(f"{pair} have no line of sight: occluded by {what}")
    return p, e


def spawn_margins(config: EnvConfig) -> tuple[float, float]:
    """Margins that make a random start survive ``spawn_margin_steps`` steps.

    In k steps of length dt the rod length changes by at most (V_p + V_e) k dt, and
    every point of the rod (a convex combination of its ends) moves at most
    max(V_p, V_e) k dt. While both ends stay in free space (the physics guarantees
    it), the rod can first touch a wall only at a convex obstacle vertex (THEORY.md
    section 0). So a start with L at least ``range_margin`` inside [L_min, L_max] and
    every convex vertex at least ``rod_clearance`` from the rod cannot break in k steps.

    Returns:
        ``(range_margin, rod_clearance)``; the range margin is capped at a quarter of
        L_max - L_min, so that a narrow sensor range still leaves room to sample (the
        guarantee then covers fewer steps).
    """
    k = config.spawn_margin_steps * config.dt
    range_margin = min(
        (config.v_pursuer + config.v_evader) * k, 0.25 * (config.l_max - config.l_min)
    )
    rod_clearance = max(config.v_pursuer, config.v_evader) * k
    return range_margin, rod_clearance


def _segment_point_distance(a: np.ndarray, b: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(n, m) distances from points v (m, 2) to segments a_i b_i (n, 2 each)."""
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)[:, None]
    rel = v[None, :, :] - a[:, None, :]
    t = np.clip(np.einsum("imj,ij->im", rel, d) / dd, 0.0, 1.0)
    closest = a[:, None, :] + t[..., None] * d[:, None, :]
    return np.linalg.norm(v[None, :, :] - closest, axis=2)


_ROOM: dict[tuple[str, float], tuple[bool, float]] = {}
"""(map digest, body radius) -> (some point is that far from the walls, the largest
distance between two such points): what :func:`check_room` computes once per map."""


def check_room(m: Any, body_radius: float, length: float, where: str = "start") -> None:
    """Refuse up front a start that cannot exist at all on map ``m``: no point of free
    space is ``body_radius`` from the walls (no agent fits), or no two such points are
    ``length`` apart (no rod of that length fits).

    The region at least ``body_radius`` from the walls is shapely's inward buffer, whose
    arcs are chords inside the true region; its diameter (the largest distance between
    two vertices of its hull) is at most 2 % of ``body_radius`` short, so the test allows
    that much.

    Raises:
        InfeasibleError: naming the map, the figures and what to change.
    """
    key = (m.digest, float(body_radius))
    if key not in _ROOM:
        import shapely

        region = m.free_region.buffer(-body_radius)
        if region.is_empty:
            _ROOM[key] = (False, 0.0)
        else:
            xy = shapely.get_coordinates(shapely.convex_hull(region))
            # the pairs a block of rows at a time: a round room of 8,000 vertices built
            # 1.5 GB of them at once (20,000: 9.6 GB) on the env's first random start
            rows = max(1, (1 << 20) // len(xy))
            far = 0.0
            for i in range(0, len(xy), rows):
                d = np.hypot(*(xy[i : i + rows, None, :] - xy[None, :, :]).transpose(2, 0, 1))
                far = max(far, float(d.max()))
            _ROOM[key] = (True, far)
        if len(_ROOM) > 64:
            _ROOM.pop(next(iter(_ROOM)))
    fits, diameter = _ROOM[key]
    if not fits:
        raise InfeasibleError(
            f"{where}: map {m.name!r} cannot hold an agent: no point of its free space is "
            f"body_radius = {body_radius:g} from the walls (the map's diameter is "
            f"{m.diameter:.4g}); use a smaller body_radius or a larger map"
        )
    if length > diameter + 0.02 * body_radius:
        raise InfeasibleError(
            f"{where}: map {m.name!r} cannot hold the rod: no two points of its free space "
            f"body_radius = {body_radius:g} from the walls are L = {length:.4g} apart (at "
            f"most {diameter:.4g}); lower l_min (or the start's L) or use a larger map"
        )


def in_sensor_range(config: EnvConfig, pursuer: Any, evader: Any) -> bool:
    """Whether the distance of two centres lies in [L_min, L_max] as
    :func:`validate_placement` computes it (``math.hypot`` of the difference).

    A proposal drawn at L = L_max exactly (a zero range margin) lands a rounding error
    beyond it about half of the time, and ``reset(options=...)`` then refuses it:
    samplers that draw at a range end keep only proposals this accepts
    (:func:`strategies.policies.starts.sample_start`).
    """
    d = math.hypot(pursuer[0] - evader[0], pursuer[1] - evader[1])
    return rules.in_range(d, config.l_min, config.l_max) is None


def random_start(
    config: EnvConfig, kernel: Any, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Draw a start configuration by rejection sampling with the env's one generator.

    Proposals are drawn in batches of :data:`BATCH`: the evader E uniform in the map's
    bounding box, theta uniform in [0, 2 pi), L uniform in
    [L_min + range_margin, L_max - range_margin] (:func:`spawn_margins`), the pursuer at
    E + L (cos theta, sin theta) (eq. 1). A proposal is kept when both centres lie in
    free space at least ``body_radius`` from every wall, every convex obstacle vertex
    is at least ``rod_clearance`` from the rod, and the pursuer sees the evader. The
    first kept proposal of the first batch with one wins, so the draw depends only on
    the generator's state.

    Raises:
        InfeasibleError: no proposal was kept in :data:`MAX_BATCHES` batches; the
            message names the map and the parameters to relax.
    """
    m = config.map
    xmin, ymin, xmax, ymax = m.bounds
    lo_xy = np.array([xmin, ymin])
    hi_xy = np.array([xmax, ymax])
    range_margin, rod_clearance = spawn_margins(config)
    l_lo = config.l_min + range_margin
    # no rod longer than the map's diameter fits: draw L below it (the accepted starts
    # are distributed as before; an L_max far beyond the map no longer starves the
    # sampler, and a range beyond the map is named as such)
    l_hi = min(config.l_max - range_margin, m.diameter)
    if l_lo > m.diameter:
        raise InfeasibleError(
            f"random start: map {m.name!r} has no two points {l_lo:.6g} apart (its diameter "
            f"is {m.diameter:.6g}), the shortest rod a start may have (l_min = "
            f"{config.l_min:g} plus a margin of {range_margin:.3g} for spawn_margin_steps); "
            "lower l_min or use a larger map"
        )
    convex = m.vertices[m.vertex_convex]
    r = config.body_radius
    check_room(m, r, l_lo, "random start")
    for _ in range(MAX_BATCHES):
        e = rng.uniform(lo_xy, hi_xy, size=(BATCH, 2))
        theta = rng.uniform(0.0, 2.0 * math.pi, size=BATCH)
        length = rng.uniform(l_lo, l_hi, size=BATCH)
        p = e + length[:, None] * np.stack([np.cos(theta), np.sin(theta)], axis=1)
        ok = m.contains(e) & m.contains(p)
        ok &= (m.distance_to_walls(e) >= r) & (m.distance_to_walls(p) >= r)
        idx = np.flatnonzero(ok)
        if len(idx) and len(convex) and rod_clearance > 0:
            clear = _segment_point_distance(e[idx], p[idx], convex).min(axis=1)
            idx = idx[clear >= rod_clearance]
        for i in idx:
            pi, ei = p[i], e[i]
            if kernel.line_of_sight(pi, ei):
                return pi.copy(), ei.copy()
    raise InfeasibleError(
        f"random start: no valid surveillance configuration found on map {m.name!r} in "
        f"{MAX_BATCHES * BATCH} proposals (L in [{l_lo:.6g}, {l_hi:.6g}], body radius {r:g}, "
        f"rod clearance {rod_clearance:.6g} from convex vertices = spawn_margin_steps "
        f"{config.spawn_margin_steps} x the faster speed "
        f"{max(config.v_pursuer, config.v_evader):g} x dt {config.dt:g}); lower "
        "spawn_margin_steps, dt or body_radius, or place the agents with "
        "reset(options={'pursuer': ..., 'evader': ...})"
    )
