"""Map pictures: what is drawn, saving, and the install hint without matplotlib."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from envs.maps import Map, builtin_map
from envs.maps.plot import DependencyNotInstalled, plot_map

pytest.importorskip("matplotlib")


def test_plot_draws_walls_free_space_and_convex_vertices(tmp_path):
    m = builtin_map("pillars")
    ax = plot_map(m, path=tmp_path / "pillars.png")
    data = (tmp_path / "pillars.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000
    assert len(ax.lines) == len(m.rings)
    for line, ring in zip(ax.lines, m.rings, strict=True):
        np.testing.assert_array_equal(line.get_xydata()[:-1], ring)
    (dots,) = ax.collections
    np.testing.assert_array_equal(dots.get_offsets(), m.vertices[m.vertex_convex])
    assert "pillars" in ax.get_title()


def test_rendered_pixels_are_free_colour_exactly_in_free_space():
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    m = builtin_map("pillars")
    ax = plot_map(m, free_color="#00ff00", obstacle_color="#0000ff", show_convex=False)
    canvas = FigureCanvasAgg(ax.figure)
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba())
    rng = np.random.default_rng(0)
    x0, y0, x1, y1 = m.bounds
    pts = rng.uniform([x0, y0], [x1, y1], size=(400, 2))
    pts = pts[m.distance_to_walls(pts) > 0.3]  # away from the drawn wall lines
    px = ax.transData.transform(pts)
    cols = rgba[(rgba.shape[0] - px[:, 1]).astype(int), px[:, 0].astype(int), :3]
    green = (cols == [0, 255, 0]).all(axis=1)
    blue = (cols == [0, 0, 255]).all(axis=1)
    free = m.contains(pts)
    assert free.any() and (~free).any()
    np.testing.assert_array_equal(green, free)
    np.testing.assert_array_equal(blue, ~free)


def test_plot_into_given_axes_with_options():
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    m = builtin_map("corner")
    out = plot_map(m, ax, show_convex=False, show_indices=True, title="T", wall_color="blue")
    assert out is ax and ax.get_title() == "T"
    assert not ax.collections
    assert len(ax.texts) == m.n_vertices


def test_plot_map_without_convex_vertices():
    ax = plot_map(Map([(0, 0), (3, 0), (3, 2), (0, 2)]))
    assert not ax.collections and "0 convex vertices" in ax.get_title()


def test_missing_matplotlib_gives_install_hint(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(DependencyNotInstalled, match=r"pip install surveil\[analysis\]") as info:
        plot_map(builtin_map("corridor"))
    assert isinstance(info.value, ImportError)
