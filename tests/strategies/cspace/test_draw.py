"""The decomposition picture: a PNG with one or two panels."""

from __future__ import annotations

import matplotlib.image as mpimg
import numpy as np

from strategies.cspace import decompose, draw_decomposition
from tests.strategies.cspace._oracle import corridor, two_rooms


def test_draws_map_and_graph(tmp_path):
    dec = decompose(two_rooms(), 2.0)
    both = draw_decomposition(dec, tmp_path / "sub" / "both.png", dpi=60)
    alone = draw_decomposition(dec, tmp_path / "alone.png", show_graph=False, dpi=60)
    a, b = mpimg.imread(both), mpimg.imread(alone)
    assert a.shape[1] > 1.8 * b.shape[1]  # the graph panel doubles the width
    # escapable regions are shaded: reddish pixels exist, and the picture is not blank
    rgb = a[..., :3]
    reddish = (rgb[..., 0] > 0.85) & (rgb[..., 1] < 0.8) & (rgb[..., 2] < 0.75)
    assert reddish.mean() > 0.02
    assert np.std(rgb) > 0.05


def test_pursuer_win_has_no_witness_star(tmp_path):
    dec = decompose(corridor(), 2.0)
    path = draw_decomposition(dec, tmp_path / "c.png", dpi=50, label_regions=True)
    img = mpimg.imread(path)[..., :3]
    star = (img[..., 0] > 0.95) & (img[..., 1] > 0.75) & (img[..., 2] < 0.35)
    assert not star.any()
