"""Fact landmarks and their orderings, the landmark count, the compiled FF and the LAMA-style first search."""

from __future__ import annotations

from collections import deque

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from alica.prophet import ground as grounding
from alica.prophet import pddl
from alica.prophet.planner import Improved
from alica.prophet.search import FirstSearch, search_task
from alica.prophet.search.encoding import CompiledTask, bits, compile_task
from alica.prophet.search.gbfs import Stats
from alica.prophet.search.heuristics import Relaxed
from alica.prophet.search.jit import CompiledFF, SwitchingFF, available
from alica.prophet.search.landmarks import LandmarkCount, Landmarks
from tests.conftest import benchmark_set
from tests.prophet.search.helpers import GroundTask, TaskBuilder, blocks_task, check_plan


def compiled(task: GroundTask) -> tuple[CompiledTask, Relaxed, LandmarkCount]:
    ct = compile_task(task)
    relaxed = Relaxed(ct)
    return ct, relaxed, LandmarkCount(ct, relaxed)


def names(ct: CompiledTask, facts: int) -> set[str]:
    return {ct.task.facts[f] for f in bits(facts)}


def reachable_avoiding(ct: CompiledTask, avoid: int, target: int, any_of: bool = False) -> bool:
    """Whether a state holding ``target`` (``any_of``: one of its facts) is reachable from the initial state
    through states holding no fact of ``avoid`` (a mask)."""
    start = ct.init
    if start & avoid:
        return False
    seen = {start}
    queue = deque([start])
    while queue:
        state = queue.popleft()
        if (state & target) if any_of else (state & target == target):
            return True
        for op in ct.applicable(state):
            nxt = ct.successor(state, op)
            if nxt & avoid or nxt in seen:
                continue
            seen.add(nxt)
            queue.append(nxt)
    return False


def logistics() -> GroundTask:
    """A package goes A -> B by truck; the truck starts at B."""
    tb = TaskBuilder("logistics")
    for x, y in (("A", "B"), ("B", "A")):
        tb.op("drive", (x, y), [f"truck {x}"], [f"truck {y}"], [f"truck {x}"])
    for x in ("A", "B"):
        tb.op("load", (x,), [f"truck {x}", f"pkg {x}"], ["pkg truck"], [f"pkg {x}"])
        tb.op("unload", (x,), [f"truck {x}", "pkg truck"], [f"pkg {x}"], ["pkg truck"])
    return tb.task(["truck B", "pkg A"], ["pkg B"])


def test_the_landmarks_of_a_small_task_and_their_orderings() -> None:
    ct, _relaxed, lmc = compiled(logistics())
    lm = lmc.landmarks
    assert names(ct, lm.mask) == {"pkg A", "pkg B", "pkg truck", "truck A", "truck B"}
    named = {(ct.task.facts[a], ct.task.facts[b]) for a, b in lm.orderings()}
    assert {("truck A", "pkg truck"), ("pkg truck", "pkg B"), ("pkg A", "pkg truck")} <= named
    gn = {(ct.task.facts[a], ct.task.facts[b]) for a, b in lm.greedy_necessary()}
    assert ("pkg truck", "pkg B") in gn and ("truck A", "pkg truck") in gn
    # 'truck B' holds initially and is needed again once the package is loaded (greedy-necessary for 'pkg B')
    assert ("truck B", "pkg B") in gn
    assert lmc.value(ct.init, lmc.initial) == 3  # truck A, pkg truck, pkg B


def test_every_landmark_and_ordering_holds_on_every_plan_of_a_blocks_task() -> None:
    ct, _relaxed, lmc = compiled(blocks_task([["a", "b"], ["c"]], [("b", "c"), ("a", "b")]))
    lm = lmc.landmarks
    assert len(lm) > len(bits(ct.goal_mask))
    for f in bits(lm.mask & ~ct.init):
        assert not reachable_avoiding(ct, 1 << f, ct.goal_mask), ct.task.facts[f]
    for before, after in lm.orderings():
        assert not reachable_avoiding(ct, 1 << before, 1 << after), (ct.task.facts[before], ct.task.facts[after])


