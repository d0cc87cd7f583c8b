"""The compiled LAMA first search gives the pure-Python search's plans, expansions and progress, and keeps its limits."""

from __future__ import annotations

from collections.abc import Generator
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from alica.prophet import ground as grounding
from alica.prophet import pddl
from alica.prophet.planner import Improved, LimitReached, Limits, Progress
from alica.prophet.search import anytime, compiled_lama
from alica.prophet.search.anytime import to_plan
from alica.prophet.search.compiled_lama import compiled_lama_search, eligible, first_plan
from alica.prophet.search.encoding import CompiledTask, compile_task
from alica.prophet.search.gbfs import Stats
from alica.prophet.search.heuristics import Relaxed
from alica.prophet.search.lama import lama_search
from alica.prophet.search.landmarks import LandmarkCount
from tests.conftest import benchmark_set
from tests.prophet.search.helpers import GroundOperator, GroundTask, check_plan


def drain(search: Generator[Progress, None, Any]) -> tuple[Any, list[int]]:
    """The search's return value and the expansion counts of its progress events."""
    progress: list[int] = []
    try:
        while True:
            progress.append(next(search).expansions)
    except StopIteration as stop:
        return stop.value, progress


def both(ct: CompiledTask, weight: float | None = None, every: int = 1000, **kw: Any) -> tuple[tuple, tuple]:
    """(result, expansions, progress) of the pure-Python and of the compiled search."""
    relaxed = Relaxed(ct)
    runs = []
    for compiled in (False, True):
        lmcount = LandmarkCount(ct, relaxed)
        stats = Stats(every)
        if compiled:
            search = compiled_lama_search(ct, relaxed, lmcount, stats, weight=weight, **kw)
        else:
            search = lama_search(ct, relaxed.ff_unit, lmcount, stats, weight=weight, **kw)
        result, progress = drain(search)
        runs.append((result, stats.expansions, progress))
    return runs[0], runs[1]


def _ipc_files(domain: str, problem: str) -> tuple[pddl.Domain, pddl.Problem]:
    folder = benchmark_set("ipc") / domain
    d = pddl.read_domain(folder / "domain.pddl")
    return d, pddl.read_problem(folder / f"{problem}.pddl", d)


def ipc_task(domain: str, problem: str) -> CompiledTask:
    return compile_task(grounding.ground(*_ipc_files(domain, problem)))


@pytest.mark.parametrize(
    ("domain", "problem", "weight"),
    [
        ("depot", "p03", None),
        ("depot", "p05", 3),
        ("logistics00", "probLOGISTICS-6-0", None),
        ("logistics00", "probLOGISTICS-6-0", 1.5),
        ("satellite", "p05-pfile5", None),
        ("elevators-sat08-strips", "p03", None),
        ("gripper", "prob05", 5),
        ("driverlog", "p07", None),
        ("zenotravel", "p05", 2),
    ],
)
def test_the_compiled_search_is_the_pure_python_one_on_ipc_problems(
    domain: str, problem: str, weight: float | None
) -> None:
    ct = ipc_task(domain, problem)
    assert eligible(ct, Relaxed(ct), weight, None)
    python, compiled = both(ct, weight, every=5)
    assert compiled == python
    (plan, exhausted), _expansions, progress = compiled
    assert plan is not None and not exhausted and progress


N_FACTS = 80  # two words per state, facts on both sides of the word boundary


@st.composite
def strips_tasks(draw: st.DrawFn) -> GroundTask:
    facts = tuple(f"(p{i % 6} o{i})" for i in range(N_FACTS))  # shared predicates: disjunctive landmarks may form
    used = draw(st.lists(st.integers(0, N_FACTS - 1), min_size=4, max_size=14, unique=True))
    subset = st.frozensets(st.sampled_from(used), max_size=3).map(lambda s: tuple(sorted(s)))
    ops = []
    for i in range(draw(st.integers(1, 14))):
        ops.append(
            GroundOperator(f"(o{i})", f"o{i}", (), draw(subset), draw(subset), draw(subset), draw(st.integers(1, 3)))
        )
    init = draw(st.frozensets(st.sampled_from(used), max_size=5))
    goal = tuple(sorted(draw(st.frozensets(st.sampled_from(used), min_size=1, max_size=3))))
    return GroundTask("random", facts, init, goal, tuple(ops), has_costs=True)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(strips_tasks(), st.sampled_from([None, 1, 1.5, 3]))
