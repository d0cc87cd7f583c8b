"""The close look (alica.skills.close_look): a sample's pose for the grasp from the robot's own camera."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from alica.skills.close_look import fit_circle_of_radius, look_at, sighting_from_points

SIZE, RADIUS = 0.1, 0.03


def _half_cylinder(centre, viewpoint, *, n=400, noise=0.0, seed=0):
    """Points on the side of an upright cylinder that faces ``viewpoint``, plus a flat ground ring."""
    rng = np.random.default_rng(seed)
    facing = math.atan2(viewpoint[1] - centre[1], viewpoint[0] - centre[0])
    a = facing + rng.uniform(-math.pi / 2, math.pi / 2, n)
    z = rng.uniform(0.0, SIZE, n)
    side = np.column_stack([centre[0] + RADIUS * np.cos(a), centre[1] + RADIUS * np.sin(a), z])
    r = rng.uniform(0.22, 0.4, n)
    b = rng.uniform(0, 2 * math.pi, n)
    ground = np.column_stack([centre[0] + r * np.cos(b), centre[1] + r * np.sin(b), np.zeros(n)])
    pts = np.vstack([side, ground])
    return pts + rng.normal(0.0, noise, pts.shape)


def test_a_circle_of_known_radius_fits_one_side_of_it():
    a = np.linspace(-1.2, 1.2, 50)
    xy = np.column_stack([1.0 + RADIUS * np.cos(a), 2.0 + RADIUS * np.sin(a)])
    x, y = fit_circle_of_radius(xy, RADIUS, (1.02, 2.0))
    assert math.hypot(x - 1.0, y - 2.0) < 1e-4


def test_an_upright_container_is_found_from_its_visible_side_with_a_bounded_error():
    centre = (3.0, 1.0)
    viewpoint = np.array([2.3, 1.2, 0.4])
    pts = _half_cylinder(centre, viewpoint, noise=0.002)
    seen = sighting_from_points(pts, viewpoint, (3.08, 0.95), size=SIZE, radius=RADIUS)  # the detection 9 cm off
    assert seen is not None and seen.upright
    assert math.hypot(seen.x - centre[0], seen.y - centre[1]) < 0.01
    assert abs(seen.ground) < 0.005 and abs(seen.top - SIZE) < 0.01


def test_nothing_standing_near_the_place_is_no_sighting():
    viewpoint = np.array([2.3, 1.2, 0.4])
    pts = _half_cylinder((3.0, 1.0), viewpoint)
    assert sighting_from_points(pts, viewpoint, (5.0, 5.0), size=SIZE, radius=RADIUS) is None
    assert sighting_from_points(np.zeros((0, 3)), viewpoint, (3.0, 1.0), size=SIZE, radius=RADIUS) is None


# -- with the robot's camera in a world ------------------------------------------------------------------------


@pytest.fixture
def field():
    pytest.importorskip("pybullet")
    from alica.worldsim.objects import SAMPLE_KINDS
    from alica.worldsim.world import World

    with World(0, bounds=(-1.0, -1.0, 10.0, 10.0)) as world:
        world.add_sample("a", SAMPLE_KINDS[0], (3.0, 3.0))
        world.add_robot("stummel", "r1", (2.27, 3.0, 0.0))  # at the arm's stand-off (reach + mount ahead)
        world.step(0.1)
        yield world


@pytest.mark.parametrize("heading", [0.0, 0.6, -0.5])
def test_look_at_measures_the_sample_within_a_centimetre(field, heading):
    world = field
    robot = world.robots["r1"]
    robot.set_pose(3.0 - 0.73 * math.cos(heading), 3.0 - 0.73 * math.sin(heading), heading)
    world.step(0.05)
    seen = look_at(robot, (2.93, 3.06), size=SIZE, radius=RADIUS)
    assert seen is not None and seen.upright
    true = world.objects["a"].position()
    assert math.hypot(seen.x - true[0], seen.y - true[1]) < 0.01


def test_a_lying_container_is_seen_lying_along_its_axis(field):
    world = field
    obj = world.objects["a"]
    axis_yaw = 0.4
    q = world.client.getQuaternionFromEuler((0.0, math.pi / 2, axis_yaw))
    world.client.resetBasePositionAndOrientation(obj.body_id, (3.0, 3.0, RADIUS + 0.002), q)
    world.step(0.5)
    seen = look_at(world.robots["r1"], (3.0, 3.0), size=SIZE, radius=RADIUS)
    assert seen is not None and not seen.upright
    true = obj.position()
    assert math.hypot(seen.x - true[0], seen.y - true[1]) < 0.025
    turn = abs(math.remainder(seen.yaw - axis_yaw, math.pi))
    assert turn < math.radians(15.0)


def test_the_grasp_takes_the_camera_measurement_not_the_detection_or_the_truth(field):
    """A detection 8 cm off: the close look before the plan corrects it, within a bounded error from the truth."""
    from alica.engine.behaviours import SkillContext
    from alica.skills.handling import Pickup
    from alica.worldmodel import WorldModel

    world = field
    wm = WorldModel("r1", clock=world.clock)
    wm.set("pos", "a", value=(3.06, 2.95))  # the team's detection
    context = SkillContext("r1", world.now, wm, wm, random.Random(0), world)
    skill = Pickup("pickup", {"object": "a", "retries": 3}, context)
    skill.setup(context=context)
    skill.initialise()
    assert skill.expected_xy() == (3.06, 2.95)  # before the look: the detection
    skill.look()
    box, kind = skill.grasp_target()
    true = world.objects["a"].position()
    assert kind == "cylinder"
    assert math.hypot(box.center[0] - true[0], box.center[1] - true[1]) < 0.01
    assert skill.site() == (box.center[0], box.center[1])


def test_a_pose_estimate_off_by_centimetres_does_not_move_the_grasp(field):
    """The camera measures relative to the robot; the arm plans relative to its base: the grasp stays on the sample."""
    from alica.engine.behaviours import SkillContext
    from alica.skills.handling import Pickup

    world = field
    robot = world.robots["r1"]
    x, y, yaw = robot.pose
    robot.set_estimate((x + 0.05, y - 0.04, yaw + 0.03))
    context = SkillContext("r1", world.now, None, None, random.Random(0), world)
    skill = Pickup("pickup", {"object": "a", "retries": 3}, context)
    skill.setup(context=context)
    skill.initialise()
    skill.look()
    assert skill.sighting is not None
    true = world.objects["a"].position()
    believed = math.hypot(skill.sighting.x - true[0], skill.sighting.y - true[1])
    assert believed > 0.03  # in the robot's believed frame the sample is off as much as the robot's estimate
    box, _ = skill.grasp_target()
    assert math.hypot(box.center[0] - true[0], box.center[1] - true[1]) < 0.01
