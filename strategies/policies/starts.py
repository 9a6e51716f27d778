"""Seeded start configurations for evaluations: valid ones, or safe ones at L_min.

``kind="valid"``: the env's own rejection sampler (:func:`envs.surveillance.placement.random_start`)
driven by the caller's generator: both bodies in free space, L inside [L_min, L_max] with
a margin, the rod clear of convex corners, line of sight.

``kind="safe"``: a valid start with L just above L_min whose orientation lies in a safe
(non-escapable) cell at L_min, at least ``angle_margin`` inside it, and is admissible in
the bounded-speed sense of Sec. 5 as the decomposition pursuer estimates it (value
``V(theta) >= 0``: from there the rod reaches a safe orientation at every point before
the evader does; for rho >= 1 nothing is admissible and only the safe cell is
required). On maps where no safe cell exists (Prop. 2 holds) it falls back to a
valid start at L_min, since no safe start exists to draw. Where some proposal lies in a
safe cell but none is admissible or leaves room to retreat (below), the first such
proposal is drawn, as at rho >= 1: as rho -> 1 the rod's rate V_p sqrt(1 - rho^2) / L
vanishes (nothing was admissible on the corridor, open room, maze and pillars at rho =
0.9, on the L hall at 0.95) and the retreat grows without bound (25 at rho = 0.99 and
L_min = 2, more than their diameters), so ``"safe"`` refused every start there, naming
the rod clearance, while rho = 1 drew one.

For rho < 1 a safe start must also leave the pursuer room to *retreat* (issue 13): the
cell test is about orientations, not about the pursuer's body, and a start at L_0 (just
above L_min) with the pursuer's back to a wall was lost in about a second to an evader
charging straight at it (maze, seed 5: the pursuer is pinned, "too_close", before its
rod has turned). The criterion, conservative and simple:

* Charged along the rod at V_e, the pursuer keeps L constant only by moving with a
  component V_e along the rod direction u (away from the evader); its remaining speed
  V_p sqrt(1 - rho^2) goes sideways and turns the rod at V_p sqrt(1 - rho^2) / L.
* It must turn until it can slide along the wall behind it while holding L: for a wall
  met square-on that is an angle asin(rho) off the wall's normal (sliding then gives
  dL/dt = V_p sin(angle) - V_e >= 0). So the turn takes
  T_turn = L_0 asin(rho) / (V_p sqrt(1 - rho^2)), and during it the pursuer recedes
  along u by V_e T_turn.
* Required: the pursuer's disc (radius ``body_radius``) can move
  ``c_req = V_e T_turn = rho L_0 asin(rho) / sqrt(1 - rho^2)`` straight along u from its
  start without touching a wall (checked exactly with the kernel: the segment has line
  of sight and keeps ``body_radius`` from every wall vertex and edge).

It is conservative because it spends none of the range margin L_0 - L_min (left as a
reserve for the policy's reaction lag and for walls that are not flat), and credits the
pursuer no sideways room. At the built-ins' rho = 0.5 and L_0 = 2.45 it asks for 0.74 of
clearance; the lost maze start had 0.18, and starts with 0.24 to 0.31 already held in
the runs that motivated it. At rho >= 1 no turn holds L against a charge and the
criterion is not applied (like admissibility, Sec. 5).

"Safe" is local, not a certificate: admissibility and the retreat test look at the rod
and the pursuer's surroundings, not at where the evader can herd the pursuer later. On
the corner world (Fig. 9b) at rho = 0.5 the referee's sound evader bound certifies every
start this draws as an evader win (episode seeds 0-31 of four variants, ``python
benchmarks/pursuer_holds.py --worlds corner --referee 24``); starts certified either way
come from :func:`strategies.referee.sample_starts`.

``kind="escapable"``: the opposite, for curricula that teach escapes (and pursuits that
must recover): a valid start with L just above L_min whose orientation lies in an
*escapable* cell of the exact decomposition at L_min (or in a free arc at a point where
no cell is safe). On maps with no escapable orientation it raises ``InfeasibleError``.
"""

from __future__ import annotations

import math
import re
import warnings

import numpy as np

