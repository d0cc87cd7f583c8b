"""When a planning problem stops replanning after failed steps, and fails (the team runs the AlternativePlan).

A step that fails the same way again and again would be planned and fail
again for ever. :class:`GiveUp` counts the failures of the leader's failed
steps by reason and gives up:

* after :data:`GIVE_UP_AFTER` failures for the same reason in the same world;
* after :data:`GIVE_UP_ANYWAY_AFTER` failures for the same reason with no step
  of the team carried out in between, whatever the world does meanwhile (a
  robot that moves a little on every new plan changes the world, but not what
  makes the step fail).
"""

from __future__ import annotations

from alica.lang.fact import Fact

#: A step that fails this many times for the same reason while the world stays the same fails the problem
#: (the team runs the AlternativePlan): planning the same plan again would fail the same way for ever.
GIVE_UP_AFTER = 3
#: A step that fails this many times for the same reason, with no step of the team carried out in between,
#: fails the problem whatever the world does meanwhile (a robot that moves a little on every new plan
#: changes the world, but not what makes the step fail).
GIVE_UP_ANYWAY_AFTER = 2 * GIVE_UP_AFTER


STEP_FAILED = "a step of "


def failure_cause(reason: str) -> str:
    """What made a step fail, from a replan's reason: without the sender a teammate's request names
    (``r2: ...``) and without the generated plan's name (``a step of StackBlocks_g2v0_r1_ab12cd failed: ...``),
    so that the same cause counts alike whichever robot reports it, in every generation."""
    text = reason if reason.startswith(STEP_FAILED) else reason.split(": ", 1)[-1]
    if text.startswith(STEP_FAILED) and " failed: " in text:
        text = text.split(" failed: ", 1)[1]
    return text


class GiveUp:
    """The leader's count of failed steps (see the module docstring)."""

    def __init__(self) -> None:
        self.failures: dict[tuple[str, frozenset[Fact]], int] = {}
        """(reason, world) -> how many steps failed for that reason in that world."""
        self.failures_any: dict[str, int] = {}
        """reason -> how many steps failed for it since a step of the team was last carried out."""
        self.steps_done = 0
        """How many steps of the team were carried out at the last failure."""

    def step_failed(self, reason: str, world: frozenset[Fact], steps_done: int) -> str | None:
        """Count a failed step; the reason to give up, or ``None`` to replan.

        Args:
            reason: why the step failed (:func:`failure_cause`: without the sender and the plan's name).
            world: the planning world's facts now.
            steps_done: how many steps of the team were carried out so far (``step_done`` facts).

        Returns:
            The message of the failure when the problem gives up (the counts start afresh), else ``None``.
        """
        same = (reason, world)
        self.failures[same] = count = self.failures.get(same, 0) + 1
        if steps_done != self.steps_done:  # a step was carried out since the last failure: count afresh
            self.steps_done = steps_done
            self.failures_any.clear()
        self.failures_any[reason] = total = self.failures_any.get(reason, 0) + 1
        if count < GIVE_UP_AFTER and total < GIVE_UP_ANYWAY_AFTER:
            return None
        self.failures.clear()
        self.failures_any.clear()
        if count >= GIVE_UP_AFTER:
            return f"gave up: the same step failed {count} times while the world stayed the same: {reason}"
        return f"gave up: the same step failed {total} times: {reason}"
