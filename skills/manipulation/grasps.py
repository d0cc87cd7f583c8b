"""Top grasps of boxes and cylinders, and tool poses that put a held object down.

Tool frame convention (the Panda's ``panda_grasptarget``): z points out of the
hand between the fingers, the fingers close along y. A top grasp points the
tool straight down (``Rz(yaw) * Rx(pi)``, see :func:`top_down_quat`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from alica.skills.manipulation.geometry import (
    Pose,
    Vec3,
    as_vec3,
    pose_inverse,
    pose_multiply,
    quat_from_yaw,
    quat_rotate,
    top_down_quat,
    vertical_yaw,
    wrap_angle,
)
from alica.worldsim.geometry import Box

#: Height of the approach (pre-grasp / above-place) pose over the grasp or place pose.
APPROACH_HEIGHT = 0.10
#: How far below an object's top the tool frame goes at most (the fingers are ~5 cm long).
GRASP_DEPTH = 0.03
#: Gap left between a placed object's bottom and its support when it is released.
PLACE_CLEARANCE = 0.008
#: Opening of the Panda's gripper (inner gap of the open fingers is 7.8 cm).
DEFAULT_MAX_WIDTH = 0.077


@dataclass(frozen=True, slots=True)
class Grasp:
    """A grasp of an object as tool poses.

    Attributes:
        pose: world pose of the tool frame when grasping.
        approach_pose: pose above ``pose`` from which the tool moves straight down.
        width: width of the object between the fingers, in metres.
        yaw: the tool's yaw about the world z axis.
    """

    pose: Pose
    approach_pose: Pose
    width: float
    yaw: float


def _width_across(half_extents: Vec3, relative_yaw: float) -> float:
    """Extent of a box along the tool's y (finger) axis when the tool is turned ``relative_yaw`` from the box."""
    hx, hy, _ = half_extents
    return 2.0 * (abs(math.sin(relative_yaw)) * hx + abs(math.cos(relative_yaw)) * hy)


def top_grasps(
    center: Sequence[float],
    half_extents: Sequence[float],
    yaw: float,
    *,
    kind: Literal["box", "cylinder"] = "box",
    approach_height: float = APPROACH_HEIGHT,
    max_width: float = DEFAULT_MAX_WIDTH,
) -> list[Grasp]:
    """Grasps from the top of an upright box or cylinder.

    A box gets four grasps (the fingers across its x or y faces, each from two
    sides); a cylinder (radius ``half_extents[0]``) gets eight yaws 45 degrees
    apart. Grasps whose width exceeds ``max_width`` are left out.

    Args:
        center: the object's centre (x, y, z).
        half_extents: half sizes (hx, hy, hz); for a cylinder (r, r, half height).
        yaw: the object's yaw about the world z axis.
        kind: ``"box"`` or ``"cylinder"``.
        approach_height: height of the approach pose over the grasp pose (> 0).
        max_width: widest object the gripper can take.

    Raises:
        ValueError: non-positive sizes or heights, or an unknown ``kind``.
    """
    c = as_vec3(center, "center")
    half = as_vec3(half_extents, "half_extents")
    if min(half) <= 0.0:
        raise ValueError(f"half_extents must be > 0, got {half}")
    if not (math.isfinite(approach_height) and approach_height > 0):
        raise ValueError(f"approach_height must be > 0, got {approach_height!r}")
    if kind == "box":
        offsets = [k * math.pi / 2.0 for k in range(4)]
    elif kind == "cylinder":
        offsets = [k * math.pi / 4.0 for k in range(8)]
        half = (half[0], half[0], half[2])
    else:
        raise ValueError(f"kind must be 'box' or 'cylinder', got {kind!r}")
    top = c[2] + half[2]
    z = top - min(half[2], GRASP_DEPTH)
    grasps = []
    for offset in offsets:
        width = _width_across(half, offset) if kind == "box" else 2.0 * half[0]
        if width > max_width:
            continue
        tool_yaw = wrap_angle(yaw + offset)
        quat = top_down_quat(tool_yaw)
        grasps.append(Grasp(((c[0], c[1], z), quat), ((c[0], c[1], z + approach_height), quat), width, tool_yaw))
    return grasps


def held_box(obj: Box, tool_pose: Pose) -> Box:
    """The object ``obj`` (world box) as a box in the frame of the tool at ``tool_pose``.

    Raises:
        ValueError: the relative rotation tilts the box (only vertical tools are supported).
    """
    pos, quat = pose_multiply(pose_inverse(tool_pose), obj.pose)
    return Box(obj.name, pos, obj.half_extents, vertical_yaw(quat))


def placed_box(held: Box, tool_pose: Pose) -> Box:
    """Where the tool-frame box ``held`` is in the world when the tool is at ``tool_pose``."""
    pos, quat = pose_multiply(tool_pose, (held.center, quat_from_yaw(held.yaw)))
    return Box(held.name, pos, held.half_extents, wrap_angle(vertical_yaw(quat)))


def place_poses(
    target_center_top: Sequence[float],
    half_extents: Sequence[float],
    held_offset: Sequence[float],
    *,
    yaws: Sequence[float] | None = None,
    clearance: float = PLACE_CLEARANCE,
) -> list[Pose]:
    """Tool poses (pointing down) that put a held object on a surface.

    The held object's centre is ``held_offset`` in the tool frame and its z axis
    is the tool's (top grasps); each returned pose puts the object's centre
    above ``target_center_top`` with its bottom ``clearance`` above that height.

    Args:
        target_center_top: the point on the support's top face (x, y, z) under the object's centre
            (the ground: z = 0; a block: its top face centre).
        half_extents: the held object's half sizes.
        held_offset: the object's centre in the tool frame.
        yaws: tool yaws to try (default eight, 45 degrees apart, starting at 0).
        clearance: gap between object and support at release (>= 0).

    Raises:
        ValueError: malformed vectors or a negative clearance.
    """
    target = as_vec3(target_center_top, "target_center_top")
    half = as_vec3(half_extents, "half_extents")
    offset = as_vec3(held_offset, "held_offset")
    if min(half) <= 0.0:
        raise ValueError(f"half_extents must be > 0, got {half}")
    if not (math.isfinite(clearance) and clearance >= 0.0):
        raise ValueError(f"clearance must be >= 0, got {clearance!r}")
    chosen = [k * math.pi / 4.0 for k in range(8)] if yaws is None else [float(y) for y in yaws]
    centre = (target[0], target[1], target[2] + clearance + half[2])
    poses = []
    for yaw in chosen:
        quat = top_down_quat(wrap_angle(yaw))
        r = quat_rotate(quat, offset)
        poses.append(((centre[0] - r[0], centre[1] - r[1], centre[2] - r[2]), quat))
    return poses
