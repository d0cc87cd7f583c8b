"""Random small STRIPS tasks against a uniform-cost reference search."""

from __future__ import annotations

import itertools

from hypothesis import given, settings
from hypothesis import strategies as st

from alica.prophet.planner import Done, Improved, PlanStatus
from alica.prophet.search import search_task
from tests.prophet.search.helpers import GroundOperator, GroundTask, check_plan, optimal_cost

N_FACTS = 7


@st.composite
def tasks(draw: st.DrawFn) -> GroundTask:
    facts = tuple(f"p{i}" for i in range(N_FACTS))
    subset = st.frozensets(st.integers(0, N_FACTS - 1), max_size=3).map(lambda s: tuple(sorted(s)))
    ops = []
    for i in range(draw(st.integers(1, 9))):
        pre, add, delete = draw(subset), draw(subset), draw(subset)
        cost = draw(st.integers(1, 4))
        cond = ()
        if draw(st.integers(0, 5)) == 0:
            cond = ((draw(subset), draw(subset), draw(subset)),)
        ops.append(GroundOperator(f"(o{i})", f"o{i}", (), pre, add, delete, cost, cond))
    init = draw(st.frozensets(st.integers(0, N_FACTS - 1), max_size=3))
    goal = tuple(sorted(draw(st.frozensets(st.integers(0, N_FACTS - 1), min_size=1, max_size=3))))
    return GroundTask("random", facts, init, goal, tuple(ops), has_costs=True)


@settings(max_examples=300)
@given(tasks())
def test_anytime_agrees_with_uniform_cost(task: GroundTask) -> None:
    events = list(search_task(task, progress_every=7))
    done = events[-1]
    assert isinstance(done, Done)
    found = [e.plan for e in events if isinstance(e, Improved)]
    ref = optimal_cost(task)
    if done.status is PlanStatus.UNSOLVABLE:
        assert ref is None and not found
        return
    assert ref is not None and found
    for plan in found:
        check_plan(task, plan)
    costs = [p.cost for p in found]
    assert all(a > b for a, b in itertools.pairwise(costs))
    assert costs[-1] >= ref
    if done.status is PlanStatus.OPTIMAL:
        assert costs[-1] == ref
