"""Fixtures of the manipulation tests: scenes, each with its own pybullet client (defined in helpers)."""

from tests.manipulation.helpers import mobile_scene, scene

__all__ = ["mobile_scene", "scene"]
