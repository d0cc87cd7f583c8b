"""Team poses (alica.skills.team_poses): robots share their pose estimates through the world model and avoid what they read."""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

import pytest

from alica.engine.behaviours import SkillContext
from alica.skills import team_poses
from alica.skills.team_poses import (
    HEARTBEAT,
    POSE,
    SHARE_PERIOD,
    STALE_AFTER,
    TeamPose,
    holders,
    share_pose,
    teammates,
)
from alica.worldmodel import WorldModel


@dataclass
class _Spec:
    radius: float = 0.4


@dataclass
class _Robot:
    """The members of a robot that sharing reads."""

    name: str
    estimate: tuple[float, float, float] = (0.0, 0.0, 0.0)
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0)
    spec: _Spec = field(default_factory=_Spec)
    crashed: bool = False


@dataclass(eq=False)
class _World:
    """A clock and robots: what the sharing functions read of a world."""

    t: float = 0.0
    robots: dict[str, _Robot] = field(default_factory=dict)

    def now(self) -> float:
        return self.t


def test_a_robot_shares_its_estimate_not_its_true_pose():
    world = _World()
    robot = _Robot("r1", estimate=(1.0, 2.0, 0.5), pose=(1.3, 2.2, 0.4))
    wm = WorldModel("r1")
    assert share_pose(wm, world, robot)  # type: ignore[arg-type]
    assert wm.get(POSE, "r1") == (1.0, 2.0, 0.5, 0.4, 0.0)
    assert "r1" in wm.members(team_poses.SHARERS)


def test_sharing_is_throttled_by_motion_and_time():
    world = _World()
    robot = _Robot("r1")
    wm = WorldModel("r1")
    assert share_pose(wm, world, robot)  # type: ignore[arg-type]
    world.t = SHARE_PERIOD / 2
    robot.estimate = (1.0, 0.0, 0.0)
    assert not share_pose(wm, world, robot)  # type: ignore[arg-type]  # too soon after the last, even moved
    world.t = SHARE_PERIOD
    assert share_pose(wm, world, robot)  # type: ignore[arg-type]  # moved: shared
    world.t = SHARE_PERIOD + 1.0
    robot.estimate = (1.02, 0.0, 0.0)
    assert not share_pose(wm, world, robot)  # type: ignore[arg-type]  # 2 cm: not worth a message
    robot.estimate = (1.02, 0.0, 0.5)
    assert share_pose(wm, world, robot)  # type: ignore[arg-type]  # turned
    world.t += HEARTBEAT - 0.01
    assert not share_pose(wm, world, robot)  # type: ignore[arg-type]
    world.t += 0.02
    assert share_pose(wm, world, robot)  # type: ignore[arg-type]  # standing still: the heartbeat
    robot.crashed = True
    world.t += HEARTBEAT
    assert not share_pose(wm, world, robot)  # type: ignore[arg-type]  # a crashed robot tells nothing


def test_a_teammate_pose_reaches_the_other_replica_and_is_listed():
    world = _World()
    r1, r2 = _Robot("r1", estimate=(0.0, 0.0, 0.0)), _Robot("r2", estimate=(3.0, 1.0, 0.0), spec=_Spec(0.6))
    wm1, wm2 = WorldModel("r1"), WorldModel("r2")
    share_pose(wm1, world, r1)  # type: ignore[arg-type]
    share_pose(wm2, world, r2)  # type: ignore[arg-type]
    delta = wm2.take_delta()
    assert delta is not None
    wm1.merge(delta)  # what the team's network does
    (seen,) = teammates(wm1, world, "r1")  # type: ignore[arg-type]
    assert seen == TeamPose("r2", 3.0, 1.0, 0.0, 0.6, 0.0)
    assert seen.disc == (3.0, 1.0, 0.6)
    assert teammates(wm2, world, "r2") == []  # type: ignore[arg-type]  # r1's pose has not reached r2 yet


def test_a_stale_or_absent_teammate_is_not_listed():
    world = _World()
    wm = WorldModel("r1")
    assert teammates(wm, world, "r1") == []  # type: ignore[arg-type]  # nobody shared
    share_pose(wm, world, _Robot("r2", estimate=(2.0, 0.0, 0.0)))  # type: ignore[arg-type]
    world.t = STALE_AFTER
    assert [p.robot for p in teammates(wm, world, "r1")] == ["r2"]  # type: ignore[arg-type]
    world.t = STALE_AFTER + 0.1
    assert teammates(wm, world, "r1") == []  # type: ignore[arg-type]


