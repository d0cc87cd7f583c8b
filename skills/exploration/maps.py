"""The map the exploration reads: the team map, with this robot's scans in it.

:class:`MapView` is all :mod:`alica.skills.exploration` needs of a map:
``resolution``, ``origin`` and ``occupancy()`` (int8: -1 unknown, 0 free,
1 occupied). The team's log-odds map (``alica.skills.mapping.LogOddsGrid``,
from ``team_map(world_model)``) offers these members.

:func:`current_map` is the one place that gets the map for a skill.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from alica.skills.context import SkillContextLike
from alica.worldsim.interface import MobileRobot

__all__ = ["MapView", "current_map"]

#: Cell size in metres of a map the exploration starts itself (no team map yet).
MAP_RESOLUTION = 0.1
#: Range in metres of the scans the robot adds to the map while it explores.
MAPPING_RANGE = 10.0


class MapView(Protocol):
    """A 2-D occupancy map as the exploration reads it."""

    @property
    def resolution(self) -> float:
        """Cell size in metres."""
        ...

    @property
    def origin(self) -> tuple[float, float]:
        """World ``(x, y)`` of cell ``(0, 0)``'s lower-left corner."""
        ...

    def occupancy(self) -> np.ndarray:
        """The cells ``[row, col]`` as int8: -1 unknown, 0 free, 1 occupied."""
        ...


def current_map(
    context: SkillContextLike, robot: MobileRobot, world_bounds: tuple[float, float, float, float]
) -> MapView:
    """The map the exploration works on now: the team map, with this robot's scan of this moment in it.

    The robot maps as it explores: its scan goes into its own layer of the team
    map (:func:`alica.skills.mapping.map_scan`, at its pose estimate), and the
    frontiers come from :func:`alica.skills.mapping.team_map`, every robot's
    layer summed, so what a teammate saw is explored by nobody again. Run
    without a world model (alone, with nowhere to share) the robot's own layer
    is the map.
    """
    from alica.skills.mapping import map_scan, robot_mapper, team_map, team_resolution

    world_model = context.world_model
    resolution = team_resolution(world_model) or MAP_RESOLUTION
    mapper = robot_mapper(context, robot.name, world_bounds, resolution)
    map_scan(robot, mapper, max_range=MAPPING_RANGE, now=context.now())
    grid = team_map(world_model) if world_model is not None else None
    return grid if grid is not None else mapper.layer
