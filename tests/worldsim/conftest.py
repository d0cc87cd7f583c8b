"""Fixtures for the simulated-world tests: small worlds, closed after each test."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from alica.worldsim.world import World
from tests.manipulation.helpers import mobile_scene, scene

__all__ = ["mobile_scene", "scene"]  # the arm scene's fixtures, shared with tests/manipulation


@pytest.fixture
def world() -> Iterator[World]:
    """An empty 20 x 20 m world with a ground plane (seed 0)."""
    w = World(seed=0)
    try:
        yield w
    finally:
        w.close()
