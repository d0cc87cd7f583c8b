"""Verify2DObject (IMPERA Section 6.4.3, Figs. 12-13): sample detection with a 2D laser and a directed colour camera.

Four skills in consecutive states of ``plans/skills/verify_2d_object.yaml``
hand their data on through the agent's scratch space (``context.scratch``),
as frozen dataclasses in typed slots (:mod:`alica.skills.vision2d_data`):

1. :class:`DetectCircles` segments a 2D lidar scan into clusters and keeps
   those whose circle has the sample radius (silhouette width and a robust
   RANSAC + least-squares circle fit): :class:`Candidates` in
   :data:`~alica.skills.vision2d_data.CANDIDATES`, and
   ``candidate(c)`` / ``candidate_pos(c)`` in the world model.
2. :class:`CropCandidate` renders the robot's camera, projects the nearest
   candidate in view (its footprint and height) into the image and crops it:
   a :class:`Crop` (with its :class:`Candidate`) in :data:`~alica.skills.vision2d_data.CROP`.
3. :class:`BlobDetect` finds green and red blobs in the crop (HSV thresholds,
   connected components; OpenCV): :class:`Blobs` in :data:`~alica.skills.vision2d_data.BLOBS`.
4. :class:`ClassifySample` decodes the kind from the upper and lower blobs and
   the middle section's brightness, and writes ``found(s)``, ``sample_kind(s)``,
   ``pos(s)`` and ``confidence(s)``; a candidate the closer look
   disagrees with is retracted and recorded as ``invalid(c)``.

The skills read lidar ranges and rendered pixels only (never the simulator's
object names or poses); pure functions do the work and are tested alone:
:func:`detect_circles` in :mod:`alica.skills.vision2d_geometry`,
:func:`find_blobs` and :func:`decode_sections` in :mod:`alica.skills.vision2d_image`
(all importable from here too). A step whose predecessor did not run fails
saying which step to run first.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.jobs import Job
from alica.skills.sample_facts import report_found, stale_verdicts
from alica.skills.vision2d_data import (
    BLOBS,
    CANDIDATES,
    CROP,
    MEMORY,
    VERDICT,
    Blobs,
    Candidate,
    Candidates,
    Crop,
    Memory,
    Verdict,
)
from alica.skills.vision2d_geometry import Circle, detect_circles, fit_circle, segment_scan
from alica.skills.vision2d_image import HSV_RANGES, WHITE_VALUE, Blob, decode_sections, find_blobs
from alica.skills.world_skill import WorldSkill, number_param
from alica.worldsim.interface import CameraImage

if TYPE_CHECKING:
    from alica.worldmodel.protocol import WorldModelLike

__all__ = [
    "HSV_RANGES",
    "WHITE_VALUE",
    "Blob",
    "BlobDetect",
    "Blobs",
    "Candidate",
    "Candidates",
    "Circle",
    "ClassifySample",
    "Crop",
    "CropCandidate",
    "DetectCircles",
    "Memory",
    "Verdict",
    "decode_sections",
    "detect_circles",
    "find_blobs",
    "fit_circle",
    "segment_scan",
]

#: A new detection within this many metres of a known candidate is the same candidate.
ASSOCIATION_RADIUS = 0.25
#: Height of the sample containers in metres (the projection of a candidate into the image).
SAMPLE_HEIGHT = 0.1
#: DetectCircles scans this many metres beyond its ``max_range`` (not the lidar's whole range): a
#: cluster that reaches that far is no sample within ``max_range`` (a sample's is a few centimetres long).
SCAN_MARGIN = 2.0
#: Fewest pixels a side of the part of the frame CropCandidate renders.
_MIN_PICTURE = 16
#: BlobDetect looks for blobs in the candidate's silhouette grown by this fraction of a section's height.
WINDOW_PAD = 0.3


# -- the skills --------------------------------------------------------------------------------------


class _Pipeline(WorldSkill):
    """A Verify2DObject step: the scratch space and the world model's candidate facts."""

    @property
    def scratch(self) -> dict[str, object]:
        """The agent's scratch space (an own dict when the skill has no context)."""
        if self.context is not None:
            return self.context.scratch
        own: dict[str, object] = self.__dict__.setdefault("_own_scratch", {})
        return own

    @property
    def memory(self) -> Memory:
        """What the steps remember across rounds (:data:`~alica.skills.vision2d_data.MEMORY`)."""
        return MEMORY.setdefault(self.scratch, Memory)

    def verdicts(self) -> dict[str, str]:
        """Candidate -> verdict (a sample's name, or ``invalid``), less the stale ones, which are forgotten.

        A verdict is stale when the sample it named was held by a teammate now
        lost: the sample fell where it was, and its candidate is looked at again.
        """
        verdicts = self.memory.verdicts
        belief = self.context.belief if self.context is not None else None
        for cid in stale_verdicts(verdicts, self.world_model, belief):
            del verdicts[cid]
        return verdicts

    def reject_candidate(self, candidate: Candidate, reason: str) -> None:
        """A closer look disagrees: retract the candidate (and a sample found there), record it as invalid."""
        cid = candidate.id
        wm = self.world_model
        if wm is not None:
            wm.retract_fact("candidate", cid)
            wm.assert_fact("invalid", cid)
            for name, at in _found_samples(wm):
                if math.hypot(at[0] - candidate.x, at[1] - candidate.y) <= ASSOCIATION_RADIUS:
                    wm.retract_fact("found", name)
                    wm.retract_fact("onground", name)
        self.memory.verdicts[cid] = "invalid"
        VERDICT.put(self.scratch, Verdict(cid, valid=False, reason=reason))