@st.composite
def strips_tasks(draw: st.DrawFn) -> GroundTask:
    n = draw(st.integers(3, 6))
    facts = [f"{'pq'[i % 2]} {i}" for i in range(n)]  # two predicates: disjunctive landmarks group by them
    tb = TaskBuilder("random")
    for f in facts:
        tb.f(f)
    for k in range(draw(st.integers(1, 7))):
        pre = draw(st.lists(st.sampled_from(facts), max_size=2, unique=True))
        add = draw(st.lists(st.sampled_from(facts), min_size=1, max_size=2, unique=True))
        delete = draw(st.lists(st.sampled_from(facts), max_size=2, unique=True))
        tb.op("o", (str(k),), pre, add, delete)
    init = draw(st.lists(st.sampled_from(facts), max_size=2, unique=True))
    goal = draw(st.lists(st.sampled_from(facts), min_size=1, max_size=2, unique=True))
    return tb.task(init, goal)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(strips_tasks(), st.randoms(use_true_random=False))
def test_landmarks_and_orderings_are_sound_on_random_tasks(task: GroundTask, rng) -> None:  # type: ignore[no-untyped-def]
    ct = compile_task(task)
    if not ct.solvable_relaxed:
        return
    relaxed = Relaxed(ct)
    lmc = LandmarkCount(ct, relaxed)
    lm = lmc.landmarks
    assert lm.goal_mask & ~lm.mask == 0  # every goal is a landmark
    for f in bits(lm.mask & ~ct.init):
        assert not reachable_avoiding(ct, 1 << f, ct.goal_mask)
    for before, after in lm.orderings():
        assert not reachable_avoiding(ct, 1 << before, 1 << after)
    n = ct.n_facts
    for facts, children in zip(lm.disjunctive, lm.disjunctive_children, strict=True):
        assert not facts & ct.init
        for child in bits(children):  # one of the facts holds before the child (a fact or a disjunction) first does
            if child < n:
                assert not reachable_avoiding(ct, facts, 1 << child)
            else:
                assert not reachable_avoiding(ct, facts, lm.disjunctive[child - n], any_of=True)
    for before, after in lm.greedy_necessary():  # a precondition of every first achiever: also natural
        assert (before, after) in set(lm.orderings())
    # along any path, the count is 0 exactly at the goal states
    state, accepted = ct.init, lmc.initial
    for _ in range(30):
        assert (lmc.value(state, accepted) == 0) == ct.is_goal(state)
        ops = ct.applicable(state)
        if not ops:
            break
        state = ct.successor(state, rng.choice(ops))
        accepted = lmc.progress(accepted, state)


def test_a_disjunctive_landmark() -> None:
    tb = TaskBuilder("disjunctive")
    for truck in ("t1", "t2"):
        tb.op("load", (truck,), [f"at {truck} A", "pkg A"], [f"in pkg {truck}"], ["pkg A"])
        tb.op("unload", (truck,), [f"in pkg {truck}"], ["pkg B"], [f"in pkg {truck}"])
        tb.op("drive", (truck,), [], [f"at {truck} A"])
    ct, _relaxed, lmc = compiled(tb.task(["pkg A"], ["pkg B"]))
    lm = lmc.landmarks
    assert [names(ct, m) for m in lm.disjunctive] == [{"in pkg t1", "in pkg t2"}, {"at t1 A", "at t2 A"}]
    n = ct.n_facts
    assert lm.disjunctive_children == [1 << ct.task.facts.index("pkg B"), 1 << n]  # backchained from the first
    ids = {name: ct.task.facts.index(name) for name in ("pkg A", "at t2 A", "in pkg t2")}
    state, accepted = ct.init, lmc.initial
    assert lmc.value(state, accepted) == 3  # pkg B, the package in a truck, a truck at A
    for fact in ("at t2 A", "in pkg t2"):
        state |= 1 << ids[fact]
        if fact == "in pkg t2":
            state &= ~(1 << ids["pkg A"])
        accepted = lmc.progress(accepted, state)
    assert lmc.value(state, accepted) == 1
    state = ct.init & ~(1 << ids["pkg A"]) | 1 << ids["at t2 A"]  # the package in no truck, not at B
    assert lmc.value(state, lmc.progress(accepted, state)) == 2  # the disjunction is required again


def test_landmarks_come_from_when_effects_too() -> None:
    tb = TaskBuilder("when")
    tb.op("arm", (), [], ["armed"])
    tb.op("fire", (), ["ready"], [], conditional=[(["armed"], ["hit"], [])])
    tb.op("prepare", (), [], ["ready"])
    ct, _relaxed, lmc = compiled(tb.task([], ["hit"]))
    assert names(ct, lmc.landmarks.mask) == {"armed", "ready", "hit"}


