"""Arm motion planning for the manipulation skills (Pickup, Putdown, Stack, Unstack and their steps).

Works on the arm's planning scene (:class:`~alica.worldsim.arm_interface.ArmPlanningScene`,
which the world implements: :class:`alica.worldsim.arm_scene.ArmScene`, a pybullet
DIRECT client, and a robot's arm gives by ``arm.planning_scene()``) with plain data
(poses, :class:`~alica.worldsim.geometry.Box` es); plans are returned as data
(configurations and joint paths) for someone else to execute. No pybullet here.
See ``docs/manipulation.md``.
"""

from __future__ import annotations

from alica.skills.manipulation.arm_paths import ArmPath, interpolate_path, path_is_free, plan_arm
from alica.skills.manipulation.cartesian import straight_line
from alica.skills.manipulation.geometry import Pose, Quat, Vec3, top_down_quat
from alica.skills.manipulation.grasps import Grasp, held_box, place_poses, placed_box, top_grasps
from alica.skills.manipulation.ik import IKResult, solve_ik
from alica.skills.manipulation.pickup import PickupPlan, PlacePlan, plan_pickup, plan_place
from alica.skills.manipulation.transport import TransportPlan, plan_transport
from alica.worldsim.arm_interface import ArmPlanningScene
from alica.worldsim.geometry import Box

__all__ = [
    "ArmPath",
    "ArmPlanningScene",
    "Box",
    "Grasp",
    "IKResult",
    "PickupPlan",
    "PlacePlan",
    "Pose",
    "Quat",
    "TransportPlan",
    "Vec3",
    "held_box",
    "interpolate_path",
    "path_is_free",
    "place_poses",
    "placed_box",
    "plan_arm",
    "plan_pickup",
    "plan_place",
    "plan_transport",
    "solve_ik",
    "straight_line",
    "top_down_quat",
    "top_grasps",
]
