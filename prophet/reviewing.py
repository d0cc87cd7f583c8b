"""The leader's side of the operator's review: propose a plan, then read the operator's decisions.

With review on (``EngineConfig.review``), the leader does not share the first
valid plan of a generation: :meth:`Reviewing.propose` keeps it as the
:class:`Proposal` and emits a ``proposal`` trace event, and the team waits.
Each tick :meth:`Reviewing.read` reads the operator's new decisions, in order,
until one settles the proposal:

* **accept**: the plan is shared as it is;
* **decline**: the leader plans again;
* **modify**: the steps reordered or dropped and tasks pinned to robots
  (:mod:`alica.prophet.review`); the change is validated against the search's
  problem and shared when it is valid, else proposed again with the error.

A decision for another generation is ignored with a ``note``. The collaborator
gets what it needs only: the trace, the decisions, task creation, and the
runtime's two ways on (share a plan, plan again).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from alica.engine.child import PlanDecision
from alica.errors import AlicaError, PlannerError
from alica.lang.fact import Fact
from alica.prophet.budget import LeaderSearch
from alica.prophet.pipeline import ValidPlan
from alica.prophet.planner import Plan as StepPlan
from alica.prophet.planner import PlanStep
from alica.prophet.review import PROPOSAL_PLAN, proposal_fields, reordered, resolve_pins
from alica.prophet.tasks import CreatedTasks, conjunction

#: The pins of a plan: task index -> the robot that alone may take it.
Pins = tuple[tuple[int, str], ...]


class Emit(Protocol):
    """Sends a trace event (``ChildHost.emit``)."""

    def __call__(self, event: str, **fields: Any) -> None: ...


class TasksFor(Protocol):
    """Task creation for a plan of the problem (``name``, its steps, the world's facts, the robots)."""

    def __call__(
        self, name: str, steps: Sequence[PlanStep], world: Sequence[Fact], robots: Sequence[str], /
    ) -> CreatedTasks: ...


@dataclass
class Proposal:
    """A plan the leader proposed to the operator (review on), waiting for a decision."""

    search: LeaderSearch
    plan: ValidPlan
    created: CreatedTasks | None


class Reviewing:
    """The leader's proposals and the operator's decisions on them (see the module docstring).

    Args:
        problem: the planning problem's name (decisions and proposal plans are named after it).
        key: the problem's key as text (for the trace).
        leader: this agent's name.
        emit: sends a trace event.
        decisions: the operator's decisions on the problem, oldest first, as ``(generation, decision)``.
        tasks_for: task creation for a plan of the problem.
        goal: the goal's text now (the operator may change it).
    """

    def __init__(
        self,
        problem: str,
        key: str,
        leader: str,
        emit: Emit,
        decisions: Callable[[], Sequence[tuple[int, PlanDecision]]],
        tasks_for: TasksFor,
        goal: Callable[[], str],
    ) -> None:
        self.problem = problem
        self.key = key
        self.leader = leader
        self.emit = emit
        self.decisions = decisions
        self.tasks_for = tasks_for
        self.goal = goal
        self.proposal: Proposal | None = None
        """The plan proposed to the operator, while the leader waits for a decision."""
        self.decided = len(decisions())
        """How many of the operator's decisions on the problem have been read (older ones are not for this agent)."""

    def catch_up(self) -> None:
        """Skip the decisions made so far (whoever leads decides on its own proposals)."""
        self.decided = len(self.decisions())

    def drop(self) -> None:
        """Forget the proposal (a new search, a new leader, or another leader's newer plan)."""
        self.proposal = None

    def propose(self, search: LeaderSearch, plan: ValidPlan) -> None:
        """Propose the generation's first valid plan to the operator (the team keeps waiting)."""
        name = PROPOSAL_PLAN.format(problem=self.problem, generation=search.generation)
        error = None
        try:
            created: CreatedTasks | None = self.tasks_for(name, plan.steps, search.world.facts, search.world.robots)
        except (PlannerError, AlicaError) as exc:
            created, error = None, f"the plan cannot be turned into tasks: {exc}"
        self.proposal = Proposal(search, plan, created)
        self._emit_proposal(self.proposal, error)

    def read(
        self,
        now: float,
        share: Callable[[float, LeaderSearch, ValidPlan, Pins], None],
        replan: Callable[[float, str], None],
    ) -> None:
        """Read the operator's new decisions, in order, until one settles the proposal.

        Args:
            now: the time now.
            share: shares a plan (accepted, or modified validly) with its pins.
            replan: plans again, with the reason (declined).
        """
        proposal = self.proposal
        if proposal is None:
            return
        decisions = self.decisions()
        generation = proposal.search.generation
        while self.decided < len(decisions) and self.proposal is proposal:
            decided_for, decision = decisions[self.decided]
            self.decided += 1
            if decided_for != generation:
                self.emit(
                    "note",
                    key=self.key,
                    message=f"the operator's '{decision.action}' for generation {decided_for} is ignored: "
                    f"the plan proposed is of generation {generation}",
                )
            elif decision.action == "accept":
                self.proposal = None
                share(now, proposal.search, proposal.plan, ())
            elif decision.action == "decline":
                replan(now, f"the operator declined the plan of generation {generation}")
            else:
                self._modify(now, proposal, decision, share)

    def _modify(
        self,
        now: float,
        proposal: Proposal,
        decision: PlanDecision,
        share: Callable[[float, LeaderSearch, ValidPlan, Pins], None],
    ) -> None:
        """Run the plan as the operator changed it if it is valid; else propose it again with the error."""
        search = proposal.search
        try:
            steps = reordered(proposal.plan.steps, decision.order)
            if search.planning is None:
                raise PlannerError("the plan was not made by a search this agent can validate against")
            check = search.planning.check(steps)
            if not check.valid:
                raise PlannerError(f"the modified plan is invalid: {check.reason}")
            name = PROPOSAL_PLAN.format(problem=self.problem, generation=search.generation)
            created = self.tasks_for(name, steps, search.world.facts, search.world.robots)
            pins = resolve_pins(created, decision.pins, search.world.robots)
        except (PlannerError, AlicaError) as exc:
            self._emit_proposal(proposal, str(exc), decision)
            return
        self.proposal = None
        share(now, search, ValidPlan(steps, check.cost, StepPlan(steps, check.cost)), pins)

    def _emit_proposal(
        self, proposal: Proposal, error: str | None = None, decision: PlanDecision | None = None
    ) -> None:
        search = proposal.search
        self.emit(
            "proposal",
            **proposal_fields(
                key=self.key,
                problem=self.problem,
                generation=search.generation,
                leader=self.leader,
                cost=proposal.plan.plan.cost,
                goal=conjunction(search.goal) if search.goal else self.goal(),
                steps=proposal.plan.steps,
                created=proposal.created,
                error=error,
                decision=decision.describe() if decision is not None else None,
            ),
        )