def _found_samples(wm: WorldModelLike) -> list[tuple[str, tuple[float, float]]]:
    """``(name, pos)`` of the samples found so far."""
    out = []
    for name, args, value in wm.values():
        if name == "pos" and len(args) == 1 and isinstance(value, (tuple, list)) and len(value) >= 2:
            if wm.holds("found", args[0]):
                out.append((str(args[0]), (float(value[0]), float(value[1]))))
    return out


class DetectCircles(_Pipeline):
    """Find circles of the sample radius in the 2D laser scan (see :func:`detect_circles`).

    The scan is taken where the robot is (the sensor); the circles are placed
    in the world by the robot's pose *estimate* (``robot.estimate``: odometry,
    corrected by Localize), the only pose a skill may know. The scan reaches
    :data:`SCAN_MARGIN` metres beyond ``max_range`` (within the lidar's range):
    nothing farther can make a candidate, and the rays cost less.

    Succeeds with :class:`Candidates` (each a :class:`Candidate`, nearest first) in the
    ``CANDIDATES`` slot and ``candidate(c)``, ``candidate_pos(c)``
    in the world model. With ``wait`` 0 (the default) it fails at once when the
    scan has no circle. With ``wait`` > 0 it waits for work: it scans every
    ``period`` seconds while no candidate without a verdict yet (an
    *unverified* one) is within ``max_range``, running meanwhile, succeeds
    when one is, and fails after ``wait`` seconds (``inf``: never).
    """

    def initialise(self) -> None:
        """Check the parameters and start the scan."""
        self.radius = number_param(self, "radius", 0.03)
        self.tolerance = number_param(self, "tolerance", 0.01, strict=False)
        self.max_range = number_param(self, "max_range", 8.0)
        self.period = number_param(self, "period", 0.5)
        raw_wait = self.param("wait", 0.0)
        try:
            self.wait = float(raw_wait) if isinstance(raw_wait, (int, float, str)) else math.nan
        except ValueError:
            self.wait = math.nan
        if not self.wait >= 0.0:  # NaN too; inf is allowed: wait until a candidate comes
            raise SkillError(
                f"skill '{self.name}': parameter 'wait' must be a number of seconds >= 0 (inf: until found), got {raw_wait!r}"
            )
        raw = self.param("n_rays", 1440)
        if not isinstance(raw, int) or isinstance(raw, bool) or not 16 <= raw <= 100_000:
            raise SkillError(
                f"skill '{self.name}': parameter 'n_rays' must be a whole number in [16, 100000], got {raw!r}"
            )
        self.n_rays = raw
        if self.tolerance >= self.radius:
            raise SkillError(
                f"skill '{self.name}': parameter 'tolerance' ({self.tolerance}) must be smaller than 'radius' ({self.radius})"
            )
        if "lidar2d" not in self.robot.spec.capabilities:
            raise SkillError(f"skill '{self.name}': robot '{self.robot.name}' has no 2D lidar")
        self.started = self.now()
        self.scans = 0
        self.next_scan = self.started
        self._waiting = "waiting for a candidate"
        self.job: Job | None = self.jobs.submit(self._scan)

    def _scan(self) -> list[Circle]:
        robot = self.robot
        # the scan reaches a little beyond max_range only: farther hits make no candidate
        scan_range = min(robot.spec.lidar_range, self.max_range + SCAN_MARGIN)
        ranges = robot.lidar(self.n_rays, scan_range)  # measured where the robot is
        sigma = robot.lidar_noise
        return detect_circles(
            ranges,
            robot.lidar_angles(self.n_rays),
            robot.estimate,  # placed where the robot believes it is
            radius=self.radius,
            tolerance=self.tolerance,
            max_range=self.max_range,
            scan_range=scan_range,
            sigma=max(sigma, 0.005),
            seed=int(self.world.seed) * 1_000_003 + round(self.now() * 1000),
        )

    def update(self) -> Status:
        """Poll the scan; hand the circles on, or scan again while waiting."""
        if self.job is None:  # waiting for the next scan
            if self.now() < self.next_scan - 1e-9:
                return self.running(self._waiting)
            self.job = self.jobs.submit(self._scan)
        if not self.job.done():
            return self.running("scanning")
        circles: list[Circle] = self.job.result()
        self.job = None
        self.scans += 1
        verdicts = self.verdicts()
        out = self._candidates(circles, verdicts)
        fresh = [c for c in out if c.id not in verdicts]
        if self.wait > 0.0 and not fresh:
            waited = self.now() - self.started
            seen = f"{len(out)} verified candidate(s)" if out else "no circle of the sample radius"
            if waited >= self.wait - 1e-9:
                return self.fail(
                    f"no unverified candidate within {self.max_range:g} m in {waited:.1f} s "
                    f"({self.scans} scans; {seen} in the last)"
                )
            self.next_scan = self.now() + self.period
            self._waiting = (
                f"waiting for a candidate within {self.max_range:g} m ({seen}; {waited:.1f} of {self.wait:g} s)"
            )
            return self.running(self._waiting)
        if not out:
            return self.fail("no circle of the sample radius in the scan")
        near = (fresh or out)[0]
        return self.succeed(
            f"{len(out)} candidate(s), {len(fresh)} unverified; nearest {near.id} at "
            f"({near.x:.2f}, {near.y:.2f}), {near.range:.2f} m"
        )

    def _candidates(self, circles: list[Circle], verdicts: dict[str, str]) -> tuple[Candidate, ...]:
        """Name the circles (a known candidate nearby keeps its id), write them to the scratch space and world model."""
        known = self.memory.known
        out = []
        wm = self.world_model
        for c in circles:
            cid = next((k for k, p in known.items() if math.hypot(p[0] - c.x, p[1] - c.y) <= ASSOCIATION_RADIUS), None)
            if cid is None:
                cid = f"{self.robot.name}_c{len(known) + 1}"
            known[cid] = (c.x, c.y)
            out.append(Candidate(cid, c.x, c.y, c.radius, c.range, c.bearing, c.points))
            if wm is not None and cid not in verdicts:  # verified ones stay found (or invalid) until a new look
                wm.assert_fact("candidate", cid)
                wm.set("candidate_pos", cid, value=(round(c.x, 3), round(c.y, 3)))
        CANDIDATES.put(self.scratch, Candidates(tuple(out), self.radius))
        return tuple(out)


