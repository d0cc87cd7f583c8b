"""Faults and sensor noise: crashed robots, slipping grasps, noisier sensors.

All settings are per world (``world.faults``, ``world.noise``) and every random
draw comes from the world's seeded :attr:`~alica.worldsim.world.World.rng`, so a run
with faults is as repeatable as one without. A crash or a recovery reaches
the robot through its declared ``crash()`` and ``recover()``
(:class:`~alica.engine.sim_world.PoweredRobot`, the Protocol the team runner
uses too); the settings see of the world only :class:`FaultedWorld`.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Protocol

from alica.worldsim.errors import WorldError
from alica.worldsim.noise import SensorNoise

if TYPE_CHECKING:
    import numpy as np

    from alica.engine.sim_world import PoweredRobot

__all__ = ["FaultedWorld", "Faults", "SensorNoise", "crash", "recover", "set_grasp_slip", "set_sensor_noise"]

logger = logging.getLogger(__name__)

#: A slipping grasp lets go this many seconds after the attach (uniformly drawn).
SLIP_DELAY = (0.1, 0.6)


class FaultedWorld(Protocol):
    """What the fault settings use of a world: its robots to power down and up, its noise, its seeded draws."""

    noise: SensorNoise

    @property
    def robots(self) -> Mapping[str, PoweredRobot]:
        """Robots by name."""
        ...

    @property
    def rng(self) -> np.random.Generator:
        """The world's seeded generator (slips are drawn from it)."""
        ...


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

    def __init__(self, world: FaultedWorld) -> None:
        self._world = world
        #: Probability that a grasp slips (see :meth:`set_grasp_slip`).
        self.grasp_slip = 0.0

    def crash(self, robot: PoweredRobot | str) -> None:
        """Crash a robot (power loss): it stops, drops what it holds and ignores every later command."""
        self._robot(robot).crash()

    def recover(self, robot: PoweredRobot | str) -> None:
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

    def _robot(self, robot: PoweredRobot | str) -> PoweredRobot:
        if isinstance(robot, str):
            if robot not in self._world.robots:
                raise WorldError(f"no robot named '{robot}' (robots: {', '.join(sorted(self._world.robots)) or '-'})")
            return self._world.robots[robot]
        return robot

    def draw_slip(self, now: float) -> float | None:
        """The time a new grasp will slip, or ``None`` (draws from the world rng only if slips are on).

        The gripper asks it at every successful attach.
        """
        if self.grasp_slip <= 0.0:
            return None
        rng = self._world.rng
        if rng.random() >= self.grasp_slip:
            return None
        at = now + float(rng.uniform(*SLIP_DELAY))
        logger.info("a grasp will slip at t=%.3f", at)
        return at


class WorldWithFaults(Protocol):
    """A world with fault settings (``world.faults``)."""

    @property
    def faults(self) -> Faults:
        """The world's fault settings."""
        ...


def crash(robot: PoweredRobot) -> None:
    """Crash ``robot`` (it stops acting and drops what it holds; commands are ignored)."""
    robot.crash()


def recover(robot: PoweredRobot) -> None:
    """Power ``robot`` up again after a crash."""
    robot.recover()


def set_grasp_slip(world: WorldWithFaults, probability: float) -> None:
    """Set the probability that a grasp in ``world`` slips (see :meth:`Faults.set_grasp_slip`)."""
    world.faults.set_grasp_slip(probability)


def set_sensor_noise(
    world: WorldWithFaults,
    lidar_sigma: float | None = None,
    position_sigma: float | None = None,
    *,
    odometry_drift: float | None = None,
) -> SensorNoise:
    """Set the sensor noise of ``world`` (see :meth:`Faults.set_sensor_noise`)."""
    return world.faults.set_sensor_noise(lidar_sigma, position_sigma, odometry_drift=odometry_drift)
