"""Arm motion for the manipulation skills: the planning scene made from the world, and a plan followed step by step.

One piece for everything an arm carries, lunar sample containers and blocks
alike; it knows no blocks-world rule (those are :mod:`alica.skills.blocks_rules`).
The planners themselves (:mod:`alica.skills.manipulation`, with OMPL) are
imported when first used, so importing the skills needs no OMPL.

- :func:`planning_scene`: the arm's planning scene
  (:meth:`~alica.worldsim.arm_interface.RobotArm.planning_scene`) with the
  objects near the arm as boxes (:func:`object_box`), minus what the planner
  adds itself and what the arm already touches.
- :class:`ArmMotion`: the steps of an arm plan (joint paths, ``"grip"``,
  ``"release"``) followed in simulated time, what was followed (to back out
  along it, :meth:`ArmMotion.back_out`), and whether the object was let go.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any, Literal

import numpy as np

from alica.skills.world_skill import distance
from alica.worldsim.arm_interface import ArmPlanningScene, RobotArm
from alica.worldsim.geometry import Box, quat_rotate
from alica.worldsim.interface import WorldThing

__all__ = [
    "JOINT_SPEED",
    "ArmMotion",
    "ArmStep",
    "arm_xy",
    "grasp_shape",
    "held_object_box",
    "object_box",
    "path_duration",
    "planning_scene",
]

#: Joint speed used to time arm paths, rad/s.
JOINT_SPEED = 1.5
#: Objects within this many metres (horizontally) of the arm's base are obstacles of its planning scene.
SCENE_RADIUS = 1.2

#: One step of an arm plan: a joint path to follow, or the gripper's action.
ArmStep = np.ndarray | Literal["grip", "release"]


def object_box(obj: WorldThing) -> Box:
    """An object as a box for arm planning: its own extents and yaw for boxes, else its bounding box."""
    from alica.skills.manipulation.geometry import upright_box  # the planners (OMPL) are imported when first used

    low, high = (np.asarray(v, dtype=float) for v in obj.aabb())
    half = tuple(obj.half_extents)
    if obj.kind == "sample" and obj.radius:
        # a cylinder: its true size, not a bounding box that grows as it turns in the hand
        r = float(obj.radius)
        half = (r, r, 0.5 * float(obj.size))
    if half and half[0] > 0.0:
        center, quat = obj.pose()
        yaw, upright = upright_box(quat, half)  # a block that fell onto a side has its faces turned another way
        return Box(obj.name, (float(center[0]), float(center[1]), float(center[2])), upright, yaw)
    return Box(obj.name, tuple((low + high) / 2.0), tuple((high - low) / 2.0))


def grasp_shape(obj: WorldThing) -> Literal["box", "cylinder"]:
    """How to grasp ``obj`` from the top: ``"cylinder"`` for a sample standing upright, else ``"box"``.

    A sample container that fell over lies as a box (its length along the
    ground, its diameter across and up: :func:`object_box`), grasped across.
    """
    if obj.kind != "sample" or not obj.radius:
        return "box"
    axis = quat_rotate(tuple(obj.pose()[1]), (0.0, 0.0, 1.0))
    return "cylinder" if abs(axis[2]) > 0.9 else "box"


def _crowds(box: Box, target: Box) -> bool:
    """Whether ``box`` stands beside ``target`` closer than the fingers need to close around it.

    Beside: its top is above the target's bottom (not the block the target stands on), and its centre
    is within 1.6 times the sum of the two boxes' largest horizontal half extents.
    """
    if box.center[2] + box.half_extents[2] <= target.center[2] - target.half_extents[2] + 0.01:
        return False
    reach = 1.6 * (max(box.half_extents[:2]) + max(target.half_extents[:2]))
    return math.dist(box.center[:2], target.center[:2]) < reach


def path_duration(path: np.ndarray) -> float:
    """Seconds to follow a joint path at :data:`JOINT_SPEED` (at least 0.2 s)."""
    steps = np.abs(np.diff(np.asarray(path), axis=0)).max(axis=1) if len(path) > 1 else np.zeros(1)
    return max(0.2, float(steps.sum()) / JOINT_SPEED)


def _reached(path: Any, q: np.ndarray) -> int:
    """The waypoint of ``path`` closest to the configuration ``q``: how far along the path the arm got."""
    return int(np.argmin(np.abs(np.asarray(path, dtype=float) - q).max(axis=1)))


def arm_xy(arm: RobotArm) -> tuple[float, float]:
    """Where the arm's base stands."""
    position = arm.base_pose()[0]
    return float(position[0]), float(position[1])