def test_a_landmark_is_required_again_when_a_goal_is_undone() -> None:
    tb = TaskBuilder("again")
    tb.op("set", ("a",), [], ["a"])
    tb.op("unset", ("a",), ["a"], ["b"], ["a"])
    tb.op("set", ("b",), [], ["b"])
    ct, _relaxed, lmc = compiled(tb.task([], ["a", "b"]))
    a, b = ct.task.facts.index("a"), ct.task.facts.index("b")
    state = 1 << a
    accepted = lmc.progress(lmc.initial, state)
    assert lmc.value(state, accepted) == 1
    state2 = 1 << b  # a undone: a goal accepted before, false now
    accepted2 = lmc.progress(accepted, state2)
    assert accepted2 >> a & 1 and lmc.value(state2, accepted2) == 1


def random_states(ct: CompiledTask, n: int, seed: int = 0) -> list[int]:
    import random

    rng = random.Random(seed)
    states, state = [ct.init], ct.init
    for _ in range(n):
        ops = ct.applicable(state)
        if not ops:
            state = ct.init
            continue
        state = ct.successor(state, rng.choice(ops))
        states.append(state)
    return states


needs_numba = pytest.mark.skipif(not available(), reason="numba is not installed")


@needs_numba
@pytest.mark.parametrize(
    ("benchmarks", "domain", "problem"),
    [
        ("pddl", "rovers", "p05"),
        ("ipc", "miconic-simpleadl", "s1-2"),  # when-effects
        ("ipc", "elevators-sat08-strips", "p01"),  # costs
        ("ipc", "optical-telegraphs", "p01-opt2"),  # free rules
    ],
    ids=["rovers", "miconic-simpleadl", "elevators", "optical-telegraphs"],
)
def test_the_compiled_ff_equals_the_pure_python_one(benchmarks: str, domain: str, problem: str) -> None:
    folder = benchmark_set(benchmarks) / domain
    d = pddl.read_domain(folder / "domain.pddl")
    ct = compile_task(grounding.ground(d, pddl.read_problem(folder / f"{problem}.pddl", d)))
    relaxed = Relaxed(ct)
    unit = CompiledFF(relaxed)
    ones = CompiledFF(relaxed, relaxed.r_unit)  # 1 per operator, 0 per derived-predicate rule
    cost = CompiledFF(relaxed, unit=False)
    assert relaxed.has_rules == bool(ct.task.axioms)
    for state in random_states(ct, 150):
        if ct.unit_cost:
            assert unit(state) == relaxed.ff_add_unit(state)
        assert ones(state) == relaxed.ff_unit(state)
        assert cost(state) == relaxed.ff_cost(state)


@needs_numba
def test_switching_to_the_compiled_ff_does_not_change_the_search() -> None:
    rovers = benchmark_set("pddl") / "rovers"
    d = pddl.read_domain(rovers / "domain.pddl")
    ct = compile_task(grounding.ground(d, pddl.read_problem(rovers / "p10.pddl", d)))
    relaxed = Relaxed(ct)
    switching = SwitchingFF(relaxed, relaxed.ff_add_unit, load_s=-1.0)  # switches after the first evaluation
    python = SwitchingFF(relaxed, relaxed.ff_add_unit, load_s=float("inf"))  # never switches
    from alica.prophet.search.lama import lama_search

    lmc = LandmarkCount(ct, relaxed)
    runs = []
    for ff in (switching, python):
        search = lama_search(ct, ff, lmc, Stats(10**9))
        try:
            while True:
                next(search)
        except StopIteration as stop:
            runs.append(stop.value)
    assert switching.compiled is not None and python.compiled is None
    assert runs[0] == runs[1] and runs[0][0] is not None


def plan_ipc(domain: str, problem: str) -> None:
    folder = benchmark_set("ipc") / domain
    d = pddl.read_domain(folder / "domain.pddl")
    task = grounding.ground(d, pddl.read_problem(folder / f"{problem}.pddl", d))
    events = list(search_task(task, anytime=False, first=FirstSearch("lama")))
    plans = [e.plan for e in events if isinstance(e, Improved)]
    assert len(plans) == 1
    check_plan(task, plans[0])  # type: ignore[arg-type]


def test_the_lama_search_solves_a_visitall_problem() -> None:
    plan_ipc("visitall-sat11-strips", "problem12")


def test_the_lama_search_solves_a_parking_problem() -> None:
    plan_ipc("parking-sat11-strips", "pfile08-031")


