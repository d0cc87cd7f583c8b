"""SemanticPerception (IMPERA Section 6.4.2, Figs. 9-10): drill samples in a stereo point cloud.

Five skills, one per state of ``plans/skills/semantic_perception.yaml``, hand
their data on through the agent's scratch space (``context.scratch``):

=====================  ===========================  ==================================================
skill                  reads                        writes
=====================  ===========================  ==================================================
``StereoPointCloud``   the robot's depth image      ``scratch["cloud"]``: a :class:`PointCloud`
``RansacGroundPlane``  ``"cloud"``                  ``"plane"`` (:class:`~alica.skills.pointcloud.Plane`)
                                                    and ``"above_ground"`` (the cloud without the plane)
``EuclideanCluster``   ``"above_ground"``           ``"clusters"``: a list of :class:`PointCloud`
``FitModel``           ``"clusters"``, ``"plane"``  ``"models"``: a list of
                                                    :class:`~alica.skills.pointcloud.CylinderFit`
``FuzzyDLClassify``    ``"models"``, ``"cloud"``    ``"detections"``: a list of :class:`Detection`,
                                                    and the world model (below)
=====================  ===========================  ==================================================

Only the depth image is used: no object names, no poses of other bodies. The
points are put into the world with the camera pose derived from the robot's
pose *estimate* (``robot.estimate``: odometry corrected by Localize), not its
true pose: with odometry drift the samples land where the robot believes they are.

**Naming the samples.** Perception cannot know the simulator's names. A
detection within ``match_radius`` of a ``Sample`` the world model already
knows (an object of type ``Sample`` with ``pos(s)``, e.g. one the 2-D vision
found) is that sample; otherwise it gets a new id from its position on a
decimetre grid, ``s_<x>_<y>`` with ``m`` for a minus sign (``s_32_m15`` lies at
about (3.2, -1.5)). For each detection FuzzyDLClassify adds the id to the
objects of type ``Sample``, writes ``pos(s) = (x, y)``, ``confidence(s)`` (the
fuzzy degree) and asserts ``found(s)``. A found sample that should be in clear
view (in the picture, within ``retract_range``, not hidden behind something
nearer) but is not detected again is retracted (``found(s)`` false): a
closer look disagrees.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import py_trees
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.context import SkillContextLike
from alica.skills.jobs import DeferredJobs, Job, Jobs
from alica.skills.pointcloud import (
    KNOWLEDGE_BASES,
    TNORMS,
    CylinderFit,
    Plane,
    euclidean_clusters,
    fit_cylinder,
    ransac_plane,
)
from alica.skills.sample_facts import report_found
from alica.skills.world_skill import WorldSkill
from alica.worldmodel.protocol import WorldModelLike

#: The world-model type of the samples FuzzyDLClassify reports.
SAMPLE_TYPE = "Sample"


@dataclass(frozen=True)
class PointCloud:
    """Points from one depth image, with where they came from.

    Attributes:
        points: world points, ``(n, 3)`` metres.
        pixels: the image row and column of every point, ``(n, 2)`` ints.
        depth: the depth image they came from (metres along the optical axis, ``inf``: nothing).
        intrinsics: the camera's ``(fx, fy, cx, cy)``.
        position: the camera centre in the world.
        rotation: world-from-camera rotation (OpenCV axes).
        max_depth: points farther than this were dropped.
        time: simulated time of the picture.
    """

    points: np.ndarray
    pixels: np.ndarray
    depth: np.ndarray
    intrinsics: tuple[float, float, float, float]
    position: np.ndarray
    rotation: np.ndarray
    max_depth: float
    time: float

    def __len__(self) -> int:
        return len(self.points)

    def subset(self, index: np.ndarray) -> PointCloud:
        """The cloud of the points selected by a boolean mask or an index array."""
        return PointCloud(
            self.points[index],
            self.pixels[index],
            self.depth,
            self.intrinsics,
            self.position,
            self.rotation,
            self.max_depth,
            self.time,
        )

    def touches_border(self, margin: int = 1) -> bool:
        """Whether any point lies within ``margin`` pixels of the image border."""
        if len(self.pixels) == 0:
            return False
        h, w = self.depth.shape
        rows, cols = self.pixels[:, 0], self.pixels[:, 1]
        return bool(
            (rows < margin).any() or (cols < margin).any() or (rows >= h - margin).any() or (cols >= w - margin).any()
        )

    def project(self, point: np.ndarray) -> tuple[float, float, float]:
        """Pixel ``(u, v)`` (column, row) and depth of a world point (depth <= 0: behind the camera)."""
        p = self.rotation.T @ (np.asarray(point, dtype=float) - self.position)
        fx, fy, cx, cy = self.intrinsics
        if p[2] <= 1e-9:
            return math.nan, math.nan, float(p[2])
        return float(fx * p[0] / p[2] + cx), float(fy * p[1] / p[2] + cy), float(p[2])


def cloud_from_depth(
    depth: np.ndarray,
    intrinsics: tuple[float, float, float, float],
    position: np.ndarray,
    rotation: np.ndarray,
    max_depth: float,
    time: float = 0.0,
) -> PointCloud:
    """The :class:`PointCloud` of a depth image (pixels nearer than ``max_depth``), as ``CameraImage.points`` computes it."""
    fx, fy, cx, cy = intrinsics
    h, w = depth.shape
    rows, cols = np.mgrid[0:h, 0:w]
    keep = np.isfinite(depth) & (depth < max_depth) & (depth > 0.0)
    z = depth[keep]
    cam = np.column_stack([(cols[keep] - cx) * z / fx, (rows[keep] - cy) * z / fy, z])
    points = cam @ np.asarray(rotation).T + np.asarray(position)
    pixels = np.column_stack([rows[keep], cols[keep]]).astype(np.int32)
    return PointCloud(points, pixels, depth, intrinsics, np.asarray(position), np.asarray(rotation), max_depth, time)


@dataclass(frozen=True)
class Detection:
    """A drill sample FuzzyDLClassify found.

    Attributes:
        sample: the id written to the world model (an existing sample's or a new one).
        position: ``(x, y)`` on the ground, metres.
        confidence: the fuzzy degree of the match, in ``[0, 1]``.
        degrees: the membership degree of every feature.
        model: the cylinder fit it came from.
    """

    sample: str
    position: tuple[float, float]
    confidence: float
    degrees: Mapping[str, float]
    model: CylinderFit


def sample_id(x: float, y: float) -> str:
    """The id of a new sample at ``(x, y)``: ``s_<x>_<y>`` in decimetres, ``m`` for minus."""

    def part(v: float) -> str:
        d = round(v * 10.0)
        return f"m{-d}" if d < 0 else str(d)

    return f"s_{part(x)}_{part(y)}"


# -- parameters ------------------------------------------------------------------


def _number(skill: Any, name: str, default: float, *, low: float, high: float = math.inf, integer: bool = False) -> Any:
    value = skill.params.get(name)
    value = default if value is None else value
    kind = "a whole number" if integer else "a number"
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if ok and integer and float(value) != int(value):
        ok = False
    if not ok or not (low <= value <= high):
        bounds = f"in [{low:g}, {high:g}]" if math.isfinite(high) else f">= {low:g}"
        raise SkillError(f"skill '{skill.name}': parameter '{name}' must be {kind} {bounds}, got {value!r}")
    return int(value) if integer else float(value)


def _choice(skill: Any, name: str, default: str, choices: Mapping[str, object] | tuple[str, ...]) -> str:
    value = skill.params.get(name)
    value = default if value is None else value
    if value not in choices:
        raise SkillError(
            f"skill '{skill.name}': parameter '{name}' must be one of {', '.join(sorted(choices))}, got {value!r}"
        )
    return str(value)


# -- the pipeline's base ------------------------------------------------------------


class PipelineSkill(py_trees.behaviour.Behaviour, abc.ABC):
    """A step of the perception pipeline: reads and writes the agent's scratch space, computes in a job.

    Needs a context with ``scratch``, not a world: the geometry steps run on
    any cloud. Subclasses check their parameters in :meth:`configure` and do
    their work in :meth:`compute`, which returns ``(succeeded, message)`` or
    raises :class:`SkillError` (the skill then fails with that message).
    """

    def __init__(self, name: str, params: Mapping[str, object], context: SkillContextLike | None = None) -> None:
        super().__init__(name)
        self.params = dict(params)
        self.context = context
        self.jobs: Jobs = DeferredJobs()
        self.job: Job | None = None

    @property
    def scratch(self) -> dict[str, object]:
        """The agent's scratch space."""
        if self.context is None:
            raise SkillError(f"skill '{self.name}' has no context: call setup(context=...) first")
        return self.context.scratch

    def setup(self, **kwargs: Any) -> None:
        """Take the context and check the parameters.

        Raises:
            SkillError: no context, or a bad parameter (named in the message).
        """
        context: SkillContextLike | None = kwargs.get("context", self.context)
        if context is None:
            raise SkillError(f"skill '{self.name}' needs a skill context (with a scratch space)")
        self.context = context
        jobs = context.extra.get("jobs")
        self.jobs = jobs if isinstance(jobs, Jobs) else DeferredJobs()
        self.configure()

    def configure(self) -> None:
        """Check and keep the parameters (raise :class:`SkillError` naming a bad one)."""

    @abc.abstractmethod
    def compute(self) -> tuple[bool, str]:
        """The step's work: ``(succeeded, message)``; every step defines it."""

    def need(self, key: str, kind: type, producer: str) -> Any:
        """``scratch[key]``, which ``producer`` writes.

        Raises:
            SkillError: it is missing or of the wrong type.
        """
        value = self.scratch.get(key)
        if not isinstance(value, kind):
            raise SkillError(f"skill '{self.name}': no {key!r} in the scratch space; run {producer} first")
        return value

    def initialise(self) -> None:
        """Start the work as a job."""
        self.job = self.jobs.submit(self.compute)

    def update(self) -> Status:
        """Poll the job."""
        if self.job is None:
            self.job = self.jobs.submit(self.compute)
        if not self.job.done():
            self.feedback_message = "computing"
            return Status.RUNNING
        job, self.job = self.job, None
        try:
            ok, message = job.result()
        except SkillError as exc:
            ok, message = False, str(exc)
        self.feedback_message = message
        return Status.SUCCESS if ok else Status.FAILURE

    def terminate(self, new_status: Status) -> None:
        """Forget an unfinished job."""
        if new_status == Status.INVALID:
            self.job = None


# -- 1. StereoPointCloud ---------------------------------------------------------------


class StereoPointCloud(WorldSkill):
    """The point cloud of the robot's stereo camera (its rendered depth image).

    Parameters: ``max_depth`` (metres; farther points dropped), ``width`` and
    ``height`` (pixels of the depth image), ``median`` (side in pixels of a
    median filter on the depth image, a stereo matcher's post-filter; 1: none).
    Writes ``scratch["cloud"]`` (a :class:`PointCloud`, with the camera pose of
    the robot's pose estimate and the depth image); fails when no pixel is
    nearer than ``max_depth``.
    """

    def setup(self, **kwargs: Any) -> None:
        """Find the robot and check the parameters.

        Raises:
            SkillError: no world or robot, a robot without a camera, or a bad parameter.
        """
        super().setup(**kwargs)
        if "stereo_camera" not in self.robot.spec.capabilities:  # a single camera gives no depth
            raise SkillError(
                f"skill '{self.name}': robot '{self.robot.name}' ({self.robot.spec.kind}) has no stereo camera"
            )
        self.max_depth = _number(self, "max_depth", 3.0, low=0.1, high=100.0)
        self.width = _number(self, "width", 640, low=8, high=4096, integer=True)
        self.height = _number(self, "height", 480, low=8, high=4096, integer=True)
        self.median = _number(self, "median", 3, low=1, high=15, integer=True)
        self.job: Job | None = None

    def _capture(self) -> tuple[bool, str]:

        # taken where the robot is, placed in the world by the camera pose of its pose estimate
        image = self.robot.camera(
            width=self.width,
            height=self.height,
            far=self.max_depth + 0.5,
            believed=True,
        )
        depth = image.depth
        if self.median > 1:
            from scipy.ndimage import median_filter

            finite = np.isfinite(depth)
            filled = np.where(finite, depth, 1e6)
            depth = median_filter(filled, size=self.median, mode="nearest")
            depth[(depth >= 1e5) | ~finite] = math.inf
        cloud = cloud_from_depth(depth, image.intrinsics, image.position, image.rotation, self.max_depth, image.time)
        self.context.scratch["cloud"] = cloud  # type: ignore[union-attr]
        if len(cloud) == 0:
            return False, f"no point nearer than {self.max_depth:g} m"
        return True, f"{len(cloud)} points within {self.max_depth:g} m"

    def initialise(self) -> None:
        """Take the picture in a job."""
        self.job = self.jobs.submit(self._capture)

    def update(self) -> Status:
        """Poll the job."""
        if self.job is None:
            self.job = self.jobs.submit(self._capture)
        if not self.job.done():
            return self.running("capturing")
        job, self.job = self.job, None
        ok, message = job.result()
        return self.succeed(message) if ok else self.fail(message)


# -- 2. RansacGroundPlane -----------------------------------------------------------------


class RansacGroundPlane(PipelineSkill):
    """Fit the ground plane to ``scratch["cloud"]`` by RANSAC and remove its points.

    Parameters: ``distance_threshold`` (metres), ``iterations``, ``max_tilt``
    (degrees between the plane's normal and up), ``min_inliers`` (fraction of
    the cloud the plane must hold). Writes ``scratch["plane"]`` and
    ``scratch["above_ground"]`` (the points more than the threshold above the
    plane); fails when no plane is found. The generator is seeded from the
    context's (``context.rng``).
    """

    def configure(self) -> None:
        """Check the parameters."""
        self.threshold = _number(self, "distance_threshold", 0.02, low=1e-4, high=1.0)
        self.iterations = _number(self, "iterations", 500, low=1, high=100_000, integer=True)
        self.max_tilt = _number(self, "max_tilt", 30.0, low=0.0, high=90.0)
        self.min_inliers = _number(self, "min_inliers", 0.1, low=0.0, high=1.0)

    def compute(self) -> tuple[bool, str]:
        """Fit, keep the plane, remove its inliers."""
        cloud: PointCloud = self.need("cloud", PointCloud, "StereoPointCloud")
        self.scratch.pop("plane", None)
        self.scratch.pop("above_ground", None)
        assert self.context is not None
        rng = np.random.default_rng(self.context.rng.getrandbits(63))
        found = ransac_plane(
            cloud.points,
            rng,
            threshold=self.threshold,
            iterations=self.iterations,
            max_tilt=math.radians(self.max_tilt),
        )
        if found is None or found[0].inliers < max(3, self.min_inliers * len(cloud)):
            held = 0 if found is None else found[0].inliers
            return False, (
                f"no ground plane: the best plane within {self.max_tilt:g} deg of level holds {held} of "
                f"{len(cloud)} points (min_inliers {self.min_inliers:g})"
            )
        plane, _ = found
        above = plane.distance(cloud.points) >= self.threshold
        self.scratch["plane"] = plane
        self.scratch["above_ground"] = cloud.subset(above)
        return True, f"ground plane with {plane.inliers} points; {int(above.sum())} points above it"


# -- 3. EuclideanCluster ----------------------------------------------------------------------


class EuclideanCluster(PipelineSkill):
    """Cluster ``scratch["above_ground"]`` (region growing over a KD-tree).

    Parameters: ``tolerance`` (metres between neighbouring points),
    ``min_points`` (smallest cluster kept), ``max_points`` (larger clusters
    dropped, 0: no limit). Writes ``scratch["clusters"]`` (a list of
    :class:`PointCloud`, largest first); fails when there is none.
    """

    def configure(self) -> None:
        """Check the parameters."""
        self.tolerance = _number(self, "tolerance", 0.03, low=1e-4, high=10.0)
        self.min_points = _number(self, "min_points", 50, low=1, high=10**9, integer=True)
        self.max_points = _number(self, "max_points", 0, low=0, high=10**9, integer=True)

    def compute(self) -> tuple[bool, str]:
        """Cluster the points above the ground."""
        cloud: PointCloud = self.need("above_ground", PointCloud, "RansacGroundPlane")
        self.scratch["clusters"] = []
        found = euclidean_clusters(cloud.points, self.tolerance, self.min_points)
        if self.max_points:
            found = [c for c in found if len(c) <= self.max_points]
        clusters = [cloud.subset(idx) for idx in found]
        self.scratch["clusters"] = clusters
        if not clusters:
            return False, f"no cluster of at least {self.min_points} points in {len(cloud)} points above the ground"
        return True, f"{len(clusters)} clusters ({', '.join(str(len(c)) for c in clusters[:8])} points)"


# -- 4. FitModel ----------------------------------------------------------------------------------


class FitModel(PipelineSkill):
    """Fit the sample's model to every cluster of ``scratch["clusters"]`` on ``scratch["plane"]``.

    Parameters: ``model`` (``cylinder``: the drill sample's), ``axis``
    (``plane``: along the ground's normal, ``pca``: the cluster's principal
    axis). Writes ``scratch["models"]`` (a list of
    :class:`~alica.skills.pointcloud.CylinderFit`, one per cluster that could
    be fitted); fails when none could.
    """

    MODELS = ("cylinder",)

    def configure(self) -> None:
        """Check the parameters."""
        self.model = _choice(self, "model", "cylinder", self.MODELS)
        self.axis = _choice(self, "axis", "plane", ("plane", "pca"))

    def compute(self) -> tuple[bool, str]:
        """One fit per cluster."""
        clusters = self.need("clusters", list, "EuclideanCluster")
        plane: Plane = self.need("plane", Plane, "RansacGroundPlane")
        models: list[CylinderFit] = []
        for cluster in clusters:
            fit = fit_cylinder(
                cluster.points, plane, cluster.position, truncated=cluster.touches_border(), axis_from=self.axis
            )
            if fit is not None:
                models.append(fit)
        self.scratch["models"] = models
        if not models:
            return False, f"no {self.model} could be fitted to {len(clusters)} clusters"
        return True, f"{len(models)} {self.model} fits"


# -- 5. FuzzyDLClassify ---------------------------------------------------------------------------


class FuzzyDLClassify(PipelineSkill):
    """Rate ``scratch["models"]`` against a fuzzy description; report the matches to the world model.

    Parameters: ``knowledge_base`` (a name of
    :data:`~alica.skills.pointcloud.KNOWLEDGE_BASES`), ``threshold`` (smallest
    degree that counts), ``tnorm`` (``min``, ``product`` or ``lukasiewicz``),
    ``match_radius`` (metres within which a detection is a sample already
    known), ``retract_range`` (metres within which a found sample in clear
    view that is not seen again is retracted; 0: never). Writes
    ``scratch["detections"]`` and the world model (see the module
    docstring); fails when nothing matches.
    """

    def configure(self) -> None:
        """Check the parameters."""
        self.concept = KNOWLEDGE_BASES[_choice(self, "knowledge_base", "drill_sample", KNOWLEDGE_BASES)]
        self.threshold = _number(self, "threshold", 0.6, low=0.0, high=1.0)
        self.tnorm = _choice(self, "tnorm", "min", tuple(TNORMS))
        self.match_radius = _number(self, "match_radius", 0.3, low=0.0, high=100.0)
        self.retract_range = _number(self, "retract_range", 2.0, low=0.0, high=100.0)

    @property
    def world_model(self) -> WorldModelLike | None:
        """The agent's world model, or None."""
        return self.context.world_model if self.context is not None else None

    def _known(self) -> list[tuple[str, tuple[float, float]]]:
        wm = self.world_model
        if wm is None:
            return []
        known = []
        for obj in wm.objects(SAMPLE_TYPE):
            pos = wm.get("pos", obj)
            if isinstance(obj, str) and isinstance(pos, (list, tuple)) and len(pos) >= 2:
                known.append((obj, (float(pos[0]), float(pos[1]))))
        return known

    def _name(self, x: float, y: float, known: list[tuple[str, tuple[float, float]]], taken: set[str]) -> str:
        best, best_d = None, self.match_radius
        for name, (kx, ky) in known:
            d = math.hypot(kx - x, ky - y)
            if d <= best_d and name not in taken:
                best, best_d = name, d
        return best if best is not None else sample_id(x, y)

    def compute(self) -> tuple[bool, str]:
        """Rate every model, write the matches, retract what a clear view disagrees with."""
        models = self.need("models", list, "FitModel")
        known = self._known()
        taken: set[str] = set()
        detections: list[Detection] = []
        for model in models:
            features = model.features()
            degree = self.concept.degree(features, self.tnorm)
            if degree < self.threshold:
                continue
            x, y = float(model.centre[0]), float(model.centre[1])
            name = self._name(x, y, known, taken)
            taken.add(name)
            detections.append(Detection(name, (x, y), degree, self.concept.degrees(features), model))
        self.scratch["detections"] = detections
        self._report(detections)
        retracted = self._retract(known, taken)
        tail = f"; retracted {', '.join(retracted)}" if retracted else ""
        if not detections:
            return False, f"no {self.concept.name} among {len(models)} models (threshold {self.threshold:g}){tail}"
        found = ", ".join(f"{d.sample} ({d.confidence:.2f})" for d in detections)
        return True, f"found {found}{tail}"

    def _report(self, detections: list[Detection]) -> None:
        wm = self.world_model
        if wm is None:
            return
        for d in detections:
            wm.add_object(d.sample, SAMPLE_TYPE)
            wm.set("pos", d.sample, value=(round(d.position[0], 3), round(d.position[1], 3)))
            wm.set("confidence", d.sample, value=round(d.confidence, 3))
            report_found(wm, d.sample, self.context.now() if self.context is not None else 0.0)

    def _retract(self, known: list[tuple[str, tuple[float, float]]], seen: set[str]) -> list[str]:
        """Retract ``found(s)`` of known samples in clear view within ``retract_range`` that were not seen."""
        wm = self.world_model
        cloud = self.scratch.get("cloud")
        if wm is None or not isinstance(cloud, PointCloud) or self.retract_range <= 0.0:
            return []
        h, w = cloud.depth.shape
        out = []
        for name, (x, y) in known:
            if name in seen or not wm.holds("found", name):
                continue
            if math.hypot(x - cloud.position[0], y - cloud.position[1]) > min(self.retract_range, cloud.max_depth):
                continue
            middle = np.array([x, y, 0.05])
            u, v, depth = cloud.project(middle)
            margin = 20
            if not (depth > 0.0 and margin <= u < w - margin and margin <= v < h - margin):
                continue  # out of the picture
            window = cloud.depth[int(v) - 2 : int(v) + 3, int(u) - 2 : int(u) + 3]
            if np.nanmin(window) < depth - 0.15:
                continue  # something nearer hides it
            wm.retract_fact("found", name)
            wm.retract_fact("onground", name)
            out.append(name)
        return out
