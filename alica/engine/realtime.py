"""One agent on the wall clock, as it runs on a robot: tick at the engine's frequency, sleep between ticks.

The engine itself never sleeps (:mod:`alica.engine.agent`); this loop does,
and it is the only place that does. A tick that overruns its period starts
the next one at once, and the schedule restarts from now rather than
ticking in a burst to catch up.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from alica.engine.agent import AgentEngine


class RealTimeLoop:
    """Ticks one :class:`AgentEngine` in real time until it is told to stop.

    Args:
        engine: the agent's engine (on a wall clock such as
            :class:`~alica.clock.SystemClock`).
        stop: set it (from a signal handler, another thread) to end the loop
            after the current tick.
        sleep: how to wait (``time.sleep``; a test may pass its own).

    Attributes:
        overruns: ticks that took longer than the period.
    """

    def __init__(
        self, engine: AgentEngine, stop: threading.Event | None = None, sleep: Callable[[float], None] = time.sleep
    ) -> None:
        self.engine = engine
        self.stop = stop or threading.Event()
        self._sleep = sleep
        self.overruns = 0

    def run(
        self,
        *,
        until_done: bool = False,
        end_at: float | None = None,
        linger: float = 1.0,
        before_tick: Callable[[float], None] | None = None,
        after_tick: Callable[[float], None] | None = None,
    ) -> str:
        """Tick until stopped, past ``end_at`` (engine time), or ``linger`` seconds after the root plan ended.

        Args:
            until_done: end once the root plan succeeded or failed, after
                ``linger`` more seconds of ticking (so that teammates hear the
                final state).
            end_at: the engine time to stop at, ``None`` for no limit.
            linger: see ``until_done``.
            before_tick: called with the engine time before each tick (operator facts, faults).
            after_tick: called with the engine time after each tick (status reports).

        Returns:
            Why it ended: ``"stopped"``, ``"time limit"`` or ``"done"``.
        """
        engine = self.engine
        period = engine.config.period
        done_at: float | None = None
        next_tick = engine.now()
        while True:
            now = engine.now()
            if self.stop.is_set():
                return "stopped"
            if end_at is not None and now >= end_at:
                return "time limit"
            if until_done and engine.done:
                done_at = now if done_at is None else done_at
                if now - done_at >= linger:
                    return "done"
            if before_tick is not None:
                before_tick(now)
            engine.tick()
            if after_tick is not None:
                after_tick(engine.now())
            next_tick += period
            wait = next_tick - engine.now()
            if wait > 0:
                self.stop.wait(wait) if self._sleep is time.sleep else self._sleep(wait)
            else:
                self.overruns += 1
                next_tick = engine.now()
