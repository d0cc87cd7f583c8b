"""The makespan search: decision epochs, plans the validator accepts, limits, and its place in the temporal planner."""

from __future__ import annotations

import random

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from alica.prophet.ground import ground
from alica.prophet.pddl import Domain, Problem, parse_domain, parse_problem
from alica.prophet.planner import Done, Improved, LimitReached, Limits, PlanStatus, PlanStep
from alica.prophet.planners.temporal import TemporalPlanner
from alica.prophet.search.planner import BuiltinPlanner
from alica.prophet.temporal import ScheduledPlan, schedule, sequential_task
from alica.prophet.temporal_ground import TemporalTask, temporal_task
from alica.prophet.temporal_search import Relaxation, TimedResult, makespan_search
from alica.prophet.validate_temporal import validate_temporal_plan
from tests.prophet.pddl.test_durative import DOMAIN
from tests.prophet.test_temporal import TWO_ROVERS


def _task(domain: Domain, problem: Problem) -> TemporalTask:
    grounded = ground(*sequential_task(domain, problem))
    return temporal_task(domain, problem, (PlanStep(op.action, op.args) for op in grounded.operators))


def _plans(task: TemporalTask, **options: object) -> tuple[list[TimedResult], Done]:
    found: list[TimedResult] = []
    events = list(makespan_search(task, on_plan=found, **options))  # type: ignore[arg-type]
    assert isinstance(events[-1], Done)
    improved = [e for e in events if isinstance(e, Improved)]
    assert [e.plan.cost for e in improved] == [round(r.makespan_ticks / 1e6, 6) for r in found]
    return found, events[-1]


def test_on_two_rovers_the_sequential_search_uses_one_rover_and_the_makespan_search_both() -> None:
    domain = parse_domain(DOMAIN)
    problem = parse_problem(TWO_ROVERS, domain=domain)
    sequential = BuiltinPlanner().solve(*sequential_task(domain, problem), time_limit=30, anytime=True)
    assert sequential.plan is not None
    assert {step.args[0] for step in sequential.plan.steps} == {"r"}  # the least summed duration: one rover
    assert schedule(domain, problem, sequential.plan.steps).plan.makespan == pytest.approx(7.502)
    found, done = _plans(_task(domain, problem))
    best = found[-1].plan
    assert validate_temporal_plan(domain, problem, best).valid
    assert best.makespan == pytest.approx(6.501) and done.status is PlanStatus.SOLVED
    assert [str(t) for t in best.steps] == [
        "0.000: (recharge r) [2.500]",
        "0.000: (recharge s) [2.500]",
        "2.501: (move r p q) [4.000]",
        "2.501: (move s p x) [3.000]",
    ]
    assert done.message == "no shorter plan with starts at the decision epochs"


def test_the_temporal_planner_returns_the_makespan_search_plan_with_its_own_timing() -> None:
    domain = parse_domain(DOMAIN)
    problem = parse_problem(TWO_ROVERS, domain=domain)
    planner = TemporalPlanner()
    result = planner.solve(domain, problem, time_limit=60, anytime=True)
    assert result.plan is not None and result.cost == pytest.approx(6.501)
    assert isinstance(result.plan, ScheduledPlan) and planner.best_source == "makespan"
    timed = TemporalPlanner.timed_plan(domain, problem, result.plan)
    assert timed.makespan == pytest.approx(6.501) and validate_temporal_plan(domain, problem, timed).valid
    off = TemporalPlanner(makespan_search=False).solve(domain, problem, time_limit=60, anytime=True)
    assert off.cost == pytest.approx(7.502) and not isinstance(off.plan, ScheduledPlan)


def test_with_no_more_steps_the_makespan_search_plan_must_not_outnumber_the_sequential_plan() -> None:
    domain = parse_domain(DOMAIN)
    problem = parse_problem(TWO_ROVERS, domain=domain)
    # the sequential plan: one rover in 3 steps (7.502 s scheduled); the makespan search's: both rovers, 4 steps
    planner = TemporalPlanner(no_more_steps=True)
    events = list(planner.search(domain, problem, anytime=True, limits=Limits(60)))
    improved = [e.plan for e in events if isinstance(e, Improved)]
    assert improved and all(len(plan.steps) <= 3 for plan in improved)
    assert improved[-1].cost == pytest.approx(7.502) and planner.best_source == "sequential"
    assert planner.sources["makespan"] == 0
    free = TemporalPlanner().solve(domain, problem, time_limit=60, anytime=True)
    assert free.cost == pytest.approx(6.501) and len(free.plan.steps) == 4  # type: ignore[union-attr]
    # without a sequential plan to compare with, the makespan search's best plan counts at the end
    alone = TemporalPlanner(no_more_steps=True, makespan_only=True).solve(domain, problem, time_limit=60, anytime=True)
    assert alone.cost == pytest.approx(6.501)


