"""Fixtures shared by the skill tests."""

from __future__ import annotations

import math

import pytest


@pytest.fixture
def teams(monkeypatch):
    """The teams ``alica run`` makes, to read their world models afterwards."""
    import alica.engine

    made = []

    class Recording(alica.engine.SimulatedTeam):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            made.append(self)

    monkeypatch.setattr(alica.engine, "SimulatedTeam", Recording)
    return made


def _free_goal(world, robot, distance=8.0):
    x, y, _ = world.robots[robot].pose
    for angle in [i * math.pi / 8 for i in range(16)]:
        gx, gy = x + distance * math.cos(angle), y + distance * math.sin(angle)
        xmin, ymin, xmax, ymax = world.bounds
        if xmin + 1 < gx < xmax - 1 and ymin + 1 < gy < ymax - 1 and world.is_free(gx, gy, 0.6):
            return gx, gy
    raise AssertionError("no free goal")


@pytest.fixture
def free_goal():
    """``free_goal(world, robot, distance=8.0)``: a free point that far from the robot, inside the field."""
    return _free_goal
