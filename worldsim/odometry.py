"""Wheel odometry with seeded drift: the pose a robot believes it has.

Each robot integrates the motion it actually made (what its wheel encoders
would count) into a pose *estimate*. With ``world.noise.odometry_drift`` = 0
(the default) the estimate is the true pose, exactly. With a drift ``d`` > 0
every step's distance and turn are scaled by ``1 + d * (b + n)``: ``b`` a
per-robot bias (a mis-measured wheel radius or track, drawn once, standard
normal) and ``n`` white noise per step (standard normal); so 0.02 is "2 %
odometry drift". The errors accumulate: driving straight the position drifts
along the track, turning the heading drifts, and a heading error turns into
position error over the following metres.

The draws come from a generator seeded from the world's seed and the robot's
name, not from ``world.rng``: turning drift on leaves every other random
draw of the world as it was. Skills read ``robot.estimate`` and may correct
it (``robot.set_estimate``, e.g. by matching a scan against a map).
"""

from __future__ import annotations

import math
import zlib
from typing import TYPE_CHECKING

import numpy as np

from alica.worldsim.geometry import wrap_angle

if TYPE_CHECKING:
    from alica.worldsim.sensing import SensingRobot

__all__ = ["Odometry"]

_BLOCK = 512


class Odometry:
    """The dead-reckoning pose estimate of one robot (``robot.odometry``).

    Args:
        robot: the robot whose motion is integrated.
        seed: the world's seed (mixed with the robot's name).

    Attributes:
        distance: metres driven since the robot was made (the true path length).
    """

    __slots__ = ("_block", "_k", "_rng", "_robot", "_unit_bias", "_x", "_y", "_yaw", "distance", "following")

    def __init__(self, robot: SensingRobot, seed: int) -> None:
        self._robot = robot
        self._rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, zlib.crc32(robot.name.encode()), 11])
        self._unit_bias = tuple(float(v) for v in self._rng.standard_normal(2))
        self._block = np.empty((0, 2))
        self._k = 0
        self._x, self._y, self._yaw = robot.pose
        self.distance = 0.0
        #: Whether the estimate is the true pose (no drift yet, no correction): then it is read from the robot.
        self.following = True

    @property
    def pose(self) -> tuple[float, float, float]:
        """The estimate ``(x, y, yaw)``."""
        if self.following:
            return self._robot.pose
        return (self._x, self._y, self._yaw)

    @property
    def bias(self) -> tuple[float, float]:
        """The robot's systematic ``(distance, turn)`` scale errors at the world's drift now."""
        d = self._drift()
        return (d * self._unit_bias[0], d * self._unit_bias[1])

    def set(self, pose: tuple[float, float, float]) -> None:
        """Overwrite the estimate (a localization's correction)."""
        self._x, self._y, self._yaw = float(pose[0]), float(pose[1]), wrap_angle(float(pose[2]))
        self.following = False

    def reset(self) -> None:
        """Make the estimate the true pose again (the robot was put somewhere by hand)."""
        self._x, self._y, self._yaw = self._robot.pose
        self.following = self._drift() <= 0.0

    def advance(self, ds: float, dyaw: float) -> None:
        """Integrate one step in which the robot drove ``ds`` metres and turned ``dyaw`` radians."""
        self.distance += abs(ds)
        drift = self._drift()
        if self.following:
            if drift <= 0.0:
                return
            # drift was just turned on: integrate from the true pose before this step
            x, y, yaw = self._robot.pose
            self._x, self._y, self._yaw = x, y, wrap_angle(yaw - dyaw)
            mid = yaw - 0.5 * dyaw
            self._x -= ds * math.cos(mid)
            self._y -= ds * math.sin(mid)
            self.following = False
        if drift > 0.0:
            if self._k >= len(self._block):
                self._block = self._rng.standard_normal((_BLOCK, 2))
                self._k = 0
            n_s, n_w = float(self._block[self._k, 0]), float(self._block[self._k, 1])
            self._k += 1
            ds *= 1.0 + drift * (self._unit_bias[0] + n_s)
            dyaw *= 1.0 + drift * (self._unit_bias[1] + n_w)
        mid = self._yaw + 0.5 * dyaw
        self._x += ds * math.cos(mid)
        self._y += ds * math.sin(mid)
        self._yaw = wrap_angle(self._yaw + dyaw)

    def _drift(self) -> float:
        return float(self._robot.world.noise.odometry_drift)

    def _state(self) -> tuple[float, float, float, float, bool]:
        return (self._x, self._y, self._yaw, self.distance, self.following)

    def _restore(self, state: tuple[float, float, float, float, bool]) -> None:
        self._x, self._y, self._yaw, self.distance, self.following = state

    def __repr__(self) -> str:
        x, y, yaw = self.pose
        return f"Odometry({self._robot.name!r}, estimate=({x:.3f}, {y:.3f}, {yaw:.3f}), following={self.following})"
