"""Top grasps, tool-frame boxes and place poses (pure geometry, no physics)."""

from __future__ import annotations

import math

import pytest

from alica.skills.manipulation import Box, held_box, place_poses, placed_box, top_down_quat, top_grasps
from alica.skills.manipulation.geometry import quat_angle, quat_rotate


def test_top_grasps_of_a_box() -> None:
    grasps = top_grasps((0.5, 0.1, 0.05), (0.02, 0.03, 0.05), 0.4, approach_height=0.12)
    assert len(grasps) == 4
    assert sorted(round(g.width, 6) for g in grasps) == [0.04, 0.04, 0.06, 0.06]
    for g in grasps:
        (x, y, z), quat = g.pose
        assert (x, y) == pytest.approx((0.5, 0.1))
        assert z == pytest.approx(0.1 - 0.03)  # 3 cm below the top of a 10 cm tall box
        assert quat_rotate(quat, (0, 0, 1)) == pytest.approx((0, 0, -1), abs=1e-9)  # tool points down
        assert g.approach_pose[0] == pytest.approx((x, y, z + 0.12))
        assert g.approach_pose[1] == quat
        assert quat_angle(quat, top_down_quat(g.yaw)) < 1e-9
    assert grasps[0].yaw == pytest.approx(0.4)
    assert grasps[0].width == pytest.approx(0.06)  # fingers close along the tool's y = the box's y


def test_small_cube_is_grasped_at_its_centre_and_wide_boxes_are_skipped() -> None:
    cube = top_grasps((0.5, 0.0, 0.025), (0.025, 0.025, 0.025), 0.0)
    assert len(cube) == 4 and all(g.pose[0][2] == pytest.approx(0.025) for g in cube)
    narrow_one_way = top_grasps((0.5, 0.0, 0.05), (0.1, 0.02, 0.05), 0.0)
    assert len(narrow_one_way) == 2 and all(g.width == pytest.approx(0.04) for g in narrow_one_way)
    assert top_grasps((0.5, 0.0, 0.05), (0.1, 0.1, 0.05), 0.0) == []
    cylinder = top_grasps((0.5, 0.0, 0.05), (0.03, 0.03, 0.05), 0.0, kind="cylinder")
    assert len(cylinder) == 8 and all(g.width == pytest.approx(0.06) for g in cylinder)


def test_held_box_round_trip() -> None:
    obj = Box("cube", (0.5, 0.1, 0.025), (0.02, 0.03, 0.025), 0.3)
    tool = ((0.5, 0.1, 0.04), top_down_quat(1.0))
    held = held_box(obj, tool)
    assert held.center == pytest.approx((0.0, 0.0, 0.015), abs=1e-9)  # tool z points down
    assert held.yaw == pytest.approx(0.7)
    back = placed_box(held, tool)
    assert back.center == pytest.approx(obj.center, abs=1e-9)
    assert math.cos(back.yaw - obj.yaw) == pytest.approx(1.0)


def test_place_poses_put_the_bottom_above_the_target() -> None:
    held = Box("cube", (0.0, 0.0, 0.01), (0.025, 0.025, 0.025), 0.2)
    poses = place_poses((0.4, -0.2, 0.05), held.half_extents, held.center, clearance=0.005)
    assert len(poses) == 8
    for pose in poses:
        placed = placed_box(held, pose)
        assert placed.center == pytest.approx((0.4, -0.2, 0.05 + 0.005 + 0.025), abs=1e-9)
        assert quat_rotate(pose[1], (0, 0, 1)) == pytest.approx((0, 0, -1), abs=1e-9)
    two = place_poses((0.4, -0.2, 0.0), held.half_extents, held.center, yaws=[0.0, math.pi / 2])
    assert len(two) == 2


def test_bad_arguments_raise_value_errors() -> None:
    with pytest.raises(ValueError, match="half_extents"):
        top_grasps((0, 0, 0), (0.0, 0.1, 0.1), 0.0)
    with pytest.raises(ValueError, match="kind"):
        top_grasps((0, 0, 0), (0.1, 0.1, 0.1), 0.0, kind="sphere")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="approach_height"):
        top_grasps((0, 0, 0), (0.01, 0.01, 0.01), 0.0, approach_height=0.0)
    with pytest.raises(ValueError, match="clearance"):
        place_poses((0, 0, 0), (0.01, 0.01, 0.01), (0, 0, 0), clearance=-0.01)
    tilted = ((0.0, 0.0, 0.5), (0.0, math.sin(0.3), 0.0, math.cos(0.3)))
    with pytest.raises(ValueError, match="tilts"):
        held_box(Box("cube", (0, 0, 0.1), (0.02, 0.02, 0.02)), tilted)


def test_a_box_fallen_onto_a_side_is_seen_upright_with_its_faces_turned() -> None:
    from alica.skills.manipulation.geometry import quat_multiply, upright_box
    from alica.worldsim.geometry import quat_to_yaw, yaw_to_quat

    half = (0.01, 0.02, 0.03)
    tip = (math.sin(math.pi / 4), 0.0, 0.0, math.cos(math.pi / 4))  # a quarter turn about x: the box lies on its side
    for turn in (0.0, 0.5, -2.0):
        q = quat_multiply(yaw_to_quat(turn), tip)
        yaw, upright = upright_box(q, half)
        assert upright == pytest.approx((0.01, 0.03, 0.02))  # its y axis points up now
        assert math.cos(2 * (yaw - turn)) == pytest.approx(1.0)  # its faces are turned like before the fall
    # upright boxes keep their yaw and extents
    assert upright_box(yaw_to_quat(0.7), half) == (pytest.approx(0.7), half)
    # the Euler yaw of a block that fell about y (at the gimbal lock) is not its faces' yaw
    fallen = quat_multiply(yaw_to_quat(0.3), (0.0, math.sin(math.pi / 4), 0.0, math.cos(math.pi / 4)))
    yaw, _ = upright_box(fallen, (0.025,) * 3)
    assert math.cos(4 * (yaw - 0.3)) == pytest.approx(1.0)
    assert math.cos(4 * (quat_to_yaw(fallen) - 0.3)) < 0.9  # the Euler yaw: 0.17 rad
