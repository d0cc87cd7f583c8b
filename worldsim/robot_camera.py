"""The robots' own cameras: colour and depth images rendered by pybullet from where the robot stands.

A robot with the ``camera`` or ``stereo_camera`` capability carries a camera
on top of its base, :data:`MOUNT_FORWARD` of its radius ahead of its centre
and :data:`MOUNT_UP` above the base, looking :data:`TILT` down and along the
robot's heading turned by the ``pan`` angle (left positive) of its pan unit:
up to ``spec.camera_pan_limit`` either way (Scout and Stummel: a directed
colour camera on a pan-tilt unit; Amparo's stereo pair is fixed, 0).
:func:`robot_camera` renders what it sees:

* ``rgb``: ``(height, width, 3)`` ``uint8``, with seeded Gaussian pixel noise
  (``world.noise.pixel_sigma``, in intensity levels);
* ``depth``: ``(height, width)`` metres along the optical axis, ``inf`` where
  nothing is within the far plane, with seeded Gaussian noise growing with the
  square of the distance (``world.noise.depth_sigma`` at 1 m, as a stereo
  pair's depth error does);
* the pinhole intrinsics ``(fx, fy, cx, cy)`` in pixels and the camera pose:
  ``position`` and ``rotation`` (world from camera, OpenCV axes: x right, y
  down, z forward), so a pixel ``(u, v)`` with depth ``d`` is the world point
  ``position + rotation @ [(u - cx) d / fx, (v - cy) d / fy, d]``
  (:meth:`CameraImage.points` does this for every pixel).

The picture is always taken where the robot truly is (it is the sensor). Its
pose is the true camera pose by default; with ``believed=True`` it is the pose
derived from the robot's pose *estimate* (``robot.estimate``: odometry,
corrected by localization), which is all a perception skill may know: points
and projections then live in the robot's believed world frame.

Nothing here reads object names or the simulator's ground truth beyond what a
camera sees: perception skills get pixels and depths only.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from alica.worldsim.camera_image import CameraImage
from alica.worldsim.errors import WorldError

if TYPE_CHECKING:
    from alica.worldsim.sensing import SensingRobot

#: The camera sits this fraction of the robot's radius ahead of its centre.
MOUNT_FORWARD = 0.8
#: ... and this many metres above the top of its base.
MOUNT_UP = 0.15
#: It looks this many radians below the horizon.
TILT = math.radians(15.0)
#: Nearest distance rendered, metres.
NEAR = 0.05


def camera_pose(
    robot: SensingRobot, pose: tuple[float, float, float] | None = None, pan: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Where the robot's camera is and how it is turned: ``(position, rotation world-from-camera)``.

    Args:
        robot: the robot (its spec gives the mount).
        pose: the base pose ``(x, y, yaw)``; default the true pose (``robot.estimate`` for what the robot believes).
        pan: the pan angle, radians left of the heading (not checked against the limit here).
    """
    x, y, yaw = robot.pose if pose is None else pose
    spec = robot.spec
    position = np.array(
        [
            x + MOUNT_FORWARD * spec.radius * math.cos(yaw),
            y + MOUNT_FORWARD * spec.radius * math.sin(yaw),
            spec.height + MOUNT_UP,
        ]
    )
    look = yaw + pan
    forward = np.array([math.cos(look) * math.cos(TILT), math.sin(look) * math.cos(TILT), -math.sin(TILT)])
    right = np.array([math.sin(look), -math.cos(look), 0.0])
    down = np.cross(forward, right)
    return position, np.column_stack([right, down, forward])


