"""A search for short makespans: forward search over decision epochs (in the style of Sapa and Temporal FD).

A search node holds the facts, the running actions (each with its start and end time) and the
current time ``now``. Its successors:

- **start** a ground durative action now: its ``at start`` condition holds, it is not running
  already, after its start effects the ``over all`` conditions of every running action (its own
  included) still hold, and its happenings do not interfere
  (:meth:`~alica.prophet.temporal_ground.Happening.interferes`) with any happening of a running
  action fewer than :data:`~alica.prophet.temporal_ground.EPSILON_TICKS` away (the validator's rule
  for simultaneous happenings);
- **advance** to the earliest end of a running action: that end, and every end chained to it by
  less than EPSILON, happen in time order (each ``at end`` condition checked in the state before it,
  the ``over all`` conditions of the actions still running checked after it); ``now`` becomes the
  last of them plus EPSILON, so a new start never meets an end that just happened.

A node with nothing running whose facts satisfy the goal is a plan; its makespan is its last end.
Each plan is thus one the validator accepts (its checks are the validator's, taken happening by
happening instead of group by group, which is stricter).

The heuristic is a temporal delete relaxation: facts of the node at time 0, the end effects of
running actions at their end times, and every ground action starting as soon as its positive
conditions hold (a Dijkstra exploration over times). It gives ``h_time``, when the last goal fact
is reached, and a relaxed plan through the earliest supporters (among equally early ones, the one
sharing the fewest objects with the plan so far, so work spreads over the agents). Two estimates
come from the relaxed plan (:class:`Estimate`): the *work* left, its summed duration, and the
*makespan* left, when it ends with its dependent actions (:meth:`Relaxation.dependent`: those that
may not overlap, such as two drives of one rover) one after another, the running ones included.
A pass orders its nodes by ``now + w * estimate`` (:class:`Pass`): starting an action of the relaxed
plan costs no time and takes its duration off the work left, so actions that can run side by side
start together; ties go to the other estimate, the lower bound, then the newest node (the search is
deterministic). ``max(last end, now + h_time)`` is a lower bound on the makespan of every plan
through the node (on temporally simple tasks, where an action's conditions hold by its start):
nodes that cannot beat the best plan (:class:`Bound`, shared with the sequential planner) are
pruned. The passes (:data:`MAKESPAN_PASSES`) run in turn, each pruned by the best plan so far: two
greedy ones by the work left, each ended by its first plan, then two by the makespan left, all but
the last starting only the actions of the relaxed plan (helpful actions). When the last exhausts its
nodes under the bound, no plan with starts at the decision epochs is shorter; else the limits end
the run.
"""

from __future__ import annotations

from collections.abc import Generator, Iterator
from dataclasses import dataclass
from enum import Enum
from heapq import heappop, heappush

from alica.prophet.planner import Done, Improved, Limits, Plan, PlanStatus, Progress, SearchEvent
from alica.prophet.temporal_ground import EPSILON_TICKS, TICKS, Happening, TemporalTask
from alica.prophet.temporal_plan import TemporalPlan, TimedStep


class Estimate(Enum):
    """What a pass orders its nodes by (``now`` plus its weight times the estimate)."""

    WORK = "work"
    """The relaxed plan's summed duration: greedy, so a first plan comes soon."""
    SCHEDULED = "scheduled"
    """When the relaxed plan ends with its dependent actions one after another: the makespan left."""


@dataclass(frozen=True, slots=True)
class Pass:
    """One pass of the search.

    Attributes:
        estimate: what orders the nodes.
        weight: the estimate's weight against ``now``.
        helpful_only: whether it starts only actions of the relaxed plan.
        first_plan_only: whether its first plan ends it (the next pass goes on under the new bound).
    """

    estimate: Estimate
    weight: float
    helpful_only: bool = True
    first_plan_only: bool = False


