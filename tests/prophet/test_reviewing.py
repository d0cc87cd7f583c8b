"""The leader's side of the operator's review (alica.prophet.reviewing), with stand-ins for the runtime."""

from __future__ import annotations

from collections.abc import Sequence
from types import SimpleNamespace
from typing import Any

from alica.engine.child import PlanDecision
from alica.errors import PlannerError
from alica.prophet.budget import LeaderSearch
from alica.prophet.pipeline import ValidPlan
from alica.prophet.planner import Plan, PlanStep
from alica.prophet.reviewing import Reviewing
from alica.prophet.world import PlanningWorld

STEPS = (PlanStep("unstack", ("c", "a", "r1")), PlanStep("put-down", ("c", "r1")))


class Stand:
    """The runtime as the review sees it: the trace, the operator's decisions, what it shared or replanned."""

    def __init__(self, tasks: bool = False) -> None:
        self.events: list[tuple[str, dict[str, Any]]] = []
        self.decisions: list[tuple[int, PlanDecision]] = []
        self.shared: list[tuple[ValidPlan, tuple[tuple[int, str], ...]]] = []
        self.replans: list[str] = []
        self.tasks = tasks

    def emit(self, event: str, **fields: Any) -> None:
        self.events.append((event, fields))

    def tasks_for(self, name: str, steps: Sequence[PlanStep], world: Sequence[object], robots: Sequence[str]) -> Any:
        if not self.tasks:
            raise PlannerError("no roles for these steps")
        return SimpleNamespace(task_entry_points=(), tasks=())

    def reviewing(self) -> Reviewing:
        return Reviewing(
            "Stack", "S/Stack", "r1", self.emit, lambda: self.decisions, self.tasks_for, lambda: "(on c a)"
        )

    def share(self, now: float, search: LeaderSearch, plan: ValidPlan, pins: tuple[tuple[int, str], ...]) -> None:
        self.shared.append((plan, pins))

    def replan(self, now: float, reason: str) -> None:
        self.replans.append(reason)


def _search(generation: int = 2, valid: bool = True) -> LeaderSearch:
    check = SimpleNamespace(valid=valid, cost=1.0, reason="step 0 does not apply")
    planning = SimpleNamespace(check=lambda steps: check)
    world = PlanningWorld((), (), ("r1",))
    return LeaderSearch(generation, world, iter(()), 0.0, planning=planning)  # type: ignore[arg-type]


PLAN = ValidPlan(STEPS, 2.0, Plan(STEPS, 2.0))


def test_a_proposal_is_emitted_with_why_it_has_no_tasks():
    stand = Stand()
    review = stand.reviewing()
    review.propose(_search(), PLAN)
    assert review.proposal is not None and review.proposal.created is None
    ((event, fields),) = stand.events
    assert event == "proposal" and fields["generation"] == 2 and fields["goal"] == "(on c a)"
    assert fields["error"] == "the plan cannot be turned into tasks: no roles for these steps"


def test_accept_shares_the_plan_as_proposed():
    stand = Stand()
    review = stand.reviewing()
    review.propose(_search(), PLAN)
    stand.decisions.append((2, PlanDecision("accept")))
    review.read(1.0, stand.share, stand.replan)
    assert stand.shared == [(PLAN, ())] and review.proposal is None


def test_decline_plans_again_and_a_decision_for_another_generation_is_ignored():
    stand = Stand()
    review = stand.reviewing()
    review.propose(_search(), PLAN)
    stand.decisions += [(1, PlanDecision("accept")), (2, PlanDecision("decline"))]
    review.read(1.0, stand.share, stand.replan)
    assert stand.replans == ["the operator declined the plan of generation 2"] and not stand.shared
    assert stand.events[1][0] == "note" and "for generation 1 is ignored" in stand.events[1][1]["message"]


def test_decisions_made_before_this_agent_led_are_skipped():
    stand = Stand()
    stand.decisions.append((2, PlanDecision("accept")))
    review = stand.reviewing()
    review.propose(_search(), PLAN)
    review.read(1.0, stand.share, stand.replan)
    assert not stand.shared
    stand.decisions.append((2, PlanDecision("decline")))
    review.catch_up()
    review.read(1.0, stand.share, stand.replan)
    assert not stand.replans and review.proposal is not None


def test_a_valid_modification_is_shared_reordered():
    stand = Stand(tasks=True)
    review = stand.reviewing()
    review.propose(_search(), PLAN)
    stand.decisions.append((2, PlanDecision("modify", order=(1, 0))))
    review.read(1.0, stand.share, stand.replan)
    ((plan, pins),) = stand.shared
    assert plan.steps == (STEPS[1], STEPS[0]) and plan.cost == 1.0 and pins == ()


def test_an_invalid_modification_is_proposed_again_with_the_error():
    stand = Stand(tasks=True)
    review = stand.reviewing()
    review.propose(_search(valid=False), PLAN)
    stand.decisions.append((2, PlanDecision("modify", order=(1,))))
    review.read(1.0, stand.share, stand.replan)
    assert not stand.shared and review.proposal is not None
    event, fields = stand.events[-1]
    assert event == "proposal" and fields["error"] == "the modified plan is invalid: step 0 does not apply"
    assert fields["decision"]


def test_a_dropped_proposal_reads_nothing():
    stand = Stand()
    review = stand.reviewing()
    review.propose(_search(), PLAN)
    review.drop()
    stand.decisions.append((2, PlanDecision("accept")))
    review.read(1.0, stand.share, stand.replan)
    assert not stand.shared
