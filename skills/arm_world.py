"""What the arm skills read and write about the world: objects by name, places, the field, outcome facts.

Shared by the monolithic manipulation skills (:mod:`alica.skills.handling`),
the steps of the Pickup and Putdown plans (:mod:`alica.skills.arm_steps`) and
the blocks-world rules (:mod:`alica.skills.blocks_rules`). They read the world
through the robot interface only (:class:`~alica.worldsim.interface.RobotWorld`).
"""

from __future__ import annotations

import math

from alica.errors import SkillError
from alica.skills.arm_scratch import NAMES
from alica.skills.world_skill import WorldSkill, distance
from alica.worldsim.interface import MobileRobot, RobotWorld, WorldThing

#: An object name the world does not know stands for the sample or block nearest where the world
#: model puts it (``pos(name)``, e.g. from perception), within this many metres.
ASSOCIATION = 0.3
#: Horizontal distance from the arm's base at which the arm works best.
REACH = 0.55
#: The footprint radius (m) counted for a sample the team knows of (a container's radius and some room).
SAMPLE_ROOM = 0.05


def mount_ahead(robot: MobileRobot) -> float:
    """How far ahead of the base centre the arm is mounted (metres; 0 without an arm)."""
    return float(robot.arm.mount_offset[0]) if robot.arm is not None else 0.0


def inside_field(world: RobotWorld, xy: tuple[float, float], margin: float) -> bool:
    """Whether ``xy`` lies at least ``margin`` metres inside the world's field."""
    xmin, ymin, xmax, ymax = world.bounds
    return xmin + margin <= xy[0] <= xmax - margin and ymin + margin <= xy[1] <= ymax - margin


def place_area(skill: WorldSkill, target: object) -> tuple[float, float, float] | None:
    """``(x, y, radius)`` of the area ``target`` names when it is one (a collection point such as ``pos(g)``), else None.

    Several objects are put down in an area, each on a free spot in it (see :func:`area_spots`).
    """
    if not isinstance(target, str):
        return None
    name = target.strip().removeprefix("pos(").removesuffix(")").strip()
    obj = skill.world.objects.get(name)
    if obj is None or obj.kind != "collection_point" or not obj.radius > 0.0:
        return None
    x, y = skill.resolve_position(target)
    return x, y, float(obj.radius)


def area_spots(
    world: RobotWorld,
    robot: MobileRobot,
    area: tuple[float, float, float],
    room: float,
    taken: list[tuple[float, float, float]] | None = None,
) -> list[tuple[float, float]]:
    """Free spots (``room`` metres around them) in a round ``area``: its centre first, then further out.

    The spots are the centre and two rings of eight, at a third and two thirds
    of the radius; on a ring the spots nearest to ``robot`` come first. Free
    means clear of the discs ``taken`` (``(x, y, radius)``: what the team knows
    lies or stands there, :func:`known_discs`); without them, clear of
    everything in the world (a known layout: the blocks world's overhead camera).
    """
    cx, cy, radius = area
    x, y, _ = robot.estimate
    spots = [(cx, cy)]
    for f in (1.0 / 3.0, 2.0 / 3.0):
        ring = [
            (cx + f * radius * math.cos(k * math.pi / 4.0), cy + f * radius * math.sin(k * math.pi / 4.0))
            for k in range(8)
        ]
        spots += sorted(ring, key=lambda spot: distance(spot, (x, y)))
    if taken is not None:
        return [
            spot for spot in spots if all(math.hypot(spot[0] - tx, spot[1] - ty) >= room + tr for tx, ty, tr in taken)
        ]
    return [spot for spot in spots if world.blocker(spot[0], spot[1], room) is None]


def known_discs(skill: WorldSkill, skip: str = "") -> list[tuple[float, float, float]]:
    """What the team knows lies or stands on the ground, as ``(x, y, radius)``.

    The samples the team's perception found (objects of type ``Sample`` with a
    ``pos``; those put down carry the ``pos`` VerifyPlaced measured), but
    ``skip`` (the one the robot holds), with :data:`SAMPLE_ROOM`; and the
    teammates' shared poses (:mod:`alica.skills.team_poses`).
    """
    from alica.skills.team_poses import teammate_discs

    wm = skill.world_model
    out = teammate_discs(skill)
    if wm is None:
        return out
    for name in wm.objects("Sample"):
        if name == skip:
            continue
        known = wm.lookup("pos", (name,))
        if isinstance(known, (tuple, list)) and len(known) >= 2:
            out.append((float(known[0]), float(known[1]), SAMPLE_ROOM))
    return out


def find_object(skill: WorldSkill, name: object) -> WorldThing:
    """The world object ``name``; a name the world does not know is the sample or block at ``pos(name)``.

    Perception names the samples it finds by itself (``green_white_red``, say);
    the object Grasp took under such a name (``scratch["names"]``), else the
    one nearest to the world model's position of it within :data:`ASSOCIATION`, is meant.

    Raises:
        SkillError: no such object, and none where the world model puts ``name``.
    """
    objects = skill.world.objects
    taken = NAMES.get(skill.context.scratch) if skill.context is not None else None  # what Grasp took under this name
    if isinstance(name, str) and taken is not None and taken.names.get(name) in objects:
        return objects[taken.names[name]]
    if isinstance(name, str) and name not in objects and skill.world_model is not None:
        known = skill.world_model.lookup("pos", (name,))
        if isinstance(known, (tuple, list)) and len(known) >= 2:
            xy = (float(known[0]), float(known[1]))
            near = sorted(
                (distance((float(o.position()[0]), float(o.position()[1])), xy), n)
                for n, o in objects.items()
                if o.kind in ("sample", "block")
            )
            if near and near[0][0] <= ASSOCIATION:
                return objects[near[0][1]]
            raise SkillError(
                f"skill '{skill.name}': no object lies within {ASSOCIATION:g} m of where the world model puts "
                f"{name!r} ({xy[0]:.2f}, {xy[1]:.2f})"
            )
    return skill.object_named(name)


def write_held(skill: WorldSkill, name: str) -> None:
    """The outcome facts of the robot holding ``name``: ``holding(self, name)``; not ``handempty``, ``onground``, ``ontable``, ``clear``."""
    me = skill.robot.name
    for positive, fact in (
        (False, ("ontable", name)),
        (False, ("clear", name)),
        (False, ("handempty", me)),
        (True, ("holding", me, name)),
        (False, ("onground", name)),
    ):
        skill.write(positive, *fact)


def write_released(skill: WorldSkill, name: str) -> None:
    """The outcome facts of the robot letting ``name`` go: not ``holding(self, name)``, ``handempty(self)``."""
    me = skill.robot.name
    skill.write(False, "holding", me, name)
    skill.write(True, "handempty", me)


def write_placed(skill: WorldSkill, name: str, obj: WorldThing, target: object) -> None:
    """The outcome facts of ``name`` (the world's ``obj``) lying at ``target`` (None: anywhere).

    ``clear(name)``; ``on(name, target)`` on a target block, else ``ontable``
    (a block) or ``onground``; ``at(name, place)`` when the target names a place (``g`` or ``pos(g)``).
    """
    skill.write(True, "clear", name)
    below = skill.world.objects.get(target) if isinstance(target, str) else None
    if isinstance(target, str) and below is not None and below.kind == "block":
        skill.write(True, "on", name, target)
        skill.write(False, "clear", target)
    elif obj.kind == "block":
        skill.write(True, "ontable", name)
    else:
        skill.write(True, "onground", name)
    if isinstance(target, str):
        skill.write(True, "at", name, target.strip().removeprefix("pos(").removesuffix(")").strip())