class CropCandidate(_Pipeline):
    """Turn the camera to the nearest unverified candidate, render it, project the candidate into it and crop it.

    Candidates come from the ``CANDIDATES`` slot (DetectCircles). The target
    is the nearest candidate within ``max_range`` without a verdict, one the
    camera could not see in the last ``retry`` seconds coming after the others;
    a camera with a pan unit (``spec.camera_pan_limit``) is turned toward it.
    The picture is taken where the robot is; the candidate is projected into
    it with the camera pose of the robot's pose *estimate*. Any candidate in
    the picture may be cropped, the target first. The crop is the
    candidate's cylinder (footprint of the sample radius,
    :data:`SAMPLE_HEIGHT` high) grown by ``margin`` metres;
    a :class:`Crop` (the candidate, ``rgb``, ``depth``, ``box``, ``expected``,
    ``range``, ``time``, ``pan``) in the ``CROP`` slot goes on to BlobDetect and
    ClassifySample. Fails when no candidate is within ``max_range``, within
    the pan unit's reach and in clear view.
    """

    def initialise(self) -> None:
        """Check the parameters, choose the candidate, turn the camera toward it and render."""
        self.margin = number_param(self, "margin", 0.1, strict=False)
        self.max_range = number_param(self, "max_range", 5.0)
        self.retry = number_param(self, "retry", 5.0, strict=False)
        self.width = self._pixels("width", 752)
        self.height = self._pixels("height", 480)
        if not ({"camera", "stereo_camera"} & self.robot.spec.capabilities):
            raise SkillError(f"skill '{self.name}': robot '{self.robot.name}' has no camera")
        self.target: Candidate | None = None
        self.reasons: list[str] = []
        self.pan = self._aim()
        self.job: Job | None = self.jobs.submit(self._render) if self.target is not None else None

    def _pixels(self, name: str, default: int) -> int:
        raw = self.param(name, default)
        if not isinstance(raw, int) or isinstance(raw, bool) or not 16 <= raw <= 4096:
            raise SkillError(
                f"skill '{self.name}': parameter '{name}' must be a whole number of pixels in [16, 4096], got {raw!r}"
            )
        return raw

    def _aim(self) -> float:
        """Choose the target (``self.target``) and the pan angle that centres it; reasons for the others."""
        circles = CANDIDATES.get(self.scratch) or ()
        verdicts = self.verdicts()
        unseen = self.memory.unseen
        robot = self.robot
        spec = robot.spec
        estimate = robot.estimate
        camera, _ = robot.camera_pose(estimate)
        limit = spec.camera_pan_limit
        # the candidate's middle must be this far inside the picture's edge
        reach = limit + 0.5 * spec.camera_fov - math.radians(3.0)
        now = self.now()
        options = []
        for c in circles:
            dx, dy = c.x - estimate[0], c.y - estimate[1]
            if math.hypot(dx, dy) > self.max_range:
                self.reasons.append(
                    f"{c.id}: {math.hypot(dx, dy):.1f} m away, beyond the {self.max_range:g} m of a closer look"
                )
                continue
            bearing = math.remainder(math.atan2(c.y - camera[1], c.x - camera[0]) - estimate[2], math.tau)
            if abs(bearing) > reach:
                self.reasons.append(
                    f"{c.id}: at {math.degrees(bearing):.0f} deg, out of the camera's reach (pan +-{math.degrees(limit):.0f} deg)"
                )
                continue
            recent = now - unseen.get(c.id, -math.inf) < self.retry
            options.append(((c.id in verdicts, recent, math.hypot(dx, dy)), bearing, c))
        if not options:
            return 0.0
        options.sort(key=lambda t: t[0])
        _, bearing, self.target = options[0]
        return max(-limit, min(limit, bearing))

    def _render(self) -> CameraImage:
        """Render the part of the frame the candidates' crops can come from (the same pixels, far cheaper)."""
        robot = self.robot
        position, rotation = robot.camera_pose(robot.estimate, self.pan)
        fx = (self.width / 2.0) / math.tan(robot.spec.camera_fov / 2.0)
        probe = CameraImage(
            np.zeros((1, 1, 3), dtype=np.uint8),
            np.zeros((1, 1)),
            (fx, fx, self.width / 2.0 - 0.5, self.height / 2.0 - 0.5),
            position,
            rotation,
            self.now(),
            self.pan,
            frame=(self.width, self.height),
        )
        circles = CANDIDATES.get(self.scratch) or Candidates((), 0.03)
        boxes = [g[0] for g in (self._geometry(probe, c, circles.radius) for c in circles) if not isinstance(g, str)]
        window = None
        if boxes:
            u0, v0 = min(b[0] for b in boxes), min(b[1] for b in boxes)
            u1, v1 = max(b[2] for b in boxes), max(b[3] for b in boxes)
            # at least the renderer's smallest picture, inside the frame
            u0, u1 = _span(u0, u1, self.width)
            v0, v1 = _span(v0, v1, self.height)
            window = (u0, v0, u1, v1)
        else:  # nothing can be cropped: a small picture says so as well as a whole one
            window = (0, 0, _MIN_PICTURE, _MIN_PICTURE)
        return robot.camera(width=self.width, height=self.height, pan=self.pan, believed=True, window=window)

    def update(self) -> Status:
        """Poll the rendering; crop the candidate."""
        circles = CANDIDATES.get(self.scratch)
        if not circles:
            return self.fail("no candidate to look at: run DetectCircles first")
        if self.job is None or self.target is None:
            return self.fail("no candidate in reach: " + "; ".join(self.reasons[:3]))
        if not self.job.done():
            return self.running(
                f"turning the camera to {self.target.id} ({math.degrees(self.pan):.0f} deg) and taking a picture"
            )
        image: CameraImage = self.job.result()
        verdicts = self.verdicts()
        views = []
        reasons: list[str] = []
        for c in circles:
            view = self._view(image, c, circles.radius)
            if isinstance(view, str):
                if c.id == self.target.id:
                    reasons.insert(0, f"{c.id}: {view}")
                    self.memory.unseen[c.id] = self.now()
                else:
                    reasons.append(f"{c.id}: {view}")
            else:
                views.append((c.id in verdicts, c.id != self.target.id, c.range, c, view))
        if not views:
            return self.fail("no candidate in view: " + "; ".join((reasons + self.reasons)[:3]))
        views.sort(key=lambda t: (t[0], t[1], t[2]))
        *_, candidate, (box, expected) = views[0]
        u0, v0, u1, v1 = box
        ou, ov = image.offset
        crop = Crop(
            candidate,
            rgb=image.rgb[v0 - ov : v1 - ov, u0 - ou : u1 - ou].copy(),
            depth=image.depth[v0 - ov : v1 - ov, u0 - ou : u1 - ou].copy(),
            box=box,
            expected=(expected[0] - u0, expected[1] - v0, expected[2] - u0, expected[3] - v0),
            range=candidate.range,
            time=image.time,
            pan=image.pan,
        )
        CROP.put(self.scratch, crop)
        return self.succeed(
            f"cropped {candidate.id} ({u1 - u0}x{v1 - v0} px at {candidate.range:.2f} m, "
            f"camera at {math.degrees(image.pan):.0f} deg)"
        )

    def _view(
        self, image: CameraImage, c: Candidate, radius: float
    ) -> tuple[tuple[int, int, int, int], tuple[float, float, float, float]] | str:
        """The crop box and the sample's expected box in frame pixels, or why the candidate cannot be seen."""
        geometry = self._geometry(image, c, radius)
        if isinstance(geometry, str):
            return geometry
        box, expected, depth = geometry
        # something nearer than the candidate covers it: the middle of its silhouette is closer in depth
        ou, ov = image.offset
        cu, cv = int(0.5 * (expected[0] + expected[2])), int(0.5 * (expected[1] + expected[3]))
        patch = image.depth[cv - 1 - ov : cv + 2 - ov, cu - 1 - ou : cu + 2 - ou] if cu >= 1 and cv >= 1 else None
        seen = float(np.median(patch)) if patch is not None and patch.size else math.inf
        if seen < depth - 4.0 * radius - 0.05:
            return f"hidden behind something {seen:.2f} m from the camera"
        return box, expected

    def _geometry(
        self, image: CameraImage, c: Candidate, radius: float
    ) -> tuple[tuple[int, int, int, int], tuple[float, float, float, float], float] | str:
        """Where the candidate lies in the camera's frame: crop box, expected box, depth (pixels of the whole
        frame, from the picture's pose and intrinsics); or why it cannot be seen there."""
        if c.range > self.max_range:
            return f"{c.range:.1f} m away, beyond the {self.max_range:.1f} m of a closer look"
        w, h = image.frame_size
        ou, ov = image.offset
        x, y = c.x, c.y
        # the sample's cylinder: its silhouette's left/right edges at the bottom and the top
        to = np.array([x, y, 0.0]) - image.position
        side = np.array([-to[1], to[0], 0.0]) / max(math.hypot(to[0], to[1]), 1e-9)
        corners = []
        for z in (0.0, SAMPLE_HEIGHT):
            for s in (-1.0, 1.0):
                corners.append(image.project(np.array([x, y, z]) + s * radius * side))
        # seen from above (close by), the top's far edge shows above the silhouette: the upper section looks taller
        along = np.array([to[0], to[1], 0.0]) / max(math.hypot(to[0], to[1]), 1e-9)
        corners.append(image.project(np.array([x, y, SAMPLE_HEIGHT]) + radius * along))
        if any(not math.isfinite(u) or d <= 0.0 for u, _, d in corners):
            return "behind the camera"
        us, vs = [u + ou for u, _, _ in corners], [v + ov for _, v, _ in corners]
        expected = (min(us), min(vs), max(us) + 1.0, max(vs) + 1.0)
        if expected[2] < 0 or expected[0] >= w or expected[3] < 0 or expected[1] >= h:
            return "outside the camera's field of view"
        if expected[0] < 0 or expected[2] > w or expected[1] < 0 or expected[3] > h:
            return "only partly in the camera's field of view"
        depth = corners[0][2]
        fx = image.intrinsics[0]
        pad = self.margin * fx / depth
        box = (
            int(max(0, math.floor(expected[0] - pad))),
            int(max(0, math.floor(expected[1] - pad))),
            int(min(w, math.ceil(expected[2] + pad))),
            int(min(h, math.ceil(expected[3] + pad))),
        )
        return box, expected, depth


