"""How long skills take: the durations a temporal planner plans with, declared and then measured.

A skill plan's signature may declare the skill's expected ``duration`` (seconds). A problem planned
for the makespan (``planner: temporal``) plans with it; as the team works, each agent measures the
steps it carries out (:class:`StepTimes`: from entering a step's running state to leaving it for the
task's next place, failed steps left out), and the leader plans with the declared duration refined by
what it measured (:meth:`StepTimes.estimates`): the mean of the measurements, with the declared
duration counted as :data:`PRIOR` measurements, so that one slow step does not swing the plan.
"""

from __future__ import annotations

from collections.abc import Iterable

from alica.engine.child import RunningPlan
from alica.model import PlanLibrary
from alica.prophet.tasks import CreatedTasks, StepKind

PRIOR = 2.0
"""How many measurements the declared duration counts as."""


class StepTimes:
    """The durations of the steps this agent carried out, per skill plan (see the module docstring)."""

    def __init__(self) -> None:
        self.total: dict[str, float] = {}
        """Skill plan -> the seconds its measured steps took, summed."""
        self.count: dict[str, int] = {}
        """Skill plan -> how many steps were measured."""
        self._running: tuple[str, int, int, str, float] | None = None
        """(plan, task, step, skill, since) of the step this agent runs now."""

    def observe(self, node: RunningPlan | None, created: CreatedTasks | None, now: float) -> None:
        """Where this agent is in the generated plan now (called every tick)."""
        place = None
        if node is not None and created is not None and node.plan is created.plan:
            place = created.place(node.state)
        running = self._running
        if running is not None:
            plan, task, step, skill, since = running
            same = place is not None and created is not None and created.plan.name == plan and place.task == task
            if same and place is not None and place.step == step and place.kind is StepKind.RUN:
                return  # still at it
            if same and place is not None and place.kind is not StepKind.FAILED and place.step > step:
                self.total[skill] = self.total.get(skill, 0.0) + (now - since)
                self.count[skill] = self.count.get(skill, 0) + 1
            self._running = None
        if place is not None and created is not None and place.kind is StepKind.RUN:
            if place.step < len(created.tasks[place.task]):
                skill = created.tasks[place.task][place.step].skill.name
                self._running = (created.plan.name, place.task, place.step, skill, now)

    def estimates(self, library: PlanLibrary, elements: Iterable[str]) -> dict[str, float]:
        """Element -> the duration to plan with: declared and measured (see the module docstring).

        An element neither declared nor measured is left out (the domain then says which lacks one).
        """
        out: dict[str, float] = {}
        for name in elements:
            plan = library.plans.get(name)
            declared = plan.signature.duration if plan is not None and plan.signature is not None else None
            n = self.count.get(name, 0)
            if declared is None and n == 0:
                continue
            prior = 0.0 if declared is None else PRIOR
            out[name] = ((declared or 0.0) * prior + self.total.get(name, 0.0)) / (prior + n)
        return out


__all__ = ["PRIOR", "StepTimes"]
