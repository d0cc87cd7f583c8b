"""The field: the rectangle that robots and objects stay in.

Plain data (no pybullet): the world keeps one (``world.field``) and checks
every pose it is given against it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from alica.worldsim.errors import WorldError

__all__ = ["Field"]


@dataclass(frozen=True, slots=True)
class Field:
    """The field ``(xmin, ymin, xmax, ymax)`` in metres."""

    bounds: tuple[float, float, float, float]

    def inside(self, x: float, y: float, radius: float = 0.0) -> bool:
        """Whether a circle of ``radius`` at ``(x, y)`` lies in the field."""
        xmin, ymin, xmax, ymax = self.bounds
        return xmin + radius <= x <= xmax - radius and ymin + radius <= y <= ymax - radius

    def check(self, x: float, y: float, what: str, radius: float = 0.0) -> None:
        """Raise unless ``what`` (a circle of ``radius``) at ``(x, y)`` lies in the field.

        Raises:
            WorldError: a position off the field or not finite.
        """
        if not (math.isfinite(x) and math.isfinite(y)) or not self.inside(x, y, radius):
            xmin, ymin, xmax, ymax = self.bounds
            raise WorldError(
                f"{what} at ({x}, {y}) is off the field x in [{xmin}, {xmax}], y in [{ymin}, {ymax}]"
                + (f" (with its radius {radius} m)" if radius else "")
                + "; choose a position inside or make the World with larger bounds"
            )
