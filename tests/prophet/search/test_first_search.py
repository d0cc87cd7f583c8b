"""The builtin planner's first search is configurable; its default is the search it always ran."""

from __future__ import annotations

import pytest

from alica.prophet import ground as grounding
from alica.prophet import pddl
from alica.prophet.planner import Improved
from alica.prophet.search import FIRST_HEURISTICS, BuiltinPlanner, FirstSearch, search_task
from tests.conftest import benchmark_set
from tests.prophet.search.helpers import check_plan


def task(name: str):
    rovers = benchmark_set("pddl") / "rovers"
    domain = pddl.read_domain(rovers / "domain.pddl")
    return grounding.ground(domain, pddl.read_problem(rovers / f"{name}.pddl", domain))


def test_the_default_first_search_is_lamas() -> None:
    t = task("p05")
    default = list(search_task(t, anytime=False, progress_every=10))
    assert FirstSearch() == FirstSearch("lama")
    assert list(search_task(t, anytime=False, progress_every=10, first=FirstSearch("lama"))) == default
    check_plan(t, next(e for e in default if isinstance(e, Improved)).plan)


def test_the_former_default_ff_search_is_unchanged() -> None:
    t = task("p05")
    events = list(search_task(t, anytime=False, progress_every=10, first=FirstSearch("ff")))
    first = next(e for e in events if isinstance(e, Improved))
    assert (first.plan.cost, first.expansions) == (23, 77)  # the figures of the builtin planner before FirstSearch


@pytest.mark.parametrize(
    "first",
    [FirstSearch(h) for h in FIRST_HEURISTICS]
    + [FirstSearch("ff", 3.0), FirstSearch("ff", None, 1), FirstSearch("lama", 3.0), FirstSearch("lama", None, 1)],
    ids=str,
)
def test_every_first_search_finds_a_valid_plan(first: FirstSearch) -> None:
    t = task("p05")
    events = list(search_task(t, anytime=False, first=first))
    plans = [e.plan for e in events if isinstance(e, Improved)]
    assert len(plans) == 1
    check_plan(t, plans[0])
    assert list(search_task(t, anytime=False, first=first)) == events  # deterministic, seeded or not


def test_other_first_searches_give_other_searches() -> None:
    t = task("p05")
    firsts = (FirstSearch(), FirstSearch("ff"), FirstSearch("ff_add_unit"), FirstSearch("ff", seed=1))
    runs = {str(f): list(search_task(t, anytime=False, first=f)) for f in firsts}
    assert len({tuple(r) for r in runs.values()}) == 4


def test_the_builtin_planner_takes_a_first_search() -> None:
    rovers = benchmark_set("pddl") / "rovers"
    domain = pddl.read_domain(rovers / "domain.pddl")
    problem = pddl.read_problem(rovers / "p05.pddl", domain)
    result = BuiltinPlanner(first=FirstSearch("ff_add_unit")).solve(domain, problem, anytime=False)
    assert result.plan is not None and result.plan.cost == 22


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"heuristic": "hmax"}, "unknown first-search heuristic 'hmax'"),
        ({"weight": 0}, "weight must be a finite number > 0"),
        ({"weight": float("inf")}, "weight must be a finite number > 0"),
        ({"weight": True}, "weight must be a finite number > 0"),
        ({"seed": 1.5}, "seed must be an int"),
    ],
)
def test_a_bad_first_search_is_refused(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        FirstSearch(**kwargs)
