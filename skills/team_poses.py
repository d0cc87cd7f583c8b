"""Team poses: where each robot believes it stands, told to its teammates through the world model.

A robot cannot see where its teammates are from the simulator; in a real
team each robot broadcasts its own pose. Here a robot *shares* its pose
*estimate* (odometry corrected by Localize: what it believes, not its true
pose) and its body's radius as ``robot_pose(robot) = (x, y, yaw, radius, time)``
in its world model, which the team's replicas share, and adds its name to the
set ``pose_sharers`` (once). The driving and arm skills avoid the teammates
they read here (:func:`teammates`).

Rate. Every write is a message to the team, so a robot shares at most every
:data:`SHARE_PERIOD` seconds, and then only when it moved more than
:data:`SHARE_MOVE` metres or turned more than :data:`SHARE_TURN` radians since
its last share, or :data:`HEARTBEAT` seconds passed (a robot standing still
shares once every :data:`HEARTBEAT` seconds, so its teammates know its pose is
current). That is at most two small writes a second per robot while it drives.
:class:`~alica.skills.world_skill.WorldSkill` shares on every tick of a world
skill, throttled so; an application may call :func:`share_pose` on every
engine tick too (robots that run no world skill then still tell where they
are).

What is not avoided:

* a teammate that never shared (it ran no world skill, and the application
  does not share for it): the skills do not know it is there;
* a teammate whose last share is older than :data:`STALE_AFTER` seconds while
  the team believes it alive: it may have moved anywhere since.

A teammate the team believes lost (it has a role, and ``alive(r)`` no longer
holds in the agent's belief: crashed, or cut off) stops sharing, but its body
stays where it stopped: its last pose is avoided however old
(:func:`teammates` with a ``belief``). Its gripper opened when it lost power,
so it holds nothing (:func:`holders`).

A skill run without a world model (a skill test, an opponent's inner skill,
``alica skill run``) shares into a table kept per world instead, which every
robot of that world reads at once (a loss-free network).

Times are the world's clock (``world.now()``): simulated time in a simulation,
shared by all robots; a team of real robots needs synchronized clocks (NTP) for
the age check, as for any time stamp it exchanges.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from typing import Protocol

from alica.worldmodel.protocol import WorldModelLike
from alica.worldsim.interface import MobileRobot, RobotWorld

__all__ = [
    "HEARTBEAT",
    "POSE",
    "SHARERS",
    "SHARE_MOVE",
    "SHARE_PERIOD",
    "SHARE_TURN",
    "STALE_AFTER",
    "BeliefLike",
    "TeamPose",
    "forget_local",
    "holders",
    "lost",
    "publish_pose",
    "share_pose",
    "team_pose",
    "teammate_discs",
    "teammates",
]

#: The world-model function of shared poses: ``robot_pose(robot) = (x, y, yaw, radius, time)``.
POSE = "robot_pose"
#: The world-model set of the robots that shared a pose (so a reader needs no roster).
SHARERS = "pose_sharers"
#: Metres a robot moves before it shares its pose again.
SHARE_MOVE = 0.05
#: Radians a robot turns before it shares its pose again.
SHARE_TURN = 0.2
#: Seconds at least between two shares of a robot's pose.
SHARE_PERIOD = 0.5
#: Seconds after which a robot shares its pose again even when it stands still.
HEARTBEAT = 2.0
#: Seconds after which a shared pose counts as stale: the teammate is not avoided.
STALE_AFTER = 10.0


@dataclass(frozen=True, slots=True)
class TeamPose:
    """A pose a robot shared.

    Attributes:
        robot: the robot's name.
        x: metres.
        y: metres.
        yaw: radians.
        radius: the robot body's radius, metres.
        time: when it was shared (the world's clock).
    """

    robot: str
    x: float
    y: float
    yaw: float
    radius: float
    time: float

    @property
    def disc(self) -> tuple[float, float, float]:
        """``(x, y, radius)``: the body as the planners' ``other_robots`` take it."""
        return (self.x, self.y, self.radius)

    def as_value(self) -> tuple[float, float, float, float, float]:
        """The world-model value (plain data, rounded to millimetres and milliseconds)."""
        return (round(self.x, 3), round(self.y, 3), round(self.yaw, 3), round(self.radius, 3), round(self.time, 3))

    @classmethod
    def from_value(cls, robot: str, value: object) -> TeamPose | None:
        """The pose in a world-model value, or None when it is not one (a malformed or cleared value)."""
        if not isinstance(value, (tuple, list)) or len(value) != 5:
            return None
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value):
            return None
        x, y, yaw, radius, time = (float(v) for v in value)
        if radius < 0.0:
            return None
        return cls(robot, x, y, yaw, radius, time)


class _Skill(Protocol):
    @property
    def world(self) -> RobotWorld: ...
    @property
    def robot(self) -> MobileRobot: ...
    def teammates(self) -> list[TeamPose]: ...


#: Poses shared without a world model, per world: robot -> pose.
_LOCAL: weakref.WeakKeyDictionary[RobotWorld, dict[str, TeamPose]] = weakref.WeakKeyDictionary()