def test_the_compiled_search_is_the_pure_python_one_on_random_tasks(task: GroundTask, weight: float | None) -> None:
    ct = compile_task(task)
    if not ct.solvable_relaxed or not ct.pre:
        return
    python, compiled = both(ct, weight, every=3)
    assert compiled == python
    (plan, _exhausted), _, _ = compiled
    if plan is not None:
        check_plan(task, to_plan(ct, plan))


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(strips_tasks(), st.sampled_from([None, 2]), st.integers(1, 8))
def test_a_cost_bound_prunes_both_searches_alike(task: GroundTask, weight: float | None, bound: int) -> None:
    ct = compile_task(task)
    if not ct.solvable_relaxed or not ct.pre:
        return
    python, compiled = both(ct, weight, every=3, bound=bound)
    assert compiled == python
    (plan, _exhausted), _, _ = compiled
    if plan is not None:
        assert ct.plan_cost(plan) < bound
        check_plan(task, to_plan(ct, plan))


def test_a_cost_bound_on_an_ipc_problem_finds_a_cheaper_plan_or_none_in_both() -> None:
    ct = ipc_task("depot", "p03")
    (first, _), _, _ = both(ct)[1]
    python, compiled = both(ct, 3, bound=ct.plan_cost(first), max_expansions=3000)
    assert compiled == python
    plan = compiled[0][0]
    assert plan is None or ct.plan_cost(plan) < ct.plan_cost(first)


def test_an_expansion_limit_stops_both_searches_alike() -> None:
    ct = ipc_task("depot", "p03")
    python, compiled = both(ct, max_expansions=40)
    assert compiled == python
    assert compiled[0] == (None, False) and compiled[1] == 41  # the expansion past the limit is counted, not used


