"""The simulated world (pybullet): robots, objects, terrain, sensors, faults.

Nothing here is imported by :mod:`alica`. Importing this package is cheap: the
names below are loaded on first use, so ``import alica.worldsim.grid`` does not load
pybullet.

Example:
    >>> from alica.worldsim import lunar
    >>> with lunar(seed=1, rocks=10) as world:
    ...     world.robots["scout"].drive(0.5, 0.0)
    ...     world.step(1.0)
    240
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

_EXPORTS = {
    "World": "alica.worldsim.world",
    "WorldError": "alica.worldsim.errors",
    "Obstacle2D": "alica.worldsim.grid",
    "OccupancyGrid": "alica.worldsim.grid",
    "Robot": "alica.worldsim.robots",
    "RobotSpec": "alica.worldsim.robot_specs",
    "ROBOT_KINDS": "alica.worldsim.robot_specs",
    "Arm": "alica.worldsim.arm",
    "WorldObject": "alica.worldsim.objects",
    "SAMPLE_KINDS": "alica.worldsim.kinds",
    "Detection": "alica.worldsim.sensors",
    "lidar_scan": "alica.worldsim.sensors",
    "perceive": "alica.worldsim.sensors",
    "scan_to_grid": "alica.worldsim.sensors",
    "crash": "alica.worldsim.faults",
    "recover": "alica.worldsim.faults",
    "set_grasp_slip": "alica.worldsim.faults",
    "set_sensor_noise": "alica.worldsim.faults",
    "blocksworld": "alica.worldsim.scenarios",
    "blocks_facts": "alica.worldsim.scenarios",
    "blocks_perception": "alica.worldsim.scenarios",
    "lunar": "alica.worldsim.scenarios",
}

__all__ = [
    "ROBOT_KINDS",
    "SAMPLE_KINDS",
    "Arm",
    "Detection",
    "Obstacle2D",
    "OccupancyGrid",
    "Robot",
    "RobotSpec",
    "World",
    "WorldError",
    "WorldObject",
    "blocks_facts",
    "blocks_perception",
    "blocksworld",
    "crash",
    "lidar_scan",
    "lunar",
    "perceive",
    "recover",
    "scan_to_grid",
    "set_grasp_slip",
    "set_sensor_noise",
]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'worldsim' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))


if TYPE_CHECKING:  # mypy proves that the simulator satisfies the interfaces it implements
    from alica.engine.sim_world import SimWorld
    from alica.worldsim.bodies import BuildingWorld
    from alica.worldsim.interface import RobotWorld
    from alica.worldsim.world import World

    def _world_is_a_robot_world(world: World) -> RobotWorld:
        return world  # the skills' robot interface

    def _world_is_a_sim_world(world: World) -> SimWorld:
        return world  # what the runtime's simulated team uses: its clock, its step, its robots' crash and recover

    def _world_builds_bodies(world: World) -> BuildingWorld:
        return world  # what the body builders use (the world hands them itself untyped, through _register)