def test_a_malformed_value_is_ignored():
    world = _World()
    wm = WorldModel("r1")
    wm.add_to_set(team_poses.SHARERS, "r2")
    wm.set(POSE, "r2", value=("x", 1.0))
    assert teammates(wm, world, "r1") == []  # type: ignore[arg-type]
    assert TeamPose.from_value("r2", (1.0, 2.0, 0.0, -1.0, 0.0)) is None  # a negative radius


def test_without_a_world_model_the_world_table_serves():
    world = _World()
    share_pose(None, world, _Robot("r2", estimate=(2.0, 0.0, 0.0)))  # type: ignore[arg-type]
    assert [p.robot for p in teammates(None, world, "r1")] == ["r2"]  # type: ignore[arg-type]
    team_poses.forget_local(world)  # type: ignore[arg-type]
    assert teammates(None, world, "r1") == []  # type: ignore[arg-type]


def test_holders_come_from_the_teams_holding_facts():
    wm = WorldModel("r1")
    assert holders(wm) == {}
    wm.assert_fact("holding", "r2", "s1")
    assert holders(wm) == {"s1": "r2"}
    assert holders(None) == {}


# -- in a world: the driving skills avoid what the team shares ----------------------------------------------------


@pytest.fixture
def two_robots():
    pytest.importorskip("pybullet")
    from alica.worldsim.world import World

    with World(0, bounds=(-1.0, -1.0, 10.0, 10.0)) as world:
        world.add_robot("stummel", "r1", (1.0, 1.0, 0.0))
        world.add_robot("stummel", "r2", (4.0, 1.0, 0.0))
        world.step(0.1)
        yield world


def _drive(world, wm, goal=(7.0, 1.0)):
    from alica.skills.navigation import MoveToPosition

    context = SkillContext("r1", world.now, wm, None, random.Random(0), world)
    skill = MoveToPosition("drive", {"goal": list(goal), "tolerance": 0.3, "timeout": 60.0}, context)
    skill.setup(context=context)
    return skill


def test_the_drive_avoids_a_teammate_that_shared_and_not_one_that_did_not(two_robots):
    world = two_robots
    wm = WorldModel("r1", clock=world.clock)
    skill = _drive(world, wm)
    assert skill._others() == []  # r2 never shared: not avoided (not known to be there)
    share_pose(wm, world, world.robots["r2"])
    ((x, y, r),) = skill._others()
    assert math.hypot(x - 4.0, y - 1.0) < 0.05 and r == world.robots["r2"].spec.radius
    world.step(STALE_AFTER + 1.0)
    assert skill._others() == []  # stale


def test_a_drive_past_a_teammate_that_shared_keeps_clear_of_it(two_robots):
    """r1 drives through where r2 stands; r2's shared pose makes r1's planner go round it."""
    from alica.skills.testing import run_skill

    world = two_robots
    closest = [math.inf]

    def watch(w, _behaviour):
        a, b = w.robots["r1"].pose, w.robots["r2"].pose
        closest[0] = min(closest[0], math.hypot(a[0] - b[0], a[1] - b[1]))

    run = run_skill("MoveToPosition", world, "r1", {"goal": [7.0, 1.0]}, timeout=60.0, on_tick=watch)
    assert run.ok, run.reason
    radii = world.robots["r1"].spec.radius + world.robots["r2"].spec.radius
    assert closest[0] > radii  # never touched
    assert not any(fact.predicate == team_poses.SHARERS for fact in run.facts)  # the team's traffic is not the skill's


class _Belief:
    """Who has a role, and who is alive."""

    def __init__(self, roles, alive):
        self.roles, self.alive = set(roles), set(alive)

    def lookup(self, name, args):
        if name == "role":
            return "Role" if args[0] in self.roles else None
        if name == "alive":
            return args[0] in self.alive
        return None


def test_a_lost_teammates_last_pose_is_avoided_however_old():
    """A crashed robot stops sharing, but its body lies where it last said."""
    world = _World()
    wm = WorldModel("r1")
    share_pose(wm, world, _Robot("r2", estimate=(2.0, 0.0, 0.0)))  # type: ignore[arg-type]
    world.t = 10 * STALE_AFTER
    assert teammates(wm, world, "r1", belief=_Belief({"r1", "r2"}, {"r1", "r2"})) == []  # type: ignore[arg-type]
    (seen,) = teammates(wm, world, "r1", belief=_Belief({"r1", "r2"}, {"r1"}))  # type: ignore[arg-type]
    assert seen.robot == "r2" and seen.x == 2.0


def test_a_lost_teammate_holds_nothing():
    wm = WorldModel("r1")
    wm.assert_fact("holding", "r2", "s1")
    assert holders(wm, _Belief({"r1", "r2"}, {"r1", "r2"})) == {"s1": "r2"}
    assert holders(wm, _Belief({"r1", "r2"}, {"r1"})) == {}  # its gripper opened when it lost power