from envs.errors import (
    InfeasibleError,
    InvalidConfigError,
    MemoryBudgetError,
    RelaxedStartWarning,
)
from envs.geometry import kernel_for
from envs.surveillance.placement import (
    check_room,
    in_sensor_range,
    random_start,
    spawn_margins,
)
from strategies.policies.lazy_table import LazySafetyTable

__all__ = ["START_KINDS", "has_retreat_clearance", "retreat_clearance_required", "sample_start"]

START_KINDS = ("valid", "safe", "escapable")
BATCH = 256
MAX_BATCHES = 100


def sample_start(
    config, rng: np.random.Generator, *, kind: str = "safe", angle_margin: float = 0.15
) -> dict[str, tuple[float, float]]:
    """Draw a start ``{"pursuer": (x, y), "evader": (x, y)}`` for ``reset(options=...)``.

    Args:
        config: the env's ``EnvConfig``.
        rng: the generator to draw from (the only source of randomness).
        kind: ``"valid"``, ``"safe"`` or ``"escapable"`` (see the module docstring).
        angle_margin: for ``"safe"``, radians the orientation keeps from the safe set's edge.

    Raises:
        InvalidConfigError: unknown kind.
        InfeasibleError: no start found (the message names the map).
        MemoryBudgetError: the judge of a ``"safe"`` or ``"escapable"`` start (a
            decomposition pursuer) has a table grid beyond the memory budget; the message
            names ``kind='valid'``, which needs no judge.
    """
    if kind not in START_KINDS:
        raise InvalidConfigError(f"kind must be one of {START_KINDS}, got {kind!r}")
    range_margin = spawn_margins(config)[0]
    shortest = min(config.l_min + range_margin, config.l_max - range_margin)
    check_room(config.map, config.body_radius, shortest, f"{kind} start")
    kernel = kernel_for(config.map)
    if kind == "valid":
        p, e = random_start(config, kernel, rng)
        return {"pursuer": (float(p[0]), float(p[1])), "evader": (float(e[0]), float(e[1]))}
    from strategies.policies.decomposition import DecompositionPursuer

    # the judge assumes the evader holds the rod's rotation to (V_p/L)(1 - rho), the
    # least rate in one given direction (eq. 6, Sec. 6.1), not the sqrt(1 - rho^2) of a
    # pursuer free to turn either way: a start called safe is safe at the slower rate
    judge = DecompositionPursuer(turn_rate="one")
    try:
        judge.reset(role="pursuer", map=config.map, config=config, seed=0)
    except MemoryBudgetError as exc:  # its table's grid, or the map's decomposition
        raise _judge_refused(exc, kind, config) from None
    tab = judge.table
    if kind == "escapable":
        return _near_l_min(config, kernel, rng, judge, tab, None, escapable=True)
    if not _anything_safe(tab):  # Prop. 2: nothing is safe anywhere
        return _near_l_min(config, kernel, rng, judge, tab, None)
    return _near_l_min(config, kernel, rng, judge, tab, angle_margin)


def _judge_refused(exc: MemoryBudgetError, kind: str, config) -> MemoryBudgetError:
    """The judge's table (or the map's decomposition it stands on) refused by the memory
    budget, told as the start's caller can act on it: the judge's resolution (its default,
    L_min / 20) is not a parameter here, so the remedy is a ``kind="valid"`` start (no
    judge) or a larger budget. The decomposition's refusal named only a larger budget or
    "a shorter L or a smaller map", on a 600-gon room where ``surveil play --start valid``
    plays the greedy pursuer at once."""
    template, knob, budget, size = exc.args
    # each refusal's own remedy (the table's names its resolution) gives way to this one
    refusal = re.split(r"; use |\. Raise the budget|\. No budget on this machine", template)[0]
    judged = "safety table at L_min / 20" if knob == "resolution" else "decomposition of the map"
    more = (
        ""
        if "No budget on this machine" in template
        else f", or raise the budget with {MemoryBudgetError.BUDGET}"
    )
    return MemoryBudgetError(
        f"a {kind!r} start on map {config.map.name!r} is judged on a decomposition pursuer's "
        f"{judged}, which does not fit: {refusal}; use {MemoryBudgetError.KNOB} (a valid "
        f"start needs no judge){more}",
        "kind='valid'",
        budget,
        size,
    )


