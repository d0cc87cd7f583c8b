"""MoveToPosition on the team map (map mode): it plans on what the robot knows, not on the world's rocks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.errors import SkillError


def _team_map_model(world, robot, edit=None):
    """A world model holding a team map at 0.1 m, all unknown but what ``edit(layer)`` writes (a surveyor's layer)."""
    from alica.skills.mapping import RobotMapper
    from alica.worldmodel import WorldModel

    wm = WorldModel(robot, clock=world.clock)
    mapper = RobotMapper.for_robot(wm, "surveyor", world.bounds, 0.1)
    if edit is not None:
        edit(mapper.layer)
    mapper.layer._dirty[:] = True  # every tile is new
    mapper.publish(force=True)
    return wm


def _recorder(robot):
    paths, bumps = [], []

    def on_tick(world, behaviour):
        follower = getattr(behaviour, "follower", None)
        if follower is not None and not getattr(behaviour, "escaping", False):
            if not paths or not np.array_equal(paths[-1], follower.path):
                paths.append(follower.path.copy())
        if robot.bumped:
            bumps.append(world.now())

    return paths, bumps, on_tick


def _distance_to_path(path, point):
    from alica.skills.motion import densify

    pts = densify(path, 0.02)
    return float(np.min(np.hypot(pts[:, 0] - point[0], pts[:, 1] - point[1])))


def test_a_rock_the_map_does_not_show_is_planned_through_then_replanned_around(lunar_world, skill_run, free_goal):
    world, robot = lunar_world, lunar_world.robots["scout"]
    goal = free_goal(world, "scout")
    x, y, _ = robot.pose
    rock = (x + 0.5 * (goal[0] - x), y + 0.5 * (goal[1] - y))
    world.add_rock("unmapped", (rock[0], rock[1], 0.0), 0.5)
    wm = _team_map_model(world, "scout")  # the team knows nothing yet: unknown counts as free
    paths, bumps, on_tick = _recorder(robot)
    run = skill_run("MoveToPosition", world, "scout", {"goal": list(goal)}, world_model=wm, on_tick=on_tick)
    assert run.ok, (run.reason, run.trace[-5:])
    assert _distance_to_path(paths[0], rock) < 0.5  # the first path runs through the rock nobody has seen
    assert any("replanning" in str(t["feedback"]) for t in run.trace)  # the robot's scans mapped it
    assert _distance_to_path(paths[-1], rock) > 0.5 + robot.spec.radius
    assert not bumps


def test_an_obstacle_only_the_map_shows_is_avoided(lunar_world, skill_run, free_goal):
    world, robot = lunar_world, lunar_world.robots["scout"]
    goal = free_goal(world, "scout")
    x, y, _ = robot.pose
    mid = np.array([x + 0.5 * (goal[0] - x), y + 0.5 * (goal[1] - y)])
    across = np.array([-(goal[1] - y), goal[0] - x]) / math.hypot(goal[0] - x, goal[1] - y)
    wall = [mid + s * across for s in np.linspace(-1.5, 1.5, 61)]  # a 3 m wall across the way, in the map only

    def draw_wall(layer):
        for px, py in wall:
            i, j = layer.world_to_cell(px, py)
            layer.logodds[j, i] = 4.0

    wm = _team_map_model(world, "scout", draw_wall)
    paths, _, on_tick = _recorder(robot)
    run = skill_run("MoveToPosition", world, "scout", {"goal": list(goal)}, world_model=wm, on_tick=on_tick)
    assert run.ok, (run.reason, run.trace[-5:])
    assert min(_distance_to_path(paths[0], p) for p in wall) >= robot.spec.radius


def test_known_map_mode_without_a_team_map_plans_on_the_world(lunar_world):
    from alica.skills.navigation import exact_checker, map_planning, planning_grid
    from alica.worldmodel import WorldModel

    wm = WorldModel("scout", clock=lunar_world.clock)
    assert map_planning(lunar_world, wm) is None
    assert exact_checker(lunar_world, 0.25, wm) is not None
    assert planning_grid(lunar_world, wm).occupied_mask().any()  # the world's rocks
    mapped = _team_map_model(lunar_world, "scout")
    assert exact_checker(lunar_world, 0.25, mapped) is None  # map mode: no meshes
    assert not planning_grid(lunar_world, mapped).occupied_mask().any()  # the map knows no rock yet


def test_in_a_mission_that_maps_positions_come_from_the_world_model(lunar_world, skill_run, free_goal):
    wm = _team_map_model(lunar_world, "scout")
    with pytest.raises(SkillError, match=r"no pos\(amparo\)"):
        skill_run("MoveToPosition", lunar_world, "scout", {"goal": "pos(amparo)"}, world_model=wm)
    run = skill_run("MoveToPosition", lunar_world, "scout", {"goal": "pos(scout)"}, world_model=wm)
    assert run.ok  # the robot itself: its pose estimate
    wm.set("pos", "depot", value=free_goal(lunar_world, "scout", 3.0))
    run = skill_run("MoveToPosition", lunar_world, "scout", {"goal": "pos(depot)"}, world_model=wm)
    assert run.ok, run.reason
