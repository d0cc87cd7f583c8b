"""Exact validity for a round robot with FCL: a cylinder against obstacles and other robots.

Used to re-check final paths (:func:`alica.skills.motion.plan_path` ``obstacles_exact``) and as
the FCL-only peer in ``bench/motion_planning.py``. FCL quaternions are (w, x, y, z).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import fcl
import numpy as np
import trimesh
from ompl import base as ob

from alica.skills.motion.validity import Robot, check_robots, densify
from alica.worldsim.grid import Obstacle2D

__all__ = ["FclChecker"]


def _yaw_quat(yaw: float) -> np.ndarray:
    """FCL quaternion (w, x, y, z) for a rotation about z."""
    return np.array([math.cos(0.5 * yaw), 0.0, 0.0, math.sin(0.5 * yaw)])


class FclChecker:
    """Exact validity: an FCL cylinder for the robot against obstacles and other robots.

    Args:
        obstacles: :class:`~alica.worldsim.grid.Obstacle2D` (circles become cylinders, boxes boxes,
            both taller than the robot) and ``trimesh.Trimesh`` rocks in world coordinates.
        robot_radius: Robot radius in metres (>= 0; 0 is treated as 1 mm).
        robot_height: Height of the robot cylinder, standing on z = 0.
        mesh_mode: ``"convex"`` (``fcl.Convex``; for convex rocks) or ``"bvh"`` (triangle mesh).

    Raises:
        ValueError: On a negative radius, a non-positive height, an unknown mesh mode or obstacle type.
    """

    def __init__(
        self,
        obstacles: Iterable[Obstacle2D | trimesh.Trimesh],
        robot_radius: float,
        *,
        robot_height: float = 1.0,
        mesh_mode: str = "convex",
    ) -> None:
        if not (robot_radius >= 0.0 and math.isfinite(robot_radius)):
            raise ValueError(f"robot_radius must be a finite value >= 0 metres, got {robot_radius}")
        if not robot_height > 0.0:
            raise ValueError(f"robot_height must be > 0 metres, got {robot_height}")
        if mesh_mode not in ("convex", "bvh"):
            raise ValueError(f"mesh_mode must be 'convex' or 'bvh', got {mesh_mode!r}")
        self.robot_radius = float(robot_radius)
        self.robot_height = float(robot_height)
        self._z = 0.5 * robot_height
        self._tall = robot_height + 2.0
        self._objects = [self._make(o, mesh_mode) for o in obstacles]
        self._manager = fcl.DynamicAABBTreeCollisionManager()
        if self._objects:
            self._manager.registerObjects(self._objects)
        self._manager.setup()
        self._robot = fcl.CollisionObject(fcl.Cylinder(max(self.robot_radius, 1e-3), robot_height), fcl.Transform())
        self._others: list[fcl.CollisionObject] = []
        self._other_radii: list[float] = []
        self._robot_manager = fcl.DynamicAABBTreeCollisionManager()
        self._robot_manager.setup()
        self.robots: tuple[Robot, ...] = ()

    def _make(self, o: Obstacle2D | trimesh.Trimesh, mesh_mode: str) -> fcl.CollisionObject:
        if isinstance(o, Obstacle2D):
            pos = np.array([o.x, o.y, self._z])
            if o.kind == "circle":
                return fcl.CollisionObject(fcl.Cylinder(o.radius, self._tall), fcl.Transform(pos))
            geom = fcl.Box(2.0 * o.half_x, 2.0 * o.half_y, self._tall)
            return fcl.CollisionObject(geom, fcl.Transform(_yaw_quat(o.yaw), pos))
        if isinstance(o, trimesh.Trimesh):
            verts = np.asarray(o.vertices, dtype=float)
            faces = np.asarray(o.faces, dtype=np.int64)
            if mesh_mode == "convex":
                flat = np.hstack([np.full((len(faces), 1), 3, dtype=np.int64), faces]).reshape(-1)
                geom = fcl.Convex(verts, len(faces), flat)
            else:
                geom = fcl.BVHModel()
                geom.beginModel(len(verts), len(faces))
                geom.addSubModel(verts, faces)
                geom.endModel()
            return fcl.CollisionObject(geom, fcl.Transform())
        raise ValueError(f"obstacles must be Obstacle2D or trimesh.Trimesh, got {type(o).__name__}")

    @property
    def obstacle_count(self) -> int:
        """Number of static obstacles."""
        return len(self._objects)

    def set_other_robots(self, robots: Iterable[Sequence[float]]) -> None:
        """Replace the other robots (``(x, y, radius)``): moved in place, added or removed as needed."""
        robots = check_robots(robots)
        while len(self._others) > len(robots):
            self._robot_manager.unregisterObject(self._others.pop())
            self._other_radii.pop()
        for k, (x, y, r) in enumerate(robots):
            r = max(r, 1e-3)
            pos = np.array([x, y, self._z])
            if k < len(self._others) and self._other_radii[k] == r:
                self._others[k].setTranslation(pos)
                continue
            obj = fcl.CollisionObject(fcl.Cylinder(r, self.robot_height), fcl.Transform(pos))
            if k < len(self._others):
                self._robot_manager.unregisterObject(self._others[k])
                self._others[k], self._other_radii[k] = obj, r
            else:
                self._others.append(obj)
                self._other_radii.append(r)
            self._robot_manager.registerObject(obj)
        self._robot_manager.update()
        self.robots = robots

    def __call__(self, state: ob.State) -> bool:
        """OMPL state validity: a Python ``bool`` for an SE2 state."""
        return self.valid_xy(state.getX(), state.getY())

    def valid_xy(self, x: float, y: float) -> bool:
        """Whether the robot cylinder at (x, y) touches no obstacle and no other robot."""
        self._robot.setTranslation(np.array([x, y, self._z]))
        data = fcl.CollisionData()
        self._manager.collide(self._robot, data, fcl.defaultCollisionCallback)
        if data.result.is_collision:
            return False
        if self._others:
            data = fcl.CollisionData()
            self._robot_manager.collide(self._robot, data, fcl.defaultCollisionCallback)
            return not data.result.is_collision
        return True

    def first_collision(self, path_xy: np.ndarray, step: float = 0.05) -> tuple[float, float] | None:
        """The first sample (x, y) of the polyline densified at ``step`` that collides, else None."""
        for x, y in densify(path_xy, step):
            if not self.valid_xy(float(x), float(y)):
                return (float(x), float(y))
        return None

    def collisions(self, path_xy: np.ndarray, step: float = 0.05) -> np.ndarray:
        """All samples of the polyline densified at ``step`` that collide; a (K, 2) array."""
        pts = densify(path_xy, step)
        bad = [k for k, (x, y) in enumerate(pts) if not self.valid_xy(float(x), float(y))]
        return pts[bad].reshape(-1, 2)
