"""Off-screen snapshots: a PNG of the asked size that shows something."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib import image as mpimg

from alica.worldsim.camera import render, snapshot
from alica.worldsim.errors import WorldError
from alica.worldsim.scenarios import blocksworld


def test_snapshot_writes_a_png_of_the_given_size(tmp_path):
    with blocksworld(agents=2, opponents=1) as world:
        path = snapshot(world, tmp_path / "pictures" / "blocks.png", width=320, height=240)
    assert path.exists() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    pixels = mpimg.imread(path)
    assert pixels.shape[:2] == (240, 320)
    assert len(np.unique(pixels[:, :, :3].reshape(-1, 3), axis=0)) > 10  # not a flat colour


def test_render_is_deterministic_and_sees_the_robots():
    with blocksworld(agents=2) as world:
        first = render(world, width=160, height=120)
        assert first.shape == (120, 160, 3) and first.dtype == np.uint8
        assert np.array_equal(first, render(world, width=160, height=120))
        world.remove("r1")
        assert not np.array_equal(first, render(world, width=160, height=120))


def test_snapshot_errors(tmp_path):
    with blocksworld(agents=1) as world:
        with pytest.raises(WorldError, match="width must be"):
            snapshot(world, tmp_path / "x.png", width=0)
        with pytest.raises(WorldError, match="pitch must be"):
            snapshot(world, tmp_path / "x.png", pitch=10.0)
        with pytest.raises(WorldError, match="target must be"):
            snapshot(world, tmp_path / "x.png", target=(1.0,))
        with pytest.raises(WorldError, match="distance must be"):
            snapshot(world, tmp_path / "x.png", distance=-2.0)
    with pytest.raises(WorldError, match="closed"):
        snapshot(world, tmp_path / "x.png")
