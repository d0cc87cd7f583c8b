"""Each skill alone in a small world, in simulated time (the alica.skills.testing fixtures)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.errors import SkillError
from alica.lang.fact import Fact


def test_move_to_position_reaches_a_goal_around_rocks(lunar_world, skill_run, free_goal):
    goal = free_goal(lunar_world, "scout")
    run = skill_run("MoveToPosition", lunar_world, "scout", {"goal": list(goal), "tolerance": 0.3})
    assert run.ok, (run.reason, run.trace[-5:])
    x, y, _ = lunar_world.robots["scout"].pose
    assert math.hypot(x - goal[0], y - goal[1]) <= 0.3
    assert not lunar_world.robots["scout"].bumped
    reached = run.values[Fact("pos", ("scout",))]  # MoveToPosition writes where it arrived
    assert math.dist(reached, (x, y)) < 0.05


def test_move_to_position_fails_clearly_on_an_unreachable_goal(lunar_world, skill_run):
    rock = next(o for o in lunar_world.objects.values() if o.kind == "rock")
    x, y = rock.position()[:2]
    run = skill_run("MoveToPosition", lunar_world, "scout", {"goal": [float(x), float(y)]})
    assert run.status == "failure"
    assert "cannot reach" in run.reason
    assert run.sim_time_s < 5.0


def test_pickup_succeeds(blocks_world, skill_run):
    run = skill_run("Pickup", blocks_world, "r1", {"object": "c"})
    assert run.ok, (run.reason, run.trace[-6:])
    arm = blocks_world.robots["r1"].arm
    assert arm.held is blocks_world.objects["c"]
    from alica.worldsim.scenarios import blocks_facts

    facts = blocks_facts(blocks_world)
    assert ("holding", "r1", "c") in facts and ("ontable", "c") not in facts


def test_pickup_of_a_block_hemmed_in_by_others_pushes_them_aside_on_its_last_attempt(blocks_world, skill_run):
    # blocks fell right beside c on all four sides: every grasp's fingers would touch one of them
    from alica.worldsim.scenarios import blocks_facts

    cx, cy, _ = blocks_world.objects["c"].position()
    for name, (dx, dy) in zip("dfhi", [(0.056, 0), (0, 0.056), (-0.056, 0), (0, -0.056)], strict=True):
        blocks_world.add_block(name, (cx + dx, cy + dy))
    blocks_world.step(1.0)
    run = skill_run("Pickup", blocks_world, "r1", {"object": "c"})
    assert run.ok, (run.reason, run.trace[-6:])
    retries = [t["feedback"] for t in run.trace if t["feedback"].startswith("retrying")]
    assert len(retries) == 2 and all("no grasp of 'c' worked" in r for r in retries)
    assert run.reason == "done after 3 attempt(s)"
    assert ("holding", "r1", "c") in blocks_facts(blocks_world)


def test_pickup_fails_when_a_block_is_put_on_its_object_before_the_grip(blocks_world, skill_run):
    # another robot stacks a block on c while r1's arm is on its way down: r1 does not lift c from under it
    cx, cy, _ = blocks_world.objects["c"].position()
    put = []

    def stack_on_c(world, behaviour):
        if getattr(behaviour, "phase", "") == "execute" and not put:
            put.append(world.add_block("d", (cx, cy, 0.075)))

    run = skill_run("Pickup", blocks_world, "r1", {"object": "c"}, on_tick=stack_on_c)
    assert put and not run.ok
    assert "something was put on c before the grip" in run.reason
    assert blocks_world.robots["r1"].arm.held is None


def test_pickup_retries_after_a_slip(blocks_world, skill_run):
    from alica.worldsim.faults import set_grasp_slip

    set_grasp_slip(blocks_world, 1.0)
    attempts = []

    def fault(world, behaviour):
        tries = getattr(behaviour, "attempts", 0)
        if tries >= 1 and not attempts:
            attempts.append(tries)
            set_grasp_slip(world, 0.0)  # the second grasp holds

    run = skill_run("Pickup", blocks_world, "r1", {"object": "c"}, on_tick=fault)
    assert run.ok, (run.reason, run.trace[-6:])
    assert attempts == [1]
    assert any("retrying" in str(t["feedback"]) for t in run.trace)


def test_pickup_fails_after_the_retry_budget(blocks_world, skill_run):
    from alica.worldsim.faults import set_grasp_slip

    set_grasp_slip(blocks_world, 1.0)
    arm = blocks_world.robots["r1"].arm
    start = np.asarray(arm.q(), dtype=float)
    run = skill_run("Pickup", blocks_world, "r1", {"object": "c", "retries": 2})
    assert run.status == "failure"
    assert "gave up after 2 attempt(s)" in run.reason
    # the arm does not stay at the block: it backs out the way it came
    assert arm.busy
    blocks_world.step(20.0)
    assert not arm.busy and np.abs(np.asarray(arm.q()) - start).max() < 1e-6


def test_putdown_on_the_ground_and_stack_on_a_block(blocks_world, skill_run):
    from alica.worldsim.scenarios import blocks_facts

    assert skill_run("Pickup", blocks_world, "r1", {"object": "c"}).ok
    run = skill_run("Putdown", blocks_world, "r1", {"object": "c"})
    assert run.ok, (run.reason, run.trace[-6:])
    facts = blocks_facts(blocks_world)
    assert ("ontable", "c") in facts and ("handempty", "r1") in facts
    assert skill_run("Pickup", blocks_world, "r1", {"object": "c"}).ok
    run = skill_run("Stack", blocks_world, "r1", {"object": "c", "target": "b"})
    assert run.ok, (run.reason, run.trace[-6:])
    assert ("on", "c", "b") in blocks_facts(blocks_world)


def test_putdown_with_spread_puts_the_block_apart_from_every_other_block(blocks_world, skill_run):
    from alica.worldsim.scenarios import blocks_facts

    assert skill_run("Pickup", blocks_world, "r1", {"object": "c"}).ok
    run = skill_run("Putdown", blocks_world, "r1", {"object": "c", "spread": 1.0})
    assert run.ok, (run.reason, run.trace[-6:])
    assert ("ontable", "c") in blocks_facts(blocks_world)
    c = blocks_world.objects["c"].position()
    others = [o.position() for name, o in blocks_world.objects.items() if o.kind == "block" and name != "c"]
    assert others and min(math.hypot(c[0] - o[0], c[1] - o[1]) for o in others) >= 1.0 - 0.05


def test_unstack_then_stack_follow_the_ipc_domain(blocks_world, skill_run):
    from alica.worldsim.scenarios import blocks_facts

    before = blocks_facts(blocks_world)
    assert ("on", "b", "a") in before and ("clear", "b") in before and ("clear", "a") not in before
    # preconditions are checked on the simulated state: a is not clear
    refused = skill_run("Unstack", blocks_world, "r1", {"object": "a", "from": "b"})
    assert refused.status == "failure" and "precondition" in refused.reason
    run = skill_run("Unstack", blocks_world, "r1", {"object": "b", "from": "a"})
    assert run.ok, (run.reason, run.trace[-6:])
    after = blocks_facts(blocks_world)
    assert ("holding", "r1", "b") in after and ("clear", "a") in after and ("on", "b", "a") not in after
    run = skill_run("Stack", blocks_world, "r1", {"object": "b", "target": "c"})
    assert run.ok, (run.reason, run.trace[-6:])
    final = blocks_facts(blocks_world)
    assert ("on", "b", "c") in final and ("handempty", "r1") in final and ("clear", "c") not in final


def test_bad_parameters_are_refused(blocks_world, skill_run):
    with pytest.raises(SkillError, match="needs the parameter 'object'"):
        skill_run("Pickup", blocks_world, "r1", {})
    with pytest.raises(SkillError, match="has no parameter 'speed'"):
        skill_run("Pickup", blocks_world, "r1", {"object": "c", "speed": 2})
    with pytest.raises(SkillError, match="no robot named 'r9'"):
        skill_run("Pickup", blocks_world, "r9", {"object": "c"})


def test_a_robot_without_an_arm_cannot_pick_up(lunar_world, skill_run):
    with pytest.raises(SkillError, match="has no arm"):
        skill_run("Pickup", lunar_world, "scout", {"object": "a"})


def test_transport_a_sample_to_the_collection_point(lunar_world, skill_run):
    steps = [
        ("Pickup", {"object": "a"}),
        ("MoveToPosition", {"goal": "pos(g)", "tolerance": 1.0}),
        ("Putdown", {"object": "a", "target": "pos(g)"}),
    ]
    for name, params in steps:
        run = skill_run(name, lunar_world, "stummel", params, timeout=200)
        assert run.ok, (name, run.reason, run.trace[-6:])
    a, g = lunar_world.objects["a"].position(), lunar_world.objects["g"].position()
    assert math.hypot(a[0] - g[0], a[1] - g[1]) < 0.1
    assert Fact("at", ("a", "g")) in run.facts and Fact("onground", ("a",)) in run.facts


def test_putdown_on_top_of_a_block(blocks_world, skill_run):
    from alica.worldsim.scenarios import blocks_facts

    assert skill_run("Pickup", blocks_world, "r1", {"object": "c"}).ok
    run = skill_run("Putdown", blocks_world, "r1", {"object": "c", "target": "b"})
    assert run.ok, (run.reason, run.trace[-6:])
    assert ("on", "c", "b") in blocks_facts(blocks_world)
    assert Fact("on", ("c", "b")) in run.facts


def test_move_to_position_replans_around_a_new_obstacle(lunar_world, skill_run, free_goal):
    goal = free_goal(lunar_world, "scout")
    robot = lunar_world.robots["scout"]
    dropped = []

    def drop_a_rock(world, behaviour):
        follower = getattr(behaviour, "follower", None)
        if follower is not None and not dropped and world.now() > 1.0:
            # a rock falls right ahead on the path
            px, py = robot.pose[:2]
            ahead = next(p for p in follower.remaining() if math.hypot(p[0] - px, p[1] - py) > 1.5)
            world.add_rock("fallen", (float(ahead[0]), float(ahead[1]), 0.0), 0.5)
            dropped.append(tuple(ahead[:2]))

    run = skill_run("MoveToPosition", lunar_world, "scout", {"goal": list(goal)}, on_tick=drop_a_rock)
    assert dropped, "the rock was never dropped"
    assert run.ok, (run.reason, run.trace[-5:])
    assert any("replanning" in str(t["feedback"]) for t in run.trace)


def test_drive_to_free_space_keeps_away_from_the_blocks(blocks_world, skill_run):
    # r1 waits right next to the stacks; with keep_away it drives to a place at least that far from every block
    blocks_world.robots["r1"].set_pose(0.0, -0.7, math.pi / 2)
    blocks = [o.position()[:2] for o in blocks_world.objects.values() if o.kind == "block"]

    def nearest_block():
        x, y, _ = blocks_world.robots["r1"].pose
        return min(math.hypot(x - bx, y - by) for bx, by in blocks)

    assert nearest_block() < 1.0
    plain = skill_run("DriveToFreeSpace", blocks_world, "r1", {"clearance": 0.4, "max_distance": 5.0})
    assert plain.ok and nearest_block() < 1.0  # enough room from obstacles already: it stays in the way
    run = skill_run("DriveToFreeSpace", blocks_world, "r1", {"clearance": 0.4, "max_distance": 5.0, "keep_away": 1.15})
    assert run.ok, run.reason
    assert nearest_block() >= 1.15 - 0.2  # the skill's goal tolerance
    assert not blocks_world.robots["r1"].bumped


def test_drive_to_free_space_gives_up_a_place_another_robot_took(blocks_world, skill_run):
    # a robot that stands on the chosen place for good (crashed, or waiting itself for what this robot does
    # next) made DriveToFreeSpace wait there until its timeout: an opponent holding a block stalled 60 s and
    # the team waiting for that block with it (blocks demo, seed 1, one opponent, r3 crashed at 3.5 s)
    blocks_world.robots["r1"].set_pose(0.0, -0.7, math.pi / 2)  # right next to the stacks: it must move
    other = blocks_world.robots["r2"]
    taken = []

    def take_the_place(world, behaviour):
        if not taken and getattr(behaviour, "follower", None) is not None:
            taken.append(behaviour.spot)
            other.set_pose(behaviour.spot[0], behaviour.spot[1], 0.0)  # and it stays there

    params = {"clearance": 0.4, "max_distance": 5.0, "keep_away": 1.15}
    run = skill_run("DriveToFreeSpace", blocks_world, "r1", params, on_tick=take_the_place)
    assert taken
    assert run.ok, (run.reason, run.trace[-4:])
    x, y, _ = blocks_world.robots["r1"].pose
    assert math.dist((x, y), taken[0]) > other.spec.radius + blocks_world.robots["r1"].spec.radius
    assert run.sim_time_s < 20.0


def test_an_escape_turns_on_the_spot_before_it_drives(blocks_world, skill_run):
    # a robot pressed against something refuses any move deeper into it, turning included, so an escape that
    # drove an arc towards free space 40 degrees off its heading stayed where it was (seed 7 of the 5-agent demo)
    robot = blocks_world.robots["r1"]
    cx, cy, _ = blocks_world.objects["c"].position()
    robot.set_pose(cx - 0.3, cy, 0.0)  # right next to c
    escapes = []

    def stuck_once_then_watch(world, behaviour):
        if getattr(behaviour, "follower", None) is None or escapes:
            return
        behaviour._stuck(world.now())  # as if the base had just bumped
        x, y, _ = robot.pose
        spot = behaviour.follower.path[-1]
        robot.set_pose(
            x, y, math.atan2(spot[1] - y, spot[0] - x) + math.radians(40.0)
        )  # free space 40 degrees to the right
        escapes.append(behaviour.follower.command(robot.pose, 0.1))

    run = skill_run("MoveToPosition", blocks_world, "r1", {"goal": [cx - 1.2, cy - 0.6]}, on_tick=stuck_once_then_watch)
    assert run.ok, (run.reason, run.trace[-4:])
    v, w, done = escapes[0]
    assert v == 0.0 and w < 0.0 and not done  # it turns right on the spot first


def _goal_in_a_rocks_clearance(world, robot):
    """A point where the robot's centre may not be (too close to a rock) with a drivable point within 0.3 m."""
    from alica.skills.navigation import drivable_goal, planning_checker

    checker = planning_checker(world, world.robots[robot].spec.radius)
    x0, y0, _ = world.robots[robot].pose
    rocks = sorted(
        (o for o in world.objects.values() if o.kind == "rock"), key=lambda o: math.dist(o.position()[:2], (x0, y0))
    )
    for rock in rocks:
        x, y = rock.position()[:2]
        for k in range(1, 60):
            goal = (x + 0.05 * k, y)
            if not checker.valid_xy(*goal):
                continue
            inside = (goal[0] - 0.06, y)  # just inside the clearance
            if not checker.valid_xy(*inside) and drivable_goal(checker, inside, 0.3) is not None:
                return inside
            break
    raise AssertionError("no rock with free space beside it")


