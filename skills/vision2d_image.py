"""The camera side of Verify2DObject: coloured blobs in a crop and the sample kind their sections encode.

Pure OpenCV and numpy, no skill and no world: :func:`find_blobs` finds
connected components of the colours' HSV ranges, :func:`decode_sections`
reads a sample's colour code from them. :mod:`alica.skills.vision2d` runs
them in :class:`~alica.skills.vision2d.BlobDetect` and
:class:`~alica.skills.vision2d.ClassifySample`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from alica.worldsim.interface import SAMPLE_KINDS

__all__ = ["HSV_RANGES", "WHITE_VALUE", "Blob", "decode_sections", "find_blobs"]

#: A middle section at least this bright (HSV value, 0-255) and unsaturated is white; a white section
#: lit from the side renders at about 147, from the front at 200 and more, a black one below 70.
WHITE_VALUE = 120
#: HSV ranges (OpenCV: hue 0-180, saturation and value 0-255) of the colours BlobDetect knows.
HSV_RANGES: dict[str, tuple[tuple[tuple[int, int, int], tuple[int, int, int]], ...]] = {
    "red": (((0, 110, 60), (8, 255, 255)), ((172, 110, 60), (180, 255, 255))),
    "green": (((40, 110, 50), (85, 255, 255)),),
    "blue": (((100, 110, 50), (130, 255, 255)),),
    "yellow": (((22, 110, 80), (35, 255, 255)),),
}


@dataclass(frozen=True, slots=True)
class Blob:
    """A connected component of one colour in a crop.

    Attributes:
        colour: the colour's name (a key of :data:`HSV_RANGES`).
        area: pixels.
        centroid: ``(u, v)`` in crop pixels.
        box: ``(u0, v0, u1, v1)`` in crop pixels (``u1``, ``v1`` exclusive).
    """

    colour: str
    area: int
    centroid: tuple[float, float]
    box: tuple[int, int, int, int]


def find_blobs(
    rgb: np.ndarray,
    colours: tuple[str, ...],
    min_area: int,
    window: tuple[float, float, float, float] | None = None,
) -> list[Blob]:
    """Connected components of each colour's HSV range with at least ``min_area`` pixels.

    With a ``window`` ``(u0, v0, u1, v1)`` only pixels inside it count (the
    candidate's silhouette, slightly grown: a red robot or rock right behind
    the sample then does not merge with its sections).

    Returns:
        The blobs, largest first.
    """
    import cv2

    hsv = cv2.cvtColor(np.ascontiguousarray(rgb), cv2.COLOR_RGB2HSV)
    keep = np.ones(hsv.shape[:2], dtype=np.uint8) * 255
    if window is not None:
        keep[:] = 0
        u0, v0, u1, v1 = (round(c) for c in window)
        keep[max(v0, 0) : max(v1, 0), max(u0, 0) : max(u1, 0)] = 255
    blobs: list[Blob] = []
    for colour in colours:
        mask = np.zeros(hsv.shape[:2], dtype=np.uint8)
        for lo, hi in HSV_RANGES[colour]:
            mask |= cv2.inRange(hsv, np.array(lo, dtype=np.uint8), np.array(hi, dtype=np.uint8))
        mask &= keep
        count, _, stats, centroids = cv2.connectedComponentsWithStats(mask, connectivity=8)
        for k in range(1, count):
            u, v, w, h, area = (int(s) for s in stats[k])
            if area >= min_area:
                centroid = (float(centroids[k][0]), float(centroids[k][1]))
                blobs.append(Blob(colour, area, centroid, (u, v, u + w, v + h)))
    blobs.sort(key=lambda b: -b.area)
    return blobs


def decode_sections(
    rgb: np.ndarray, blobs: Sequence[Blob], expected: tuple[float, float, float, float]
) -> tuple[str, float] | str:
    """The sample kind and a confidence from the blobs of a crop, or why it is not a sample.

    The blobs inside the sample's expected box (``(u0, v0, u1, v1)`` in crop
    pixels) are read top to bottom: the uppermost is the upper section, the
    lowest the lower one; both must be about a third of the box high and the
    two must be apart by about a section. The middle section is the strip
    between them: white when bright and unsaturated, black when dark. The
    confidence combines how much of the expected sections the blobs cover and
    how clear the middle is.

    Returns:
        ``(kind, confidence)`` or a reason string.
    """
    import cv2

    u0, v0, u1, v1 = expected
    width, height = max(u1 - u0, 1.0), max(v1 - v0, 1.0)
    section = height / 3.0
    inside = [
        b
        for b in blobs
        if u0 - 0.5 * width <= b.centroid[0] <= u1 + 0.5 * width
        and v0 - 0.5 * section <= b.centroid[1] <= v1 + 0.5 * section
    ]
    if len(inside) < 2:
        return f"{len(inside)} coloured blob(s) where the sample should be; a sample has two"
    too_big = [
        b for b in inside if (b.box[3] - b.box[1]) > 1.6 * section + 2 or (b.box[2] - b.box[0]) > 2.0 * width + 2
    ]
    if too_big:
        b = too_big[0]
        return f"a {b.colour} blob of {b.box[2] - b.box[0]}x{b.box[3] - b.box[1]} px is larger than a section of the sample ({width:.0f}x{section:.0f} px)"
    inside.sort(key=lambda b: b.centroid[1])
    upper, lower = inside[0], inside[-1]
    gap = lower.centroid[1] - upper.centroid[1]
    if not (1.2 * section <= gap + 1.0 and gap - 1.0 <= 2.8 * section):
        return f"the coloured blobs are {gap:.1f} px apart, the sample's sections {2 * section:.1f} px"
    top, bottom = upper.box[3], lower.box[1]
    left = int(max(min(upper.box[0], lower.box[0]), 0))
    right = int(max(upper.box[2], lower.box[2]))
    strip = rgb[int(top) : int(max(bottom, top + 1)), left : max(right, left + 1)]
    if strip.size == 0:
        return "no middle section between the coloured blobs"
    hsv = cv2.cvtColor(np.ascontiguousarray(strip), cv2.COLOR_RGB2HSV).reshape(-1, 3).astype(float)
    value, saturation = float(np.median(hsv[:, 2])), float(np.median(hsv[:, 1]))
    if value >= WHITE_VALUE and saturation <= 80:
        middle, clarity = "white", min(1.0, (value - WHITE_VALUE) / 60 + 0.5)
    elif value <= 70:
        middle, clarity = "black", min(1.0, (70 - value) / 40 + 0.5)
    else:
        return f"the middle section is neither black nor white (value {value:.0f}, saturation {saturation:.0f})"
    ends = sorted((upper.colour, lower.colour))  # green before red: the kinds list green first
    kind = f"{ends[0]}-{middle}-{ends[1]}"
    if kind not in SAMPLE_KINDS:
        return f"the code {upper.colour}-{middle}-{lower.colour} is no sample kind"
    area = width * section
    cover = min(1.0, min(upper.area, lower.area) / max(0.6 * area, 1.0))
    return kind, round(float(0.5 * cover + 0.5 * clarity), 3)
