"""Clocks: simulated time that tests advance by hand, and wall time for real robots.

Every part of the engine that needs the time (the engine tick, the team view,
the simulated network, the world model) takes a :class:`Clock`; nothing reads
``time.time()`` directly, so a test steps time and never sleeps.
"""

from __future__ import annotations

import time
from typing import Protocol, runtime_checkable


@runtime_checkable
class Clock(Protocol):
    """A source of the current time in seconds."""

    def now(self) -> float:
        """The current time in seconds."""
        ...


class ManualClock:
    """Simulated time: it moves only when told to.

    Args:
        start: the initial time in seconds.
    """

    __slots__ = ("_now",)

    def __init__(self, start: float = 0.0) -> None:
        self._now = float(start)

    def now(self) -> float:
        """The current simulated time."""
        return self._now

    def advance(self, seconds: float) -> float:
        """Move time forward by ``seconds`` (at least 0); returns the new time.

        Raises:
            ValueError: ``seconds`` is negative.
        """
        if seconds < 0:
            raise ValueError(f"time cannot go backwards (advance by {seconds})")
        self._now += seconds
        return self._now

    def set(self, when: float) -> None:
        """Jump to ``when``, which must not lie in the past.

        Raises:
            ValueError: ``when`` is earlier than now.
        """
        if when < self._now:
            raise ValueError(f"time cannot go backwards (from {self._now} to {when})")
        self._now = float(when)

    def __repr__(self) -> str:
        return f"ManualClock({self._now:.3f})"


class WallClock:
    """Monotonic wall time, for runs on real robots."""

    __slots__ = ()

    def now(self) -> float:
        """Seconds of :func:`time.monotonic`."""
        return time.monotonic()


class SystemClock:
    """Seconds since the epoch (:func:`time.time`): the clock agents in several processes share.

    Agents on different hosts compare each other's send times, so their hosts'
    clocks must be synchronised (NTP, chrony); on one host every process reads
    the same clock.
    """

    __slots__ = ()

    def now(self) -> float:
        """Seconds of :func:`time.time`."""
        return time.time()
