"""Test helpers: the GroundTask contract as local dataclasses, small tasks, a plan checker, a reference search."""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Iterable
from dataclasses import dataclass, field

from alica.prophet.planner import Plan


@dataclass(frozen=True, slots=True)
class GroundOperator:
    """The grounding's operator shape (a local copy for hand-built tasks)."""

    name: str
    action: str
    args: tuple[str, ...]
    pre: tuple[int, ...]
    add: tuple[int, ...]
    delete: tuple[int, ...]
    cost: int = 1
    conditional: tuple[tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...]], ...] = ()


@dataclass(frozen=True)
class GroundTask:
    """The grounding's task shape (a local copy)."""

    name: str
    facts: tuple[str, ...]
    init: frozenset[int]
    goal: tuple[int, ...]
    operators: tuple[GroundOperator, ...]
    has_costs: bool = False
    unsolvable_reason: str | None = field(default=None)
    axioms: tuple[object, ...] = ()
    derived: frozenset[int] = frozenset()
    relaxed_axioms: tuple[tuple[int, tuple[int, ...]], ...] = ()


class TaskBuilder:
    """Build a GroundTask by fact names."""

    def __init__(self, name: str = "t") -> None:
        self.name = name
        self.facts: list[str] = []
        self.ids: dict[str, int] = {}
        self.ops: list[GroundOperator] = []

    def f(self, fact: str) -> int:
        """The id of a fact (created on first use)."""
        if fact not in self.ids:
            self.ids[fact] = len(self.facts)
            self.facts.append(fact)
        return self.ids[fact]

    def fs(self, facts: Iterable[str]) -> tuple[int, ...]:
        """Sorted ids of facts."""
        return tuple(sorted({self.f(x) for x in facts}))

    def op(
        self,
        action: str,
        args: tuple[str, ...],
        pre: Iterable[str],
        add: Iterable[str],
        delete: Iterable[str] = (),
        cost: int = 1,
        conditional: Iterable[tuple[Iterable[str], Iterable[str], Iterable[str]]] = (),
    ) -> None:
        """Add an operator."""
        cond = tuple((self.fs(c), self.fs(a), self.fs(d)) for c, a, d in conditional)
        name = f"({' '.join((action, *args))})"
        self.ops.append(GroundOperator(name, action, args, self.fs(pre), self.fs(add), self.fs(delete), cost, cond))

    def task(self, init: Iterable[str], goal: Iterable[str]) -> GroundTask:
        """The task (facts of init and goal created as needed)."""
        init_ids = frozenset(self.f(x) for x in init)
        goal_ids = self.fs(goal)
        return GroundTask(
            self.name,
            tuple(self.facts),
            init_ids,
            goal_ids,
            tuple(self.ops),
            has_costs=any(o.cost != 1 for o in self.ops),
        )


def blocks_task(stacks: list[list[str]], goal_on: list[tuple[str, str]], goal_table: Iterable[str] = ()) -> GroundTask:
    """A 4-operator blocks world task: ``stacks`` bottom first, goal ``on`` pairs."""
    blocks = sorted(b for s in stacks for b in s)
    tb = TaskBuilder("blocks")
    for x in blocks:
        tb.op(
            "pick-up",
            (x,),
            [f"clear {x}", f"ontable {x}", "handempty"],
            [f"holding {x}"],
            [f"ontable {x}", f"clear {x}", "handempty"],
        )
        tb.op("put-down", (x,), [f"holding {x}"], [f"clear {x}", "handempty", f"ontable {x}"], [f"holding {x}"])
        for y in blocks:
            if x == y:
                continue
            tb.op(
                "stack",
                (x, y),
                [f"holding {x}", f"clear {y}"],
                [f"clear {x}", "handempty", f"on {x} {y}"],
                [f"holding {x}", f"clear {y}"],
            )
            tb.op(
                "unstack",
                (x, y),
                [f"on {x} {y}", f"clear {x}", "handempty"],
                [f"holding {x}", f"clear {y}"],
                [f"on {x} {y}", f"clear {x}", "handempty"],
            )
    init = ["handempty"]
    for s in stacks:
        init.append(f"ontable {s[0]}")
        init += [f"on {a} {b}" for b, a in itertools.pairwise(s)]
        init.append(f"clear {s[-1]}")
    goal = [f"on {a} {b}" for a, b in goal_on] + [f"ontable {x}" for x in goal_table]
    return tb.task(init, goal)


def apply(task: GroundTask, state: frozenset[int], op: GroundOperator) -> frozenset[int]:
    """The reference semantics: effects evaluated on the old state, adds win over deletes."""
    add = set(op.add)
    delete = set(op.delete)
    for cond, cadd, cdel in op.conditional:
        if set(cond) <= state:
            add |= set(cadd)
            delete |= set(cdel)
    return frozenset((state - (delete - add)) | add)


def check_plan(task: GroundTask, plan: Plan) -> None:
    """Assert that ``plan`` is applicable, reaches the goal and costs what it says."""
    by_step = {(o.action, tuple(o.args)): o for o in task.operators}
    state = frozenset(task.init)
    cost = 0
    for step in plan.steps:
        op = by_step[(step.action, tuple(step.args))]
        assert set(op.pre) <= state, f"{op.name} not applicable"
        state = apply(task, state, op)
        cost += op.cost
    assert set(task.goal) <= state, "goal not reached"
    assert cost == plan.cost


def optimal_cost(task: GroundTask, limit: int = 200_000) -> int | None:
    """Uniform-cost search on frozensets: the optimal plan cost, or None if unsolvable."""
    start = frozenset(task.init)
    goal = set(task.goal)
    best = {start: 0}
    heap = [(0, 0, start)]
    tick = itertools.count(1)
    while heap:
        g, _n, state = heapq.heappop(heap)
        if best[state] < g:
            continue
        if goal <= state:
            return g
        assert len(best) < limit, "reference search too large"
        for op in task.operators:
            if set(op.pre) <= state:
                s2 = apply(task, state, op)
                g2 = g + op.cost
                if g2 < best.get(s2, g2 + 1):
                    best[s2] = g2
                    heapq.heappush(heap, (g2, next(tick), s2))
    return None
