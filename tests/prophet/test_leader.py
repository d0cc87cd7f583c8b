"""The leader's side of a planning problem's runtime (alica.prophet.leader), with stand-ins for the runtime.

The leader's searches, shares and checks in a team run are tested in tests/prophet/test_runtime.py.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from alica.model import Condition, ConditionKind, PlanningProblem
from alica.prophet.board import PlanShare, ShareStatus
from alica.prophet.budget import LeaderSearch, SearchBudget
from alica.prophet.leader import Leader
from alica.prophet.pipeline import ValidPlan
from alica.prophet.planner import Plan
from alica.prophet.reviewing import Proposal, Reviewing
from alica.prophet.runtime_states import LeaderPhase
from alica.prophet.world import PlanningWorld

KEY: Any = ("Top", "Stack")
PROBLEM = PlanningProblem("Stack", (), Condition(ConditionKind.POST, "on(a, b)"))


class Team:
    """The runtime as the leader sees it."""

    def __init__(self) -> None:
        self.share: PlanShare | None = None
        self.created = None
        self.failed_generation = -1
        self.problem = PROBLEM
        self.published: list[PlanShare] = []

    def publish(self, share: PlanShare, now: float) -> None:
        self.published.append(share)
        self.share = share

    def read_world(self, problem: PlanningProblem, facts: Any = None) -> PlanningWorld:
        return PlanningWorld((), (), ("r1",))

    def next_generation(self) -> int:
        return 1


def _leader() -> tuple[Leader, Team, list[tuple[str, dict[str, Any]]]]:
    events: list[tuple[str, dict[str, Any]]] = []
    host: Any = SimpleNamespace(
        name="r1", emit=lambda event, **fields: events.append((event, fields)), decisions=lambda name: []
    )
    slot: Any = SimpleNamespace(element=PROBLEM, key=KEY, members=lambda: ("r1", "r2"), node=None, entry_task="T")
    team = Team()
    reviewing = Reviewing("Stack", "Top/Stack", "r1", host.emit, list, None, lambda: "on(a, b)")  # type: ignore[arg-type]
    leader = Leader(team, host, slot, None, SearchBudget(), None, reviewing, None, stepwise=False, plan=print)  # type: ignore[arg-type]
    return leader, team, events


def _search(generation: int) -> LeaderSearch:
    return LeaderSearch(generation, PlanningWorld((), (), ("r1",)), iter(()), 0.0)


def _share(generation: int, leader: str, status: ShareStatus = ShareStatus.PLAN) -> PlanShare:
    return PlanShare(KEY, generation, 1, leader, status)


def test_the_phase_follows_what_the_leader_holds():
    leader, team, _ = _leader()
    assert leader.phase(False) is LeaderPhase.FOLLOWING
    assert leader.phase(True) is LeaderPhase.STARTING
    team.share = _share(2, "r1")
    assert leader.phase(True) is LeaderPhase.EXECUTING
    team.failed_generation = 2
    assert leader.phase(True) is LeaderPhase.STARTING
    leader.search = _search(3)
    assert leader.phase(True) is LeaderPhase.SEARCHING
    leader.pending = (1.0, "a step failed")
    assert leader.phase(True) is LeaderPhase.SETTLING


def test_handing_over_drops_the_search_and_the_proposal_once():
    leader, _, events = _leader()
    leader.search = _search(2)
    leader.reviewing.proposal = Proposal(_search(2), ValidPlan((), 0.0, Plan((), 0.0)), None)
    leader.hand_over()
    assert leader.search is None and leader.reviewing.proposal is None
    assert [e for e, f in events if f.get("what") == "handed over"] == ["planner"]
    leader.hand_over()
    assert len(events) == 1


def test_another_leaders_newer_share_supersedes_the_search_but_not_an_older_one_or_its_own():
    leader, _, events = _leader()
    leader.search = _search(3)
    leader.pending = (1.0, "x")
    leader.supersede(_share(2, "r0"))  # older: this agent's search goes on
    leader.supersede(_share(3, "r1"))  # its own share
    assert leader.search is not None and leader.pending is not None and not events
    leader.supersede(_share(3, "r0"))
    assert leader.search is None and leader.pending is None
    assert events == [("planner", {"key": "Top/Stack", "what": "superseded", "generation": 3})]
