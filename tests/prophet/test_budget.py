"""The leader's search budget per tick (alica.prophet.budget)."""

from __future__ import annotations

import pytest

from alica.prophet.budget import LeaderSearch, SearchBudget, advance
from alica.prophet.pipeline import Found, Rejected, ValidPlan
from alica.prophet.planner import Done, Plan, PlanStatus, Progress
from alica.prophet.world import PlanningWorld


def _search(events: list[object]) -> LeaderSearch:
    world = PlanningWorld((), (), ("r1",))
    return LeaderSearch(1, world, iter(events), 0.0)  # type: ignore[arg-type]


def _plan(cost: float) -> ValidPlan:
    return ValidPlan((), cost, Plan((), cost))


def test_a_budget_needs_expansions_and_positive_seconds():
    with pytest.raises(ValueError, match="expansions >= 1"):
        SearchBudget(expansions=0)
    with pytest.raises(ValueError, match="seconds > 0"):
        SearchBudget(seconds=0.0)


def test_a_tick_spends_its_expansions_and_the_search_goes_on_next_tick():
    search = _search([Progress(400), Progress(800), Progress(1200), Progress(1600), Progress(2400)])
    assert advance(search, SearchBudget(expansions=1000), print) is None
    assert search.expansions == 1200
    assert advance(search, SearchBudget(expansions=1000), print) is None
    assert search.expansions == 2400


def test_the_first_plan_ends_the_tick_at_once_and_later_ones_do_not():
    first, better = _plan(5.0), _plan(3.0)
    search = _search([Progress(10), Found(first, 20), Found(better, 30), Progress(40)])
    assert advance(search, SearchBudget(expansions=1000), print) is None
    assert search.best is first and search.expansions == 20
    search.shared_cost = 5.0
    finished = advance(search, SearchBudget(expansions=1000), print)  # the events run out: solved
    assert finished is not None and finished.status is PlanStatus.SOLVED and search.best is better


def test_a_rejected_plan_is_reported_and_done_ends_the_search():
    warnings: list[str] = []
    search = _search([Rejected("a precondition fails", 5), Done(PlanStatus.UNSOLVABLE, 9, "none")])
    finished = advance(search, SearchBudget(), warnings.append)
    assert finished is not None and finished.status is PlanStatus.UNSOLVABLE and search.expansions == 9
    assert warnings == ["the planner's plan is invalid and not shared: a precondition fails"]


def test_events_that_run_out_without_a_plan_are_unsolvable():
    finished = advance(_search([Progress(1)]), SearchBudget(), print)
    assert finished is not None and finished.status is PlanStatus.UNSOLVABLE


def test_a_wall_time_budget_ends_the_tick_at_its_deadline():
    budget = SearchBudget(seconds=1e-9)
    search = _search([Progress(i) for i in range(1, 100)])
    assert advance(search, budget, print) is None
    assert search.expansions < 99