def test_every_improvement_of_the_temporal_planner_validates_and_shortens_the_makespan() -> None:
    domain = parse_domain(DOMAIN)
    problem = parse_problem(TWO_ROVERS, domain=domain)
    events = list(TemporalPlanner().search(domain, problem, anytime=True, limits=Limits(60)))
    costs = [e.plan.cost for e in events if isinstance(e, Improved)]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    for event in events:
        if isinstance(event, Improved):
            timed = TemporalPlanner.timed_plan(domain, problem, event.plan)
            assert validate_temporal_plan(domain, problem, timed).valid and timed.makespan == event.plan.cost


# random durative tasks over five propositions: conditions and effects of every kind, durations down to
# zero and below EPSILON (so simultaneous happenings and the EPSILON separation are exercised)
_LITERAL = st.tuples(st.integers(0, 4), st.booleans())
_DURATIONS = (0, 0.0005, 0.001, 1, 1.5, 2)


def _literals(items: list[tuple[int, bool]], kind: str) -> str:
    seen: dict[int, bool] = {}
    for p, positive in items:
        seen.setdefault(p, positive)
    parts = [f"(p{p})" if positive else f"(not (p{p}))" for p, positive in sorted(seen.items())]
    return " ".join(f"({kind} {part})" for part in parts)


_ACTION = st.tuples(
    st.lists(_LITERAL, max_size=2),
    st.lists(_LITERAL, max_size=2),
    st.lists(_LITERAL, max_size=1),
    st.lists(_LITERAL, max_size=2),
    st.lists(_LITERAL, max_size=2),
    st.sampled_from(_DURATIONS),
)


def _random_domain(actions: list[tuple]) -> str:
    text = []
    for k, (at_start, over_all, at_end, start_eff, end_eff, duration) in enumerate(actions):
        condition = " ".join(
            filter(
                None,
                (_literals(at_start, "at start"), _literals(over_all, "over all"), _literals(at_end, "at end")),
            )
        )
        effect = " ".join(filter(None, (_literals(start_eff, "at start"), _literals(end_eff, "at end"))))
        text.append(
            f"(:durative-action a{k} :parameters () :duration (= ?duration {duration})"
            f" :condition (and {condition}) :effect (and {effect}))"
        )
    return (
        "(define (domain random-t) (:requirements :durative-actions :negative-preconditions)"
        " (:predicates (p0) (p1) (p2) (p3) (p4))\n" + "\n".join(text) + ")"
    )


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(_ACTION, min_size=1, max_size=4),
    st.sets(st.integers(0, 4)),
    st.lists(_LITERAL, min_size=1, max_size=3),
)
def test_plans_of_the_makespan_search_on_random_durative_tasks_validate(
    actions: list[tuple], init: set[int], goal: list[tuple[int, bool]]
) -> None:
    domain = parse_domain(_random_domain(actions))
    goal_text = " ".join(f"(p{p})" if positive else f"(not (p{p}))" for p, positive in goal)
    problem = parse_problem(
        f"(define (problem r) (:domain random-t) (:init {' '.join(f'(p{p})' for p in sorted(init))})"
        f" (:goal (and {goal_text})))",
        domain=domain,
    )
    task = temporal_task(domain, problem, [PlanStep(a.name) for a in domain.durative_actions])
    found, done = _plans(task)
    for result in found:
        checked = validate_temporal_plan(domain, problem, result.plan)
        assert checked.valid, f"{checked.reason}\n{result.plan}"
        assert result.plan.makespan == pytest.approx(result.makespan_ticks / 1e6)
    makespans = [r.makespan_ticks for r in found]
    assert makespans == sorted(makespans, reverse=True)
    assert done.status in ({PlanStatus.SOLVED} if found else {PlanStatus.TIMEOUT, PlanStatus.UNSOLVABLE})