MAKESPAN_PASSES: tuple[Pass, ...] = (
    Pass(Estimate.WORK, 5.0, first_plan_only=True),
    Pass(Estimate.WORK, 1.0, first_plan_only=True),
    Pass(Estimate.SCHEDULED, 1.0),
    Pass(Estimate.SCHEDULED, 1.0, helpful_only=False),
)
"""The passes in turn: two by the work left, each until its first plan (a first plan soon), then two by the
makespan left, the last starting any action."""
PROGRESS_EVERY = 100
"""Expansions between two ``Progress`` events."""
CHECK_EVERY = 16
"""Expansions between two checks of the limits."""
NODE_BYTES = 700
"""The memory estimate of a node kept by the search (its entry in the duplicate table and the open list)."""
_INF = 1 << 62

Running = tuple[tuple[int, int, int], ...]
"""The running actions as ``(end, op index, start)`` in ticks, sorted."""


@dataclass(slots=True)
class Bound:
    """The shortest makespan known so far, in ticks (``None``: no plan yet); shared between searches."""

    ticks: int | None = None


@dataclass(frozen=True, slots=True)
class TimedResult:
    """A plan of the makespan search."""

    plan: TemporalPlan
    makespan_ticks: int


class _Node:
    __slots__ = ("facts", "last", "now", "parent", "running", "started")

    def __init__(
        self, facts: int, running: Running, now: int, last: int, parent: _Node | None, started: tuple[int, int] | None
    ) -> None:
        self.facts = facts
        self.running = running
        self.now = now
        self.last = last
        self.parent = parent
        self.started = started

    def key(self) -> tuple[int, tuple[tuple[int, int, bool], ...]]:
        now = self.now
        return self.facts, tuple((end - now, i, start == now) for end, i, start in self.running)


