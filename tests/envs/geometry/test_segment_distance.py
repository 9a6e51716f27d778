"""segments.segment_distance / point_segment_distance against shapely's distance."""

import numpy as np
import shapely

from envs.geometry.segments import cross2d, point_segment_distance, segment_distance


def test_segment_distance_is_shapelys_on_random_segments():
    rng = np.random.default_rng(7)
    p, q, a, b = (rng.uniform(-3.0, 3.0, size=(400, 2)) for _ in range(4))
    # some touching and collinear cases: an end on the other segment, overlapping collinear
    a[:20] = p[:20] + 0.3 * (q[:20] - p[:20])
    a[20:40], b[20:40] = (
        p[20:40] + 0.2 * (q[20:40] - p[20:40]),
        p[20:40] + 1.5 * (q[20:40] - p[20:40]),
    )
    b[40:50] = a[40:50]  # zero-length segments: their point
    got = segment_distance(p, q, a, b)
    want = shapely.distance(
        shapely.linestrings(np.stack([p, q], 1)), shapely.linestrings(np.stack([a, b], 1))
    )
    np.testing.assert_allclose(got, want, atol=1e-12)
    assert (got[:20] < 1e-12).all() and (got[20:40] < 1e-12).all()
    assert (got > 0.0).sum() > 200  # mostly apart: the four end distances are compared too


def test_one_segment_against_many_broadcasts():
    # the shooting evader's use: one path against the wall edges near it
    rng = np.random.default_rng(3)
    e, q = np.array([0.0, 0.0]), np.array([2.0, 1.0])
    a, b = rng.uniform(-1.0, 3.0, size=(50, 2)), rng.uniform(-1.0, 3.0, size=(50, 2))
    path = shapely.LineString([e, q])
    want = [path.distance(shapely.LineString([x, y])) for x, y in zip(a, b, strict=True)]
    np.testing.assert_allclose(segment_distance(e, q, a, b), want, atol=1e-12)
    ends = [
        shapely.Point(q).distance(shapely.LineString([x, y])) for x, y in zip(a, b, strict=True)
    ]
    np.testing.assert_allclose(point_segment_distance(q, a, b), ends, atol=1e-12)


def test_cross2d_is_the_z_of_the_cross_product():
    u, w = np.array([[1.0, 2.0], [3.0, -1.0]]), np.array([[4.0, 5.0], [0.5, 2.0]])
    np.testing.assert_array_equal(cross2d(u, w), np.cross(np.c_[u, [0, 0]], np.c_[w, [0, 0]])[:, 2])
