"""What the Verify2DObject steps hand on to each other through the agent's scratch space, typed.

=================  ==========================  ===================================  =====================
slot               type                        written by                           read by
=================  ==========================  ===================================  =====================
:data:`CANDIDATES` :class:`Candidates`         DetectCircles                        CropCandidate
:data:`CROP`       :class:`Crop`               CropCandidate                        BlobDetect, ClassifySample
:data:`BLOBS`      :class:`Blobs`              BlobDetect                           ClassifySample
:data:`VERDICT`    :class:`Verdict`            BlobDetect, ClassifySample           (the last verdict, for people)
:data:`MEMORY`     :class:`Memory`             every step                           every step
=================  ==========================  ===================================  =====================

A step's inputs and outputs are frozen dataclasses; :class:`Memory` is what
the steps remember across rounds of the plan's loop (candidate ids, verdicts,
candidates the camera could not see), and is changed in place.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from alica.skills.scratch import ScratchSlot
from alica.skills.vision2d_image import Blob

__all__ = [
    "BLOBS",
    "CANDIDATES",
    "CROP",
    "MEMORY",
    "VERDICT",
    "Blobs",
    "Candidate",
    "Candidates",
    "Crop",
    "Memory",
    "Verdict",
]


@dataclass(frozen=True, slots=True)
class Candidate:
    """A circle of the sample radius in a scan, named: a candidate sample.

    Attributes:
        id: the candidate's name (``<robot>_c<k>``; a detection near a known candidate keeps its name).
        x: centre in the world (by the robot's pose estimate), metres.
        y: centre in the world, metres.
        radius: the estimated radius, metres.
        range: distance from the scanner, metres.
        bearing: direction relative to the robot's heading, radians.
        points: scan points in the cluster.
    """

    id: str
    x: float
    y: float
    radius: float
    range: float
    bearing: float
    points: int


@dataclass(frozen=True, slots=True)
class Candidates:
    """DetectCircles' output: the candidates of the last scan, nearest first, and the sample radius looked for."""

    items: tuple[Candidate, ...]
    radius: float

    def __iter__(self) -> Iterator[Candidate]:
        return iter(self.items)

    def __len__(self) -> int:
        return len(self.items)


@dataclass(frozen=True, slots=True, eq=False)
class Crop:
    """CropCandidate's output: the candidate it cropped and the crop.

    Attributes:
        candidate: the candidate in the crop.
        rgb: the crop's colour pixels (``(h, w, 3)`` uint8).
        depth: the crop's depth pixels, metres.
        box: the crop in frame pixels ``(u0, v0, u1, v1)`` (``u1``, ``v1`` exclusive).
        expected: the sample's expected box in crop pixels.
        range: the candidate's range, metres.
        time: when the picture was taken, seconds.
        pan: the camera's pan angle, radians.
    """

    candidate: Candidate
    rgb: np.ndarray
    depth: np.ndarray
    box: tuple[int, int, int, int]
    expected: tuple[float, float, float, float]
    range: float
    time: float
    pan: float


@dataclass(frozen=True, slots=True)
class Blobs:
    """BlobDetect's output: the blobs of the crop's colours, largest first (:func:`~alica.skills.vision2d_image.find_blobs`)."""

    items: tuple[Blob, ...]


@dataclass(frozen=True, slots=True)
class Verdict:
    """The last verdict on a candidate: a sample (its name, kind, position, confidence) or no sample (why)."""

    candidate: str
    valid: bool
    sample: str | None = None
    kind: str | None = None
    position: tuple[float, float] | None = None
    confidence: float | None = None
    reason: str | None = None


@dataclass(slots=True)
class Memory:
    """What the steps remember across rounds, changed in place.

    Attributes:
        verdicts: candidate -> the sample's name, or ``invalid``.
        unseen: candidate -> when the camera last could not see it, seconds.
        known: candidate -> where it was last detected (the candidates' names).
    """

    verdicts: dict[str, str] = field(default_factory=dict)
    unseen: dict[str, float] = field(default_factory=dict)
    known: dict[str, tuple[float, float]] = field(default_factory=dict)


CANDIDATES: ScratchSlot[Candidates] = ScratchSlot("circles", Candidates, "DetectCircles")
CROP: ScratchSlot[Crop] = ScratchSlot("crop", Crop, "CropCandidate")
BLOBS: ScratchSlot[Blobs] = ScratchSlot("blobs", Blobs, "BlobDetect")
VERDICT: ScratchSlot[Verdict] = ScratchSlot("last_verdict", Verdict, "BlobDetect or ClassifySample")
MEMORY: ScratchSlot[Memory] = ScratchSlot("verify2d", Memory, "DetectCircles")
