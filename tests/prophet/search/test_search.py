"""The builtin search on hand-built tasks: valid plans, anytime improvement, verdicts, determinism."""

from __future__ import annotations

import pytest

from alica.prophet.planner import Done, Feature, Improved, PlanStatus, Progress
from alica.prophet.search import BuiltinPlanner, search_task
from alica.prophet.search.encoding import bits, compile_task
from alica.prophet.search.heuristics import INF, Relaxed
from tests.prophet.search.helpers import TaskBuilder, blocks_task, check_plan, optimal_cost


def run(task, **kw):
    events = list(search_task(task, **kw))
    assert isinstance(events[-1], Done)
    assert not any(isinstance(e, Done) for e in events[:-1])
    return events


def plans(events):
    return [e.plan for e in events if isinstance(e, Improved)]


def grid_task(n: int, cost_right: int = 1, cost_up: int = 1) -> object:
    """An n x n grid, from (0,0) to (n-1,n-1), with a wall of static-false cells."""
    tb = TaskBuilder("grid")
    for x in range(n):
        for y in range(n):
            if x + 1 < n:
                tb.op("right", (f"{x}", f"{y}"), [f"at {x} {y}"], [f"at {x + 1} {y}"], [f"at {x} {y}"], cost_right)
                tb.op("left", (f"{x + 1}", f"{y}"), [f"at {x + 1} {y}"], [f"at {x} {y}"], [f"at {x + 1} {y}"], 1)
            if y + 1 < n:
                tb.op("up", (f"{x}", f"{y}"), [f"at {x} {y}"], [f"at {x} {y + 1}"], [f"at {x} {y}"], cost_up)
    return tb.task(["at 0 0"], [f"at {n - 1} {n - 1}"])


SMALL_BLOCKS = [
    ([["a", "b", "c"], ["d"]], [("d", "c"), ("c", "b"), ("b", "a")]),
    ([["c", "a"], ["b"]], [("a", "b"), ("b", "c")]),
    ([["a", "b", "c", "d"]], [("a", "b"), ("b", "c"), ("c", "d")]),
    ([["b", "a"], ["d", "c"], ["e"]], [("a", "e"), ("c", "a"), ("b", "d")]),
]


@pytest.mark.parametrize(("stacks", "goal"), SMALL_BLOCKS)
def test_blocks_plans_valid_improving_and_optimal(stacks, goal):
    task = blocks_task(stacks, goal)
    events = run(task, progress_every=5)
    found = plans(events)
    assert found, "GBFS finds a plan"
    for plan in found:
        check_plan(task, plan)
    costs = [p.cost for p in found]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    assert events[-1].status is PlanStatus.OPTIMAL
    assert costs[-1] == optimal_cost(task)


def test_first_plan_only():
    task = blocks_task(*SMALL_BLOCKS[3])
    events = run(task, anytime=False)
    assert len(plans(events)) == 1
    assert events[-1].status is PlanStatus.SOLVED
    check_plan(task, plans(events)[0])


def test_unsolvable_relaxed_and_exhausted():
    tb = TaskBuilder()
    tb.op("a", (), ["p"], ["q"], ["p"])
    relaxed_dead = tb.task(["p"], ["r"])
    assert run(relaxed_dead)[-1].status is PlanStatus.UNSOLVABLE
    # Relaxed solvable, but q and r exclude each other: only the full search sees it.
    tb = TaskBuilder()
    tb.op("mk-q", (), ["p"], ["q"], ["p"])
    tb.op("mk-r", (), ["p"], ["r"], ["p"])
    task = tb.task(["p"], ["q", "r"])
    events = run(task)
    assert events[-1].status is PlanStatus.UNSOLVABLE
    assert not plans(events)
    assert optimal_cost(task) is None


def test_unsolvable_reason_and_empty_goal():
    tb = TaskBuilder()
    tb.op("a", (), ["p"], ["q"])
    task = tb.task(["p"], ["q"])
    flagged = type(task)(task.name, task.facts, task.init, task.goal, task.operators, False, "static goal false")
    done = run(flagged)[-1]
    assert done.status is PlanStatus.UNSOLVABLE and "static" in done.message
    trivial = tb.task(["p"], ["p"])
    events = run(trivial)
    assert [p.cost for p in plans(events)] == [0]
    assert events[-1].status is PlanStatus.OPTIMAL


