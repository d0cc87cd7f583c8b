"""A simulated run paced on the wall clock: ``--speed X`` simulated seconds per wall second."""

from __future__ import annotations

import math
import time


class WallPace:
    """Sleeps after a tick until the wall clock has caught up with simulated time.

    A run far behind (a slow tick, more than a wall second late) keeps the pace
    from there on instead of rushing to catch up.

    Args:
        speed: simulated seconds per wall second (``inf``: no pacing).
    """

    def __init__(self, speed: float) -> None:
        if not speed > 0 or math.isnan(speed):
            raise ValueError(f"a speed is a positive number of simulated seconds per wall second, got {speed}")
        self.speed = speed
        self._start: tuple[float, float] | None = None

    def __call__(self, now: float) -> None:
        """After the tick that reached simulated time ``now``."""
        wall = time.monotonic()
        if self._start is None or math.isinf(self.speed):
            self._start = (wall, now)
            return
        ahead = self._start[0] + (now - self._start[1]) / self.speed - wall
        if ahead > 0:
            time.sleep(ahead)  # the wall clock catches up with simulated time (a live run, not a test's wait)
        elif ahead < -1.0:
            self._start = (wall, now)
