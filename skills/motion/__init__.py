"""Base motion for round robots: occupancy-grid validity, OMPL planning, path following.

Importing this package imports OMPL and FCL (``skills/__init__.py`` does not import it).

Example:
    >>> from alica.worldsim.grid import OccupancyGrid, Obstacle2D
    >>> grid = OccupancyGrid.from_obstacles([Obstacle2D("circle", 0.0, 0.0, radius=1.0)], (-5, -5, 5, 5))
    >>> result = plan_path((-4.0, 0.0, 0.0), (4.0, 0.0), grid, 0.3)
    >>> result.status, result.length > 8.0
    ('exact', True)
"""

from __future__ import annotations

from alica.skills.motion.base_paths import STATUSES, PathResult, configure_ompl, plan_path
from alica.skills.motion.exact import FclChecker
from alica.skills.motion.follow import PathFollower, escape_goal
from alica.skills.motion.reach import coarse_reachable
from alica.skills.motion.validity import GridChecker, SegmentValidator, default_margin, densify

__all__ = [
    "STATUSES",
    "FclChecker",
    "GridChecker",
    "PathFollower",
    "PathResult",
    "SegmentValidator",
    "coarse_reachable",
    "configure_ompl",
    "default_margin",
    "densify",
    "escape_goal",
    "plan_path",
]
