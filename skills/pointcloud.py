"""Point-cloud geometry for semantic perception: ground plane, clusters, cylinder fits, fuzzy rating.

Pure numpy and scipy, no simulator: the skills of
:mod:`alica.skills.semantic_perception` call these on the cloud rendered from a
robot's depth image, and the tests call them on synthetic clouds with known answers.

* :func:`ransac_plane`: a RANSAC plane fit (three-point hypotheses from a
  seeded generator, scored on a subsample, refined by least squares on all inliers);
* :func:`euclidean_clusters`: Euclidean clustering by region growing over a
  ``cKDTree`` (points closer than the tolerance are neighbours; clusters are
  the connected components), after a voxel grid of half the tolerance thins
  dense near-range clouds;
* :func:`fit_cylinder`: an upright-or-tilted cylinder per cluster: axis from
  the plane normal or PCA, radius by a circle fit of the points projected
  along the axis, height and base gap from the plane, tilt of the axis, and
  the silhouette width seen from the camera;
* :class:`Trapezoid` and :class:`FuzzyConcept`: trapezoidal membership
  functions and a fuzzy concept (one membership per feature, combined by a
  t-norm), the fuzzy description FuzzyDL would hold (:data:`KNOWLEDGE_BASES`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "KNOWLEDGE_BASES",
    "TNORMS",
    "CylinderFit",
    "FuzzyConcept",
    "Plane",
    "Trapezoid",
    "circle_fit",
    "euclidean_clusters",
    "fit_cylinder",
    "ransac_plane",
]


@dataclass(frozen=True)
class Plane:
    """A plane ``normal . p + offset = 0`` with a unit ``normal``.

    Attributes:
        normal: unit normal, shape ``(3,)``.
        offset: the plane's signed offset.
        inliers: number of points within the threshold when it was fitted.
    """

    normal: np.ndarray
    offset: float
    inliers: int = 0

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distances of ``(n, 3)`` points (positive on the normal's side)."""
        return np.asarray(points, dtype=float) @ self.normal + self.offset

    def tilt(self) -> float:
        """Angle in radians between the normal and the world's up axis."""
        return math.acos(min(1.0, abs(float(self.normal[2]))))