def _local(world: RobotWorld) -> dict[str, TeamPose]:
    table = _LOCAL.get(world)
    if table is None:
        table = _LOCAL[world] = {}
    return table


def forget_local(world: RobotWorld) -> None:
    """Drop the poses shared without a world model in ``world`` (a test that reuses its world)."""
    _LOCAL.pop(world, None)


def team_pose(world_model: WorldModelLike | None, world: RobotWorld, robot: str) -> TeamPose | None:
    """The last pose ``robot`` shared (in ``world_model``, or the world's table without one), however old."""
    if world_model is None:
        return _local(world).get(robot)
    return TeamPose.from_value(robot, world_model.get(POSE, robot))


def publish_pose(world_model: WorldModelLike | None, world: RobotWorld, pose: TeamPose) -> None:
    """Write ``pose`` for its robot now, unthrottled (:func:`share_pose` throttles)."""
    if world_model is None:
        _local(world)[pose.robot] = pose
        return
    world_model.set(POSE, pose.robot, value=pose.as_value())
    if pose.robot not in world_model.members(SHARERS):
        world_model.add_to_set(SHARERS, pose.robot)


def share_pose(
    world_model: WorldModelLike | None, world: RobotWorld, robot: MobileRobot, *, force: bool = False
) -> bool:
    """Share ``robot``'s pose estimate, throttled: see the module's docstring for when.

    Public so that an application can call it on every engine tick for each
    of its robots; :class:`~alica.skills.world_skill.WorldSkill` calls it on
    every tick of a world skill. A crashed robot shares nothing.

    Args:
        world_model: the robot's world model (None: the world's table).
        world: the world (its clock stamps the pose).
        robot: the robot; its :attr:`~alica.worldsim.interface.MobileRobot.estimate` is shared.
        force: share now whatever the throttle says.

    Returns:
        Whether it wrote.
    """
    if robot.crashed:
        return False
    now = float(world.now())
    x, y, yaw = (float(v) for v in robot.estimate)
    last = team_pose(world_model, world, robot.name)
    if not force and last is not None and now >= last.time:
        age = now - last.time
        if age < SHARE_PERIOD:
            return False
        turned = abs(math.remainder(yaw - last.yaw, math.tau))
        if age < HEARTBEAT and math.hypot(x - last.x, y - last.y) < SHARE_MOVE and turned < SHARE_TURN:
            return False
    publish_pose(world_model, world, TeamPose(robot.name, x, y, yaw, float(robot.spec.radius), now))
    return True


class BeliefLike(Protocol):
    """What the team's belief answers here: ``role(r)`` and ``alive(r)`` (the engine's agent belief)."""

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None: ...


def lost(belief: BeliefLike | None, robot: str) -> bool:
    """Whether ``belief`` counts ``robot`` as a teammate (it has a role) that is no longer alive."""
    if belief is None:
        return False
    return belief.lookup("role", (robot,)) is not None and not belief.lookup("alive", (robot,))


def teammates(
    world_model: WorldModelLike | None,
    world: RobotWorld,
    me: str,
    *,
    max_age: float = STALE_AFTER,
    belief: BeliefLike | None = None,
) -> list[TeamPose]:
    """The poses the other robots shared, no older than ``max_age`` seconds, sorted by name.

    A robot that never shared, or whose last share is older, is not listed,
    unless ``belief`` counts it lost (:func:`lost`): its body lies where it
    last said (see the module's docstring).
    """
    now = float(world.now())
    if world_model is None:
        names: list[str] = sorted(_local(world))
    else:
        names = sorted(str(m) for m in world_model.members(SHARERS))
    out = []
    for name in names:
        if name == me:
            continue
        pose = team_pose(world_model, world, name)
        if pose is not None and (now - pose.time <= max_age or lost(belief, name)):
            out.append(pose)
    return out


def teammate_discs(skill: _Skill, *, margin: float = 0.0) -> list[tuple[float, float, float]]:
    """The skill's robot's teammates as ``(x, y, radius + margin)`` discs (:func:`teammates`)."""
    return [(p.x, p.y, p.radius + margin) for p in skill.teammates()]


def holders(world_model: WorldModelLike | None, belief: BeliefLike | None = None) -> dict[str, str]:
    """Object -> the robot that holds it, from the team's ``holding(robot, object)`` facts.

    The arm skills write ``holding`` when a grip succeeds and retract it when
    the object is let go (:func:`alica.skills.arm_world.write_held`); without a
    world model nothing is known of the teammates' grippers (an empty dict). A
    robot ``belief`` counts lost (:func:`lost`) holds nothing: its gripper
    opened when it lost power.
    """
    if world_model is None:
        return {}
    out: dict[str, str] = {}
    for fact in world_model.facts():
        if fact.predicate == "holding" and len(fact.args) == 2 and not lost(belief, str(fact.args[0])):
            out[str(fact.args[1])] = str(fact.args[0])
    return out