class Relaxation:
    """The temporal delete relaxation of a task (see the module docstring)."""

    def __init__(self, task: TemporalTask) -> None:
        n = len(task.facts)
        self.n = n
        self.ticks = [op.ticks for op in task.ops]
        self.pre = [op.relaxed_pre for op in task.ops]
        self.n_pre = [len(p) for p in self.pre]
        self.start_adds = [_ids(op.start.add) for op in task.ops]
        self.end_adds = [_ids(op.end.add) for op in task.ops]
        self.pre_of: list[list[int]] = [[] for _ in range(n)]
        for a, pre in enumerate(self.pre):
            for f in pre:
                self.pre_of[f].append(a)
        self.free = [a for a, pre in enumerate(self.pre) if not pre]
        self.goal = _ids(task.goal_pos)
        self.ops = task.ops
        self.objects = [frozenset(op.step.args) for op in task.ops]
        self._dependent: dict[tuple[int, int], bool] = {}
        self.achievers: list[list[tuple[int, bool]]] = [[] for _ in range(n)]
        for a in range(len(task.ops)):
            for f in self.start_adds[a]:
                self.achievers[f].append((a, False))
            for f in self.end_adds[a]:
                self.achievers[f].append((a, True))

    def evaluate(self, facts: int, running: Running, now: int) -> tuple[int, int, int, set[int]] | None:
        """``(h_time, scheduled, rp_sum, relaxed plan)`` (times in ticks from ``now``, the plan's action indices)
        from the node, or None when the relaxation cannot reach the goal."""
        time = [_INF] * self.n
        support = [-1] * self.n
        heap: list[tuple[int, int]] = []
        for f in _ids(facts):
            time[f] = 0
            heap.append((0, f))
        for end, a, _start in running:
            for f in self.end_adds[a]:
                if end - now < time[f]:
                    time[f] = end - now
                    heap.append((end - now, f))
        heap.sort()
        ticks, start_adds, end_adds, pre_of = self.ticks, self.start_adds, self.end_adds, self.pre_of
        unsat = self.n_pre[:]
        done = [False] * self.n
        left = sum(1 for g in self.goal if time[g] != 0)
        began = [-1] * len(ticks)

        def fire(a: int, t: int) -> None:
            began[a] = t
            for g in start_adds[a]:
                if t < time[g]:
                    time[g], support[g] = t, a
                    heappush(heap, (t, g))
            te = t + ticks[a]
            for g in end_adds[a]:
                if te < time[g]:
                    time[g], support[g] = te, a
                    heappush(heap, (te, g))

        for a in self.free:
            fire(a, 0)
        is_goal = set(self.goal)
        while heap and left:
            t, f = heappop(heap)
            if done[f] or t > time[f]:
                continue
            done[f] = True
            if f in is_goal and t != 0:
                left -= 1
            for a in pre_of[f]:
                unsat[a] -= 1
                if unsat[a] == 0:
                    fire(a, t)
        if left:
            return None
        h_time = max((time[g] for g in self.goal), default=0)
        rp_sum, chosen, via = self._extract(time, support, began)
        scheduled = self._schedule(chosen, via, time, began, running, now)
        return h_time, max(h_time, scheduled), rp_sum, chosen

    def _schedule(
        self,
        chosen: set[int],
        via: dict[int, tuple[int, bool]],
        time: list[int],
        began: list[int],
        running: Running,
        now: int,
    ) -> int:
        """When the relaxed plan ends when its dependent actions (those that may not overlap:
        :meth:`dependent`) run one after another, the running ones included: each action in the order of its
        relaxed start, after what it needs and after every dependent action placed before it."""
        ticks = self.ticks
        placed: list[tuple[int, int]] = [(end - now, i) for end, i, _start in running]
        finish = max((end for end, _i in placed), default=0)
        start_at: dict[int, int] = {}
        for a in sorted(chosen, key=lambda c: (began[c], c)):
            t = 0
            for f in self.pre[a]:
                by = via.get(f)
                if by is not None and by[0] in start_at:
                    t = max(t, start_at[by[0]] + (ticks[by[0]] if by[1] else 0))
                else:
                    t = max(t, time[f])
            for end, other in placed:
                if end > t and self.dependent(a, other):
                    t = end
            start_at[a] = t
            placed.append((t + ticks[a], a))
            finish = max(finish, t + ticks[a])
        return finish

    def dependent(self, a: int, b: int) -> bool:
        """Whether two actions may not overlap: a happening of one interferes with one of the other's, or
        changes what the other needs over all (the schedule's rule, :mod:`alica.prophet.temporal`)."""
        key = (a, b) if a < b else (b, a)
        hit = self._dependent.get(key)
        if hit is None:
            x, y = self.ops[a], self.ops[b]
            hit = a == b or any(h.interferes(k) for h in (x.start, x.end) for k in (y.start, y.end))
            for first, second in ((x, y), (y, x)):
                hit = hit or bool(
                    (first.start.delete | first.end.delete) & second.over_pos
                    or (first.start.add | first.end.add) & second.over_neg
                )
            self._dependent[key] = hit
        return hit

    def _extract(
        self, time: list[int], support: list[int], began: list[int]
    ) -> tuple[int, set[int], dict[int, tuple[int, bool]]]:
        """The relaxed plan back from the goal through the earliest supporters; among those reaching a fact
        equally early, one already in the plan, else the one sharing the fewest objects with the plan (so that
        work spreads over the agents: two rovers rather than one rover twice)."""
        ticks, objects, achievers = self.ticks, self.objects, self.achievers
        chosen: set[int] = set()
        used: set[str] = set()
        via: dict[int, tuple[int, bool]] = {}
        stack = list(reversed(self.goal))
        while stack:
            f = stack.pop()
            if support[f] < 0:
                continue
            t = time[f]
            candidates = [
                (a, at_end)
                for a, at_end in achievers[f]
                if began[a] >= 0 and began[a] + (ticks[a] if at_end else 0) == t
            ]
            a, at_end = min(candidates, key=lambda c: (c[0] not in chosen, len(objects[c[0]] & used), c[0]))
            if f not in via:
                via[f] = (a, at_end)
            if a not in chosen:
                chosen.add(a)
                used |= objects[a]
                stack.extend(reversed(self.pre[a]))
        return sum(ticks[a] for a in chosen), chosen, via


def _order(step: Pass, now: int, scored: tuple[int, int, int, set[int]]) -> tuple[float, int]:
    """A node's place in a pass's open list: ``now`` plus the weighted estimate, then the other estimate."""
    _lower, scheduled, work, _plan = scored
    if step.estimate is Estimate.WORK:
        return now + step.weight * work, scheduled
    return now + step.weight * scheduled, work


