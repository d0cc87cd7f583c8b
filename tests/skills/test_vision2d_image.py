"""The camera side of Verify2DObject (alica.skills.vision2d_image): blobs and the colour code on painted crops."""

from __future__ import annotations

import numpy as np
import pytest

from alica.skills.vision2d_image import Blob, decode_sections, find_blobs

pytest.importorskip("cv2")

GREEN, RED, WHITE, BLACK, GREY = (30, 200, 40), (210, 20, 20), (235, 235, 235), (15, 15, 15), (120, 110, 100)


def _sample(top, middle, bottom, size=(60, 40)):
    """A grey crop with a sample of three 12-pixel sections in the box (14, 12, 26, 48)."""
    rgb = np.full((*size, 3), GREY, dtype=np.uint8)
    for k, colour in enumerate((top, middle, bottom)):
        rgb[12 + 12 * k : 24 + 12 * k, 14:26] = colour
    return rgb, (14.0, 12.0, 26.0, 48.0)


@pytest.mark.parametrize(
    ("sections", "kind"),
    [
        ((GREEN, WHITE, RED), "green-white-red"),
        ((RED, BLACK, GREEN), "green-black-red"),
        ((RED, WHITE, RED), "red-white-red"),
    ],
)
def test_the_colour_code_is_read_from_the_blobs(sections, kind):
    rgb, expected = _sample(*sections)
    blobs = find_blobs(rgb, ("green", "red"), 12)
    assert all(isinstance(b, Blob) for b in blobs) and len(blobs) == 2
    assert blobs[0].area == 144 and blobs[0].box[2] - blobs[0].box[0] == 12
    result = decode_sections(rgb, blobs, expected)
    assert not isinstance(result, str), result
    assert result[0] == kind and 0.5 <= result[1] <= 1.0


def test_a_window_keeps_blobs_outside_it_away():
    rgb, _ = _sample(GREEN, WHITE, RED)
    assert {b.colour for b in find_blobs(rgb, ("green", "red"), 12, window=(0.0, 0.0, 40.0, 30.0))} == {"green"}


def test_a_middle_neither_black_nor_white_is_no_sample():
    rgb, expected = _sample(GREEN, (95, 90, 85), RED)  # HSV value 95: between black (70) and white (120)
    reason = decode_sections(rgb, find_blobs(rgb, ("green", "red"), 12), expected)
    assert isinstance(reason, str) and "neither black nor white" in reason
    assert "a sample has two" in str(decode_sections(rgb, [], expected))