def _plane_through(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Normals ``(k, 3)`` (unit, zero where degenerate) and offsets of planes through point triples ``(k, 3, 3)``."""
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    norm = np.linalg.norm(n, axis=1)
    ok = norm > 1e-12
    n[ok] /= norm[ok, None]
    n[~ok] = 0.0
    return n, -np.einsum("ij,ij->i", n, p[:, 0])


def _refine(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares plane through points: (unit normal, offset)."""
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    normal = vt[2]
    return normal, -float(normal @ centre)


def ransac_plane(
    points: np.ndarray,
    rng: np.random.Generator,
    *,
    threshold: float = 0.02,
    iterations: int = 500,
    max_tilt: float = math.radians(30.0),
    sample_size: int = 4000,
    up: np.ndarray | None = None,
) -> tuple[Plane, np.ndarray] | None:
    """The dominant plane of a cloud by RANSAC, and its inlier mask.

    Hypotheses are planes through three random points whose normal is within
    ``max_tilt`` of the world's up axis (the ground, not a rock's face); each
    is scored by its inliers (distance below ``threshold``) among a random
    subsample of ``sample_size`` points; the best is refined by a
    least-squares fit to all its inliers (twice). The normal is turned towards
    ``up`` (default ``+z``).

    Returns:
        ``(plane, inlier mask)``, or ``None`` when the cloud has fewer than three
        points or no hypothesis fits.
    """
    pts = np.asarray(points, dtype=float)
    n = len(pts)
    if n < 3:
        return None
    up_axis = np.array([0.0, 0.0, 1.0]) if up is None else np.asarray(up, dtype=float)
    scoring = pts if n <= sample_size else pts[rng.choice(n, sample_size, replace=False)]
    triples = pts[rng.integers(0, n, (iterations, 3))]
    normals, offsets = _plane_through(triples)
    cos_tilt = np.abs(normals @ up_axis)
    valid = cos_tilt >= math.cos(max_tilt)
    if not valid.any():
        return None
    normals, offsets = normals[valid], offsets[valid]
    best, best_count = -1, -1
    chunk = max(1, 2_000_000 // max(1, len(scoring)))  # bounded memory: hypotheses x points per block
    for start in range(0, len(normals), chunk):
        d = np.abs(scoring @ normals[start : start + chunk].T + offsets[start : start + chunk])
        counts = (d < threshold).sum(axis=0)
        k = int(np.argmax(counts))
        if counts[k] > best_count:
            best, best_count = start + k, int(counts[k])
    normal, offset = normals[best], float(offsets[best])
    mask = np.abs(pts @ normal + offset) < threshold
    for _ in range(2):
        if mask.sum() < 3:
            break
        refined_normal, refined_offset = _refine(pts[mask])
        if abs(float(refined_normal @ up_axis)) < math.cos(max_tilt):
            break
        normal, offset = refined_normal, refined_offset
        mask = np.abs(pts @ normal + offset) < threshold
    if float(normal @ up_axis) < 0.0:
        normal, offset = -normal, -offset
    return Plane(normal, offset, int(mask.sum())), mask


def euclidean_clusters(points: np.ndarray, tolerance: float, min_points: int = 1) -> list[np.ndarray]:
    """Indices of the clusters of a cloud: points closer than ``tolerance`` are neighbours.

    Region growing over a ``scipy.spatial.cKDTree``: the clusters are the
    connected components of the neighbour graph. Points are first gathered
    into voxels of ``tolerance / 2`` (points in one voxel are always
    neighbours), and voxels whose centroids are within ``tolerance`` are
    joined, so a dense cloud costs no more than its voxels. Clusters of fewer
    than ``min_points`` points are dropped; the rest come largest first (ties
    by lowest index).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pts = np.asarray(points, dtype=float)
    if len(pts) == 0:
        return []
    keys = np.floor(pts / (0.5 * tolerance)).astype(np.int64)
    _, voxel_of, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    voxel_of = voxel_of.reshape(-1)
    sums = np.zeros((len(counts), 3))
    np.add.at(sums, voxel_of, pts)
    centroids = sums / counts[:, None]
    pairs = cKDTree(centroids).query_pairs(tolerance, output_type="ndarray")
    graph = coo_matrix(
        (np.ones(len(pairs), dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(len(counts), len(counts))
    )
    _, component = connected_components(graph, directed=False)
    labels = component[voxel_of]
    sizes = np.bincount(labels)
    order = sorted((label for label in range(len(sizes)) if sizes[label] >= min_points), key=lambda c: -sizes[c])
    clusters = [np.flatnonzero(labels == label) for label in order]
    clusters.sort(key=lambda idx: (-len(idx), int(idx[0])))
    return clusters


def circle_fit(xy: np.ndarray) -> tuple[float, float, float, float]:
    """A circle through 2-D points: ``(cx, cy, radius, rms residual)``.

    The algebraic (Kåsa) fit, refined by Gauss-Newton steps on the geometric
    distances. Fewer than three points or collinear points give ``nan``.
    """
    p = np.asarray(xy, dtype=float)
    if len(p) < 3:
        return math.nan, math.nan, math.nan, math.nan
    mean = p.mean(axis=0)
    q = p - mean
    a = np.column_stack([q, np.ones(len(q))])
    b = (q**2).sum(axis=1)
    try:
        sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    except np.linalg.LinAlgError:
        return math.nan, math.nan, math.nan, math.nan
    c = sol[:2] / 2.0
    r2 = sol[2] + c @ c
    if not (np.isfinite(r2) and r2 > 0.0):
        return math.nan, math.nan, math.nan, math.nan
    r = math.sqrt(r2)
    for _ in range(10):  # Gauss-Newton on sum (|p - c| - r)^2
        diff = q - c
        dist = np.linalg.norm(diff, axis=1)
        dist = np.where(dist < 1e-12, 1e-12, dist)
        jac = np.column_stack([-diff / dist[:, None], -np.ones(len(q))])
        res = dist - r
        step, *_ = np.linalg.lstsq(jac, -res, rcond=None)
        c = c + step[:2]
        r = r + step[2]
        if float(np.abs(step).max()) < 1e-9:
            break
    rms = float(np.sqrt(np.mean((np.linalg.norm(q - c, axis=1) - abs(r)) ** 2)))
    centre = c + mean
    return float(centre[0]), float(centre[1]), abs(float(r)), rms


@dataclass(frozen=True)
class CylinderFit:
    """A cylinder fitted to one cluster, with the features the fuzzy rating reads.

    Attributes:
        centre: the axis' foot on the ground plane, world metres ``(x, y, z)``.
        axis: unit axis direction (upwards).
        radius: radius of the circle fit of the points projected along the axis, metres.
        height: top of the cluster above the ground plane, metres (98th percentile).
        tilt: angle in degrees between the silhouette's main axis and the plane normal: 0 for an
            upright slender object, 90 for one lying, or wider than tall (a rock).
        base_gap: bottom of the cluster above the plane, metres (2nd percentile): about
            the RANSAC threshold for an object standing on the ground.
        width: the silhouette width across the line of sight, metres (4th to 96th percentile).
        rms: root-mean-square residual of the circle fit, metres.
        points: the number of points in the cluster.
        truncated: the cluster touches the image border (the object may be cut off).
    """

    centre: np.ndarray
    axis: np.ndarray
    radius: float
    height: float
    tilt: float
    base_gap: float
    width: float
    rms: float
    points: int
    truncated: bool = False

    def features(self) -> dict[str, float]:
        """The features by name: radius, height, tilt, base_gap, width, truncated (0 or 1)."""
        return {
            "radius": self.radius,
            "height": self.height,
            "tilt": self.tilt,
            "base_gap": self.base_gap,
            "width": self.width,
            "truncated": 1.0 if self.truncated else 0.0,
        }


def _basis(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors orthogonal to ``axis`` and to each other."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(axis, e1)


def fit_cylinder(
    points: np.ndarray,
    plane: Plane,
    viewpoint: np.ndarray,
    *,
    truncated: bool = False,
    axis_from: str = "plane",
) -> CylinderFit | None:
    """Fit a cylinder to a cluster standing on ``plane``, seen from ``viewpoint``.

    The tilt is measured on the silhouette: the angle from the plane normal of
    the principal axis of the points
    in the plane across the line of sight (spanned by the plane normal and the
    horizontal perpendicular to the view), where a stereo camera's depth error
    (along the line of sight) does not reach; an object wider than tall has
    its main axis across, a tilt near 90 degrees. ``axis_from="plane"`` takes the
    cylinder axis along the plane normal (drill samples stand upright);
    ``"pca"`` takes the cluster's principal axis in 3-D. The radius is a
    circle fit of the points projected along the axis; the height and the
    base gap are distances from the plane; the width is the silhouette's
    extent across the line of sight.

    Returns:
        The fit, or ``None`` for fewer than five points.
    """
    pts = np.asarray(points, dtype=float)
    if len(pts) < 5:
        return None
    up = plane.normal
    heights = plane.distance(pts)
    centroid = pts.mean(axis=0)
    view = centroid - np.asarray(viewpoint, dtype=float)
    view_flat = view - (view @ up) * up
    if np.linalg.norm(view_flat) < 1e-9:
        view_flat = _basis(up)[0]
    view_flat = view_flat / np.linalg.norm(view_flat)
    across = np.cross(up, view_flat)
    # silhouette: coordinates across the line of sight and up
    sil = np.column_stack([(pts - centroid) @ across, heights])
    sil = sil - sil.mean(axis=0)
    _, vecs = np.linalg.eigh(np.cov(sil.T))
    major = vecs[:, 1]
    tilt = math.degrees(math.acos(min(1.0, abs(float(major[1])))))
    lo_w, hi_w = np.percentile(sil[:, 0], [4.0, 96.0])
    width = float(hi_w - lo_w)
    if axis_from == "pca":
        _, _, vt = np.linalg.svd(pts - centroid, full_matrices=False)
        axis = vt[0] if float(vt[0] @ up) >= 0.0 else -vt[0]
    else:
        axis = up
    e1, e2 = _basis(axis)
    rel = pts - centroid
    cx, cy, radius, rms = circle_fit(np.column_stack([rel @ e1, rel @ e2]))
    if not math.isfinite(radius):
        return None
    foot = centroid + cx * e1 + cy * e2
    foot = foot - plane.distance(foot[None, :])[0] * up
    lo, hi = np.percentile(heights, [2.0, 98.0])
    return CylinderFit(
        centre=foot,
        axis=axis,
        radius=radius,
        height=float(hi),
        tilt=tilt,
        base_gap=float(lo),
        width=width,
        rms=rms,
        points=len(pts),
        truncated=truncated,
    )


@dataclass(frozen=True)
class Trapezoid:
    """A trapezoidal membership function: 0 below ``a``, rising to 1 at ``b``, 1 up to ``c``, 0 from ``d``.

    ``a == b`` (or ``c == d``) makes a crisp edge: a left (right) shoulder.
    """

    a: float
    b: float
    c: float
    d: float

    def __post_init__(self) -> None:
        if not (self.a <= self.b <= self.c <= self.d):
            raise ValueError(f"a trapezoid needs a <= b <= c <= d, got {self.a}, {self.b}, {self.c}, {self.d}")

    def __call__(self, x: float) -> float:
        if not math.isfinite(x) or x < self.a or x > self.d:
            return 0.0
        if x < self.b:
            return (x - self.a) / (self.b - self.a)
        if x <= self.c:
            return 1.0
        if x < self.d:
            return (self.d - x) / (self.d - self.c)
        return 1.0 if self.c == self.d else 0.0  # x == d: the top of a crisp right edge, or the foot of a slope


def _goedel(a: float, b: float) -> float:
    return min(a, b)


def _product(a: float, b: float) -> float:
    return a * b


def _lukasiewicz(a: float, b: float) -> float:
    return max(0.0, a + b - 1.0)


#: t-norms (fuzzy conjunctions) by name: Goedel (Zadeh) minimum, product, Lukasiewicz.
TNORMS: dict[str, Callable[[float, float], float]] = {"min": _goedel, "product": _product, "lukasiewicz": _lukasiewicz}


@dataclass(frozen=True)
class FuzzyConcept:
    """A fuzzy concept: the conjunction (a t-norm) of memberships of named features.

    Attributes:
        name: the concept's name.
        memberships: feature name -> membership function.
        doc: what it describes.
    """

    name: str
    memberships: Mapping[str, Trapezoid] = field(default_factory=dict)
    doc: str = ""

    def degrees(self, features: Mapping[str, float]) -> dict[str, float]:
        """The membership degree of every feature of the concept (a missing feature has degree 0)."""
        return {f: m(float(features.get(f, math.nan))) for f, m in self.memberships.items()}

    def degree(self, features: Mapping[str, float], tnorm: str = "min") -> float:
        """How far the features satisfy the concept: the t-norm of the memberships."""
        combine = TNORMS[tnorm]
        value = 1.0
        for d in self.degrees(features).values():
            value = combine(value, d)
        return float(value)


#: The fuzzy descriptions FuzzyDLClassify rates against, by ``knowledge_base`` name.
#: ``drill_sample``: the IMPERA sample container (radius 0.03 m, height 0.1 m),
#: upright, standing on the ground, wholly in the picture. The radius and width
#: memberships are wide because a stereo cloud of a 6 cm object is noisy.
KNOWLEDGE_BASES: dict[str, FuzzyConcept] = {
    "drill_sample": FuzzyConcept(
        "drill_sample",
        {
            "radius": Trapezoid(0.008, 0.018, 0.05, 0.075),
            "width": Trapezoid(0.025, 0.04, 0.085, 0.11),
            "height": Trapezoid(0.06, 0.08, 0.125, 0.15),
            "tilt": Trapezoid(0.0, 0.0, 20.0, 40.0),
            "base_gap": Trapezoid(-1.0, -1.0, 0.04, 0.07),
            "truncated": Trapezoid(-1.0, -1.0, 0.0, 1.0),
        },
        "an upright cylinder of radius 3 cm and height 10 cm standing on the ground, wholly in view",
    ),
}
