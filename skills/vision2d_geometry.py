"""The lidar geometry of Verify2DObject: clusters of a 2D scan, robust circle fits, circles of the sample radius.

Pure numpy and scipy, no skill and no world: :func:`detect_circles` turns a
scan (ranges, ray angles, the scanner's pose) into :class:`Circle` s, nearest
first. :mod:`alica.skills.vision2d` runs it in :class:`~alica.skills.vision2d.DetectCircles`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Circle", "detect_circles", "fit_circle", "segment_scan"]


@dataclass(frozen=True, slots=True)
class Circle:
    """A circle of the sample radius found in a scan.

    Attributes:
        x: centre in the world, metres.
        y: centre in the world, metres.
        radius: the estimated radius (silhouette width and circle fit combined), metres.
        range: distance of the centre from the scanner, metres.
        bearing: direction of the centre relative to the robot's heading, radians.
        points: scan points in the cluster.
        fit_radius: the radius of the free least-squares circle fit (NaN with fewer than 4 points).
    """

    x: float
    y: float
    radius: float
    range: float
    bearing: float
    points: int
    fit_radius: float


def segment_scan(ranges: np.ndarray, max_range: float, jump: float = 0.05) -> list[np.ndarray]:
    """Clusters of consecutive hits: index arrays, split where the range jumps by more than ``jump`` metres.

    Readings at ``max_range`` or beyond (no hit) end a cluster; a cluster that
    wraps around the end of the scan is joined with the one at its start.
    """
    ranges = np.asarray(ranges, dtype=float)
    n = len(ranges)
    hit = ranges < max_range - 1e-6
    clusters: list[list[int]] = []
    current: list[int] = []
    for i in range(n):
        if not hit[i]:
            if current:
                clusters.append(current)
            current = []
            continue
        if current and abs(ranges[i] - ranges[current[-1]]) > jump:
            clusters.append(current)
            current = []
        current.append(i)
    if current:
        clusters.append(current)
    if (
        len(clusters) > 1
        and clusters[0][0] == 0
        and clusters[-1][-1] == n - 1
        and abs(ranges[0] - ranges[n - 1]) <= jump
    ):
        clusters[0] = clusters.pop() + clusters[0]
    return [np.asarray(c, dtype=int) for c in clusters]


def _circle_through(p: np.ndarray) -> tuple[float, float, float] | None:
    """The circle through three points, or None when they are (nearly) collinear."""
    (x1, y1), (x2, y2), (x3, y3) = p
    d = 2.0 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
    if abs(d) < 1e-12:
        return None
    s1, s2, s3 = x1 * x1 + y1 * y1, x2 * x2 + y2 * y2, x3 * x3 + y3 * y3
    cx = (s1 * (y2 - y3) + s2 * (y3 - y1) + s3 * (y1 - y2)) / d
    cy = (s1 * (x3 - x2) + s2 * (x1 - x3) + s3 * (x2 - x1)) / d
    return cx, cy, math.hypot(x1 - cx, y1 - cy)


def _kasa(points: np.ndarray) -> tuple[float, float, float] | None:
    """Algebraic (Kasa) least-squares circle: solve ``x^2 + y^2 + D x + E y + F = 0``."""
    a = np.column_stack([points, np.ones(len(points))])
    b = -(points**2).sum(axis=1)
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    d, e, f = sol
    r2 = 0.25 * (d * d + e * e) - f
    if not (np.isfinite(r2) and r2 > 0.0):
        return None
    return float(-0.5 * d), float(-0.5 * e), float(math.sqrt(r2))


def fit_circle(
    points: np.ndarray,
    *,
    threshold: float,
    rng: np.random.Generator,
    iterations: int = 60,
    radius: float | None = None,
) -> tuple[float, float, float, np.ndarray] | None:
    """A robust circle fit: RANSAC over circles through three points, then a geometric least-squares refinement.

    Args:
        points: ``(n, 2)`` points, ``n >= 3``.
        threshold: largest distance in metres of an inlier from the circle.
        rng: the generator of the RANSAC samples (seeded: the fit is repeatable).
        iterations: RANSAC samples.
        radius: when given, only circles within ``3 * threshold`` of it are hypotheses.

    Returns:
        ``(cx, cy, r, inliers)`` or None when no circle has three inliers.
    """
    from scipy.optimize import least_squares

    n = len(points)
    if n < 3:
        return None
    best: np.ndarray | None = None
    for _ in range(iterations if n > 3 else 1):
        pick = rng.choice(n, 3, replace=False) if n > 3 else np.arange(3)
        circle = _circle_through(points[pick])
        if circle is None:
            continue
        if radius is not None and abs(circle[2] - radius) > 3.0 * threshold:
            continue
        d = np.abs(np.hypot(points[:, 0] - circle[0], points[:, 1] - circle[1]) - circle[2])
        inliers = d <= threshold
        if best is None or inliers.sum() > best.sum():
            best = inliers
    if best is None or best.sum() < 3:
        return None
    inl = points[best]
    start = _kasa(inl)
    if start is None:
        return None

    def residual(c: np.ndarray) -> np.ndarray:
        return np.hypot(inl[:, 0] - c[0], inl[:, 1] - c[1]) - c[2]

    sol = least_squares(residual, np.asarray(start), method="lm" if len(inl) >= 3 else "trf")
    cx, cy, r = (float(v) for v in sol.x)
    return cx, cy, abs(r), best


def _fixed_radius_centre(points: np.ndarray, origin: np.ndarray, radius: float) -> np.ndarray:
    """The centre of a circle of known ``radius`` through ``points`` seen from ``origin`` (least squares)."""
    from scipy.optimize import least_squares

    mean = points.mean(axis=0)
    away = mean - origin
    away /= max(float(np.linalg.norm(away)), 1e-9)
    start = mean + radius * away

    def residual(c: np.ndarray) -> np.ndarray:
        return np.hypot(points[:, 0] - c[0], points[:, 1] - c[1]) - radius

    if len(points) < 2:
        return start
    sol = least_squares(residual, start, method="trf")
    centre = np.asarray(sol.x, dtype=float)
    # the centre lies behind the points as seen from the scanner
    if float(np.dot(centre - mean, away)) < 0.0:
        centre = start
    return centre


def _radius_error(points: np.ndarray, cx: float, cy: float, sigma: float) -> float:
    """Standard error of a geometric circle fit's radius: ``sigma`` times the root of (J^T J)^-1 at the fit.

    A short arc of a few points leaves the radius nearly free (a large error),
    so the fit then hardly constrains the acceptance and the estimate.
    """
    d = np.maximum(np.hypot(points[:, 0] - cx, points[:, 1] - cy), 1e-9)
    jac = np.column_stack([-(points[:, 0] - cx) / d, -(points[:, 1] - cy) / d, -np.ones(len(points))])
    cov = np.linalg.pinv(jac.T @ jac)
    return float(sigma * math.sqrt(max(float(cov[2, 2]), 0.0)))


def detect_circles(
    ranges: np.ndarray,
    angles: np.ndarray,
    pose: tuple[float, float, float],
    *,
    radius: float,
    tolerance: float,
    max_range: float,
    scan_range: float,
    sigma: float = 0.01,
    min_points: int = 2,
    jump: float = 0.05,
    seed: int = 0,
) -> list[Circle]:
    """Circles of ``radius`` (within ``tolerance``) in a 2D scan, nearest first.

    Each cluster of :func:`segment_scan` is measured twice: its silhouette
    width across the bearing gives a radius whose error is at most half the
    spacing of two rays at that range (so the tolerance grows by that much),
    and, with four points or more, a robust circle fit (:func:`fit_circle`)
    gives another, accepted within ``tolerance`` plus three times its
    standard error. Clusters much wider than a sample (rocks, robots, walls)
    fail the first test. The centre is the least-squares centre of a circle
    of the nominal radius through the cluster.

    Args:
        ranges: the scan's ranges, metres.
        angles: the rays' angles relative to the heading (:func:`alica.worldsim.sensors.lidar_angles`).
        pose: the scanner's ``(x, y, yaw)``.
        radius: the sample radius, metres.
        tolerance: allowed radius error, metres.
        max_range: farthest centre to report, metres.
        scan_range: the scanner's maximum range (a reading at it is no hit).
        sigma: the scanner's range noise, metres (the inlier threshold of the fit).
        min_points: fewest points in a cluster.
        jump: a range jump that splits two clusters, metres.
        seed: seeds the RANSAC samples.
    """
    ranges = np.asarray(ranges, dtype=float)
    angles = np.asarray(angles, dtype=float)
    x0, y0, yaw = pose
    origin = np.array([x0, y0])
    step = float(2.0 * math.pi / len(ranges)) if len(ranges) else 0.0
    rng = np.random.default_rng(seed)
    out: list[Circle] = []
    for idx in segment_scan(ranges, scan_range, jump):
        if len(idx) < min_points:
            continue
        r_i, a_i = ranges[idx], yaw + angles[idx]
        near = float(r_i.min())
        if near > max_range + radius:
            continue
        spacing = near * step
        # the silhouette: angular extent of the cluster, widened by one ray spacing (the rays hit inside it)
        span = float(np.unwrap(a_i)[-1] - np.unwrap(a_i)[0])
        silhouette = 0.5 * (near * abs(span) + spacing)
        if abs(silhouette - radius) > tolerance + 0.5 * spacing:
            continue
        points = np.column_stack([x0 + r_i * np.cos(a_i), y0 + r_i * np.sin(a_i)])
        fit_r = math.nan
        estimate = silhouette
        if len(points) >= 4:
            fit = fit_circle(points, threshold=max(2.5 * sigma, 0.005), rng=rng, radius=None)
            if fit is not None:
                fit_r = fit[2]
                err = _radius_error(points[fit[3]], fit[0], fit[1], sigma)
                if abs(fit_r - radius) > tolerance + 3.0 * err:
                    continue
                w_fit, w_sil = 1.0 / max(err, 1e-4) ** 2, 12.0 / max(spacing, 1e-4) ** 2
                estimate = (w_fit * fit_r + w_sil * silhouette) / (w_fit + w_sil)
        centre = _fixed_radius_centre(points, origin, radius)
        d = float(np.hypot(*(centre - origin)))
        if d > max_range:
            continue
        bearing = math.atan2(centre[1] - y0, centre[0] - x0) - yaw
        bearing = (bearing + math.pi) % (2.0 * math.pi) - math.pi
        out.append(Circle(float(centre[0]), float(centre[1]), float(estimate), d, bearing, len(idx), fit_r))
    out.sort(key=lambda c: c.range)
    return out