def test_costs_anytime_reaches_the_optimum():
    # GBFS on plan length goes up (expensive); the cheap way is longer.
    task = grid_task(5, cost_right=1, cost_up=10)
    ref = optimal_cost(task)
    events = run(task)
    found = plans(events)
    for plan in found:
        check_plan(task, plan)
    assert found[-1].cost == ref
    assert events[-1].status is PlanStatus.OPTIMAL


def test_expensive_shortcut_loses_to_a_cheap_detour():
    tb = TaskBuilder("detour")
    tb.op("jump", (), ["s"], ["g"], ["s"], 10)
    tb.op("walk1", (), ["s"], ["m1"], ["s"], 1)
    tb.op("walk2", (), ["m1"], ["m2"], ["m1"], 1)
    tb.op("walk3", (), ["m2"], ["g"], ["m2"], 1)
    task = tb.task(["s"], ["g"])
    events = run(task)
    found = plans(events)
    assert found[0].cost >= found[-1].cost == 3
    assert [s.action for s in found[-1].steps] == ["walk1", "walk2", "walk3"]


def test_conditional_effects():
    # A switch that toggles a light depending on the light: the goal needs the second press's condition.
    tb = TaskBuilder("cond")
    tb.op("press", (), ["hand"], [], [], 1, conditional=[(["off"], ["on"], ["off"]), (["on"], ["off", "done"], ["on"])])
    tb.op("wrap", (), ["done", "on"], ["wrapped"], [], 1)
    task = tb.task(["hand", "off"], ["wrapped"])
    events = run(task)
    found = plans(events)
    for plan in found:
        check_plan(task, plan)
    assert found[-1].cost == optimal_cost(task) == 4
    assert events[-1].status is PlanStatus.OPTIMAL


def test_conditional_add_wins_over_delete():
    tb = TaskBuilder("addwins")
    tb.op("set", (), ["p"], ["q"], ["q"], conditional=[(["p"], ["r"], ["r", "p"])])
    task = tb.task(["p"], ["q", "r"])
    events = run(task)
    check_plan(task, plans(events)[-1])
    assert plans(events)[-1].cost == 1


def test_deterministic_events():
    task = blocks_task([["e", "a", "c"], ["b", "d"], ["f"]], [("a", "b"), ("b", "c"), ("c", "d"), ("f", "e")])
    assert run(task, progress_every=3) == run(task, progress_every=3)


def test_progress_events():
    task = grid_task(9, cost_right=1, cost_up=3)
    events = run(task, progress_every=10)
    progress = [e for e in events if isinstance(e, Progress)]
    assert progress
    counts = [e.expansions for e in events]
    assert counts == sorted(counts)


def test_heuristics_agree_on_a_small_task():
    task = blocks_task(*SMALL_BLOCKS[3])
    ct = compile_task(task)
    rel = Relaxed(ct)
    s = ct.init
    hmax, hadd, ff = rel.h_max(s)[0], rel.h_add(s)[0], rel.ff(s)[0]
    assert 0 < hmax <= ff <= hadd
    assert rel.goal_count(s)[0] == len(task.goal) - len([g for g in task.goal if g in task.init])
    _h, pref = rel.ff(s)
    assert pref and all(op in ct.applicable(s) for op in pref)
    assert rel.ff_cost(s)[0] == rel.ff_add_unit(s)[0]
    dead = ct.init & ~ct.init
    assert rel.h_max(dead)[0] == INF


def test_encoding_applicable_matches_brute_force():
    task = blocks_task(*SMALL_BLOCKS[3])
    ct = compile_task(task)
    state = ct.init
    for _ in range(6):
        fast = ct.applicable(state)
        brute = [op for op in range(len(ct.pre)) if state & ct.pre_mask[op] == ct.pre_mask[op]]
        assert sorted(fast) == brute
        state = ct.successor(state, fast[-1])
    assert all(f < ct.n_facts for f in bits(state))


def test_planner_features_and_name():
    planner = BuiltinPlanner()
    assert planner.name == "builtin"
    assert (
        planner.missing({Feature.CONDITIONAL_EFFECTS, Feature.ACTION_COSTS, Feature.NEGATIVE_PRECONDITIONS})
        == frozenset()
    )
