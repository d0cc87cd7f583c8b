"""Stand-off reservations: where a robot is about to work, told to its teammates.

A robot that drives to a work site (a stack of blocks, a sample) to work
there *reserves* the point it will stand on: it writes
``standoff(robot) = (x, y)`` into its world model, which the team's
replicas share. Teammates choose their own stand-off points and waiting
places clear of the reserved ones, and a robot that waits on a point that
someone reserved moves away (:class:`alica.skills.waiting.WaitAside`).
Reservations carry a time to live and are refreshed while the robot works, so
a crashed robot's reservation lapses.

A skill run without a world model (a skill test, ``alica skill run``) keeps
the reservations in the world's cache instead, which every robot of that
world sees at once.
"""

from __future__ import annotations

import math
from typing import Protocol

from alica.skills.world_skill import world_cache
from alica.worldmodel.protocol import WorldModelLike
from alica.worldsim.interface import MobileRobot, RobotWorld

#: The world-model function of reservations: ``standoff(robot) = (x, y)``.
STANDOFF = "standoff"
#: Seconds a reservation lives unless refreshed.
RESERVATION_TTL = 8.0
#: Seconds between two refreshes of a held reservation.
REFRESH_PERIOD = 2.0


class _Skill(Protocol):
    @property
    def world(self) -> RobotWorld: ...
    @property
    def robot(self) -> MobileRobot: ...
    @property
    def world_model(self) -> WorldModelLike | None: ...
    def now(self) -> float: ...


def _local(world: RobotWorld) -> dict[str, tuple[float, float, float]]:
    """The reservations of a world without world models: robot -> (x, y, expiry)."""
    table: dict[str, tuple[float, float, float]] = world_cache(world).setdefault("standoff-reservations", {})
    return table


def reserve(skill: _Skill, xy: tuple[float, float]) -> None:
    """Reserve ``xy`` as the skill's robot's stand-off point (replacing its earlier one)."""
    point = (round(float(xy[0]), 3), round(float(xy[1]), 3))
    wm = skill.world_model
    if wm is None:
        _local(skill.world)[skill.robot.name] = (*point, skill.now() + RESERVATION_TTL)
        return
    try:
        wm.set(STANDOFF, skill.robot.name, value=point, ttl=RESERVATION_TTL)
    except ValueError:  # a world model without a clock: no time to live
        wm.set(STANDOFF, skill.robot.name, value=point)


def release(skill: _Skill) -> None:
    """Drop the skill's robot's reservation, if it has one."""
    wm = skill.world_model
    if wm is None:
        _local(skill.world).pop(skill.robot.name, None)
    elif wm.get(STANDOFF, skill.robot.name) is not None:
        wm.set(STANDOFF, skill.robot.name, value=None)


def reserved(skill: _Skill) -> list[tuple[float, float, float]]:
    """The other robots' reserved stand-off points as ``(x, y, radius of the robot that reserved it)``."""
    me = skill.robot
    world = skill.world
    out = []
    wm = skill.world_model
    local = _local(world) if wm is None else {}
    now = skill.now()
    for name, robot in sorted(world.robots.items()):
        if robot is me:
            continue
        point: tuple[object, ...] | None = None
        if wm is None:
            hit = local.get(name)
            point = hit[:2] if hit is not None and hit[2] > now else None
        else:
            value = wm.get(STANDOFF, name)
            point = tuple(value) if isinstance(value, (tuple, list)) and len(value) == 2 else None
        if point is None or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in point):
            continue
        out.append((float(point[0]), float(point[1]), float(robot.spec.radius)))  # type: ignore[arg-type]
    return out
