"""The blocks-world rules of the manipulation skills: the IPC blocks domain on the simulated state.

Pickup, Unstack, Putdown and Stack (:mod:`alica.skills.handling`) and the
opponents' skill (:mod:`alica.skills.opponent`) keep the IPC blocks domain's
preconditions and effects (``clear``, ``on``, ``ontable``, ``holding``,
``handempty``). The facts they check come from the robot interface
(:meth:`~alica.worldsim.interface.RobotWorld.blocks_facts`: perfect perception
in the simulator), checked just before and after acting, since a teammate or an
opponent may have moved a block meanwhile. The arm's motion knows nothing of
blocks (:mod:`alica.skills.arm_motion`); these rules are the skills' hooks.

Each check returns why the action cannot go on (a sentence for the skill's
failure), or ``None``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from alica.skills.arm_world import REACH, inside_field, mount_ahead

if TYPE_CHECKING:
    from alica.skills.world_skill import WorldSkill
    from alica.worldsim.interface import MobileRobot, RobotWorld

__all__ = [
    "EDGE_ROOM",
    "PUTDOWN_ROOM",
    "PUTDOWN_TURNS",
    "Facts",
    "blocks_state",
    "grip_refusal",
    "pickup_refusal",
    "putdown_spots",
    "spread_spots",
    "stack_refusal",
    "stacked_refusal",
    "unstack_refusal",
    "write_stacked",
    "write_unstacked",
]

Facts = set[tuple[str, ...]]

#: Turns (rad) from straight ahead tried for a free spot to put a block down.
PUTDOWN_TURNS = (0.0, 0.6, -0.6, 1.2, -1.2, 1.8, -1.8, 3.14)
#: Free room (m) a put-down spot needs around it.
PUTDOWN_ROOM = 0.15
#: Room (m) between a put-down spot and the field's edge: robots must find sides of the block to stand on.
EDGE_ROOM = 0.8
#: Spacing (m) of the grid of spots a spread put-down looks through (:func:`spread_spots`).
SPREAD_STEP = 0.2


def blocks_state(world: RobotWorld) -> Facts:
    """The IPC blocks facts now, as the robot interface senses them."""
    return set(world.blocks_facts())


def spread_spots(
    world: RobotWorld,
    robot: MobileRobot,
    spread: float,
    taken: Sequence[tuple[float, float]] = (),
    reachable: Sequence[tuple[float, float]] | None = None,
) -> list[tuple[float, float]]:
    """Spots at least ``spread`` metres from every block lying in the world and from ``taken``, nearest the arm first.

    A block put down there starts a stack of its own, with room on every side
    for robots to stand while others work at the stacks around: a team of
    several robots does not crowd one corner of the field. ``taken`` are
    points teammates will stand on (their reserved stand-off points), so two
    robots putting blocks down at the same time choose places apart. The spots
    come first from :func:`putdown_spots` (the arm reaches them where the robot
    stands; ``reachable`` gives them when the caller has them already), then from a grid of :data:`SPREAD_STEP` metres, :data:`EDGE_ROOM`
    inside the field and clear of robots by :data:`PUTDOWN_ROOM`, nearest first
    to the point straight ahead at the arm's reach (the least driving); none
    when the field has no such room left (the caller then puts the block down
    where it stands).
    """
    held = {r.arm.held.name for r in world.robots.values() if r.arm is not None and r.arm.held is not None}
    lying = [
        (float(obj.position()[0]), float(obj.position()[1]))
        for obj in world.objects.values()
        if obj.kind == "block" and obj.name not in held
    ]
    avoid = [*lying, *taken]

    def apart(spot: tuple[float, float]) -> bool:
        return all(math.hypot(spot[0] - ax, spot[1] - ay) >= spread for ax, ay in avoid)

    reach = putdown_spots(world, robot) if reachable is None else reachable
    near = [spot for spot in reach if apart(spot)]  # the arm reaches them from here
    xmin, ymin, xmax, ymax = world.bounds
    x, y, yaw = robot.pose
    ahead = REACH + mount_ahead(robot)
    x0, y0 = x + ahead * math.cos(yaw), y + ahead * math.sin(yaw)  # where the arm reaches now: the least driving
    found: list[tuple[float, float, float]] = []
    nx = int((xmax - xmin - 2 * EDGE_ROOM) / SPREAD_STEP) + 1
    ny = int((ymax - ymin - 2 * EDGE_ROOM) / SPREAD_STEP) + 1
    for i in range(max(nx, 0)):
        for j in range(max(ny, 0)):
            spot = (xmin + EDGE_ROOM + i * SPREAD_STEP, ymin + EDGE_ROOM + j * SPREAD_STEP)
            if apart(spot) and world.blocker(spot[0], spot[1], PUTDOWN_ROOM) is None:
                found.append((math.hypot(spot[0] - x0, spot[1] - y0), spot[0], spot[1]))
    return [*near, *((sx, sy) for _, sx, sy in sorted(found))]


def pickup_refusal(facts: Facts, block: str, *, from_table: bool) -> str | None:
    """IPC pickup: the block is clear and (``from_table``) on the table."""
    if ("clear", block) not in facts:
        return f"precondition clear({block}) does not hold: something lies on it"
    if ("ontable", block) not in facts and from_table:
        return f"precondition ontable({block}) does not hold: use Unstack to take it off a block"
    return None


def unstack_refusal(facts: Facts, block: str, below: object) -> str | None:
    """IPC unstack (besides pickup's clear): the block lies on ``below``."""
    if ("on", block, below) not in facts:
        return f"precondition on({block}, {below}) does not hold"
    return None


def stack_refusal(facts: Facts, below: str) -> str | None:
    """IPC stack (besides holding the block): the block below is clear."""
    if ("clear", below) not in facts:
        return f"precondition clear({below}) does not hold: something lies on it"
    return None


def grip_refusal(facts: Facts, block: str) -> str | None:
    """Just before the fingers close: still clear (lifting it would throw off what was put on it)."""
    if ("clear", block) not in facts:
        return f"something was put on {block} before the grip"
    return None


def stacked_refusal(facts: Facts, block: str, below: str) -> str | None:
    """After a stack: the block rests on ``below``."""
    if ("on", block, below) not in facts:
        return f"{block} did not come to rest on {below}"
    return None


def write_unstacked(skill: WorldSkill, block: str, below: str) -> None:
    """The effects of unstack besides holding: not ``on(block, below)``, ``clear(below)``."""
    skill.write(False, "on", block, below)
    skill.write(True, "clear", below)


def write_stacked(skill: WorldSkill, block: str, below: str) -> None:
    """The effects of stack besides the release: ``clear(block)``, ``on(block, below)``, not ``clear(below)``."""
    skill.write(True, "clear", block)
    skill.write(True, "on", block, below)
    skill.write(False, "clear", below)


def putdown_spots(world: RobotWorld, robot: MobileRobot) -> list[tuple[float, float]]:
    """The spots at the arm's reach where ``robot`` could put a block down, straight ahead first, then turned.

    Only spots with :data:`PUTDOWN_ROOM` free of objects and other robots are listed, and
    only those :data:`EDGE_ROOM` inside the field: a robot stands beside a block to take
    it, and a block at the edge leaves it few sides to stand on.
    """
    x, y, yaw = robot.pose
    ahead = REACH + mount_ahead(robot)
    spots = []
    for turn in PUTDOWN_TURNS:
        spot = (x + ahead * math.cos(yaw + turn), y + ahead * math.sin(yaw + turn))
        if not inside_field(world, spot, EDGE_ROOM):
            continue
        hit = world.blocker(spot[0], spot[1], PUTDOWN_ROOM)
        if hit is None or hit == f"robot '{robot.name}'":
            spots.append(spot)
    return spots