def _anything_safe(tab) -> bool:
    """Some point of the map has a non-escapable orientation.

    An eager table knows it from its rows; a lazy one (maps over
    ``DecompositionPursuer.DISTINCT_TABLE_POINTS`` grid points) has classified nothing
    yet, so its exact decomposition answers: some cell is known not to be escapable.
    """
    if isinstance(tab, LazySafetyTable):
        return any(c.escapable is False for c in tab.decomposition.cells)
    return bool(tab.guaranteed.any())


def _escapable(dec, e, theta: float) -> bool:
    """The rod at ``theta`` lies in an escapable cell of the exact decomposition (or in a
    free arc at a point where no cell is known to be safe)."""
    arcs = dec.free_arcs(e)
    if not any(ca.escapable is False for ca in arcs):
        return True
    for ca in arcs:
        if ca.arc.contains(theta):
            return ca.escapable is True
    return False


def _near_l_min(config, kernel, rng, judge, tab, angle_margin, escapable=False):
    m = config.map
    if escapable:  # judged exactly, at L_min (the paper's cells), not on the table's grid
        from strategies.cspace import decompose

        dec = decompose(m, config.l_min)
    admissible = config.rho < 1.0  # for rho >= 1 no configuration is admissible (Sec. 5)
    range_margin, rod_clearance = spawn_margins(config)
    # near L_min (the pursuer's target), but inside the sensor range even when it is
    # narrower than the pursuer's distance buffer
    length = min(max(judge.L_target, config.l_min + range_margin), config.l_max - range_margin)
    xmin, ymin, xmax, ymax = m.bounds
    r = config.body_radius
    convex = m.vertices[m.vertex_convex]
    margin_bins = 0 if angle_margin is None else math.ceil(angle_margin / tab.bin_width)
    retreat = retreat_clearance_required(config, length) if admissible else 0.0
    # no retreat longer than the map's diameter fits anywhere (rho near 1: 24.5 at rho =
    # 0.99 and L_0 = 2.45), so every proposal in a safe cell would be refused as
    # unretreatable and the first of them drawn: it is drawn at once
    hopeless = admissible and angle_margin is not None and retreat > m.diameter
    in_safe_cell = None  # the first proposal refused only as inadmissible or unretreatable
    for _ in range(MAX_BATCHES):
        e = rng.uniform((xmin, ymin), (xmax, ymax), size=(BATCH, 2))
        theta = rng.uniform(-math.pi, math.pi, size=BATCH)
        p = e + length * np.stack([np.cos(theta), np.sin(theta)], axis=1)
        ok = m.contains(e) & m.contains(p)
        ok &= (m.distance_to_walls(e) >= r) & (m.distance_to_walls(p) >= r)
        for i in np.flatnonzero(ok):
            if len(convex):
                d = p[i] - e[i]
                t = np.clip((convex - e[i]) @ d / (d @ d), 0.0, 1.0)
                if np.min(np.linalg.norm(convex - (e[i] + t[:, None] * d), axis=1)) < rod_clearance:
                    continue
            # the range as reset(options=...) checks it: at L = L_max exactly (a zero
            # range margin) half of the proposals are a rounding error beyond it
            if not in_sensor_range(config, p[i], e[i]) or not kernel.line_of_sight(p[i], e[i]):
                continue
            # the rod at its real start length (plus the pursuer's disc) is free, with
            # the same angular margin, not only the table's shorter one
            if angle_margin is not None and not _free_with_margin(
                kernel, e[i], length + r, float(theta[i]), angle_margin
            ):
                continue
            if escapable and not _escapable(dec, e[i], float(theta[i])):
                continue
            if angle_margin is not None:
                row = tab.row(e[i])
                if row < 0 or not tab.guaranteed[row]:
                    continue
                b = tab.bin_of(float(theta[i]))
                bins = (b + np.arange(-margin_bins, margin_bins + 1)) % tab.n_bins
                if not tab.safe[row, bins].all():
                    continue
                # the retreat first: the cheaper test (V is a probe fan per proposal)
                if admissible and (
                    hopeless
                    or not has_retreat_clearance(m, kernel, p[i], e[i], retreat, r)
                    or judge.orientation_values(e[i])[b] < 0.0
                ):
                    if in_safe_cell is None:
                        in_safe_cell = _placement(p[i], e[i])
                    if hopeless:
                        break
                    continue
            return _placement(p[i], e[i])
        if hopeless and in_safe_cell is not None:
            break
    if in_safe_cell is not None:  # nothing admissible (rho near 1): a safe cell, as at rho >= 1
        why = (
            f"none can retreat {retreat:.4g} along the rod, more than the map's diameter "
            f"{m.diameter:.4g}"
            if hopeless
            else f"no proposal in a safe cell was admissible (V(theta) >= 0) with a retreat "
            f"of {retreat:.4g} along the rod"
        )
        warnings.warn(
            f"map {m.name!r}, rho = {config.rho:g}: {why}; drew one in a safe cell only, as "
            "at rho >= 1 (the pursuer may not be able to hold from it)",
            RelaxedStartWarning,
            stacklevel=2,
        )
        return in_safe_cell
    what = "escapable" if escapable else ("safe" if angle_margin is not None else "valid")
    retreating = f", a retreat of {retreat:.4g} along the rod" if angle_margin is not None else ""
    fastest = max(config.v_pursuer, config.v_evader)
    raise InfeasibleError(
        f"no {what} start at L = {length:.4g} found on map {m.name!r} in "
        f"{MAX_BATCHES * BATCH} proposals (body radius {r:g}, rod clearance "
        f"{rod_clearance:.4g} from convex vertices{retreating}); the rod clearance is "
        f"max(v_pursuer, v_evader) dt spawn_margin_steps = {fastest:g} x {config.dt:g} x "
        f"{config.spawn_margin_steps}: lower spawn_margin_steps, dt or the speeds"
    )


