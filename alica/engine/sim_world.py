"""What a simulated team needs of the world it runs in: a clock, a step, and robots to power down.

:class:`~alica.engine.SimulatedTeam` runs on the world's clock, steps it once a
tick, and on a crash or a recovery of an agent powers that agent's robot down or
up. The runtime layer cannot import the world layer, so it declares the little
it uses here; :class:`alica.worldsim.World` satisfies it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

from alica.clock import Clock

__all__ = ["PoweredRobot", "SimWorld"]


class PoweredRobot(Protocol):
    """A robot a fault can switch off and on."""

    def crash(self) -> None:
        """Lose power: stop where it is and let go of what it holds."""
        ...

    def recover(self) -> None:
        """Power up again where it stopped."""
        ...


class SimWorld(Protocol):
    """A world a simulated team runs in."""

    @property
    def clock(self) -> Clock:
        """The world's clock: the team runs on it."""
        ...

    def step(self, seconds: float) -> object:
        """Move the world on by ``seconds``."""
        ...

    @property
    def robots(self) -> Mapping[str, PoweredRobot]:
        """Robots by name: an agent's robot has the agent's name."""
        ...
