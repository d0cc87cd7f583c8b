"""The map the exploration reads, and a lidar stand-in until the team map is merged.

:class:`MapView` is all :mod:`alica.skills.exploration` needs of a map:
``resolution``, ``origin`` and ``occupancy()`` (int8: -1 unknown, 0 free,
1 occupied). The team's log-odds map (``alica.skills.mapping.LogOddsGrid``,
from ``team_map(world_model)``) offers these members.

:func:`current_map` is the one place that gets the map for a skill. Until the
team map is merged it is :class:`LidarMap`: the agent's own grid in its
scratch space, fed by the robot's 2-D lidar (:func:`alica.worldsim.sensors.lidar_scan`).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from alica.skills.context import SkillContextLike
from alica.worldsim.interface import MobileRobot

__all__ = ["LidarMap", "MapView", "current_map"]

#: Cell size of the stand-in map in metres.
STANDIN_RESOLUTION = 0.1
#: Range in metres of the scans the robot adds to the team map while it explores.
MAPPING_RANGE = 10.0
#: Range in metres the stand-in reads of each lidar scan (beyond it nothing counts as seen).
STANDIN_RANGE = 6.0
#: Rays per stand-in scan.
STANDIN_RAYS = 360
#: Scratch key of the stand-in map.
SCRATCH_KEY = "exploration_map"


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


class LidarMap:
    """A plain occupancy grid fed by lidar scans (a stand-in for the team map).

    Args:
        bounds: ``(xmin, ymin, xmax, ymax)`` in metres.
        resolution: cell size in metres.
    """

    def __init__(self, bounds: tuple[float, float, float, float], resolution: float = STANDIN_RESOLUTION) -> None:
        from alica.worldsim.sensors import unknown_grid

        self.grid = unknown_grid(bounds, resolution)
        self.last_scan = -float("inf")

    @property
    def resolution(self) -> float:
        return float(self.grid.resolution)

    @property
    def origin(self) -> tuple[float, float]:
        return float(self.grid.origin[0]), float(self.grid.origin[1])

    def occupancy(self) -> np.ndarray:
        from alica.worldsim.grid import UNKNOWN

        cells = self.grid.cells
        out = cells.astype(np.int8)
        out[cells == UNKNOWN] = -1
        return out

    def scan(self, robot: MobileRobot, max_range: float = STANDIN_RANGE) -> None:
        """Add one lidar scan of ``robot`` taken now, read to ``max_range`` metres."""
        from alica.worldsim.sensors import lidar_scan, scan_to_grid

        reach = min(float(max_range), float(robot.spec.lidar_range))
        ranges = lidar_scan(robot, STANDIN_RAYS, reach)  # type: ignore[arg-type]
        scan_to_grid(self.grid, robot, ranges, reach)  # type: ignore[arg-type]


def current_map(
    context: SkillContextLike, robot: MobileRobot, world_bounds: tuple[float, float, float, float]
) -> MapView:
    """The map the exploration works on now: the team map, with this robot's scan of this moment in it.

    The robot maps as it explores: its scan goes into its own layer of the team
    map (:func:`alica.skills.mapping.map_scan`, at its pose estimate), and the
    frontiers come from :func:`alica.skills.mapping.team_map`, every robot's
    layer summed, so what a teammate saw is explored by nobody again. A skill
    run without a world model (alone, with nowhere to share) keeps a
    :class:`LidarMap` of its own in its scratch space instead.
    """
    from alica.skills.mapping import map_scan, robot_mapper, team_map

    world_model = context.world_model
    if world_model is not None:
        existing = team_map(world_model)
        resolution = existing.resolution if existing is not None else STANDIN_RESOLUTION
        mapper = robot_mapper(context, robot.name, world_bounds, resolution)
        map_scan(robot, mapper, max_range=MAPPING_RANGE, now=context.now())
        grid = team_map(world_model)
        if grid is not None:
            return grid
    found = context.scratch.get(SCRATCH_KEY)
    if not isinstance(found, LidarMap):
        found = LidarMap(world_bounds)
        context.scratch[SCRATCH_KEY] = found
    found.scan(robot)
    return found
