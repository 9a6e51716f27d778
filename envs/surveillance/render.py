"""Rendering, a pure consumer of read-only snapshots (pygame, imported lazily).

Nothing here feeds back into the simulation: observations come from geometry, never
from pixels. :func:`render_frame` draws one :class:`Snapshot` without an env (the CLI
uses it to write replays); :class:`Renderer` keeps a surface (and, in ``"human"``
mode, a window) between frames.

Colours: free space light, obstacles dark, pursuer blue, evader red, the rod green
while surveillance holds and red once broken, the sensor annulus (L_min and L_max
circles about the pursuer) grey, the occluding wall feature orange.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from envs.maps import Feature, Map

__all__ = ["DEFAULT_SIZE", "Renderer", "Snapshot", "render_frame"]

DEFAULT_SIZE = 600
"""Frame size in pixels along the map's longer side."""

_BACKGROUND = (40, 40, 48)
_FREE = (236, 236, 228)
_WALL = (90, 90, 100)
_PURSUER = (40, 90, 220)
_EVADER = (220, 50, 50)
_ROD_OK = (30, 170, 60)
_ROD_BROKEN = (220, 30, 30)
_ANNULUS = (150, 150, 160)
_FEATURE = (255, 140, 0)
_TRAIL_P = (140, 170, 235)
_TRAIL_E = (235, 150, 150)


@dataclass(frozen=True)
class Snapshot:
    """Everything a frame shows, copied out of the env.

    Attributes:
        map: the world.
        pursuer, evader: centres (x, y).
        l_min, l_max: the sensor range.
        body_radius: disc radius of both agents.
        surveillance: False once surveillance has broken.
        cause: why it broke (``"occluded"``, ``"too_far"``, ``"too_close"``) or ``None``.
        feature: the occluding wall feature, if any.
        step, time: steps taken and simulated time.
        trail_pursuer, trail_evader: recent centres, oldest first (may be empty).
        shading: ``(polygon, rgb)`` pairs filled over free space under everything else
            (a caller's overlay, e.g. regions of a decomposition; the env sets none).
    """

    map: Map
    pursuer: tuple[float, float]
    evader: tuple[float, float]
    l_min: float
    l_max: float
    body_radius: float
    surveillance: bool = True
    cause: str | None = None
    feature: Feature | None = None
    step: int = 0
    time: float = 0.0
    trail_pursuer: tuple[tuple[float, float], ...] = ()
    trail_evader: tuple[tuple[float, float], ...] = ()
    shading: tuple[tuple[np.ndarray, tuple[int, int, int]], ...] = ()


def _pygame() -> Any:
    try:
        import pygame
    except ImportError as exc:
        raise ImportError(
            "rendering needs pygame (pygame-ce): install it with `pip install surveil[render]`"
        ) from exc
    return pygame


class _Frame:
    """World-to-pixel transform for one map and frame size (y axis up)."""

    def __init__(self, world_map: Map, size: int) -> None:
        xmin, ymin, xmax, ymax = world_map.bounds
        span = max(xmax - xmin, ymax - ymin)
        self.margin = 10
        inner = max(int(size) - 2 * self.margin, 16)
        self.scale = inner / span
        self.xmin, self.ymax = xmin, ymax
        self.width = round((xmax - xmin) * self.scale) + 2 * self.margin
        self.height = round((ymax - ymin) * self.scale) + 2 * self.margin

    def px(self, p: Any) -> tuple[int, int]:
        return (
            round(self.margin + (p[0] - self.xmin) * self.scale),
            round(self.margin + (self.ymax - p[1]) * self.scale),
        )

    def length(self, d: float) -> int:
        return max(1, round(d * self.scale))


