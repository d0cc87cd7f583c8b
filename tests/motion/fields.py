"""Random rock fields for the motion tests and bench (circles on a 40 x 40 m field)."""

from __future__ import annotations

import math

import numpy as np

from alica.worldsim.grid import Obstacle2D, OccupancyGrid

BOUNDS = (-20.0, -20.0, 20.0, 20.0)
CORNER_A = (-19.0, -19.0)
CORNER_B = (19.0, 19.0)


def rocks(
    seed: int, count: int, keep_free: tuple[tuple[float, float], ...] = (CORNER_A, CORNER_B), free_radius: float = 2.0
) -> list[Obstacle2D]:
    """``count`` circular rocks (radius 0.2-1.0 m), none within ``free_radius`` of the ``keep_free`` points."""
    rng = np.random.default_rng(seed)
    out: list[Obstacle2D] = []
    while len(out) < count:
        x, y = rng.uniform(-20.0, 20.0, 2)
        r = float(rng.uniform(0.2, 1.0))
        if all(math.hypot(x - px, y - py) > free_radius + r for px, py in keep_free):
            out.append(Obstacle2D("circle", float(x), float(y), radius=r, name=f"rock{len(out)}"))
    return out


def field(seed: int, count: int, resolution: float = 0.05) -> tuple[list[Obstacle2D], OccupancyGrid]:
    """Rocks and their grid."""
    obstacles = rocks(seed, count)
    return obstacles, OccupancyGrid.from_obstacles(obstacles, BOUNDS, resolution)