def held_object_box(arm: RobotArm, scene: ArmPlanningScene, q: np.ndarray) -> Box | None:
    """What the arm holds, as a box in the tool's frame (None when it holds nothing, or holds it tilted)."""
    held = arm.held
    if held is None:
        return None
    from alica.skills.manipulation import held_box

    try:
        return held_box(object_box(held), scene.fk(q))
    except ValueError:
        return None  # tilted in the hand: the planner says so itself


def planning_scene(
    arm: RobotArm, objects: Mapping[str, WorldThing], left_out: set[str], crowded: WorldThing | None = None
) -> ArmPlanningScene:
    """The arm's planning scene with the objects near it as obstacles, but those in ``left_out``.

    When the arm, or what it holds, touches an object already (pushed against
    it), the objects it touches are left out too: no plan could leave a start
    in collision. Else, with ``crowded`` given (the target of a last grasp
    attempt), the objects pressed against it are left out, and the closing
    fingers push them aside.
    """
    scene = arm.planning_scene()
    here = arm_xy(arm)
    boxes = [
        object_box(o)
        for name, o in sorted(objects.items())
        if name not in left_out and _near(o, here) and o.kind not in ("terrain", "collection_point")
    ]
    scene.set_obstacles(boxes)
    q = np.asarray(arm.q(), dtype=float)
    held = held_object_box(arm, scene, q)
    if boxes and scene.collides(q, held):
        touching = []
        for box in boxes:
            scene.set_obstacles([box])
            if scene.collides(q, held):
                touching.append(box)
        scene.set_obstacles([b for b in boxes if b not in touching])
    elif crowded is not None:
        near = object_box(crowded)
        crowding = [b for b in boxes if _crowds(b, near)]
        if crowding:
            scene.set_obstacles([b for b in boxes if b not in crowding])
    return scene


def _near(obj: WorldThing, xy: tuple[float, float], radius: float = SCENE_RADIUS) -> bool:
    position = obj.position()
    return distance((float(position[0]), float(position[1])), xy) <= radius


class ArmMotion:
    """The steps of one arm plan, followed one at a time, and the way back.

    Attributes:
        steps: the plan's steps (:data:`ArmStep`), in order.
        index: how many steps were started.
        followed: the paths followed since the start (or since the release), for :meth:`back_out`.
        released: whether the held object was let go.
    """

    def __init__(self) -> None:
        self.steps: list[ArmStep] = []
        self.index = 0
        self.followed: list[np.ndarray] = []
        self.released = False

    def start(self, steps: list[ArmStep]) -> None:
        """Follow ``steps`` from the first."""
        self.steps = steps
        self.index = 0

    @property
    def progress(self) -> str:
        """``"step i/n"`` for feedback messages."""
        return f"step {self.index}/{len(self.steps)}"

    def advance(self, arm: RobotArm, hand: Callable[[str], str | None]) -> tuple[bool, str | None]:
        """Start the next path, doing the gripper's steps on the way (``hand(step)`` says why one cannot be done).

        Returns:
            ``(done, refusal)``: whether every step is done, and why a gripper step was refused (then stop).
        """
        while self.index < len(self.steps):
            step = self.steps[self.index]
            self.index += 1
            if isinstance(step, str):
                refusal = hand(step)
                if refusal is not None:
                    return False, refusal
                continue
            arm.follow(step, path_duration(step))
            if not self.released:  # after a release the way back would lead through what was put down
                self.followed.append(np.asarray(step, dtype=float))
            return False, None
        return True, None

    def release(self, arm: RobotArm) -> None:
        """Let the held object go and open the fingers."""
        arm.detach()
        arm.open()
        self.followed = []
        self.released = True

    def back_out(self, arm: RobotArm) -> None:
        """Get an empty hand away from the work site.

        Before anything was put down, the arm follows the paths backwards to
        where it started (nothing it passed has moved: a failed grip lets go
        where it gripped). After a release it goes on with the rest of the
        plan instead (the retreat and the way back to the transport pose),
        since the way back leads through the object it put down.
        """
        q = np.asarray(arm.q(), dtype=float)
        followed = self.followed
        if followed:
            last = followed[-1]
            k = _reached(last, q)
            way = [last[: k + 1][::-1], *(path[::-1] for path in reversed(followed[:-1]))]
        elif self.released:
            steps, index = self.steps, self.index
            way = [np.asarray(step, dtype=float) for step in steps[index:] if not isinstance(step, str)]
            current = steps[index - 1] if 0 < index <= len(steps) else None
            if current is not None and not isinstance(current, str) and arm.busy:
                way.insert(
                    0, np.asarray(current, dtype=float)[_reached(current, q) :]
                )  # the rest of the path it was on
        else:
            way = []
        self.followed = []
        if way:
            arm.stop()
            arm.follow(np.vstack(way))