def _ids(mask: int) -> tuple[int, ...]:
    out: list[int] = []
    while mask:
        low = mask & -mask
        out.append(low.bit_length() - 1)
        mask ^= low
    return tuple(out)


def makespan_search(
    task: TemporalTask,
    *,
    anytime: bool = True,
    limits: Limits | None = None,
    bound: Bound | None = None,
    passes: tuple[Pass, ...] = MAKESPAN_PASSES,
    progress_every: int = PROGRESS_EVERY,
    on_plan: list[TimedResult] | None = None,
) -> Iterator[SearchEvent]:
    """The search (see the module docstring) as planner events.

    Args:
        task: the ground task.
        anytime: go on after the first plan (through all the passes).
        limits: the run's limits, checked every :data:`CHECK_EVERY` expansions.
        bound: the best makespan known, shared with another search (read for pruning, updated on each plan).
        passes: the passes (the last one should start any action: its exhausting the nodes is the proof).
        progress_every: expansions between two ``Progress`` events.
        on_plan: each plan found is appended here (the ``Improved`` event carries its steps and makespan).

    Raises:
        LimitReached: a limit of ``limits`` was reached.
    """
    bound = Bound() if bound is None else bound
    if task.unsolvable:
        yield Done(PlanStatus.UNSOLVABLE, 0, task.unsolvable)
        return
    search = _Search(task, limits, bound, max(1, progress_every), on_plan)
    proven = False  # a pass starting any action exhausted its nodes under the bound
    for step in passes:
        exhausted = yield from search.run(step, stop_at_plan=step.first_plan_only or not anytime)
        proven = exhausted and not step.helpful_only
        if proven or (search.found and not anytime):
            break
    if not search.found:
        why = "every node was expanded" if proven else "the passes ended"
        yield Done(PlanStatus.TIMEOUT, search.expansions, f"no plan with starts at the decision epochs ({why})")
    elif proven:
        yield Done(PlanStatus.SOLVED, search.expansions, "no shorter plan with starts at the decision epochs")
    else:
        yield Done(PlanStatus.SOLVED, search.expansions)


