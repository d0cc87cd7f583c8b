"""Faults and sensor noise: crashed robots, slipping grasps, noisier sensors.

All settings are per world (``world.faults``, ``world.noise``) and every random
draw comes from the world's seeded :attr:`~alica.worldsim.world.World.rng`, so a run
with faults is as repeatable as one without.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from alica.worldsim.errors import WorldError

if TYPE_CHECKING:
    from alica.worldsim.robots import Robot
    from alica.worldsim.world import World

__all__ = ["Faults", "SensorNoise", "crash", "recover", "set_grasp_slip", "set_sensor_noise"]

logger = logging.getLogger(__name__)

#: A slipping grasp lets go this many seconds after the attach (uniformly drawn).
SLIP_DELAY = (0.1, 0.6)


@dataclass(frozen=True, slots=True)
class SensorNoise:
    """Noise of the simulated sensors.

    Attributes:
        lidar_sigma: standard deviation (m) of the Gaussian noise added to lidar hits.
        position_sigma: standard deviation (m) of a camera detection's position at close range;
            it grows linearly to twice that at the perception range; 3-D perception has a quarter of it.
        camera_misclassification: probability that a camera reports a wrong sample kind.
        stereo_misclassification: the same for 3-D (stereo and 3-D lidar) perception.
        pixel_sigma: standard deviation of the Gaussian noise on each colour channel of a robot
            camera's pixels, in intensity levels (0-255).
        depth_sigma: standard deviation (m) of a robot camera's depth at 1 m; it grows with the
            square of the distance, as a stereo pair's does.
        odometry_drift: relative error of the robots' odometry (0.02 = 2 %): each step's distance and
            turn are scaled by ``1 + drift * (bias + noise)`` (see :mod:`alica.worldsim.odometry`);
            0 keeps every robot's pose estimate equal to its true pose.
    """

    lidar_sigma: float = 0.0
    position_sigma: float = 0.03
    camera_misclassification: float = 0.1
    stereo_misclassification: float = 0.01
    pixel_sigma: float = 2.0
    depth_sigma: float = 0.005
    odometry_drift: float = 0.0


def _probability(value: float, what: str) -> float:
    value = float(value)
    if not 0.0 <= value <= 1.0:
        raise WorldError(f"{what} is a probability in [0, 1], got {value}")
    return value


def _sigma(value: float, what: str) -> float:
    value = float(value)
    if not (value >= 0.0 and math.isfinite(value)):
        raise WorldError(f"{what} is a standard deviation in metres (>= 0), got {value}")
    return value


class Faults:
    """The fault settings of one world (``world.faults``)."""

    __slots__ = ("_world", "grasp_slip")

    def __init__(self, world: World) -> None:
        self._world = world
        #: Probability that a grasp slips (see :meth:`set_grasp_slip`).
        self.grasp_slip = 0.0

    def crash(self, robot: Robot | str) -> None:
        """Crash a robot (power loss): it stops, drops what it holds and ignores every later command."""
        self._robot(robot).crash()

    def recover(self, robot: Robot | str) -> None:
        """Power a crashed robot up again: it takes commands from where it stopped."""
        self._robot(robot).recover()

    def set_grasp_slip(self, probability: float) -> None:
        """Each later successful attach slips with this probability: the object drops within a short time."""
        self.grasp_slip = _probability(probability, "the grasp slip")

    def set_sensor_noise(
        self,
        lidar_sigma: float | None = None,
        position_sigma: float | None = None,
        *,
        odometry_drift: float | None = None,
    ) -> SensorNoise:
        """Change the lidar range noise, the perception position noise and the odometry drift (``None`` keeps a value)."""
        noise = self._world.noise
        changes = {}
        if odometry_drift is not None:
            drift = float(odometry_drift)
            if not (0.0 <= drift < 1.0):
                raise WorldError(f"odometry_drift is a relative error in [0, 1), got {odometry_drift}")
            changes["odometry_drift"] = drift
        if lidar_sigma is not None:
            changes["lidar_sigma"] = _sigma(lidar_sigma, "lidar_sigma")
        if position_sigma is not None:
            changes["position_sigma"] = _sigma(position_sigma, "position_sigma")
        self._world.noise = dataclasses.replace(noise, **changes)
        return self._world.noise

    def _robot(self, robot: Robot | str) -> Robot:
        if isinstance(robot, str):
            if robot not in self._world.robots:
                raise WorldError(f"no robot named '{robot}' (robots: {', '.join(sorted(self._world.robots)) or '-'})")
            return self._world.robots[robot]
        return robot

    def _draw_slip(self, now: float) -> float | None:
        """The time a new grasp will slip, or ``None`` (draws from the world rng only if slips are on)."""
        if self.grasp_slip <= 0.0:
            return None
        rng = self._world.rng
        if rng.random() >= self.grasp_slip:
            return None
        at = now + float(rng.uniform(*SLIP_DELAY))
        logger.info("a grasp will slip at t=%.3f", at)
        return at


def crash(robot: Robot) -> None:
    """Crash ``robot`` (it stops acting and drops what it holds; commands are ignored)."""
    robot.crash()


def recover(robot: Robot) -> None:
    """Power ``robot`` up again after a crash."""
    robot.recover()


def set_grasp_slip(world: World, probability: float) -> None:
    """Set the probability that a grasp in ``world`` slips (see :meth:`Faults.set_grasp_slip`)."""
    world.faults.set_grasp_slip(probability)


def set_sensor_noise(
    world: World,
    lidar_sigma: float | None = None,
    position_sigma: float | None = None,
    *,
    odometry_drift: float | None = None,
) -> SensorNoise:
    """Set the sensor noise of ``world`` (see :meth:`Faults.set_sensor_noise`)."""
    return world.faults.set_sensor_noise(lidar_sigma, position_sigma, odometry_drift=odometry_drift)
