"""A robot camera's picture: colour, depth, intrinsics and the camera pose, as plain data.

:class:`CameraImage` is what ``robot.camera(...)`` returns
(:class:`~alica.worldsim.interface.MobileRobot`); the simulator renders it in
:mod:`alica.worldsim.robot_camera`, a real robot's driver fills it from its
own camera. Perception skills read it (pixels and depths only, no names).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["CameraImage"]


@dataclass(frozen=True)
class CameraImage:
    """One picture of a robot's camera (see :mod:`alica.worldsim.robot_camera`).

    Attributes:
        rgb: colour image, ``(height, width, 3)`` ``uint8``.
        depth: metres along the optical axis, ``(height, width)``; ``inf`` where nothing was hit.
        intrinsics: ``(fx, fy, cx, cy)`` in pixels.
        position: the camera centre in the world, metres.
        rotation: 3x3 rotation, world from camera (OpenCV axes: x right, y down, z forward).
        time: the simulated time of the picture.
        pan: the pan angle the picture was taken at, radians left of the heading.
        offset: ``(u0, v0)``: where this picture lies in the camera's frame; a picture of a
            ``window`` of the frame (see :func:`~alica.worldsim.robot_camera.robot_camera`) is its pixels ``[v0:v0+height, u0:u0+width]``.
            The intrinsics are this picture's (the principal point shifted by the offset).
        frame: ``(width, height)`` of the whole frame; ``None``: the picture is the whole frame.
    """

    rgb: np.ndarray
    depth: np.ndarray
    intrinsics: tuple[float, float, float, float]
    position: np.ndarray
    rotation: np.ndarray
    time: float
    pan: float = 0.0
    offset: tuple[int, int] = (0, 0)
    frame: tuple[int, int] | None = None

    @property
    def frame_size(self) -> tuple[int, int]:
        """``(width, height)`` of the camera's whole frame (this picture's size when it is the whole frame)."""
        if self.frame is not None:
            return self.frame
        h, w = self.depth.shape
        return w, h

    def points(self, max_depth: float = math.inf) -> np.ndarray:
        """World points of every pixel with a depth below ``max_depth``: ``(n, 3)``, row-major pixel order."""
        fx, fy, cx, cy = self.intrinsics
        h, w = self.depth.shape
        v, u = np.mgrid[0:h, 0:w]
        d = self.depth
        keep = np.isfinite(d) & (d < max_depth)
        z = d[keep]
        cam = np.column_stack([(u[keep] - cx) * z / fx, (v[keep] - cy) * z / fy, z])
        return cam @ self.rotation.T + self.position

    def project(self, point: np.ndarray | tuple[float, float, float]) -> tuple[float, float, float]:
        """Pixel ``(u, v)`` and depth of a world point (depth <= 0: behind the camera)."""
        p = self.rotation.T @ (np.asarray(point, dtype=float) - self.position)
        fx, fy, cx, cy = self.intrinsics
        if p[2] <= 1e-9:
            return math.nan, math.nan, float(p[2])
        return float(fx * p[0] / p[2] + cx), float(fy * p[1] / p[2] + cy), float(p[2])