def _span(a: int, b: int, size: int) -> tuple[int, int]:
    """``[a, b)`` grown to at least :data:`_MIN_PICTURE` pixels, kept inside ``[0, size)``."""
    if b - a < _MIN_PICTURE:
        a = max(0, min(a, size - _MIN_PICTURE))
        b = min(size, a + _MIN_PICTURE)
    return a, b


class BlobDetect(_Pipeline):
    """Find coloured blobs in the crop (HSV thresholds, connected components of at least ``min_area`` pixels).

    Reads the :class:`Crop` (CropCandidate), writes :class:`Blobs` (see
    :func:`find_blobs`). Fails, retracting the candidate, when no blob of the
    colours is near the candidate: a closer look disagrees.
    """

    def initialise(self) -> None:
        """Check the parameters."""
        raw = self.param("colours", ("green", "red"))
        colours = (raw,) if isinstance(raw, str) else tuple(raw) if isinstance(raw, (list, tuple)) else None
        if not colours or any(c not in HSV_RANGES for c in colours):
            raise SkillError(
                f"skill '{self.name}': parameter 'colours' must list colours of {', '.join(sorted(HSV_RANGES))}, got {raw!r}"
            )
        self.colours: tuple[str, ...] = tuple(str(c) for c in colours)
        area = self.param("min_area", 12)
        if not isinstance(area, int) or isinstance(area, bool) or area < 1:
            raise SkillError(
                f"skill '{self.name}': parameter 'min_area' must be a whole number of pixels >= 1, got {area!r}"
            )
        self.min_area = area

    def update(self) -> Status:
        """Detect the blobs (cheap: the crop is small)."""
        crop = CROP.get(self.scratch)
        if crop is None:
            return self.fail("no cropped candidate: run CropCandidate first")
        candidate = crop.candidate
        u0, v0, u1, v1 = crop.expected
        pad = max(2.0, WINDOW_PAD * (v1 - v0) / 3.0)
        blobs = find_blobs(crop.rgb, self.colours, self.min_area, (u0 - pad, v0 - pad, u1 + pad, v1 + pad))
        BLOBS.put(self.scratch, Blobs(tuple(blobs)))
        if not blobs:
            reason = f"no {' or '.join(self.colours)} blob of {self.min_area} px or more at {candidate.id}"
            self.reject_candidate(candidate, reason)
            return self.fail(reason)
        summary = ", ".join(f"{b.colour} {b.area} px" for b in blobs[:4])
        return self.succeed(f"{len(blobs)} blob(s) at {candidate.id}: {summary}")


