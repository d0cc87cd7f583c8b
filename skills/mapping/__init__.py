"""Mapping and localization: a log-odds occupancy grid from lidar scans, one team map, scan matching.

* :class:`LogOddsGrid` (:mod:`.grid`): the grid, ray tracing a scan, ``occupancy()``;
* :func:`team_map`, :class:`RobotMapper` (:mod:`.sharing`): each robot's layer shared
  through the world model tile by tile, the team map as the sum of the layers;
* :func:`match_scan` (:mod:`.matching`): ICP of a scan against a map;
* the skills :class:`BuildMap` and :class:`Localize` (:mod:`.skills`), and
  :func:`robot_mapper` / :func:`map_scan` for skills that map as they go.
"""

from __future__ import annotations

from alica.skills.mapping.grid import FREE, OCCUPIED, TILE, UNKNOWN, LogOddsGrid
from alica.skills.mapping.matching import Match, match_scan
from alica.skills.mapping.sharing import RobotMapper, team_map, team_map_changes, team_resolution
from alica.skills.mapping.skills import MAPPER_KEY, BuildMap, Localize, lidar, map_scan, rays_for, robot_mapper

__all__ = [
    "FREE",
    "MAPPER_KEY",
    "OCCUPIED",
    "TILE",
    "UNKNOWN",
    "BuildMap",
    "Localize",
    "LogOddsGrid",
    "Match",
    "RobotMapper",
    "lidar",
    "map_scan",
    "match_scan",
    "rays_for",
    "robot_mapper",
    "team_map",
    "team_map_changes",
    "team_resolution",
]
