"""Looking for a sample a crashed teammate dropped: DriveToDroppedSample.

A robot that loses power opens its gripper (the lunar robots' Jaco hands
do), so a sample it held falls where it stood. Its teammates cannot know
where exactly, and its last fact, ``holding(r, s)``, says otherwise; the
planner leaves out a sample a robot outside the team holds. Someone has to
look: this skill drives a teammate near where the sample was last seen
(``pos(s)``), and the perception that runs next (Verify2DObject in the
lunar mission's WaitForPlan) finds it again. A detection of a sample standing on the
ground retracts ``holding(r, s)`` (:func:`alica.skills.sample_facts.seen_on_the_ground`),
and the planner plans with it again.

A teammate counts as lost when the agent's team view says it is not alive
(``alive(r)``, the engine's belief). Held samples of robots that are
merely cut off (a partition) count as dropped too: the look finds nothing
where they were seen, the plan gives up after a while (WaitForPlan's
NothingThere) and nothing is retracted.
"""

from __future__ import annotations

import math

from py_trees.common import Status

from alica.skills.navigation import MoveToPosition
from alica.skills.sample_facts import dropped_samples

__all__ = ["DriveToDroppedSample"]

#: How close to its viewpoint the robot must come (metres).
VIEWPOINT_TOLERANCE = 0.5


class DriveToDroppedSample(MoveToPosition):
    """Stand still until a lost teammate held a sample, then drive to a viewpoint ``distance`` metres from where it was seen.

    Runs (standing still, looking every ``period`` seconds) while no sample
    is dropped; succeeds at the viewpoint, ready for the perception to look;
    fails as MoveToPosition does (``timeout``, a blocked path). The place is
    the sample's last known position ``pos(s)``: exact for a crash at the
    grasp, where the sample was picked up for a crash on the way. The
    crashed robot stands beside the sample and may hide it, so the first
    viewpoint lies on the far side from the holder's last known position
    ``pos(r)``; each later run for the same sample (the look found nothing)
    goes a third of the way round (``scratch["dropped_views"]``). On arrival
    it writes ``pos(self)`` but no at-fact: the goal is a point, and the robot
    stands off the sample.
    """

    def initialise(self) -> None:
        """Look for a dropped sample; drive when there is one."""
        self.period = float(self.param("period", 1.0))  # type: ignore[arg-type]
        self.sample: str | None = None
        self.next_look = self.now()
        self.robot.stop()
        self._look()

    def _look(self) -> bool:
        belief = self.context.belief if self.context is not None else None
        dropped = dropped_samples(self.world_model, belief)
        self.next_look = self.now() + self.period
        if not dropped:
            return False
        here = self.robot.estimate
        sample, holder, seen = min(dropped, key=lambda d: math.dist(d[2], here[:2]))
        self.sample, self.holder = sample, holder
        self.params["goal"] = list(self._viewpoint(sample, holder, seen))
        self.params["tolerance"] = VIEWPOINT_TOLERANCE
        super().initialise()
        return True

    def _viewpoint(self, sample: str, holder: str, seen: tuple[float, float]) -> tuple[float, float]:
        """The next place to look from: ``distance`` from the sample, away from the holder first."""
        reach = float(self.param("distance", 1.5))  # type: ignore[arg-type]
        views = self.context.scratch if self.context is not None else {}
        tries = views.setdefault("dropped_views", {})
        if not isinstance(tries, dict):  # another skill's data under this key: keep count here only
            tries = {}
        turn = int(tries.get(sample, 0))
        tries[sample] = turn + 1
        wm = self.world_model
        at = wm.get("pos", holder) if wm is not None else None
        if isinstance(at, (tuple, list)) and len(at) >= 2 and math.dist(at[:2], seen) > 1e-3:
            away = math.atan2(seen[1] - float(at[1]), seen[0] - float(at[0]))
        else:
            here = self.robot.estimate
            away = math.atan2(here[1] - seen[1], here[0] - seen[0])  # no holder position: from this side
        angle = away + turn * 2.0 * math.pi / 3.0
        return seen[0] + reach * math.cos(angle), seen[1] + reach * math.sin(angle)

    def update(self) -> Status:
        """Wait for a dropped sample, then drive like MoveToPosition."""
        if self.sample is None:
            if self.now() < self.next_look - 1e-9 or not self._look():
                return self.running("no teammate that held a sample is lost")
        status = super().update()
        if status == Status.SUCCESS:
            return self.succeed(f"looking at where {self.sample} was last seen, which lost teammate {self.holder} held")
        return status
