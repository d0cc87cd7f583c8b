"""Geometric questions about a world: obstacle footprints, free space, contacts.

Used by :class:`~alica.worldsim.world.World` (call them through its methods).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from alica.worldsim.grid import Obstacle2D

if TYPE_CHECKING:
    from alica.worldsim.interface import RobotWorld
    from alica.worldsim.robots import Robot
    from alica.worldsim.world import World

__all__ = ["blocker", "body_names", "contacts", "obstacles"]


def obstacles(world: World, *, include_samples: bool = False) -> list[Obstacle2D]:
    """Footprints of rocks, tables and blocks (and samples), leaving out held objects."""
    held = world._held_bodies()
    out: list[Obstacle2D] = []
    for obj in world.objects.values():
        if obj.kind in ("rock", "table", "block") or (include_samples and obj.kind == "sample"):
            if obj.body_id in held:
                continue
            fp = obj.footprint()
            if fp is not None:
                out.append(fp)
    return out


def blocker(world: RobotWorld, x: float, y: float, radius: float) -> str | None:
    """What a circle at ``(x, y)`` would overlap: a robot, a rock, table, block or sample; or ``None``.

    It reads only the robot interface, so skills may ask it of any :class:`~alica.worldsim.interface.RobotWorld`.
    """
    for other in world.robots.values():
        if math.hypot(x - other.pose[0], y - other.pose[1]) < radius + other.spec.radius:
            return f"robot '{other.name}'"
    held = {r.arm.held.name for r in world.robots.values() if r.arm is not None and r.arm.held is not None}
    for obj in world.objects.values():
        if obj.kind in ("rock", "table", "block", "sample") and obj.name not in held:
            fp = obj.footprint()
            if fp is not None and float(fp.distance(np.array(x), np.array(y))) < radius:
                return f"{obj.kind} '{obj.name}'"
    return None


def body_names(world: World) -> dict[int, str]:
    """The name of the robot or object each pybullet body belongs to."""
    names = {o.body_id: n for n, o in world.objects.items()}
    for n, r in world.robots.items():
        names[r.body_id] = n
        if r.arm is not None:
            names[r.arm.body_id] = n
    return names


def contacts(world: World, robot: Robot, *, margin: float = 0.0, include_ground: bool = False) -> set[str]:
    """Names of what the robot's base, arm or held object touches (closest points within ``margin``)."""
    c = world.client
    own = [robot.body_id]
    if robot.arm is not None:
        own.append(robot.arm.body_id)
        if robot.arm.held is not None:
            own.append(robot.arm.held.body_id)
    names = body_names(world)
    found: set[str] = set()
    c.performCollisionDetection()
    for body in own:
        for link in range(-1, c.getNumJoints(body)):
            lo, hi = c.getAABB(body, link)
            lo = [v - margin for v in lo]
            hi = [v + margin for v in hi]
            for other, _ in c.getOverlappingObjects(lo, hi) or ():
                name = names.get(other)
                if other in own or name is None or name in found:
                    continue
                if not include_ground and name in world.objects and world.objects[name].kind == "terrain":
                    continue
                if c.getClosestPoints(body, other, margin, linkIndexA=link):
                    found.add(name)
    return found
