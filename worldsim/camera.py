"""Off-screen pictures of a world: pybullet's tiny (software) renderer, written as PNG with matplotlib.

No GUI and no display are needed: :func:`snapshot` works on a ``DIRECT``
client. The camera looks at the middle of the field (or a given target)
from above at an angle, far enough back that every robot and object fits in
the picture.

Example::

    from alica.worldsim.camera import snapshot
    from alica.worldsim.scenarios import blocksworld

    with blocksworld(agents=2, opponents=1) as world:
        snapshot(world, "build/blocks.png")
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from alica.worldsim.errors import WorldError

if TYPE_CHECKING:
    from alica.worldsim.world import World

__all__ = ["DEFAULT_PITCH", "DEFAULT_YAW", "FOV", "render", "snapshot"]

#: Camera yaw in degrees: 0 looks from -y towards +y (the blocks-world row runs across the picture).
DEFAULT_YAW = 0.0
#: Camera pitch in degrees (negative looks down).
DEFAULT_PITCH = -50.0
#: Vertical field of view in degrees.
FOV = 45.0
#: Room in metres kept around the robots and objects when the distance is chosen.
FRAME_MARGIN = 0.5
#: Largest picture side in pixels.
MAX_SIDE = 4096
#: Light direction of the tiny renderer (from above, slightly from the camera side).
LIGHT = (0.4, -0.6, 1.0)


def snapshot(
    world: World,
    path: str | Path,
    *,
    width: int = 640,
    height: int = 480,
    target: Sequence[float] | None = None,
    distance: float | None = None,
    yaw: float = DEFAULT_YAW,
    pitch: float = DEFAULT_PITCH,
) -> Path:
    """Render ``world`` off-screen and write a PNG.

    Args:
        world: the world (its own pybullet client, ``world.client``, renders).
        path: the PNG file; missing folders are made.
        width: picture width in pixels.
        height: picture height in pixels.
        target: the point looked at, ``(x, y)`` or ``(x, y, z)``; the middle of the field by default.
        distance: metres from the camera to the target; by default far enough to show every robot and object.
        yaw: camera yaw in degrees (0 looks along +y).
        pitch: camera pitch in degrees (negative looks down; -90 straight down).

    Returns:
        The path written.

    Raises:
        WorldError: a closed world, a bad size, target, distance or pitch.
    """
    from matplotlib import image as mpimg

    pixels = render(world, width=width, height=height, target=target, distance=distance, yaw=yaw, pitch=pitch)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    mpimg.imsave(out, pixels, format="png")
    return out


def render(
    world: World,
    *,
    width: int = 640,
    height: int = 480,
    target: Sequence[float] | None = None,
    distance: float | None = None,
    yaw: float = DEFAULT_YAW,
    pitch: float = DEFAULT_PITCH,
) -> np.ndarray:
    """The picture :func:`snapshot` writes, as a ``(height, width, 3)`` ``uint8`` RGB array.

    Raises:
        WorldError: as :func:`snapshot`.
    """
    if world.closed:
        raise WorldError("snapshot: the world is closed; take pictures before world.close()")
    width, height = _size(width, "width"), _size(height, "height")
    if not (math.isfinite(pitch) and -90.0 <= pitch < 0.0):
        raise WorldError(f"snapshot: pitch must be in [-90, 0) degrees (looking down), got {pitch}")
    if not math.isfinite(yaw):
        raise WorldError(f"snapshot: yaw must be a finite number of degrees, got {yaw}")
    aim = _target(world, target)
    aspect = width / height
    far = distance if distance is not None else _fit_distance(world, aim, yaw, pitch, aspect)
    if not (math.isfinite(far) and far > 0.0):
        raise WorldError(f"snapshot: distance must be a positive number of metres, got {distance}")
    client = world.client
    view = client.computeViewMatrixFromYawPitchRoll(list(aim), far, yaw, pitch, 0.0, 2)
    projection = client.computeProjectionMatrixFOV(FOV, aspect, max(0.01, 0.02 * far), 4.0 * far + 10.0)
    _, _, rgba, _, _ = client.getCameraImage(
        width, height, view, projection, renderer=client.ER_TINY_RENDERER, lightDirection=list(LIGHT), shadow=0
    )
    pixels = np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)
    return np.ascontiguousarray(pixels[:, :, :3])


def _size(value: object, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= int(value) <= MAX_SIDE:
        raise WorldError(f"snapshot: {what} must be a whole number of pixels from 1 to {MAX_SIDE}, got {value!r}")
    return int(value)


def _target(world: World, target: Sequence[float] | None) -> tuple[float, float, float]:
    """The point looked at: the given one (z = 0 when 2-D), or the middle of the field."""
    if target is None:
        xmin, ymin, xmax, ymax = world.bounds
        return 0.5 * (xmin + xmax), 0.5 * (ymin + ymax), 0.0
    values = [float(v) for v in target]
    if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
        raise WorldError(f"snapshot: target must be (x, y) or (x, y, z) of finite numbers, got {tuple(target)}")
    return values[0], values[1], values[2] if len(values) == 3 else 0.0


def _content(world: World) -> list[tuple[float, float, float]]:
    """Points to keep in the picture: robots (base top) and objects (their bounding-box corners)."""
    points = [(float(x), float(y), float(r.spec.height)) for r in world.robots.values() for x, y, _ in [r.pose]]
    for obj in world.objects.values():
        if obj.kind == "terrain":
            continue
        low, high = obj.aabb()
        points += [(float(x), float(y), float(high[2])) for x in (low[0], high[0]) for y in (low[1], high[1])]
    return points


def _fit_distance(world: World, aim: tuple[float, float, float], yaw: float, pitch: float, aspect: float) -> float:
    """The camera distance at which every robot and object (with :data:`FRAME_MARGIN`) is in the picture.

    Points are taken into the camera's frame (right, up, forward) at distance 0; each one
    needs the camera far enough back that its right and up offsets fit the half angles.
    """
    points = _content(world) or [aim]
    yaw_r, pitch_r = math.radians(yaw), math.radians(pitch)
    forward = np.array([-math.sin(yaw_r) * math.cos(pitch_r), math.cos(yaw_r) * math.cos(pitch_r), math.sin(pitch_r)])
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    tan_v = math.tan(math.radians(FOV) / 2.0)
    tan_h = tan_v * aspect
    needed = 1.0
    for point in points:
        offset = np.asarray(point, dtype=float) - np.asarray(aim, dtype=float)
        depth = float(offset @ forward)
        across = abs(float(offset @ right)) + FRAME_MARGIN
        upward = abs(float(offset @ up)) + FRAME_MARGIN
        needed = max(needed, across / tan_h - depth, upward / tan_v - depth)
    return needed
