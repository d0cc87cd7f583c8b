"""The lidar geometry of Verify2DObject (alica.skills.vision2d_geometry): scan clusters and robust circle fits."""

from __future__ import annotations

import math

import numpy as np


def test_segment_scan_splits_at_jumps_and_joins_around_the_end():
    from alica.skills.vision2d_geometry import segment_scan

    ranges = np.array([1.0, 1.01, 30.0, 2.0, 2.02, 3.0, 3.0, 0.99])
    clusters = [c.tolist() for c in segment_scan(ranges, 30.0, jump=0.1)]
    assert clusters == [[7, 0, 1], [3, 4], [5, 6]]


def test_fit_circle_finds_the_circle_among_outliers():
    from alica.skills.vision2d_geometry import fit_circle

    rng = np.random.default_rng(1)
    a = np.linspace(-1.2, 1.2, 30)
    points = np.column_stack([2.0 + 0.03 * np.cos(a + math.pi), 1.0 + 0.03 * np.sin(a + math.pi)])
    points += rng.normal(0, 0.001, points.shape)
    points = np.vstack([points, [[1.9, 1.1], [2.1, 0.8]]])
    cx, cy, r, inliers = fit_circle(points, threshold=0.004, rng=rng)
    assert abs(cx - 2.0) < 0.005 and abs(cy - 1.0) < 0.005 and abs(r - 0.03) < 0.004
    assert inliers.sum() >= 28 and not inliers[-1] and not inliers[-2]
