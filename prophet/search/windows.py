"""Window replanning: a cheaper stretch of the plan, searched among the window's own objects.

For a window ``plan[i:j]``, the facts the rest of the plan needs are regressed
from the goal through ``plan[j:]``; any state holding them lets the rest of
the plan run to the goal (exactly so for STRIPS; every spliced plan is
checked by simulation anyway). A uniform-cost search from the plan's state
before ``i`` then looks for a cheaper way to reach those facts, using only
the operators whose arguments are all objects the window's actions mention:
a small space, searched exhaustively up to a state limit.

Before the windows slide over it, the plan is reordered: deordered into the
partial order of its interfering action pairs, then linearised so that an
action follows one that shares the most objects with it. Stretches of one
rover's (one agent's) work then come together, so a window holds a whole
errand rather than pieces of several.
"""

from __future__ import annotations

from collections.abc import Generator, Sequence
from heapq import heappop, heappush

from alica.prophet.planner import Progress
from alica.prophet.search.encoding import AxiomTask, CompiledTask, bits
from alica.prophet.search.gbfs import Stats, trace

WINDOW_SIZES: tuple[int, ...] = (6, 10, 16, 24, 32)
"""The window lengths tried, shortest first."""
WINDOW_STATES = 3000
"""The most states one window search expands."""
QUICK_WINDOW_STATES = 300
"""The state limit of the quick sweeps (on every new plan, before the full ones)."""


