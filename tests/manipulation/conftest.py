"""Fixtures of the manipulation tests: scenes, each with its own pybullet client."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from alica.worldsim.arm_scene import ArmScene
from tests.manipulation.helpers import BASE_HEIGHT, PLATFORM


@pytest.fixture
def scene() -> Iterator[ArmScene]:
    """A Panda with its base at the origin on the ground, no obstacles."""
    s = ArmScene()
    yield s
    s.close()


@pytest.fixture
def mobile_scene() -> Iterator[ArmScene]:
    """A Panda on a 0.3 m high mobile base (the platform is an obstacle)."""
    s = ArmScene(base_pose=((0.0, 0.0, BASE_HEIGHT), (0.0, 0.0, 0.0, 1.0)), obstacles=[PLATFORM])
    yield s
    s.close()