_PLACES = ("p", "q", "x", "y")


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6))
def test_plans_on_random_rover_problems_validate(seed: int) -> None:
    """Random problems of the durative rovers domain (with ``close`` and ``drain``, which break what a drive needs)."""
    rng = random.Random(seed)
    rovers = ["r", "s"][: rng.randint(1, 2)]
    paths = sorted({(a, b) for a in _PLACES for b in _PLACES if a != b and rng.random() < 0.4})
    init = [f"(at {r} {rng.choice(_PLACES)})" for r in rovers]
    init += [f"(charged {r})" for r in rovers if rng.random() < 0.5]
    init += [f"(path {a} {b}) (= (travel {a} {b}) {rng.choice((1, 2, 3.5))})" for a, b in paths]
    goal = " ".join(f"(visited {p})" for p in rng.sample(_PLACES, rng.randint(1, 2)))
    domain = parse_domain(DOMAIN)
    problem = parse_problem(
        f"(define (problem g) (:domain rovers-t) (:objects {' '.join(rovers)} - rover p q x y - place)"
        f" (:init {' '.join(init)}) (:goal (and {goal})))",
        domain=domain,
    )
    found, _done = _plans(_task(domain, problem))
    for result in found:
        checked = validate_temporal_plan(domain, problem, result.plan)
        assert checked.valid, f"{checked.reason}\n{result.plan}"


def _busy_task() -> tuple[Domain, Problem]:
    """Enough work that the search passes its first check of the limits."""
    domain = parse_domain(DOMAIN)
    problem = parse_problem(
        "(define (problem busy) (:domain rovers-t) (:objects r s - rover p q x y - place)"
        " (:init (at r p) (at s y) (path p q) (path q x) (path x y) (path y p) (path q p) (path x q)"
        " (= (travel p q) 2) (= (travel q x) 3) (= (travel x y) 1) (= (travel y p) 2) (= (travel q p) 2)"
        " (= (travel x q) 3))"
        " (:goal (and (visited p) (visited q) (visited x) (visited y))))",
        domain=domain,
    )
    return domain, problem


def test_the_makespan_search_stops_at_the_deadline_and_at_the_memory_bound() -> None:
    task = _task(*_busy_task())
    now = [0.0]
    limits = Limits(5.0, clock=lambda: now[0])
    now[0] = 10.0  # past the deadline before the search starts
    with pytest.raises(LimitReached, match=r"time limit 5 s reached while searching for a short makespan") as hit:
        list(makespan_search(task, limits=limits))
    assert hit.value.kind == "time"
    with pytest.raises(LimitReached, match=r"searching for a short makespan needs more than 0.001 MB") as hit:
        list(makespan_search(task, limits=Limits(memory_mb=0.001)))
    assert hit.value.kind == "memory"


def test_the_temporal_planner_ends_with_a_timeout_past_its_deadline() -> None:
    domain, problem = _busy_task()
    now = [0.0]
    limits = Limits(5.0, clock=lambda: now[0])
    now[0] = 10.0
    events = list(TemporalPlanner().search(domain, problem, limits=limits))
    assert not any(isinstance(e, Improved) for e in events)
    assert isinstance(events[-1], Done) and events[-1].status is PlanStatus.TIMEOUT


def test_the_makespan_search_is_deterministic() -> None:
    task = _task(*_busy_task())
    first = [str(r.plan) for r in _plans(task)[0]]
    assert first and first == [str(r.plan) for r in _plans(task)[0]]


def test_a_task_the_makespan_search_cannot_take_leaves_the_sequential_plan() -> None:
    domain = parse_domain(
        DOMAIN.replace(
            ":condition ()\n    :effect (at end (charged ?r)))",
            ":condition (at start (or (charged ?r) (not (charged ?r))))\n    :effect (at end (charged ?r)))",
            1,
        )
    )
    problem = parse_problem(TWO_ROVERS, domain=domain)
    planner = TemporalPlanner()
    events = list(planner.search(domain, problem, anytime=False, limits=Limits(60)))
    assert any(isinstance(e, Improved) for e in events) and planner.best_source == "sequential"
    done = events[-1]
    assert isinstance(done, Done) and done.status is PlanStatus.SOLVED
    assert (
        "makespan search: step (recharge r): the makespan search takes a condition that is a conjunction"
        in done.message
    )


def test_the_makespan_left_puts_one_rovers_drives_one_after_another() -> None:
    domain = parse_domain(DOMAIN)
    one = TWO_ROVERS.replace("r s - rover", "r - rover").replace(" (at s p)", "")
    task = _task(domain, parse_problem(one, domain=domain))
    relax = Relaxation(task)
    estimate = relax.evaluate(task.init, (), 0)
    assert estimate is not None
    h_time, scheduled, work, plan = estimate
    names = sorted(str(task.ops[a].step) for a in plan)
    assert names == ["(move r p q)", "(move r p x)", "(recharge r)"]  # relaxed: both drives from p
    assert (h_time, work) == (6_500_000, 9_500_000)  # relaxed, the drives run at once
    assert scheduled == 9_500_000  # but the rover drives once at a time: 2.5 + 4 + 3
    first, second = (a for a in plan if task.ops[a].step.action == "move")
    assert relax.dependent(first, second)