def test_move_to_position_drives_next_to_a_goal_within_a_rocks_clearance(lunar_world, skill_run):
    from alica.skills.navigation import drivable_goal, planning_checker

    goal = _goal_in_a_rocks_clearance(lunar_world, "scout")
    run = skill_run("MoveToPosition", lunar_world, "scout", {"goal": list(goal), "tolerance": 0.3})
    assert run.ok, (run.reason, run.trace[-5:])
    x, y, _ = lunar_world.robots["scout"].pose
    assert math.hypot(x - goal[0], y - goal[1]) <= 0.3
    assert not lunar_world.robots["scout"].bumped
    # with a smaller tolerance than the clearance asks for, the goal stays out of reach
    checker = planning_checker(lunar_world, lunar_world.robots["scout"].spec.radius)
    assert drivable_goal(checker, goal, 0.01) is None


def test_drivable_goal_is_the_nearest_valid_point_within_the_tolerance():
    from alica.skills.motion import GridChecker
    from alica.skills.navigation import drivable_goal
    from alica.worldsim.grid import Obstacle2D, OccupancyGrid

    grid = OccupancyGrid.from_obstacles([Obstacle2D("circle", 0.0, 0.0, radius=0.5)], (-3.0, -3.0, 3.0, 3.0))
    checker = GridChecker(grid, 0.3, margin=0.0)
    assert drivable_goal(checker, (2.0, 0.0), 0.3) == (2.0, 0.0)  # valid: kept as it is
    goal = (0.75, 0.0)  # 0.25 m from the rock's edge, the robot needs 0.3 m
    point = drivable_goal(checker, goal, 0.3)
    assert point is not None and checker.valid_xy(*point)
    assert 0.0 < math.dist(point, goal) <= 0.3 and point[0] > goal[0]
    assert drivable_goal(checker, (0.0, 0.0), 0.3) is None  # the rock's centre: nothing within the tolerance