class Windows:
    """Window replanning on one compiled task (indexes built once).

    Args:
        ct: the compiled task.
    """

    def __init__(self, ct: CompiledTask) -> None:
        self.ct = ct
        operators = ct.task.operators
        self.objects: list[frozenset[str]] = [frozenset(operators[s].args) for s in ct.source]
        by_object: dict[str, list[int]] = {}
        no_args: list[int] = []
        for op, objs in enumerate(self.objects):
            if not objs:
                no_args.append(op)
            for name in objs:
                by_object.setdefault(name, []).append(op)
        self.by_object = by_object
        self.no_args = no_args
        self.exact = not any(ct.cond) and not (
            isinstance(ct, AxiomTask) and ct.axioms
        )  # derived facts: no swap analysis
        self._deletes: dict[int, list[int]] = {}
        """Per operator met so far, the facts it deletes (and does not add)."""
        self.failed: dict[tuple[int, int, frozenset[str]], tuple[int, int]] = {}
        """Window searches that found nothing: (start, needed facts, objects) -> (bound, state limit)."""

    def operators_among(self, objects: frozenset[str]) -> list[int]:
        """The operators whose arguments are all in ``objects`` (increasing ids)."""
        found = set(self.no_args)
        own = self.objects
        for name in objects:
            for op in self.by_object.get(name, ()):
                if op not in found and own[op] <= objects:
                    found.add(op)
        return sorted(found)

    # ------------------------------------------------------------ reordering
    def interferes(self, a: int, b: int) -> bool:
        """Whether operators ``a`` and ``b`` may not swap places (one needs, adds or deletes what the other touches)."""
        ct = self.ct
        pa, aa, da = ct.pre_mask[a], ct.add_mask[a], ct.del_mask[a]
        pb, ab, db = ct.pre_mask[b], ct.add_mask[b], ct.del_mask[b]
        return bool(aa & pb or da & pb or pa & db or aa & db or da & ab or ct.cond[a] or ct.cond[b])

    def regroup(self, plan: Sequence[int]) -> list[int]:
        """The plan reordered so that actions sharing objects come together (a valid reordering).

        Only pairs of non-interfering actions change their relative order, so the
        result reaches the same final state. Ties go to the earlier action.
        """
        n = len(plan)
        succ: list[list[int]] = [[] for _ in range(n)]
        waiting = [0] * n
        if any(self.ct.cond[op] for op in plan):  # a conditional effect may touch anything
            for j in range(n):
                for i in range(j):
                    if self.interferes(plan[i], plan[j]):
                        succ[i].append(j)
                        waiting[j] += 1
        else:
            self._interfering_pairs(plan, succ, waiting)
        ready = [j for j in range(n) if not waiting[j]]
        order: list[int] = []
        last: frozenset[str] = frozenset()
        objects = self.objects
        while ready:
            best = max(ready, key=lambda k: (len(objects[plan[k]] & last), -k))
            ready.remove(best)
            order.append(plan[best])
            last = objects[plan[best]]
            for k in succ[best]:
                waiting[k] -= 1
                if not waiting[k]:
                    ready.append(k)
        return order

    def _deleted(self, op: int) -> list[int]:
        """The facts ``op`` deletes (and does not add)."""
        dels = self._deletes.get(op)
        if dels is None:
            dels = self._deletes[op] = bits(self.ct.del_mask[op])
        return dels

    def _interfering_pairs(self, plan: Sequence[int], succ: list[list[int]], waiting: list[int]) -> None:
        """The pairs :meth:`interferes` finds, through the facts the actions touch (no pair of positions is
        tried unless they share a fact): ``succ[i]`` gets each later ``j`` in order, ``waiting[j]`` counts them.
        """
        ct = self.ct
        changes: dict[int, list[int]] = {}  # fact -> the positions adding or deleting it
        needs_or_adds: dict[int, list[int]] = {}
        deletes: dict[int, list[int]] = {}
        for j, op in enumerate(plan):
            dels = self._deleted(op)
            before: set[int] = set()
            for f in ct.pre[op]:  # an earlier action adds or deletes what this one needs
                before.update(changes.get(f, ()))
            for f in dels:  # ... needs or adds what this one deletes
                before.update(needs_or_adds.get(f, ()))
            for f in ct.add[op]:  # ... deletes what this one adds
                before.update(deletes.get(f, ()))
            for i in sorted(before):
                succ[i].append(j)
            waiting[j] = len(before)
            for f in ct.pre[op]:
                needs_or_adds.setdefault(f, []).append(j)
            for f in ct.add[op]:
                changes.setdefault(f, []).append(j)
                needs_or_adds.setdefault(f, []).append(j)
            for f in dels:
                changes.setdefault(f, []).append(j)
                deletes.setdefault(f, []).append(j)

    # ---------------------------------------------------------------- windows
    def needs(self, plan: Sequence[int]) -> list[int]:
        """Per position ``k``, the facts (mask) a state needs for ``plan[k:]`` to reach the goal."""
        ct = self.ct
        need = ct.goal_mask
        out = [need]
        for op in reversed(plan):
            need = (need & ~ct.add_mask[op]) | ct.pre_mask[op]
            out.append(need)
        out.reverse()
        return out

    def valid(self, plan: Sequence[int]) -> bool:
        """Whether ``plan`` is applicable from the initial state and reaches the goal."""
        ct = self.ct
        state = ct.init
        for op in plan:
            m = ct.pre_mask[op]
            if state & m != m:
                return False
            state = ct.successor(state, op)
        return ct.is_goal(state)

    def search(
        self, start: int, need: int, ops: Sequence[int], bound: int, limit: int, stats: Stats
    ) -> Generator[Progress, None, list[int] | None]:
        """A* from ``start`` to a state holding ``need``, cheaper than ``bound``, with ``ops`` only.

        The estimate is the number of missing ``need`` facts over the most of them
        one operator adds, times the cheapest operator cost (admissible).
        """
        ct = self.ct
        pre_facts = [ct.pre[o] for o in ops]
        if self.exact:
            # the search on the facts the window's operators touch, as a small bitset: nothing else
            # changes in it (and the rest of ``need`` already holds at ``start``, as the window's own
            # actions reach it from there), so the states, their order and the result are the same
            touched = sorted({f for o in ops for f in (*ct.pre[o], *ct.add[o], *self._deleted(o))})
            slot = {f: i for i, f in enumerate(touched)}

            def small(facts: Sequence[int]) -> int:
                m = 0
                for f in facts:
                    m |= 1 << slot[f]
                return m

            outside = need
            for f in touched:
                outside &= ~(1 << f)
            if start & outside != outside:
                return None
            start = sum(1 << i for i, f in enumerate(touched) if start >> f & 1)
            need = sum(1 << i for i, f in enumerate(touched) if need >> f & 1)
            pre_facts = [tuple(slot[f] for f in facts) for facts in pre_facts]
            pre = [small(ct.pre[o]) for o in ops]
            adds = [small(ct.add[o]) for o in ops]
            dels = [small(self._deleted(o)) for o in ops]
        else:
            pre = [ct.pre_mask[o] for o in ops]
            adds = [ct.add_mask[o] for o in ops]
            dels = []
        cost = [ct.cost[o] for o in ops]
        most = max([(a & need).bit_count() for a in adds], default=0)
        if not most:
            return [] if start & need == need else None
        cheapest = min(cost, default=0)
        # each operator watched by its precondition the fewest others share: a state tries only the operators
        # whose watched fact it holds (taken in increasing k, so the search is the same as trying them all)
        uses: dict[int, int] = {}
        for facts in pre_facts:
            for f in facts:
                uses[f] = uses.get(f, 0) + 1
        watch: dict[int, list[int]] = {}
        free: list[int] = []
        for k, facts in enumerate(pre_facts):
            if facts:
                watch.setdefault(min(facts, key=lambda f: (uses[f], f)), []).append(k)
            else:
                free.append(k)
        watched = list(watch.items())
        successor = ct.successor
        dist = {start: 0}
        parent: dict[int, tuple[int, int]] = {start: (-1, -1)}
        heap = [(0, 0, 0, start)]
        count = 0
        expanded = 0
        while heap:
            _f, _n, g, state = heappop(heap)
            if dist[state] < g:
                continue
            if state & need == need:
                return trace(parent, state)
            expanded += 1
            if expanded > limit:
                return None
            stats.expansions += 1
            if stats.progress_due():
                yield Progress(stats.expansions)
            tried = list(free)
            groups = 0
            for f, ks in watched:
                if state >> f & 1:
                    tried += ks
                    groups += 1
            if groups > 1 or (groups and free):
                tried.sort()
            for k in tried:
                m = pre[k]
                if state & m != m:
                    continue
                o = ops[k]
                g2 = g + cost[k]
                if g2 >= bound:
                    continue
                nxt = (state & ~dels[k]) | adds[k] if dels else successor(state, o)
                old = dist.get(nxt)
                if old is not None and old <= g2:
                    continue
                f2 = g2 + -(-(need & ~nxt).bit_count() // most) * cheapest
                if f2 >= bound:
                    continue
                dist[nxt] = g2
                parent[nxt] = (state, o)
                count += 1
                heappush(heap, (f2, count, g2, nxt))
        return None

    def improve_once(
        self, plan: list[int], stats: Stats, sizes: Sequence[int] = WINDOW_SIZES, limit: int = WINDOW_STATES
    ) -> Generator[Progress, None, list[int] | None]:
        """The first cheaper plan one sweep of windows finds (shortest windows first), or ``None``."""
        ct = self.ct
        plan = self.regroup(plan) if self.exact else list(plan)
        states = [ct.init]
        for op in plan:
            states.append(ct.successor(states[-1], op))
        needs = self.needs(plan)
        cost = ct.cost
        tried: set[tuple[int, int]] = set()
        n = len(plan)
        for size in sizes:
            size = min(size, n)
            step = max(1, size // 3)
            for i in range(0, max(1, n - size + step), step):
                j = min(n, i + size)
                if (i, j) in tried:
                    continue
                tried.add((i, j))
                window = plan[i:j]
                bound = sum(cost[o] for o in window)
                if bound <= 0:
                    continue
                objects = frozenset().union(*(self.objects[o] for o in window))
                key = (states[i], needs[j], objects)
                old_bound, old_limit = self.failed.get(key, (-1, -1))
                if old_bound >= bound and old_limit >= limit:
                    continue  # the same search already failed with a looser bound and as many states
                ops = self.operators_among(objects)
                found = yield from self.search(states[i], needs[j], ops, bound, limit, stats)
                if found is None:
                    self.failed[key] = (bound, limit)
                    continue
                candidate = plan[:i] + found + plan[j:]
                if self.valid(candidate):
                    return candidate
            if size == n:
                break
        return None