class _Search:
    def __init__(
        self,
        task: TemporalTask,
        limits: Limits | None,
        bound: Bound,
        progress_every: int,
        on_plan: list[TimedResult] | None,
    ) -> None:
        self.task = task
        self.ops = task.ops
        self.relax = Relaxation(task)
        self.limits = limits
        self.bound = bound
        self.progress_every = progress_every
        self.on_plan = on_plan
        self.expansions = 0
        self.found = False
        self.table_size = 0

    def run(self, step: Pass, *, stop_at_plan: bool) -> Generator[SearchEvent, None, bool]:
        """One pass; returns whether it exhausted its nodes under the bound (with every start, not only
        the helpful ones)."""
        task = self.task
        root = _Node(task.init, (), 0, 0, None, None)
        seen: dict[tuple[int, tuple[tuple[int, int, bool], ...]], int] = {root.key(): 0}
        heap: list[tuple[float, int, int, int, _Node, set[int]]] = []
        counter = 0
        if self._is_goal(root):
            yield from self._plan(root)
            return True
        scored = self._score(root)
        if scored is None:
            return True
        heappush(heap, (*_order(step, 0, scored), scored[0], counter, root, scored[3]))
        while heap:
            _f, _h, lower, _c, node, chosen = heappop(heap)
            if seen.get(node.key(), _INF) < node.now:
                continue
            best = self.bound.ticks
            if best is not None and lower >= best:
                continue
            self.expansions += 1
            if self.expansions % CHECK_EVERY == 0 and self.limits is not None:
                self.limits.check(
                    "searching for a short makespan", len(seen) * NODE_BYTES, f"{self.expansions} expansions"
                )
            if self.expansions % self.progress_every == 0:
                yield Progress(self.expansions)
            for child in self._successors(node, chosen if step.helpful_only else None):
                key = child.key()
                if seen.get(key, _INF) <= child.now:
                    continue
                seen[key] = child.now
                if self._is_goal(child):
                    if best is None or child.last < best:
                        yield from self._plan(child)
                        best = self.bound.ticks
                        if stop_at_plan:
                            return False
                    continue
                scored = self._score(child)
                if scored is None or (best is not None and scored[0] >= best):
                    continue
                counter -= 1  # among equals, the newest node first
                heappush(heap, (*_order(step, child.now, scored), scored[0], counter, child, scored[3]))
        return True

    def _score(self, node: _Node) -> tuple[int, int, int, set[int]] | None:
        """``(lower bound, scheduled, rp_sum, relaxed plan)``, or None on a relaxed dead end."""
        estimate = self.relax.evaluate(node.facts, node.running, node.now)
        if estimate is None:
            return None
        h_time, scheduled, rp_sum, chosen = estimate
        lower = max(node.last, node.now + h_time if h_time > 0 else 0)
        return lower, scheduled, rp_sum, chosen

    def _is_goal(self, node: _Node) -> bool:
        task = self.task
        return not node.running and node.facts & task.goal_pos == task.goal_pos and not node.facts & task.goal_neg

    def _plan(self, node: _Node) -> Iterator[SearchEvent]:
        starts: list[tuple[int, int]] = []
        at: _Node | None = node
        while at is not None:
            if at.started is not None:
                starts.append(at.started)
            at = at.parent
        starts.sort(key=lambda s: (s[1], s[0]))
        steps = tuple(TimedStep(round(start / TICKS, 6), self.ops[i].step, self.ops[i].duration) for i, start in starts)
        self.found = True
        self.bound.ticks = node.last
        result = TimedResult(TemporalPlan(steps), node.last)
        if self.on_plan is not None:
            self.on_plan.append(result)
        yield Improved(Plan(tuple(t.step for t in steps), round(node.last / TICKS, 6)), self.expansions)

    def _successors(self, node: _Node, helpful: set[int] | None) -> Iterator[_Node]:
        """The starts (of the ``helpful`` actions only, unless None) in the actions' order, then the advance."""
        facts, running, now = node.facts, node.running, node.now
        busy = {i for _e, i, _s in running}
        ops = self.ops
        for i in range(len(ops)) if helpful is None else sorted(helpful):
            op = ops[i]
            s = op.start
            if i in busy or facts & s.pos != s.pos or facts & s.neg:
                continue
            after = (facts & ~s.delete) | s.add
            if after & op.over_pos != op.over_pos or after & op.over_neg:
                continue
            end = now + op.ticks
            if not self._fits(op.start, op.end, now, end, running, after):
                continue
            grown = tuple(sorted((*running, (end, i, now))))
            yield _Node(after, grown, now, max(node.last, end), node, (i, now))
        advanced = self._advance(node)
        if advanced is not None:
            yield advanced

    def _fits(self, start: Happening, end_h: Happening, now: int, end: int, running: Running, after: int) -> bool:
        ops = self.ops
        for r_end, r, r_start in running:
            other = ops[r]
            if after & other.over_pos != other.over_pos or after & other.over_neg:
                return False
            if now - r_start < EPSILON_TICKS and other.start.interferes(start):
                return False
            if abs(r_end - now) < EPSILON_TICKS and other.end.interferes(start):
                return False
            if abs(r_end - end) < EPSILON_TICKS and other.end.interferes(end_h):
                return False
            if abs(r_start - end) < EPSILON_TICKS and other.start.interferes(end_h):
                return False
        return True

    def _advance(self, node: _Node) -> _Node | None:
        running = node.running
        if not running:
            return None
        facts = node.facts
        limit = running[0][0] + EPSILON_TICKS
        k = 0
        while k < len(running) and running[k][0] < limit:
            end, i, _start = running[k]
            happening = self.ops[i].end
            if facts & happening.pos != happening.pos or facts & happening.neg:
                return None
            facts = (facts & ~happening.delete) | happening.add
            k += 1
            for _e, j, _s in running[k:]:
                other = self.ops[j]
                if facts & other.over_pos != other.over_pos or facts & other.over_neg:
                    return None
            limit = end + EPSILON_TICKS
        last_end = running[k - 1][0]
        return _Node(facts, running[k:], last_end + EPSILON_TICKS, node.last, node, None)


__all__ = ["MAKESPAN_PASSES", "Bound", "Estimate", "Pass", "Relaxation", "TimedResult", "makespan_search"]
