"""The robots' own cameras: colour and depth from pybullet, with consistent geometry."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from alica.worldsim.errors import WorldError
from alica.worldsim.robot_camera import camera_pose, robot_camera


def test_a_sample_in_view_projects_onto_its_pixels_at_its_depth(lunar_world):
    scout = lunar_world.robots["scout"]
    sample = lunar_world.objects["a"]
    sx, sy, sz = sample.position()
    toward = -np.array([sx, sy]) / math.hypot(sx, sy)  # from the sample towards the field's centre
    scout.set_pose(
        sx + 2.0 * toward[0], sy + 2.0 * toward[1], math.atan2(-toward[1], -toward[0])
    )  # 2 m away, facing it
    lunar_world.step(0.01)
    image = robot_camera(scout, width=160, height=120)
    assert image.rgb.shape == (120, 160, 3) and image.rgb.dtype == np.uint8
    u, v, d = image.project((sx, sy, sz))
    assert 0 <= u < 160 and 0 <= v < 120
    seen = image.depth[round(v), round(u)]
    assert abs(seen - d) < 0.1  # the surface of the container, a few cm before its axis
    # the pixel goes back to a world point on the container
    points = image.points(max_depth=5.0)
    near = points[np.linalg.norm(points[:, :2] - np.array([sx, sy]), axis=1) < 0.15]
    assert len(near) > 10


def test_empty_sky_has_no_depth_and_the_ground_is_below_the_camera(lunar_world):
    scout = lunar_world.robots["scout"]
    image = robot_camera(scout, width=80, height=60)
    assert np.isinf(image.depth[0]).any()  # the top row looks above the horizon (tilt 15 deg, fov 60 deg: not all)
    ground = image.points(max_depth=3.0)
    assert len(ground) and np.all(ground[:, 2] < camera_pose(scout)[0][2])


def test_same_seed_same_picture(lunar_world):
    scout = lunar_world.robots["scout"]
    a = robot_camera(scout, width=40, height=30)
    b = robot_camera(scout, width=40, height=30)
    assert np.array_equal(np.isinf(a.depth), np.isinf(b.depth))
    assert not np.array_equal(a.rgb, b.rgb) or lunar_world.noise.pixel_sigma == 0  # fresh noise per picture


def test_a_robot_without_a_camera_and_bad_sizes_are_clear_errors(blocks_world, lunar_world):
    with pytest.raises(WorldError, match="width and height"):
        robot_camera(lunar_world.robots["scout"], width=2)
    with pytest.raises(WorldError, match="fov"):
        robot_camera(lunar_world.robots["scout"], fov=4.0)


def test_the_pan_unit_turns_the_camera_and_a_fixed_camera_refuses_to_turn(lunar_world):
    scout = lunar_world.robots["scout"]
    sample = lunar_world.objects["a"]
    sx, sy, sz = sample.position()
    # the sample 2 m to the robot's left: out of the forward view, in view with the camera turned left
    scout.set_pose(sx, sy - 2.0, 0.0)
    lunar_world.step(0.01)
    ahead = robot_camera(scout, width=160, height=120)
    u, _, d = ahead.project((sx, sy, sz))
    assert not (d > 0 and 0 <= u < 160)
    left = robot_camera(scout, width=160, height=120, pan=math.pi / 2)
    u, v, d = left.project((sx, sy, sz))
    assert 0 <= u < 160 and 0 <= v < 120 and left.pan == math.pi / 2
    assert abs(left.depth[round(v), round(u)] - d) < 0.1
    assert np.allclose(left.position, ahead.position)  # the pan unit turns the camera where it is mounted
    with pytest.raises(WorldError, match="at most 2.793 rad"):
        robot_camera(scout, pan=math.radians(170.0))
    with pytest.raises(WorldError, match="fixed camera"):
        robot_camera(lunar_world.robots["amparo"], pan=0.1)


def test_a_believed_picture_carries_the_camera_pose_of_the_estimate(lunar_world):
    scout = lunar_world.robots["scout"]
    x, y, yaw = scout.pose
    scout.set_estimate((x + 0.5, y, yaw + 0.1))
    true = robot_camera(scout, width=40, height=30, pan=0.3)
    believed = robot_camera(scout, width=40, height=30, pan=0.3, believed=True)
    assert np.array_equal(np.isinf(true.depth), np.isinf(believed.depth))  # the same view, taken where it is
    position, rotation = camera_pose(scout, (x + 0.5, y, yaw + 0.1), 0.3)
    assert np.allclose(believed.position, position) and np.allclose(believed.rotation, rotation)
    assert np.allclose(true.position, camera_pose(scout, pan=0.3)[0])


def test_a_window_is_the_same_pixels_as_the_whole_frame_there(lunar_world):
    scout = lunar_world.robots["scout"]
    lunar_world.noise = dataclasses.replace(lunar_world.noise, pixel_sigma=0.0, depth_sigma=0.0)
    whole = robot_camera(scout, width=160, height=120, pan=0.2)
    part = robot_camera(scout, width=160, height=120, pan=0.2, window=(40, 50, 100, 90))
    assert part.rgb.shape == (40, 60, 3) and part.offset == (40, 50) and part.frame == (160, 120)
    assert part.frame_size == (160, 120) and whole.frame_size == (160, 120) and whole.offset == (0, 0)
    assert np.array_equal(part.rgb, whole.rgb[50:90, 40:100])
    finite = np.isfinite(whole.depth[50:90, 40:100])
    assert np.array_equal(finite, np.isfinite(part.depth))
    assert np.allclose(part.depth[finite], whole.depth[50:90, 40:100][finite], rtol=1e-4)
    # the window's intrinsics project a world point onto the same pixel, shifted by the offset
    point = whole.points(max_depth=5.0)[0]
    u, v, d = whole.project(point)
    pu, pv, pd = part.project(point)
    assert (pu + 40, pv + 50, pd) == pytest.approx((u, v, d))


@pytest.mark.parametrize(
    ("window", "match"),
    [
        ((0, 0, 4, 40), "at least 8 pixels"),
        ((150, 0, 170, 40), "must lie in the 160x120 frame"),
        ((0.5, 0, 20, 20), "whole numbers"),
        ((0, 0, 20), r"\(u0, v0, u1, v1\)"),
    ],
)
def test_a_bad_window_is_refused(lunar_world, window, match):
    with pytest.raises(WorldError, match=match):
        robot_camera(lunar_world.robots["scout"], width=160, height=120, window=window)
