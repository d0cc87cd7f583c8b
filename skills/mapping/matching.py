"""Scan matching: the pose at which a lidar scan fits a map best (ICP on a KD-tree).

:func:`match_scan` aligns the scan's hit points with the centres of the
map's occupied cells near the pose estimate by point-to-point ICP
(``scipy.spatial.cKDTree`` for the nearest cells, the closed-form rigid fit
of the matched pairs per iteration, a correspondence gate shrinking from
``gate`` to two cells so that points of things the map does not know, such as
other robots, drop out). Before ICP a small search over headings around the
estimate picks the start with the most points close to the map, which
catches heading errors of a few degrees that plain ICP could slide past.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from alica.skills.mapping.grid import LogOddsGrid

__all__ = ["Match", "compose", "match_scan", "relative", "scan_points"]


@dataclass(frozen=True, slots=True)
class Match:
    """The result of :func:`match_scan`.

    Attributes:
        pose: the corrected ``(x, y, yaw)`` of the scan.
        ok: whether the fit is trustworthy (enough inliers, small residual, a plausible correction).
        inliers: the fraction of the scan's hits within two cells of an occupied map cell at ``pose``.
        rmse: root mean square distance (m) of the inlier pairs.
        points: the scan's hits used.
        reason: why the fit is not trusted (empty when ``ok``).
    """

    pose: tuple[float, float, float]
    ok: bool
    inliers: float
    rmse: float
    points: int
    reason: str = ""


def scan_points(ranges: np.ndarray, angles: np.ndarray, max_range: float) -> np.ndarray:
    """The hits of a scan as ``(N, 2)`` points in the scanner's frame (readings at ``max_range`` are no hits)."""
    r = np.asarray(ranges, dtype=float).reshape(-1)
    a = np.asarray(angles, dtype=float).reshape(-1)
    hit = np.isfinite(r) & (r < max_range)
    return np.column_stack([r[hit] * np.cos(a[hit]), r[hit] * np.sin(a[hit])])


def _transform(points: np.ndarray, pose: Sequence[float]) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return np.column_stack(
        [pose[0] + c * points[:, 0] - s * points[:, 1], pose[1] + s * points[:, 0] + c * points[:, 1]]
    )


def compose(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float]:
    """The pose ``a * b`` (``b`` expressed in ``a``'s frame)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    yaw = math.atan2(math.sin(a[2] + b[2]), math.cos(a[2] + b[2]))
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], yaw)


def relative(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float]:
    """The pose of ``b`` in ``a``'s frame (``a^-1 * b``): the motion from ``a`` to ``b``."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    dyaw = math.atan2(math.sin(b[2] - a[2]), math.cos(b[2] - a[2]))
    return (c * dx + s * dy, -s * dx + c * dy, dyaw)


def _rigid_fit(src: np.ndarray, dst: np.ndarray) -> tuple[float, float, float]:
    """The rigid motion ``(tx, ty, theta)`` taking ``src`` onto ``dst`` in the least-squares sense."""
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - ms, dst - md
    sxx = float((a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]).sum())
    sxy = float((a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum())
    theta = math.atan2(sxy, sxx)
    c, s = math.cos(theta), math.sin(theta)
    return (float(md[0] - (c * ms[0] - s * ms[1])), float(md[1] - (s * ms[0] + c * ms[1])), theta)


def match_scan(
    grid: LogOddsGrid,
    estimate: Sequence[float],
    ranges: np.ndarray,
    angles: np.ndarray,
    max_range: float,
    *,
    gate: float = 1.0,
    max_correction: float = 2.0,
    min_inliers: float = 0.5,
    min_points: int = 20,
    iterations: int = 30,
) -> Match:
    """Align a scan taken at about ``estimate`` with the occupied cells of ``grid``.

    Args:
        grid: the map (e.g. :func:`~alica.skills.mapping.sharing.team_map`).
        estimate: ``(x, y, yaw)`` the robot believes it scanned from.
        ranges: the scan's ranges; angles: the rays' angles relative to the heading.
        max_range: readings at or beyond it are no hits.
        gate: the first correspondence distance in metres (the largest error ICP can pull in).
        max_correction: a fit that moves the estimate further than this (m) is not trusted.
        min_inliers: the smallest fraction of hits that must lie on the map.
        min_points: the fewest hits (in the scan and occupied cells near it) to try.
        iterations: ICP iterations at most.

    Returns:
        The :class:`Match`; ``ok`` tells whether to use it.
    """
    est = (float(estimate[0]), float(estimate[1]), float(estimate[2]))
    pts = scan_points(ranges, angles, max_range)
    if len(pts) < min_points:
        return Match(est, False, 0.0, math.inf, len(pts), f"only {len(pts)} lidar hits: nothing to match")
    occupied = grid.occupied_points()
    reach = max_range + gate + max_correction
    if len(occupied):
        near = np.abs(occupied - np.array(est[:2])).max(axis=1) <= reach
        occupied = occupied[near]
    if len(occupied) < min_points:
        return Match(est, False, 0.0, math.inf, len(pts), f"the map has only {len(occupied)} occupied cells in reach")
    tree = cKDTree(occupied)
    tight = 2.0 * grid.resolution
    # a coarse heading search: the start that puts most hits near the map
    best, best_score = est, -1
    for dyaw in np.radians([0.0, -1.5, 1.5, -3.0, 3.0, -5.0, 5.0]):
        start = (est[0], est[1], est[2] + float(dyaw))
        d, _ = tree.query(_transform(pts, start), distance_upper_bound=0.5 * gate)
        score = int(np.isfinite(d).sum())
        if score > best_score:
            best, best_score = start, score
    pose = best
    for k in range(iterations):
        g = max(tight, gate * (0.6**k))
        world = _transform(pts, pose)
        d, idx = tree.query(world, distance_upper_bound=g)
        inl = np.isfinite(d)
        if inl.sum() < min_points // 2 + 3:
            break
        tx, ty, th = _rigid_fit(world[inl], occupied[idx[inl]])
        pose = compose((tx, ty, th), pose)
        if math.hypot(tx, ty) < 1e-4 and abs(th) < 1e-5 and g <= tight:
            break
    d, _ = tree.query(_transform(pts, pose), distance_upper_bound=tight)
    inl = np.isfinite(d)
    frac = float(inl.mean())
    rmse = float(np.sqrt(np.mean(d[inl] ** 2))) if inl.any() else math.inf
    moved = math.hypot(pose[0] - est[0], pose[1] - est[1])
    reason = ""
    if frac < min_inliers:
        reason = f"only {frac:.0%} of the hits lie on the map (need {min_inliers:.0%})"
    elif moved > max_correction:
        reason = f"the fit moves the estimate {moved:.2f} m (more than {max_correction} m)"
    return Match(pose, not reason, frac, rmse, len(pts), reason)