def _cross_the_path(blocks_world, leave_after):
    """r2 steps onto r1's path once r1 drives, and leaves after ``leave_after`` s (None: stays)."""
    blocks_world.robots["r1"].set_pose(-2.0, -1.2, 0.0)
    other = blocks_world.robots["r2"]
    stepped = []

    def cross(world, behaviour):
        if not stepped and getattr(behaviour, "follower", None) is not None and world.now() > 0.5:
            stepped.append(world.now())
            other.set_pose(0.0, -1.2, math.pi / 2)
        elif stepped and leave_after is not None and world.now() - stepped[0] > leave_after and other.pose[1] < 0:
            other.set_pose(0.0, 2.0, math.pi / 2)

    return cross, stepped


def test_move_to_position_lets_a_robot_on_its_path_pass(blocks_world, skill_run):
    cross, stepped = _cross_the_path(blocks_world, leave_after=1.0)
    run = skill_run("MoveToPosition", blocks_world, "r1", {"goal": [2.0, -1.2]}, on_tick=cross)
    assert stepped and run.ok, (run.reason, run.trace[-4:])
    feedback = [str(t["feedback"]) for t in run.trace]
    assert any("letting it pass" in f for f in feedback)
    assert not any("path blocked" in f for f in feedback)  # it waited instead of planning a detour


def test_move_to_position_plans_around_a_robot_that_stays_on_its_path(blocks_world, skill_run):
    cross, stepped = _cross_the_path(blocks_world, leave_after=None)
    run = skill_run("MoveToPosition", blocks_world, "r1", {"goal": [2.0, -1.2]}, on_tick=cross)
    assert stepped and run.ok, (run.reason, run.trace[-4:])
    feedback = [str(t["feedback"]) for t in run.trace]
    assert any("letting it pass" in f for f in feedback)
    assert any("path blocked by another robot: replanning" in f for f in feedback)
