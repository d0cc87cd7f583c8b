"""What both demos need to run their team as processes around a world server in this process."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from alica.app.processes import ProcessTeam
    from alica.app.world_server import WorldServer

#: Wall seconds the run waits for the first step (every agent started and connected) before it gives up.
START_WAIT_S = 60.0
#: Wall seconds without a step after which a lock-step run gives up (an agent hangs).
STALL_S = 30.0


def stop_serving(team: ProcessTeam, server: WorldServer) -> None:
    """Stop the agents while the server still steps: a lock-step agent then finishes its tick and its summary.

    ``team.stop()`` (SIGTERM, wait, collect the summaries) runs on a thread while this thread, the world's,
    goes on serving; then the server stops.
    """
    from alica.app.processes import STOP_GRACE

    stopper = threading.Thread(target=team.stop, name="stop-agents", daemon=True)
    stopper.start()
    server.serve(duration=STOP_GRACE + 5.0, until=lambda: not stopper.is_alive())
    stopper.join()
    server.stop()


def stalled(now: float, waited: float, everyone_down: bool) -> str:
    """Why a lock-step run cannot go on (``""``: it can): no agent left, none started, or one hangs.

    Args:
        now: the world's time.
        waited: wall seconds since the world last stepped.
        everyone_down: no agent process runs.
    """
    if everyone_down:
        return "every agent process ended"
    if now == 0.0 and waited > START_WAIT_S:
        return f"the agents did not all start within {START_WAIT_S:g} s"
    if now > 0.0 and waited > STALL_S:
        return f"no step for {STALL_S:g} s: an agent does not finish its tick"
    return ""
