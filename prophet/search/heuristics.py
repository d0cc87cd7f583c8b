"""Delete-relaxation heuristics over a :class:`~alica.prophet.search.encoding.CompiledTask`.

Every operator is one relaxed action (its fluent preconditions and adds);
every when-effect is one more, with the effect's condition added to the
preconditions. The explorations count unsatisfied preconditions per relaxed
action in flat lists copied from templates, so one evaluation does no
dictionary look-ups and allocates only a few lists.

Each evaluator maps a state to ``(h, preferred)``: ``h`` is ``INF`` on a
relaxed dead end, ``preferred`` lists the compiled operators the FF
heuristics call helpful (operators of the relaxed plan applicable in the
state), empty for the other heuristics.
"""

from __future__ import annotations

from collections.abc import Callable
from heapq import heappop, heappush

from alica.prophet.search.encoding import AxiomTask, CompiledTask, mask

INF = float("inf")

Evaluator = Callable[[int], tuple[float, list[int]]]
"""A heuristic: state -> (estimate or INF, preferred operators)."""


class Relaxed:
    """The relaxed task of a compiled task, and the heuristics computed on it.

    Args:
        ct: the compiled task.
    """

    def __init__(self, ct: CompiledTask) -> None:
        r_pre: list[tuple[int, ...]] = []
        r_add: list[tuple[int, ...]] = []
        r_cost: list[int] = []
        r_op: list[int] = []
        for op in range(len(ct.pre)):
            r_pre.append(ct.pre[op])
            r_add.append(ct.add[op])
            r_cost.append(ct.cost[op])
            r_op.append(op)
            for cond, cadd, _cdel in ct.cond_raw[op]:
                r_pre.append(tuple(sorted(set(ct.pre[op]) | set(cond))))
                r_add.append(cadd)
                r_cost.append(ct.cost[op])
                r_op.append(op)
        for head, pos in ct.relaxed_axioms if isinstance(ct, AxiomTask) else ():  # derived facts: free, never preferred
            r_pre.append(pos)
            r_add.append((head,))
            r_cost.append(0)
            r_op.append(-1)
        n = ct.n_facts
        pre_of: list[list[int]] = [[] for _ in range(n)]
        multi_of: list[list[int]] = [[] for _ in range(n)]
        unary_of: list[list[tuple[int, int]]] = [[] for _ in range(n)]
        for a, p in enumerate(r_pre):
            for f in p:
                pre_of[f].append(a)
                if len(p) > 1:
                    multi_of[f].append(a)
            if len(p) == 1:
                unary_of[p[0]].extend((g, a) for g in r_add[a])
        self.multi_of = multi_of
        self.unary_of = unary_of
        self.goal_mask = ct.goal_mask
        self.r_pre = r_pre
        self.r_add = r_add
        self.r_cost = r_cost
        self.r_op = r_op
        self.r_unit = [1 if op >= 0 else 0 for op in r_op]
        self.has_rules = 0 in self.r_unit
        """Whether some relaxed actions are derived-predicate rules (``r_op`` -1, free)."""
        self.r_pre_mask = [mask(p) for p in r_pre]
        self.pre_of = pre_of
        self.zero = [a for a, p in enumerate(r_pre) if not p]
        self.is_goal = [False] * n
        for f in range(n):
            if ct.goal_mask >> f & 1:
                self.is_goal[f] = True
        self._npre = [len(p) for p in r_pre]
        self._neg = [-1] * n
        self._inf = [INF] * n
        self._zero_a: list[float] = [0] * len(r_pre)

    # ------------------------------------------------------------------ FF
    def ff(self, state: int) -> tuple[float, list[int]]:
        """FF with h_max (first-layer) supporters, plan length as the estimate."""
        return self._ff_layered(state, True)

    def ff_cost(self, state: int) -> tuple[float, list[int]]:
        """FF with h_add supporters, the relaxed plan's cost as the estimate."""
        return self._ff_add(state, False)

    def ff_add_unit(self, state: int) -> tuple[float, list[int]]:
        """FF with h_add supporters, the relaxed plan's length as the estimate."""
        return self._ff_add(state, True)

    def ff_unit(self, state: int) -> tuple[float, list[int]]:
        """FF with h_add supporters as if every action cost 1, the relaxed plan's length as the estimate.

        LAMA's FF (``adapt_costs(one)``); the same as :meth:`ff_add_unit` on a task
        whose relaxed actions all cost 1. With every cost 1 the exploration needs
        no heap: the facts of cost ``c`` are all known once those of cost ``c - 1``
        are done, and taking each level in increasing fact ids keeps the heap's
        order (and so its supporters) exactly, 1.2-1.5x faster.
        """
        gm = self.goal_mask
        if state & gm == gm:
            return 0, []
        if self.has_rules:  # derived-predicate rules are free: costs 0 and 1 need the heap
            explored, sup = self._explore_add(state, True, self.r_unit)
            return (INF, []) if explored is None else self._extract(state, sup, True)
        pre_of = self.pre_of
        r_add = self.r_add
        is_goal = self.is_goal
        cost: list = self._inf[:]
        sup = self._neg[:]
        unsat = self._npre[:]
        acc = self._zero_a[:]
        goals_left = (gm & ~state).bit_count()
        level: list[int] = []
        s = state
        while s:
            low = s & -s
            f = low.bit_length() - 1
            cost[f] = 0
            level.append(f)
            s ^= low
        buckets: dict[float, list[int]] = {}
        for a in self.zero:
            for g in r_add[a]:
                if 1 < cost[g]:
                    cost[g] = 1
                    sup[g] = a
                    buckets.setdefault(1, []).append(g)
        c: float = 0
        while True:
            for f in level:
                if cost[f] != c:
                    continue
                if is_goal[f] and not state >> f & 1:
                    goals_left -= 1
                    if not goals_left:
                        return self._extract(state, sup, True)
                for a in pre_of[f]:
                    n = unsat[a] - 1
                    unsat[a] = n
                    acc[a] += c
                    if not n:
                        ac = acc[a] + 1
                        for g in r_add[a]:
                            if ac < cost[g]:
                                cost[g] = ac
                                sup[g] = a
                                bucket = buckets.get(ac)
                                if bucket is None:
                                    buckets[ac] = [g]
                                else:
                                    bucket.append(g)
            if not buckets:
                return INF, []
            c = min(buckets)
            level = sorted(buckets.pop(c))

    def _ff_layered(self, state: int, unit: bool) -> tuple[float, list[int]]:
        gm = self.goal_mask
        if state & gm == gm:
            return 0, []
        multi_of = self.multi_of
        unary_of = self.unary_of
        r_add = self.r_add
        is_goal = self.is_goal
        level = self._neg[:]
        sup = self._neg[:]
        unsat = self._npre[:]
        frontier: list[int] = []
        s = state
        while s:
            low = s & -s
            f = low.bit_length() - 1
            level[f] = 0
            frontier.append(f)
            s ^= low
        goals_left = (gm & ~state).bit_count()
        ready = list(self.zero)
        layer = 0
        while True:
            layer += 1
            nxt: list[int] = []
            # Actions with one precondition fire straight from the frontier.
            for f in frontier:
                for g, a in unary_of[f]:
                    if level[g] < 0:
                        level[g] = layer
                        sup[g] = a
                        nxt.append(g)
                        if is_goal[g]:
                            goals_left -= 1
                for a in multi_of[f]:
                    c = unsat[a] - 1
                    unsat[a] = c
                    if not c:
                        ready.append(a)
            for a in ready:
                for g in r_add[a]:
                    if level[g] < 0:
                        level[g] = layer
                        sup[g] = a
                        nxt.append(g)
                        if is_goal[g]:
                            goals_left -= 1
            if not goals_left:
                break
            if not nxt:
                return INF, []
            frontier = nxt
            ready = []
        return self._extract(state, sup, unit)

    def _extract(self, state: int, sup: list[int], unit: bool) -> tuple[float, list[int]]:
        """Relaxed plan extraction from the goals through the supporters ``sup``."""
        r_pre = self.r_pre
        r_cost = self.r_cost
        r_op = self.r_op
        r_unit = self.r_unit
        r_pre_mask = self.r_pre_mask
        used = bytearray(len(r_pre))
        done = bytearray(len(sup))
        s = state
        while s:
            low = s & -s
            done[low.bit_length() - 1] = 1
            s ^= low
        h = 0
        preferred: list[int] = []
        stack: list[int] = []
        s = self.goal_mask & ~state
        while s:
            low = s & -s
            stack.append(low.bit_length() - 1)
            s ^= low
        while stack:
            g = stack.pop()
            if done[g]:
                continue
            done[g] = 1
            a = sup[g]
            if used[a]:
                continue
            used[a] = 1
            h += r_unit[a] if unit else r_cost[a]
            m = r_pre_mask[a]
            if state & m == m:
                op = r_op[a]
                if op >= 0 and op not in preferred:
                    preferred.append(op)
            for p in r_pre[a]:
                if not done[p]:
                    stack.append(p)
        return h, preferred

    def _ff_add(self, state: int, unit: bool) -> tuple[float, list[int]]:
        gm = self.goal_mask
        if state & gm == gm:
            return 0, []
        cost, sup = self._explore_add(state, True)
        if cost is None:
            return INF, []
        return self._extract(state, sup, unit)

    def _explore_add(self, state: int, additive: bool, costs: list[int] | None = None) -> tuple[list | None, list[int]]:
        """Generalised Dijkstra for h_add (``additive``) or h_max; costs per fact, supporters.

        ``costs``: the relaxed actions' costs (default: their own).
        """
        pre_of = self.pre_of
        r_add = self.r_add
        r_cost = self.r_cost if costs is None else costs
        is_goal = self.is_goal
        gm = self.goal_mask
        cost: list = self._inf[:]
        sup = self._neg[:]
        unsat = self._npre[:]
        acc = self._zero_a[:]
        heap: list[tuple[float, int]] = []
        goals_left = (gm & ~state).bit_count()
        s = state
        while s:
            low = s & -s
            f = low.bit_length() - 1
            cost[f] = 0
            heap.append((0, f))
            s ^= low
        for a in self.zero:
            c: float = r_cost[a]
            for g in r_add[a]:
                if c < cost[g]:
                    cost[g] = c
                    sup[g] = a
                    heappush(heap, (c, g))
        while heap:
            c, f = heappop(heap)
            if c != cost[f]:
                continue
            if is_goal[f] and not state >> f & 1:
                goals_left -= 1
                if not goals_left:
                    return cost, sup
            for a in pre_of[f]:
                n = unsat[a] - 1
                unsat[a] = n
                if additive:
                    acc[a] += c
                elif c > acc[a]:
                    acc[a] = c
                if not n:
                    ac = acc[a] + r_cost[a]
                    for g in r_add[a]:
                        if ac < cost[g]:
                            cost[g] = ac
                            sup[g] = a
                            heappush(heap, (ac, g))
        if goals_left:
            return None, sup
        return cost, sup

    # ------------------------------------------------------- other estimates
    def h_add(self, state: int) -> tuple[float, list[int]]:
        """The additive heuristic (sum of the goals' relaxed costs)."""
        return self._goal_costs(state, additive=True)

    def h_max(self, state: int) -> tuple[float, list[int]]:
        """The admissible max heuristic (the costliest goal's relaxed cost)."""
        return self._goal_costs(state, additive=False)

    def _goal_costs(self, state: int, additive: bool) -> tuple[float, list[int]]:
        gm = self.goal_mask
        if state & gm == gm:
            return 0, []
        cost, _sup = self._explore_add(state, additive)
        if cost is None:
            return INF, []
        goals = (c for f, c in enumerate(cost) if self.is_goal[f])
        return (sum(goals) if additive else max(goals)), []

    def goal_count(self, state: int) -> tuple[float, list[int]]:
        """The number of unsatisfied goals (INF on a relaxed dead end is not detected)."""
        return (self.goal_mask & ~state).bit_count(), []
