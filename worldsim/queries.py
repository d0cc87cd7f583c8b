"""Geometric questions about a world: obstacle footprints, free space, contacts, the blocks' IPC facts.

Used by :class:`~alica.worldsim.world.World` (call them through its methods:
skills ask :meth:`~alica.worldsim.interface.RobotWorld.blocker` and
:meth:`~alica.worldsim.interface.RobotWorld.blocks_facts` of the robot interface).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from alica.worldsim.grid import Obstacle2D

if TYPE_CHECKING:
    from alica.worldsim.interface import RobotWorld
    from alica.worldsim.objects import WorldObject

__all__ = ["BodiedRobot", "BodiedWorld", "blocker", "blocks_facts", "body_names", "contacts", "obstacles"]


class _BodiedArm(Protocol):
    """An arm as the geometric questions see it: its body and what it holds."""

    @property
    def body_id(self) -> int:
        """The arm's pybullet body."""
        ...

    @property
    def held(self) -> WorldObject | None:
        """The object in the gripper, or ``None``."""
        ...


class BodiedRobot(Protocol):
    """A robot as the geometric questions see it: its base body and its arm."""

    @property
    def body_id(self) -> int:
        """The pybullet body of the base."""
        ...

    @property
    def arm(self) -> _BodiedArm | None:
        """The arm, or ``None``."""
        ...


class BodiedWorld(Protocol):
    """The world as :func:`obstacles`, :func:`body_names` and :func:`contacts` read it (the concrete
    :class:`~alica.worldsim.world.World` satisfies it, checked by mypy where it hands itself to them)."""

    @property
    def client(self) -> Any:
        """The world's own pybullet client."""
        ...

    @property
    def objects(self) -> Mapping[str, WorldObject]:
        """The objects by name."""
        ...

    @property
    def robots(self) -> Mapping[str, BodiedRobot]:
        """The robots by name."""
        ...

    def _held_bodies(self) -> set[int]:
        """The bodies of the objects the arms hold now."""
        ...


def obstacles(world: BodiedWorld, *, include_samples: bool = False) -> list[Obstacle2D]:
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


def blocks_facts(world: RobotWorld, tolerance: float | None = None) -> set[tuple[str, ...]]:
    """The IPC blocks-world facts of the simulated state.

    ``("on", x, y)``, ``("ontable", x)``, ``("clear", x)``, ``("holding", robot, x)``
    and ``("handempty", robot)`` for every robot with an arm. A block is on another
    when its bottom lies within ``tolerance`` of the other's top and its centre
    over the other; on the table when its bottom is within ``tolerance`` of the
    ground or a table top. A falling block is neither.

    Args:
        world: the world to read.
        tolerance: vertical tolerance in metres (default 30 % of the smallest block).
    """
    blocks = {n: o for n, o in world.objects.items() if o.kind == "block"}
    facts: set[tuple[str, ...]] = set()
    held: dict[str, str] = {}
    for rname, robot in world.robots.items():
        if robot.arm is None:
            continue
        obj = robot.arm.held
        if obj is not None and obj.kind == "block":
            facts.add(("holding", rname, obj.name))
            held[obj.name] = rname
        elif obj is None:
            facts.add(("handempty", rname))
    if not blocks:
        return facts
    tol = 0.3 * min(o.size for o in blocks.values()) if tolerance is None else float(tolerance)
    boxes = {n: o.aabb() for n, o in blocks.items() if n not in held}
    tables = [o for o in world.objects.values() if o.kind == "table"]
    covered: set[str] = set()
    for x, (lo_x, hi_x) in boxes.items():
        cx, cy = 0.5 * (lo_x[0] + hi_x[0]), 0.5 * (lo_x[1] + hi_x[1])
        bottom = lo_x[2]
        support = None
        for y, (lo_y, hi_y) in boxes.items():
            if y != x and abs(bottom - hi_y[2]) <= tol and lo_y[0] <= cx <= hi_y[0] and lo_y[1] <= cy <= hi_y[1]:
                support = y
                break
        if support is not None:
            facts.add(("on", x, support))
            covered.add(support)
            continue
        floor = 0.0
        for table in tables:
            lo_t, hi_t = table.aabb()
            if lo_t[0] <= cx <= hi_t[0] and lo_t[1] <= cy <= hi_t[1]:
                floor = max(floor, hi_t[2])
        if abs(bottom - floor) <= tol:
            facts.add(("ontable", x))
    for x in boxes:
        if x not in covered:
            facts.add(("clear", x))
    return facts


def body_names(world: BodiedWorld) -> dict[int, str]:
    """The name of the robot or object each pybullet body belongs to."""
    names = {o.body_id: n for n, o in world.objects.items()}
    for n, r in world.robots.items():
        names[r.body_id] = n
        if r.arm is not None:
            names[r.arm.body_id] = n
    return names


def contacts(world: BodiedWorld, robot: BodiedRobot, *, margin: float = 0.0, include_ground: bool = False) -> set[str]:
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