def test_full_arrays_grow_and_the_search_goes_on(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(compiled_lama, "DEFAULT_BUDGET", 1)
    monkeypatch.setattr(compiled_lama, "INITIAL_STATES", 4)
    monkeypatch.setattr(compiled_lama, "INITIAL_ENTRIES", 8)
    grown: list[int] = []
    original = compiled_lama._Arrays.grow

    def counting(self: Any) -> None:
        grown.append(int(self.sc[self.k.S_STATES]))
        original(self)

    monkeypatch.setattr(compiled_lama._Arrays, "grow", counting)
    ct = ipc_task("depot", "p03")
    python, compiled = both(ct)
    assert compiled == python and len(grown) > 5


def test_the_deadline_and_the_memory_bound_hold_in_the_compiled_search() -> None:
    ct = ipc_task("depot", "p05")
    relaxed = Relaxed(ct)
    now = [0.0]

    def clock() -> float:
        now[0] += 0.01  # every look at the clock is 10 ms later
        return now[0]

    stats = Stats(1000, Limits(0.1, clock=clock))
    with pytest.raises(LimitReached) as late:
        drain(compiled_lama_search(ct, relaxed, LandmarkCount(ct, relaxed), stats))
    assert late.value.kind == "time" and 0 < late.value.expansions < 688
    stats = Stats(1000, Limits(memory_mb=0.05))
    with pytest.raises(LimitReached) as full:
        drain(compiled_lama_search(ct, relaxed, LandmarkCount(ct, relaxed), stats))
    assert full.value.kind == "memory" and "searching needs more than 0.05 MB" in str(full.value)


def test_first_plan_switches_to_the_compiled_search_without_changing_the_plan(monkeypatch: pytest.MonkeyPatch) -> None:
    ct = ipc_task("depot", "p05")
    relaxed = Relaxed(ct)
    python, _ = both(ct)
    calls: list[str] = []
    original = compiled_lama.compiled_lama_search

    def spy(*args: Any, **kw: Any) -> Any:
        calls.append("compiled")
        return original(*args, **kw)

    monkeypatch.setattr(compiled_lama, "compiled_lama_search", spy)
    budget = int(compiled_lama.EXPANSIONS_PER_STEP * relaxed.ff_unit(ct.init)[0]) + 1  # the search needs more
    assert budget < python[1]
    monkeypatch.setattr(compiled_lama, "python_budget", lambda _relaxed: budget)
    stats = Stats(1000)
    result, _ = drain(first_plan(ct, relaxed, relaxed.ff_unit, LandmarkCount(ct, relaxed), stats))
    assert calls == ["compiled"] and result == python[0]
    assert stats.expansions == budget + 1 + python[1]  # the pure-Python start is counted too


def test_tasks_the_kernel_does_not_cover_stay_in_pure_python() -> None:
    makes_c = GroundOperator("(m)", "m", (), (0,), (2,), (), 1)
    when = GroundOperator("(o)", "o", (), (0,), (1,), (), 1, (((2,), (3,), ()),))  # adds d too once c holds
    task = GroundTask("t", ("(a)", "(b)", "(c)", "(d)"), frozenset({0}), (1, 3), (makes_c, when))
    ct = compile_task(task)
    relaxed = Relaxed(ct)
    assert not eligible(ct, relaxed, None, None)
    assert not eligible(ipc_task("depot", "p03"), Relaxed(ipc_task("depot", "p03")), None, 7)  # a tie-breaking seed
    assert not eligible(ipc_task("depot", "p03"), Relaxed(ipc_task("depot", "p03")), 1.25, None)  # keys not exact
    with pytest.raises(ValueError, match="covers STRIPS tasks"):
        drain(compiled_lama_search(ct, relaxed, LandmarkCount(ct, relaxed), Stats()))
    (plan, exhausted), _ = drain(first_plan(ct, relaxed, relaxed.ff_unit, LandmarkCount(ct, relaxed), Stats()))
    assert not exhausted and [ct.source[o] for o in plan] == [0, 1]


def test_a_search_longer_than_the_budget_starts_compiled(monkeypatch: pytest.MonkeyPatch) -> None:
    ct = ipc_task("depot", "p05")
    relaxed = Relaxed(ct)
    python, _ = both(ct)
    monkeypatch.setattr(compiled_lama, "python_budget", lambda _relaxed: 10)  # FF's estimate of the start is more
    stats = Stats(1000)
    result, _ = drain(first_plan(ct, relaxed, relaxed.ff_unit, LandmarkCount(ct, relaxed), stats))
    assert result == python[0] and stats.expansions == python[1]  # no pure-Python start


def test_ff_past_its_cost_levels_goes_over_to_the_heap_and_the_search_stays_the_same(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(compiled_lama, "LEVELS", 3)  # depot's h_add costs go far past 3
    ct = ipc_task("depot", "p03")
    python, compiled = both(ct)
    assert compiled == python


def test_after_a_compiled_first_search_the_anytime_restarts_run_compiled_under_the_best_cost(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    task = grounding.ground(*_ipc_files("depot", "p03"))
    monkeypatch.setattr(compiled_lama, "python_budget", lambda _relaxed: 10)  # the first search starts compiled
    restarts: list[tuple[float | None, float]] = []
    original = anytime.compiled_lama_search

    def spy(*args: Any, **kw: Any) -> Any:
        restarts.append((kw["weight"], kw["bound"]))
        return original(*args, **kw)

    monkeypatch.setattr(anytime, "compiled_lama_search", spy)
    events = list(anytime.search_task(task, anytime=True, optimal_pass=False))
    costs = [event.plan.cost for event in events if isinstance(event, Improved)]
    assert [w for w, _ in restarts] == list(anytime.COMPILED_RESTART_WEIGHTS)
    assert all(bound <= costs[0] for _, bound in restarts) and restarts[-1][1] >= costs[-1]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    for event in events:
        if isinstance(event, Improved):
            check_plan(task, event.plan)
