"""What each kind of robot is and can do: :class:`RobotSpec` and the kinds of :data:`ROBOT_KINDS`.

Pure data (no pybullet): skills read a robot's spec (``robot.spec``, through
:mod:`alica.worldsim.interface`), the world builds its robots from them
(:mod:`alica.worldsim.robots`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["ROBOT_KINDS", "RobotSpec"]


@dataclass(frozen=True, slots=True)
class RobotSpec:
    """What a kind of robot is and can do.

    Attributes:
        kind: the kind name (a key of :data:`ROBOT_KINDS`).
        capabilities: the capability words of ``plans/roles.yaml`` ``requires``.
        radius: footprint radius in metres.
        max_speed: largest forward or backward speed in m/s.
        max_yaw_rate: largest turning rate in rad/s.
        has_arm: carries a Panda arm with a parallel gripper.
        lidar_range: range of the 2-D laser scanner in metres.
        perception: ``"camera"`` (directed colour camera) or ``"3d"`` (stereo and 3-D lidar).
        height: height of the base body (the arm is mounted on top).
        lidar_height: height of the scan plane above the ground.
        camera_fov: horizontal field of view of the object perception in radians.
        camera_pan_limit: how far the camera's pan unit turns it left or right of the heading, radians
            (0: a fixed camera looking ahead).
        perception_range: default range of the object perception in metres.
        mass: nominal mass in kg (descriptive; the base is kinematic).
        colour: RGBA of the base body.
    """

    kind: str
    capabilities: frozenset[str]
    radius: float
    max_speed: float
    max_yaw_rate: float
    has_arm: bool
    lidar_range: float
    perception: str
    height: float = 0.25
    lidar_height: float = 0.1
    camera_fov: float = math.radians(70.0)
    camera_pan_limit: float = 0.0
    perception_range: float = 4.0
    mass: float = 30.0
    colour: tuple[float, float, float, float] = (0.5, 0.5, 0.5, 1.0)


#: The robot kinds: the three IMPERA robots and a generic mobile manipulator for the blocks world.
ROBOT_KINDS: dict[str, RobotSpec] = {
    "scout": RobotSpec(
        "scout",
        frozenset({"base", "lidar2d", "camera"}),
        radius=0.25,
        max_speed=1.2,
        max_yaw_rate=2.0,
        has_arm=False,
        lidar_range=30.0,
        lidar_height=0.05,
        perception="camera",
        height=0.2,
        camera_fov=math.radians(60.0),
        camera_pan_limit=math.radians(160.0),  # a pan-tilt unit's +-159 degrees
        perception_range=5.0,
        mass=25.0,
        colour=(0.15, 0.45, 0.85, 1.0),
    ),
    "stummel": RobotSpec(
        "stummel",
        frozenset({"base", "arm", "gripper", "lidar2d", "camera"}),
        radius=0.3,
        max_speed=0.8,
        max_yaw_rate=1.5,
        has_arm=True,
        lidar_range=30.0,
        lidar_height=0.05,
        perception="camera",
        height=0.25,
        camera_fov=math.radians(60.0),
        camera_pan_limit=math.radians(160.0),  # a pan-tilt unit's +-159 degrees
        perception_range=4.0,
        mass=35.0,
        colour=(0.9, 0.55, 0.1, 1.0),
    ),
    "amparo": RobotSpec(
        "amparo",
        frozenset({"base", "arm", "gripper", "lidar3d", "stereo_camera"}),
        radius=0.35,
        max_speed=0.5,
        max_yaw_rate=1.0,
        has_arm=True,
        lidar_range=20.0,
        perception="3d",
        height=0.28,
        camera_fov=math.radians(90.0),
        perception_range=6.0,
        mass=60.0,
        colour=(0.75, 0.15, 0.2, 1.0),
    ),
    "manipulator": RobotSpec(
        "manipulator",
        frozenset({"base", "arm", "gripper", "lidar2d", "camera"}),
        radius=0.25,
        max_speed=0.5,
        max_yaw_rate=1.5,
        has_arm=True,
        lidar_range=10.0,
        perception="camera",
        height=0.22,
        camera_fov=math.radians(70.0),
        perception_range=3.0,
        mass=30.0,
        colour=(0.3, 0.6, 0.35, 1.0),
    ),
}