def _free_with_margin(kernel, e, L: float, theta: float, margin: float) -> bool:
    """The rod of length ``L`` from ``e`` is free at every orientation within ``margin``."""
    for arc in kernel.free_arcs(e, L).arcs:
        if arc.is_full:
            return True
        if (theta - margin - arc.lo) % (2.0 * math.pi) + 2.0 * margin <= arc.width:
            return True
    return False


def retreat_clearance_required(config, length: float) -> float:
    """Distance ``rho L asin(rho) / sqrt(1 - rho^2)`` the pursuer must be able to retreat
    along the rod from a safe start at rod length ``length`` (module docstring); ``inf``
    for rho >= 1."""
    rho = config.rho
    if rho >= 1.0:
        return math.inf
    return rho * length * math.asin(rho) / math.sqrt(1.0 - rho * rho)


def _placement(p: np.ndarray, e: np.ndarray) -> dict[str, tuple[float, float]]:
    return {"pursuer": (float(p[0]), float(p[1])), "evader": (float(e[0]), float(e[1]))}


def has_retreat_clearance(m, kernel, p, e, distance: float, radius: float) -> bool:
    """The disc of ``radius`` at the pursuer ``p`` can move ``distance`` straight away from
    the evader ``e`` (along e -> p) in free space, touching no wall."""
    p = np.asarray(p, dtype=float)
    d = p - np.asarray(e, dtype=float)
    q = p + distance * d / np.linalg.norm(d)
    if np.array_equal(q, p):  # too short a retreat to move p (a very slow evader)
        return bool(m.distance_to_walls(p[None])[0] >= radius)
    if not m.contains(q[None])[0] or not kernel.line_of_sight(p, q):
        return False
    # no crossing, so the segment's distance to the walls is the least of its ends' and
    # the wall vertices' distance to it
    if np.min(m.distance_to_walls(np.stack([p, q]))) < radius:
        return False
    seg = q - p
    t = np.clip((m.vertices - p) @ seg / (seg @ seg), 0.0, 1.0)
    return bool(np.min(np.linalg.norm(m.vertices - (p + t[:, None] * seg), axis=1)) >= radius)
