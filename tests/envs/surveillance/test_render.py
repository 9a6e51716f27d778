"""The renderer draws snapshots without an env, and fails with an install hint."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from envs.maps import Feature
from envs.surveillance import render
from tests.envs.surveillance._worlds import l_room, open_room

PURSUER = (40, 90, 220)
EVADER = (220, 50, 50)
ROD_OK = (30, 170, 60)
ROD_BROKEN = (220, 30, 30)
FEATURE = (255, 140, 0)


def _colours(img: np.ndarray) -> set[tuple[int, ...]]:
    return {tuple(int(v) for v in c) for c in img.reshape(-1, 3)}


def test_render_frame_from_a_bare_snapshot() -> None:
    snap = render.Snapshot(
        map=l_room(),
        pursuer=(2.0, 2.0),
        evader=(2.0, 5.0),
        l_min=2.0,
        l_max=4.0,
        body_radius=0.1,
        trail_pursuer=((1.0, 1.0), (1.5, 1.5), (2.0, 2.0)),
    )
    img = render.render_frame(snap, size=200)
    assert img.dtype == np.uint8 and img.shape == (200, 200, 3)
    assert {PURSUER, EVADER, ROD_OK} <= _colours(img)
    # y axis up: the evader (higher y) is drawn above the pursuer (smaller row index)
    rows_e = np.flatnonzero((img == EVADER).all(axis=2).any(axis=1))
    rows_p = np.flatnonzero((img == PURSUER).all(axis=2).any(axis=1))
    assert rows_e.mean() < rows_p.mean()


def test_a_broken_rod_is_red_and_the_feature_highlighted() -> None:
    world = l_room()
    corner = int(np.flatnonzero(world.vertex_convex)[0])
    snap = render.Snapshot(
        map=world,
        pursuer=(7.0, 3.0),
        evader=(4.0, 8.0),
        l_min=2.0,
        l_max=8.0,
        body_radius=0.1,
        surveillance=False,
        cause="occluded",
        feature=Feature("vertex", corner),
    )
    colours = _colours(render.render_frame(snap, size=300))
    assert ROD_BROKEN in colours and FEATURE in colours and ROD_OK not in colours
    snap_edge = render.Snapshot(
        map=world,
        pursuer=(7.0, 3.0),
        evader=(4.0, 8.0),
        l_min=2.0,
        l_max=8.0,
        body_radius=0.1,
        surveillance=False,
        cause="occluded",
        feature=Feature("edge", 2),
    )
    assert FEATURE in _colours(render.render_frame(snap_edge, size=300))


def test_non_square_maps_keep_their_aspect() -> None:
    from envs.maps import Map

    wide = Map([(0, 0), (20, 0), (20, 5), (0, 5)])
    snap = render.Snapshot(
        map=wide, pursuer=(2, 2), evader=(5, 2), l_min=2, l_max=4, body_radius=0.1
    )
    h, w, _ = render.render_frame(snap, size=420).shape
    assert w == 420 and abs((h - 20) / (w - 20) - 0.25) < 0.01


def test_missing_pygame_gives_an_install_hint(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "pygame", None)  # makes `import pygame` fail
    snap = render.Snapshot(
        map=open_room(), pursuer=(2, 2), evader=(5, 2), l_min=2, l_max=4, body_radius=0.1
    )
    with pytest.raises(ImportError, match=r"pip install surveil\[render\]"):
        render.render_frame(snap)