def robot_camera(
    robot: SensingRobot,
    *,
    width: int = 320,
    height: int = 240,
    fov: float | None = None,
    far: float | None = None,
    pan: float = 0.0,
    believed: bool = False,
    window: tuple[int, int, int, int] | None = None,
) -> CameraImage:
    """Render the robot's camera (see the module docstring).

    Args:
        robot: a robot with the ``camera`` or ``stereo_camera`` capability.
        width: image width in pixels.
        height: image height in pixels.
        fov: horizontal field of view in radians (default: the robot's ``camera_fov``).
        far: farthest distance rendered, metres (default: twice the robot's ``perception_range``).
        pan: the pan angle, radians left of the heading, within ``spec.camera_pan_limit`` either way.
        believed: give the picture the camera pose of the robot's pose estimate instead of the true one.
        window: ``(u0, v0, u1, v1)``: render only these pixels ``[v0:v1, u0:u1]`` of the ``width`` x ``height``
            frame (the same pixels as the whole frame's there, at a fraction of the cost); the picture's
            ``offset`` and ``frame`` say where it lies, its intrinsics are the window's. At least 8 pixels a side.

    Raises:
        WorldError: a robot without a camera, a closed world, a bad size, field of view, range, pan angle or window.
    """
    spec = robot.spec
    if not ({"camera", "stereo_camera"} & spec.capabilities):
        raise WorldError(f"robot '{robot.name}' ({spec.kind}) has no camera")
    world = robot.world
    if world.closed:
        raise WorldError("robot_camera: the world is closed")
    if not (isinstance(width, int) and isinstance(height, int) and 8 <= width <= 4096 and 8 <= height <= 4096):
        raise WorldError(
            f"robot_camera: width and height are whole numbers of pixels in [8, 4096], got {width}x{height}"
        )
    hfov = spec.camera_fov if fov is None else float(fov)
    if not (math.isfinite(hfov) and 0.0 < hfov < math.pi):
        raise WorldError(f"robot_camera: fov must be in (0, pi) radians, got {fov}")
    far_plane = 2.0 * spec.perception_range if far is None else float(far)
    if not (math.isfinite(far_plane) and far_plane > NEAR):
        raise WorldError(f"robot_camera: far must be a number of metres above {NEAR}, got {far}")
    try:
        pan = float(pan)
    except (TypeError, ValueError):
        raise WorldError(f"robot_camera: pan must be a number of radians, got {pan!r}") from None
    limit = spec.camera_pan_limit
    if not (math.isfinite(pan) and abs(pan) <= limit + 1e-9):
        turn = f"turns its camera at most {limit:.3f} rad either way" if limit > 0.0 else "has a fixed camera (pan 0)"
        raise WorldError(f"robot_camera: robot '{robot.name}' ({spec.kind}) {turn}, got pan {pan!r}")
    u0, v0, u1, v1 = _window(window, width, height)
    position, rotation = camera_pose(robot, pan=pan)
    forward, down = rotation[:, 2], rotation[:, 1]
    fx = (width / 2.0) / math.tan(hfov / 2.0)
    fy = fx
    client = world.client
    view = client.computeViewMatrix(list(position), list(position + forward), list(-down))
    # the frustum through the window's pixel edges (the whole frame's when there is no window)
    n, f = NEAR, far_plane
    left, right = n * (u0 - width / 2.0) / fx, n * (u1 - width / 2.0) / fx
    top, bottom = n * (height / 2.0 - v0) / fy, n * (height / 2.0 - v1) / fy
    projection = (
        client.computeProjectionMatrixFOV(math.degrees(2.0 * math.atan((height / 2.0) / fy)), width / height, n, f)
        if window is None
        else [
            *(2.0 * n / (right - left), 0.0, 0.0, 0.0),
            *(0.0, 2.0 * n / (top - bottom), 0.0, 0.0),
            *((right + left) / (right - left), (top + bottom) / (top - bottom), -(f + n) / (f - n), -1.0),
            *(0.0, 0.0, -2.0 * f * n / (f - n), 0.0),
        ]
    )
    w, h = u1 - u0, v1 - v0
    _, _, rgba, zbuffer, _ = client.getCameraImage(w, h, view, projection, renderer=client.ER_TINY_RENDERER, shadow=0)
    rgb = np.asarray(rgba, dtype=np.uint8).reshape(h, w, 4)[:, :, :3].astype(float)
    z = np.asarray(zbuffer, dtype=float).reshape(h, w)
    depth = far_plane * NEAR / (far_plane - (far_plane - NEAR) * z)
    depth[z >= 1.0 - 1e-7] = math.inf
    noise = world.noise
    if noise.pixel_sigma > 0.0:
        rgb += world.rng.normal(0.0, noise.pixel_sigma, rgb.shape)
    finite = np.isfinite(depth)
    if noise.depth_sigma > 0.0 and finite.any():
        depth[finite] += world.rng.normal(0.0, 1.0, int(finite.sum())) * noise.depth_sigma * depth[finite] ** 2
    image = np.clip(np.rint(rgb), 0, 255).astype(np.uint8)
    if believed:
        position, rotation = camera_pose(robot, robot.estimate, pan)
    intrinsics = (fx, fy, width / 2.0 - 0.5 - u0, height / 2.0 - 0.5 - v0)
    frame = None if window is None else (width, height)
    return CameraImage(image, depth, intrinsics, position, rotation, world.now(), pan, (u0, v0), frame)


def _window(window: tuple[int, int, int, int] | None, width: int, height: int) -> tuple[int, int, int, int]:
    """The pixels ``(u0, v0, u1, v1)`` to render, checked against the frame."""
    if window is None:
        return 0, 0, width, height
    try:
        u0, v0, u1, v1 = window
    except (TypeError, ValueError):
        raise WorldError(f"robot_camera: window is (u0, v0, u1, v1) in pixels, got {window!r}") from None
    if not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in (u0, v0, u1, v1)):
        raise WorldError(f"robot_camera: window is four whole numbers of pixels, got {window!r}")
    if not (0 <= u0 and u1 <= width and 0 <= v0 and v1 <= height and u1 - u0 >= 8 and v1 - v0 >= 8):
        raise WorldError(
            f"robot_camera: window {window!r} must lie in the {width}x{height} frame and be at least 8 pixels a side"
        )
    return int(u0), int(v0), int(u1), int(v1)
