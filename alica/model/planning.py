"""Planning problems: states whose plan is found at run time (IMPERA Section 7.1)."""

from __future__ import annotations

from dataclasses import dataclass

from alica.model.common import Condition, Variable, span_field
from alica.source import SourceSpan


@dataclass(frozen=True, slots=True)
class PlanningProblem:
    """A planning problem O: the planner fills the state at run time.

    Args:
        name: unique among all plans, plan types, behaviours and problems.
        elements: ProblemElement(O), the skill plans the planner may use.
        goal: Goal(O), the formula the plan must make true.
        wait_plan: WaitPlan(O), run by the team until the first plan is ready.
        alternative_plan: AlternativePlan(O), run when planning fails.
        update_time: UpdateTime(O), seconds between plan updates.
        timeout: seconds the leader may plan without a first plan before the
            team gives up and runs the AlternativePlan.
        world: World(O) for offline use, a conjunction of facts; ``None`` reads
            the world model at run time.
        objects: typed objects for an offline world.
        planner: name of the planner to use.
    """

    name: str
    elements: tuple[str, ...]
    goal: Condition
    wait_plan: str | None = None
    alternative_plan: str | None = None
    update_time: float = 1.0
    timeout: float = 60.0
    world: Condition | None = None
    objects: tuple[Variable, ...] = ()
    planner: str = "builtin"
    description: str = ""
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<PlanningProblem {self.name}>"
