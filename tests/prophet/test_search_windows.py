"""Window replanning: regrouping keeps plans valid, regressed needs suffice, a detour is cut short."""

from __future__ import annotations

from alica.prophet import pddl
from alica.prophet.ground import ground
from alica.prophet.planner import Done, Improved, PlanStatus, Progress
from alica.prophet.search import search_task
from alica.prophet.search.encoding import CompiledTask, compile_task
from alica.prophet.search.gbfs import Stats
from alica.prophet.search.windows import Windows
from tests.conftest import benchmark_set
from tests.prophet.search.helpers import TaskBuilder, check_plan, optimal_cost

ROAD = [("p0", "p1"), ("p1", "p2"), ("p2", "p3"), ("p0", "p3"), ("p3", "p4")]
"""A chain p0-p1-p2-p3-p4 with a shortcut p0-p3."""


def couriers_task() -> object:
    """Two robots on the same road: r1 from p0 to p4, r2 from p4 to p0; a parcel for r1 to carry."""
    tb = TaskBuilder("couriers")
    for robot in ("r1", "r2"):
        for a, b in ROAD:
            for x, y in ((a, b), (b, a)):
                tb.op("move", (robot, x, y), [f"at {robot} {x}"], [f"at {robot} {y}"], [f"at {robot} {x}"])
    for place in ("p0", "p1", "p2", "p3", "p4"):
        tb.op("load", ("r1", place), ["at r1 " + place, "parcel " + place], ["carried"], ["parcel " + place])
        tb.op("unload", ("r1", place), ["at r1 " + place, "carried"], ["parcel " + place], ["carried"])
    return tb.task(["at r1 p0", "at r2 p4", "parcel p0"], ["at r1 p4", "at r2 p0", "parcel p4"])


def ops_named(ct: CompiledTask, names: list[str]) -> list[int]:
    by_name = {ct.task.operators[s].name: o for o, s in enumerate(ct.source)}
    return [by_name[n] for n in names]


DETOUR = [
    "(load r1 p0)",
    "(move r2 p4 p3)",
    "(move r1 p0 p1)",
    "(move r2 p3 p2)",
    "(move r1 p1 p2)",
    "(move r2 p2 p1)",
    "(move r1 p2 p3)",
    "(move r2 p1 p0)",
    "(move r1 p3 p4)",
    "(unload r1 p4)",
]


def final_state(ct: CompiledTask, plan: list[int]) -> int:
    state = ct.init
    for op in plan:
        assert state & ct.pre_mask[op] == ct.pre_mask[op]
        state = ct.successor(state, op)
    return state


def test_regroup_keeps_the_plan_valid_and_brings_each_robot_together() -> None:
    ct = compile_task(couriers_task())
    windows = Windows(ct)
    plan = ops_named(ct, DETOUR)
    regrouped = windows.regroup(plan)
    assert sorted(regrouped) == sorted(plan)
    assert windows.valid(regrouped)
    assert final_state(ct, regrouped) == final_state(ct, plan)
    robots = [
        ct.task.operators[ct.source[o]].args[0] for o in regrouped if ct.task.operators[ct.source[o]].action == "move"
    ]
    assert robots == sorted(robots) or robots == sorted(robots, reverse=True)


def test_needs_are_enough_for_the_rest_of_the_plan() -> None:
    ct = compile_task(couriers_task())
    windows = Windows(ct)
    plan = ops_named(ct, DETOUR)
    needs = windows.needs(plan)
    assert needs[-1] == ct.goal_mask
    state = ct.init
    for k in range(len(plan) + 1):
        assert state & needs[k] == needs[k]
        rest = needs[k]  # only the needed facts: the rest of the plan still runs to the goal
        for op in plan[k:]:
            assert rest & ct.pre_mask[op] == ct.pre_mask[op]
            rest = ct.successor(rest, op)
        assert ct.is_goal(rest)
        if k < len(plan):
            state = ct.successor(state, plan[k])


def drain(gen):  # type: ignore[no-untyped-def]
    try:
        while True:
            next(gen)
    except StopIteration as stop:
        return stop.value


def test_a_window_cuts_the_detour_short() -> None:
    ct = compile_task(couriers_task())
    windows = Windows(ct)
    plan = ops_named(ct, DETOUR)
    better = drain(windows.improve_once(plan, Stats()))
    assert better is not None and windows.valid(better)
    assert ct.plan_cost(better) < ct.plan_cost(plan)
    while better is not None:
        plan, better = better, drain(windows.improve_once(better, Stats()))
    assert ct.plan_cost(plan) == optimal_cost(ct.task) == 6


def test_anytime_search_reaches_the_optimum_deterministically() -> None:
    task = couriers_task()
    runs = [list(search_task(task, progress_every=10)) for _ in range(2)]
    assert [repr(e) for e in runs[0]] == [repr(e) for e in runs[1]]
    found = [e.plan for e in runs[0] if isinstance(e, Improved)]
    for plan in found:
        check_plan(task, plan)
    costs = [p.cost for p in found]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    assert isinstance(runs[0][-1], Done) and runs[0][-1].status is PlanStatus.OPTIMAL
    assert costs[-1] == optimal_cost(task)


def test_when_effects_skip_the_regrouping_and_plans_stay_valid() -> None:
    tb = TaskBuilder("switch")
    tb.op("toggle", ("a",), ["ready"], ["done a"], [], 1, [(["lamp"], ["lit"], [])])
    tb.op("plug", ("lamp",), ["ready"], ["lamp"], [])
    tb.op("wait", ("x",), ["ready"], ["waited"], [])
    tb.op("finish", ("a", "x"), ["done a", "waited"], ["finished"], [])
    task = tb.task(["ready"], ["lit", "finished"])
    ct = compile_task(task)
    windows = Windows(ct)
    assert not windows.exact
    plan = ops_named(ct, ["(wait x)", "(plug lamp)", "(toggle a)", "(finish a x)"])
    assert windows.regroup(plan) == plan
    better = drain(windows.improve_once(plan, Stats()))
    assert better is None or (windows.valid(better) and ct.plan_cost(better) < ct.plan_cost(plan))


def test_rovers_anytime_plans_valid_and_strictly_cheaper() -> None:
    rovers = benchmark_set("pddl") / "rovers"
    domain = pddl.read_domain(rovers / "domain.pddl")
    task = ground(domain, pddl.read_problem(rovers / "p07.pddl", domain))
    found = []
    for event in search_task(task, progress_every=100):
        if isinstance(event, Improved):
            found.append(event.plan)
        if isinstance(event, Progress) and event.expansions > 20_000:
            break
    for plan in found:
        check_plan(task, plan)
    costs = [p.cost for p in found]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    assert costs[-1] == 18  # the optimum (benchmarks/pddl/rovers/optimal_costs.tsv)