def test_landmarks_of_an_unreachable_goal() -> None:
    tb = TaskBuilder("stuck")
    tb.op("go", (), ["x"], ["y"])
    ct = compile_task(tb.task([], ["y"]))
    lm = Landmarks(Relaxed(ct), ct.init)
    assert not lm.reachable


def test_a_failing_compilation_keeps_the_pure_python_ff(monkeypatch: pytest.MonkeyPatch) -> None:
    from alica.prophet.search import jit

    class Broken:
        def __init__(self, *args: object, **kwargs: object) -> None:
            raise RuntimeError("no LLVM here")

    monkeypatch.setattr(jit, "CompiledFF", Broken)
    monkeypatch.setattr(jit, "available", lambda: True)
    rovers = benchmark_set("pddl") / "rovers"
    d = pddl.read_domain(rovers / "domain.pddl")
    ct = compile_task(grounding.ground(d, pddl.read_problem(rovers / "p05.pddl", d)))
    relaxed = Relaxed(ct)
    ff = jit.SwitchingFF(relaxed, relaxed.ff_add_unit, load_s=-1.0)
    states = random_states(ct, 20)
    assert [ff(s) for s in states] == [relaxed.ff_add_unit(s) for s in states]
    assert ff.compiled is None


def test_mutex_groups_and_reasonable_orderings_of_a_blocks_task() -> None:
    from alica.prophet.search.mutexes import Mutexes, mutex_groups

    blocks = benchmark_set("pddl") / "blocks"
    d = pddl.read_domain(blocks / "domain.pddl")
    task = grounding.ground(d, pddl.read_problem(blocks / "probBLOCKS-6-2.pddl", d))
    groups = [{task.facts[f] for f in g} for g in mutex_groups(task)]
    assert {"(handempty)", "(holding a)", "(holding b)"} <= next(g for g in groups if "(handempty)" in g)
    assert any({"(clear a)", "(holding a)", "(on b a)"} <= g for g in groups)  # what is on a
    assert any({"(ontable a)", "(holding a)", "(on a b)"} <= g for g in groups)  # where a is
    ct, _relaxed, lmc = compiled(task)
    mutexes = Mutexes(mutex_groups(task), ct.n_facts)
    assert mutexes.mutex(task.fact_id("(holding a)"), task.fact_id("(handempty)"))
    assert not mutexes.mutex(task.fact_id("(clear a)"), task.fact_id("(clear b)"))
    reasonable = lmc.landmarks.reasonable_orderings()
    assert reasonable and not set(reasonable) & set(lmc.landmarks.orderings())
    for before, after in reasonable:  # each interferes: the later one would be destroyed again
        assert lmc.landmarks.mask >> before & 1 and lmc.landmarks.mask >> after & 1


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6))
def test_mutex_groups_hold_in_every_state_of_random_walks(seed: int) -> None:
    import random

    from alica.prophet.search.mutexes import mutex_groups

    blocks = benchmark_set("pddl") / "blocks"
    d = pddl.read_domain(blocks / "domain.pddl")
    task = grounding.ground(d, pddl.read_problem(blocks / "probBLOCKS-5-1.pddl", d))
    groups = mutex_groups(task)
    rng = random.Random(seed)
    state = frozenset(task.init)
    for _ in range(40):
        assert all(len(g & state) <= 1 for g in groups)
        ops = [o for o in task.operators if task.applicable(state, o)]
        state = task.apply(state, rng.choice(ops))


def test_the_landmark_count_is_zero_at_the_goal_with_reasonable_orderings() -> None:
    from alica.prophet.search.lama import lama_search

    blocks = benchmark_set("pddl") / "blocks"
    d = pddl.read_domain(blocks / "domain.pddl")
    for name in ("probBLOCKS-9-2", "probBLOCKS-8-1"):
        ct, relaxed, lmc = compiled(grounding.ground(d, pddl.read_problem(blocks / f"{name}.pddl", d)))
        assert lmc.landmarks.reasonable_orderings()
        for weight in (None, 1, 3):
            search = lama_search(ct, relaxed.ff_unit, lmc, Stats(10**9), weight=weight)
            try:
                while True:
                    next(search)
            except StopIteration as stop:
                plan, _ = stop.value
            state, accepted = ct.init, lmc.initial
            for op in plan:
                state = ct.successor(state, op)
                accepted = lmc.progress(accepted, state)
            assert ct.is_goal(state) and lmc.value(state, accepted) == 0