class ClassifySample(_Pipeline):
    """Decode the sample's kind from the blobs' vertical order and the middle section (see :func:`decode_sections`).

    On success: ``found(s)``, ``sample_kind(s)``, ``pos(s)`` and
    ``confidence(s)`` in the world model; ``s`` is the sample the mission
    already knows with that kind (a value ``sample_kind(s)`` set beforehand,
    e.g. ``a``), else one named after the kind. The candidate fact is
    retracted (it is a sample now). On failure the candidate is retracted and
    recorded as ``invalid(c)``, and a sample found at its place is retracted.
    """

    def initialise(self) -> None:
        """Check the parameters."""
        self.min_confidence = number_param(self, "min_confidence", 0.3, strict=False)
        if self.min_confidence > 1.0:
            raise SkillError(
                f"skill '{self.name}': parameter 'min_confidence' must be in [0, 1], got {self.min_confidence}"
            )

    def update(self) -> Status:
        """Classify and write the result."""
        crop = CROP.get(self.scratch)
        blobs = BLOBS.get(self.scratch)
        if crop is None or blobs is None:
            return self.fail("nothing to classify: run CropCandidate and BlobDetect first")
        candidate = crop.candidate
        result = decode_sections(crop.rgb, blobs.items, crop.expected)
        if isinstance(result, str):
            self.reject_candidate(candidate, result)
            return self.fail(f"{candidate.id} is no sample: {result}")
        kind, confidence = result
        if confidence < self.min_confidence:
            reason = f"{kind} with confidence {confidence:.2f} below {self.min_confidence:.2f}"
            self.reject_candidate(candidate, reason)
            return self.fail(f"{candidate.id} is no sample: {reason}")
        name = self._name(kind, candidate)
        position = (round(candidate.x, 3), round(candidate.y, 3))
        wm = self.world_model
        if wm is not None:
            wm.set("sample_kind", name, value=kind)
            wm.set("pos", name, value=position)
            wm.set("confidence", name, value=confidence)
            report_found(wm, name, self.now())
            wm.retract_fact("candidate", candidate.id)
            wm.add_object(name, "Sample")
        self.memory.verdicts[candidate.id] = name
        VERDICT.put(
            self.scratch,
            Verdict(candidate.id, valid=True, sample=name, kind=kind, position=position, confidence=confidence),
        )
        return self.succeed(
            f"found {name}: {kind} at ({position[0]:.2f}, {position[1]:.2f}), confidence {confidence:.2f}"
        )

    def _name(self, kind: str, candidate: Candidate) -> str:
        """The sample's name: the known sample of this kind nearby or without a position, else a new one."""
        wm = self.world_model
        here = (candidate.x, candidate.y)
        base = kind.replace("-", "_")
        if wm is None:
            return base
        taken: dict[str, tuple[float, float] | None] = {}
        for name, args, value in wm.values():
            if name == "sample_kind" and len(args) == 1 and value == kind:
                at = wm.get("pos", args[0])
                taken[str(args[0])] = (
                    (float(at[0]), float(at[1])) if isinstance(at, (tuple, list)) and len(at) >= 2 else None
                )
        for name, at in sorted(taken.items(), key=lambda t: t[1] is None):
            if at is not None and math.hypot(at[0] - here[0], at[1] - here[1]) <= 2 * ASSOCIATION_RADIUS:
                return name
        for name, at in sorted(taken.items()):
            if at is None:
                return name
        k = 1
        name = base
        while name in taken:
            k += 1
            name = f"{base}_{k}"
        return name
