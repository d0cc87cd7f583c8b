"""Helpers of the manipulation tests: the mobile-base set-up, the arm-scene fixtures and an independent path check.

The fixtures are used by tests/manipulation and tests/worldsim (the scene is the world's); each conftest imports them.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator

import numpy as np
import pytest

from alica.skills.manipulation import Box
from alica.worldsim.arm_scene import ArmScene

#: The arm base sits on a mobile base 0.3 m above the ground ...
BASE_HEIGHT = 0.3
#: ... which is modelled as a box under the arm, its front edge 0.15 m ahead of the arm's axis.
PLATFORM = Box("platform", (-0.1, 0.0, 0.15), (0.25, 0.25, 0.145))


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


def dense_states(path: np.ndarray, step: float = 0.02) -> np.ndarray:
    """Re-implementation of the re-check sampling: no joint moves more than ``step`` between states."""
    out = [np.asarray(path[0], dtype=float)]
    for a, b in itertools.pairwise(path):
        n = max(1, math.ceil(float(np.max(np.abs(b - a))) / step - 1e-9))
        out.extend(a + (b - a) * (k / n) for k in range(1, n + 1))
    return np.array(out)


def assert_path_free(scene: ArmScene, path: np.ndarray, held: Box | None = None, step: float = 0.02) -> None:
    """Every state of ``path`` sampled at ``step`` rad is inside the limits and collision free."""
    lower, upper = scene.joint_limits
    for k, q in enumerate(dense_states(path, step)):
        assert np.all(q >= lower - 1e-9) and np.all(q <= upper + 1e-9), f"state {k} outside the limits"
        assert not scene.in_collision(q, held), f"state {k} of a {len(path)}-waypoint path in collision: {q}"
