"""The simulated world (pybullet): robots, objects, terrain, sensors, faults.

Nothing here is imported by :mod:`alica`. Importing this package is cheap: the
names below are loaded on first use, so ``import worldsim.grid`` does not load
pybullet.

Example:
    >>> from worldsim import lunar
    >>> with lunar(seed=1, rocks=10) as world:
    ...     world.robots["scout"].drive(0.5, 0.0)
    ...     world.step(1.0)
    240
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "World": "worldsim.world",
    "WorldError": "worldsim.errors",
    "Obstacle2D": "worldsim.grid",
    "OccupancyGrid": "worldsim.grid",
    "Robot": "worldsim.robots",
    "RobotSpec": "worldsim.robots",
    "ROBOT_KINDS": "worldsim.robots",
    "Arm": "worldsim.arm",
    "WorldObject": "worldsim.objects",
    "SAMPLE_KINDS": "worldsim.objects",
    "Detection": "worldsim.sensors",
    "lidar_scan": "worldsim.sensors",
    "perceive": "worldsim.sensors",
    "scan_to_grid": "worldsim.sensors",
    "crash": "worldsim.faults",
    "set_grasp_slip": "worldsim.faults",
    "set_sensor_noise": "worldsim.faults",
    "blocksworld": "worldsim.scenarios",
    "blocks_facts": "worldsim.scenarios",
    "lunar": "worldsim.scenarios",
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
    "blocksworld",
    "crash",
    "lidar_scan",
    "lunar",
    "perceive",
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