def _draw(pygame: Any, surface: Any, frame: _Frame, snap: Snapshot) -> None:
    m = snap.map
    surface.fill(_BACKGROUND)
    pygame.draw.polygon(surface, _FREE, [frame.px(v) for v in m.rings[0]])
    for polygon, colour in snap.shading:
        if len(polygon) >= 3:
            pygame.draw.polygon(surface, colour, [frame.px(v) for v in polygon])
    for ring in m.rings[1:]:
        pygame.draw.polygon(surface, _WALL, [frame.px(v) for v in ring])
    for ring in m.rings:
        pygame.draw.lines(surface, _WALL, True, [frame.px(v) for v in ring], 2)
    for trail, colour in ((snap.trail_pursuer, _TRAIL_P), (snap.trail_evader, _TRAIL_E)):
        if len(trail) >= 2:
            pygame.draw.lines(surface, colour, False, [frame.px(v) for v in trail], 1)
    centre = frame.px(snap.pursuer)
    pygame.draw.circle(surface, _ANNULUS, centre, frame.length(snap.l_min), 1)
    pygame.draw.circle(surface, _ANNULUS, centre, frame.length(snap.l_max), 1)
    rod = _ROD_OK if snap.surveillance else _ROD_BROKEN
    pygame.draw.line(surface, rod, centre, frame.px(snap.evader), 3)
    if snap.feature is not None:
        if snap.feature.kind == "vertex":
            v = m.vertices[snap.feature.index]
            pygame.draw.circle(surface, _FEATURE, frame.px(v), 7, 3)
        else:
            a, b = m.edge_start[snap.feature.index], m.edge_end[snap.feature.index]
            pygame.draw.line(surface, _FEATURE, frame.px(a), frame.px(b), 5)
    r = max(3, frame.length(snap.body_radius))
    pygame.draw.circle(surface, _PURSUER, centre, r)
    pygame.draw.circle(surface, _EVADER, frame.px(snap.evader), r)


def _to_array(pygame: Any, surface: Any) -> np.ndarray:
    # surfarray is (W, H, 3); images are (H, W, 3)
    return np.ascontiguousarray(
        np.transpose(pygame.surfarray.array3d(surface), (1, 0, 2)), dtype=np.uint8
    )


def render_frame(snapshot: Snapshot, size: int = DEFAULT_SIZE) -> np.ndarray:
    """Draw one snapshot off-screen.

    Args:
        snapshot: what to draw.
        size: pixels along the map's longer side (plus a small margin).

    Returns:
        An (H, W, 3) uint8 RGB image.
    """
    pygame = _pygame()
    frame = _Frame(snapshot.map, size)
    surface = pygame.Surface((frame.width, frame.height))
    _draw(pygame, surface, frame, snapshot)
    return _to_array(pygame, surface)


class Renderer:
    """Keeps the drawing surface (and a window in human mode) between frames.

    Args:
        world_map: the map, which fixes the frame size.
        human: open a window and draw into it (``draw`` then returns ``None``).
        fps: frame rate the window is paced at.
        size: pixels along the map's longer side.
    """

    def __init__(
        self,
        world_map: Map,
        *,
        human: bool,
        fps: float,
        size: int = DEFAULT_SIZE,
        title: str = "surveillance",
    ) -> None:
        self._pygame = _pygame()
        self.title = title
        self.frame = _Frame(world_map, size)
        self.human = human
        self.fps = fps
        self._window = None
        self._clock = None
        self._surface = self._pygame.Surface((self.frame.width, self.frame.height))

    def draw(self, snapshot: Snapshot) -> np.ndarray | None:
        """Draw ``snapshot``; return the image (``rgb_array``) or ``None`` (``human``)."""
        pygame = self._pygame
        _draw(pygame, self._surface, self.frame, snapshot)
        if not self.human:
            return _to_array(pygame, self._surface)
        if self._window is None:
            pygame.display.init()
            pygame.display.set_caption(self.title)
            self._window = pygame.display.set_mode((self.frame.width, self.frame.height))
            self._clock = pygame.time.Clock()
        self._window.blit(self._surface, (0, 0))
        pygame.event.pump()
        pygame.display.flip()
        self._clock.tick(self.fps)
        return None

    def close(self) -> None:
        """Close the window, if one is open (idempotent)."""
        if self._window is not None:
            self._pygame.display.quit()
            self._window = None
            self._clock = None
