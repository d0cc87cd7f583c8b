"""Fact landmarks with orderings, and LAMA's landmark-count heuristic.

A *fact landmark* is a fact that every plan makes true at some point. The
landmarks here are the causal landmarks of the delete relaxation from the
initial state, found by Zhu and Givan's label propagation over the relaxed
actions of :class:`~alica.prophet.search.heuristics.Relaxed` (operators,
when-effects, and any zero-cost axioms alike): the label of a fact is the set
of facts every relaxed path to it achieves first,

    label(f) = {f} | AND over the relaxed actions a adding f of (OR over p in pre(a) of label(p)),

with ``label(f) = {f}`` for the facts of the initial state, computed to a
fixpoint (labels only shrink once a fact is reached). The landmarks are the
union of the goals' labels. Every plan is a relaxed plan, so each landmark
holds at some point of every plan; this is complete for the causal fact
landmarks of the relaxation (LAMA's RHW backchaining finds a subset of
these, plus disjunctive ones). Labels are ``int`` bitsets, so a union is
``|`` and an intersection ``&``.

Disjunctive landmarks, RHW's way: when every possible first achiever of a
landmark (one whose preconditions' labels hold none of its facts) has a
precondition of one predicate, those preconditions together (2 to
:data:`MAX_DISJUNCTION` facts, none true initially, none a fact landmark)
are a disjunctive landmark, greedy-necessary before it; the search goes on
backwards from each new one (at most :data:`MAX_DISJUNCTIVE_PER_FACT_LANDMARK`
per fact landmark). The label propagation already holds every fact such
backchaining could find.

Orderings: ``l`` in ``label(f)`` with ``l != f`` is a *natural* ordering
(``l`` is true strictly before ``f`` first is, in every plan); ``l`` is a
*greedy-necessary* predecessor of ``f`` when ``l`` is a precondition of every
relaxed action that can first achieve ``f`` (one whose preconditions' labels
do not hold ``f``); *reasonable* orderings come from the task's mutex groups
(:meth:`Landmarks.add_reasonable`).

The heuristic (LAMA's landmark count) follows the landmarks a search path
has *accepted*: those true in the initial state, then each landmark the
moment it becomes true while its natural predecessors are all accepted
already (the parent's accepted set). A state's estimate is the cost of the
landmarks not accepted plus those *required again*: accepted, false now, and
a goal or a greedy-necessary predecessor of a landmark not accepted, and the
accepted ones with a reasonable predecessor not accepted yet (they will have
to be reached again after it, as in Fast Downward's landmark count). With
``unit`` every landmark counts 1 (LAMA's first search); otherwise each costs
its cheapest achiever (the cost-sum variant). Its preferred operators are
the applicable operators that achieve a fact landmark the state needs and
whose natural predecessors are accepted, or else a fact of a needed
disjunctive landmark (as LAMA's). A disjunctive landmark is accepted once one
of its facts holds, and required again as a greedy-necessary one.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence

from alica.prophet.search.encoding import CompiledTask, bits
from alica.prophet.search.heuristics import Relaxed
from alica.prophet.search.mutexes import Mutexes, mutex_groups

MAX_DISJUNCTION = 4
"""The most facts of a disjunctive landmark (as LAMA's)."""
CACHE_SIZE = 100_000
"""The most accepted sets whose live landmarks the count keeps (then it starts again)."""
MAX_DISJUNCTIVE_PER_FACT_LANDMARK = 2
"""At most this many disjunctive landmarks per fact landmark (a bound on the backchaining)."""


def fact_labels(
    n_facts: int, init: int, r_pre: Sequence[Sequence[int]], r_add: Sequence[Sequence[int]]
) -> list[int | None]:
    """Zhu and Givan's labels (see the module docstring): per fact, a bitset, or ``None`` if unreachable."""
    label: list[int | None] = [None] * n_facts
    pre_of: list[list[int]] = [[] for _ in range(n_facts)]
    unreached = [len(p) for p in r_pre]
    for a, p in enumerate(r_pre):
        for f in p:
            pre_of[f].append(a)
    queue: deque[int] = deque()
    for f in bits(init):
        label[f] = 1 << f
        queue.append(f)

    def fire(a: int) -> None:
        alabel = 0
        for p in r_pre[a]:
            alabel |= label[p]  # type: ignore[operator]  # every precondition is reached
        for g in r_add[a]:
            old = label[g]
            new = (1 << g) | alabel if old is None else old & ((1 << g) | alabel)
            if new != old:
                label[g] = new
                queue.append(g)

    for a, p in enumerate(r_pre):
        if not p:
            fire(a)
    first = [True] * n_facts
    while queue:
        f = queue.popleft()
        for a in pre_of[f]:
            if first[f]:
                unreached[a] -= 1
            if not unreached[a]:
                fire(a)
        first[f] = False
    return label


class Landmarks:
    """The fact landmarks of a relaxed task and their orderings (disjunctive landmarks too, given the facts' names).

    Attributes:
        mask: the landmarks as a fact bitset.
        parents: per fact, its natural predecessors among the landmarks (a bitset; 0 if none).
        reasonable: per fact, its reasonable predecessors (a bitset; see :meth:`add_reasonable`).
        gn_children: per fact, the landmarks it is a greedy-necessary predecessor of (a bitset).
        cost: per fact, its cheapest relaxed achiever's cost (0 for facts nothing adds).
        goal_mask: the (fluent) goal facts.
        disjunctive: the disjunctive landmarks, as fact bitsets (only with ``facts``).
        disjunctive_children: per disjunctive landmark, the landmarks it is a greedy-necessary
            predecessor of, as landmark ids (a fact, or ``n_facts + k`` for disjunctive landmark ``k``).
        disjunctive_cost: per disjunctive landmark, its cheapest relaxed achiever's cost.

    Args:
        relaxed: the relaxed task.
        init: the initial state.
        facts: the facts' names ``(predicate args...)``; with them, disjunctive landmarks too.
    """

    def __init__(self, relaxed: Relaxed, init: int, facts: Sequence[str] | None = None) -> None:
        n = len(relaxed.is_goal)
        label = fact_labels(n, init, relaxed.r_pre, relaxed.r_add)
        goal = relaxed.goal_mask
        lms = 0
        for g in bits(goal):
            lms |= label[g] or 0
        self.mask = lms
        self.goal_mask = goal
        self.parents = [0] * n
        self.reasonable = [0] * n
        self.gn_children = [0] * n
        self.cost = [0] * n
        self.reachable = all(label[g] is not None for g in bits(goal))
        r_pre_mask = relaxed.r_pre_mask
        shared = [-1] * n
        first: list[list[int]] = [[] for _ in range(n)]
        cheapest: list[float] = [float("inf")] * n
        for a, adds in enumerate(relaxed.r_add):
            if any(label[p] is None for p in relaxed.r_pre[a]):
                continue
            alabel = 0
            for p in relaxed.r_pre[a]:
                alabel |= label[p] or 0
            for g in adds:
                if relaxed.r_cost[a] < cheapest[g]:
                    cheapest[g] = relaxed.r_cost[a]
                if not lms >> g & 1:
                    continue
                if not alabel >> g & 1:  # a possible first achiever of g
                    shared[g] &= r_pre_mask[a]
                    first[g].append(a)
        for f in bits(lms):
            self.parents[f] = (label[f] or 0) & ~(1 << f) & lms
            self.cost[f] = 0 if cheapest[f] == float("inf") else int(cheapest[f])
            if shared[f] != -1 and not init >> f & 1:
                for p in bits(shared[f] & lms):
                    self.gn_children[p] |= 1 << f
        self.gn_parents_mask = 0
        for f in bits(lms):
            if self.gn_children[f]:
                self.gn_parents_mask |= 1 << f
        self.disjunctive: list[int] = []
        self.disjunctive_children: list[int] = []
        self.disjunctive_cost: list[int] = []
        if facts is not None:
            self._disjunctive(relaxed, init, facts, first, label, cheapest)

    def _disjunctive(
        self,
        relaxed: Relaxed,
        init: int,
        facts: Sequence[str],
        first: list[list[int]],
        label: list[int | None],
        cheapest: list[float],
    ) -> None:
        """Disjunctive landmarks, backchained from the fact landmarks and from each other (see the module docstring)."""
        n = len(label)
        pred = [name.strip("()").split(" ", 1)[0] for name in facts]
        lms = self.mask
        r_pre = relaxed.r_pre
        alabel: dict[int, int] = {}
        adders: list[list[int]] = [[] for _ in range(n)]
        for a, adds in enumerate(relaxed.r_add):
            if any(label[p] is None for p in r_pre[a]):
                continue
            m = 0
            for p in r_pre[a]:
                m |= label[p] or 0
            alabel[a] = m
            for g in adds:
                adders[g].append(a)
        index: dict[int, int] = {}
        used = 0
        cap = MAX_DISJUNCTIVE_PER_FACT_LANDMARK * max(1, lms.bit_count())
        todo: list[tuple[list[int], int]] = [(first[f], 1 << f) for f in bits(lms & ~init)]
        while todo:
            achievers, child = todo.pop(0)
            if not achievers:
                continue
            union: dict[str, int] = {}
            count: dict[str, int] = {}
            for a in achievers:
                mine: dict[str, int] = {}
                for p in r_pre[a]:
                    mine[pred[p]] = mine.get(pred[p], 0) | 1 << p
                for name, m in mine.items():
                    union[name] = union.get(name, 0) | m
                    count[name] = count.get(name, 0) + 1
            for name, m in union.items():
                if count[name] != len(achievers) or m & (lms | init) or not 2 <= m.bit_count() <= MAX_DISJUNCTION:
                    continue
                if any(label[p] is None for p in bits(m)):
                    continue
                k = index.get(m)
                if k is None:
                    if len(self.disjunctive) >= cap or m & used:  # a fact is in one disjunctive landmark at most
                        continue
                    used |= m
                    k = index[m] = len(self.disjunctive)
                    self.disjunctive.append(m)
                    self.disjunctive_children.append(0)
                    self.disjunctive_cost.append(int(min(cheapest[p] for p in bits(m))))
                    # its own possible first achievers: those whose preconditions need none of its facts first
                    own = sorted({a for p in bits(m) for a in adders[p] if not alabel[a] & m})
                    todo.append((own, 1 << (n + k)))
                self.disjunctive_children[k] |= child

    def __len__(self) -> int:
        return self.mask.bit_count() + len(self.disjunctive)

    def orderings(self) -> list[tuple[int, int]]:
        """The natural orderings ``(before, after)`` between landmarks."""
        return [(p, f) for f in bits(self.mask) for p in bits(self.parents[f])]

    def greedy_necessary(self) -> list[tuple[int, int]]:
        """The greedy-necessary orderings ``(before, after)`` between landmarks."""
        return [(p, f) for p in bits(self.gn_parents_mask) for f in bits(self.gn_children[p])]

    def add_reasonable(self, ct: CompiledTask, mutexes: Mutexes) -> None:
        """Reasonable orderings between fact landmarks, as LAMA's (Hoffmann, Porteous and Sebastia's rules).

        ``a`` *interferes* with ``b`` when they are mutex, when every operator adding ``a`` deletes
        ``b`` or adds a fact mutex with ``b``, or when a greedy-necessary predecessor of ``a`` is mutex
        with ``b``: then reaching ``b`` before ``a`` means destroying ``b`` again. ``a`` is ordered
        reasonably before ``b`` when ``b`` is a goal, or when ``b`` is a greedy-necessary predecessor
        of a landmark that ``a`` precedes (naturally or greedy-necessarily), as Fast Downward's
        approximation does. An ordering that would close a cycle with the others is left out. The orderings go
        to :attr:`reasonable`; they do not hold on every plan (unlike the natural ones), so only the
        landmark count reads them: an accepted landmark whose reasonable predecessor is not accepted
        yet counts as needed again.
        """
        n = len(self.parents)
        lms = self.mask
        adders: list[list[int]] = [[] for _ in range(n)]
        for op, adds in enumerate(ct.add):
            for f in adds:
                if lms >> f & 1:
                    adders[f].append(op)
        shared_add = [0] * n
        shared_del = [0] * n
        for f in bits(lms):
            if adders[f]:
                add = del_ = -1
                for op in adders[f]:
                    add &= ct.add_mask[op]
                    del_ &= ct.del_mask[op]
                shared_add[f] = add & ~(1 << f)
                shared_del[f] = del_
        gn_parents = [0] * n
        for c in bits(self.gn_parents_mask):
            for f in bits(self.gn_children[c]):
                gn_parents[f] |= 1 << c

        # the landmarks that interfere with b, as a bitset: mutex with b, deleting it on every way in, or adding
        # (or needing greedily) a fact mutex with it; indexed by fact so that no pair is tried in vain
        deleting = [0] * n  # fact -> the landmarks every adder of which deletes it
        adding = [0] * n  # fact -> the landmarks every adder of which adds it, or with it as a gn-predecessor
        for a in bits(lms):
            for e in bits(shared_del[a]):
                deleting[e] |= 1 << a
            for e in bits(shared_add[a] | gn_parents[a]):
                adding[e] |= 1 << a

        def interfering(b: int) -> int:
            out = mutexes.mutex_with(b) | deleting[b]
            for e in bits(mutexes.mutex_with(b)):
                out |= adding[e]
            return out & ~(1 << b)

        after = [self.parents[f] | self.reasonable[f] for f in range(n)]

        def before(a: int, b: int) -> bool:  # whether a is (transitively) ordered before b already or b before a
            stack, seen = [a], 1 << a
            while stack:
                for p in bits(after[stack.pop()]):
                    if p == b:
                        return True
                    if not seen >> p & 1:
                        seen |= 1 << p
                        stack.append(p)
            return False

        def order(candidates: int, b: int) -> None:  # in increasing a: the ones added before count in before()
            for a in bits(candidates & interfering(b)):
                if after[b] >> a & 1 or before(a, b):
                    continue
                self.reasonable[b] |= 1 << a
                after[b] |= 1 << a

        for b in bits(lms & self.goal_mask):
            order(lms, b)
        for b in bits(lms & ~self.goal_mask):
            for c in bits(self.gn_children[b]):
                order(self.parents[c] | gn_parents[c], b)

    def reasonable_orderings(self) -> list[tuple[int, int]]:
        """The reasonable orderings ``(before, after)`` (see :meth:`add_reasonable`)."""
        return [(p, f) for f in bits(self.mask) for p in bits(self.reasonable[f])]


class LandmarkCount:
    """LAMA's landmark-count heuristic on a compiled task (see the module docstring).

    Landmark ids: a fact landmark is its fact id; disjunctive landmark ``k`` is
    ``ct.n_facts + k``. Accepted and needed sets are bitsets over these ids.

    Args:
        ct: the compiled task.
        relaxed: its relaxed task.
        unit: count every landmark 1 (else its cheapest achiever's cost).
        disjunctive: find disjunctive landmarks too.
        reasonable: order the fact landmarks reasonably too (from the task's mutex groups,
            :mod:`~alica.prophet.search.mutexes`), as LAMA does.
    """

    def __init__(
        self, ct: CompiledTask, relaxed: Relaxed, unit: bool = True, disjunctive: bool = True, reasonable: bool = True
    ) -> None:
        self.ct = ct
        self.landmarks = lm = Landmarks(relaxed, ct.init, ct.task.facts if disjunctive else None)
        if reasonable:
            lm.add_reasonable(ct, Mutexes(mutex_groups(ct.task), ct.n_facts))
        self.unit = unit
        n = ct.n_facts
        self._dis = [(1 << (n + k), m, lm.disjunctive_children[k]) for k, m in enumerate(lm.disjunctive)]
        dmask = 0
        for bit, _m, _children in self._dis:
            dmask |= bit
        self.initial = ct.init & lm.mask  # no disjunctive landmark holds initially
        self._mask = lm.mask | dmask
        self._dmask = dmask
        self._dfacts = 0
        self._dbit = [0] * n
        for bit, m, _children in self._dis:
            self._dfacts |= m
            for f in bits(m):
                self._dbit[f] = bit
        self._cache: dict[int, tuple[int, int]] = {}
        self._facts = lm.mask
        self._parents = lm.parents
        self._ordered = 0  # the landmarks with a reasonable predecessor
        for f in bits(lm.mask):
            if lm.reasonable[f]:
                self._ordered |= 1 << f
        self.cost = lm.cost + lm.disjunctive_cost
        """Per landmark id, its cost in the cost-sum variant."""

    def progress(self, accepted: int, state: int) -> int:
        """The accepted set after reaching ``state`` from a state whose accepted set is ``accepted``."""
        new = state & self._facts & ~accepted
        gained = 0
        if new:
            parents = self._parents
            while new:
                low = new & -new
                if not parents[low.bit_length() - 1] & ~accepted:
                    gained |= low
                new ^= low
        if self._dis:
            gained |= self._true_disjunctive(state) & ~accepted
        return accepted | gained

    def _true_disjunctive(self, state: int) -> int:
        """The disjunctive landmarks (as id bits) with a fact true in ``state``."""
        s = state & self._dfacts
        out = 0
        dbit = self._dbit
        while s:
            low = s & -s
            out |= dbit[low.bit_length() - 1]
            s ^= low
        return out

    def _live(self, accepted: int) -> tuple[int, int]:
        """The accepted landmarks that would be required again if false (goals, and greedy-necessary
        predecessors of a landmark not accepted), and those required again in any case (a reasonable
        predecessor not accepted yet); cached per accepted set: siblings share theirs."""
        cached = self._cache.get(accepted)
        if cached is None:
            if len(self._cache) > CACHE_SIZE:
                self._cache.clear()
            unaccepted = self._mask & ~accepted
            live = accepted & self.landmarks.goal_mask
            gn_children = self.landmarks.gn_children
            for f in bits(accepted & self.landmarks.gn_parents_mask):
                if gn_children[f] & unaccepted:
                    live |= 1 << f
            for bit, _m, children in self._dis:
                if accepted & bit and children & unaccepted:
                    live |= bit
            again = 0
            reasonable = self.landmarks.reasonable
            for f in bits(accepted & self._ordered):
                if reasonable[f] & unaccepted:
                    again |= 1 << f
            cached = self._cache[accepted] = (live, again)
        return cached

    def needed(self, state: int, accepted: int) -> int:
        """The landmarks ``state`` still needs: not accepted, required again (accepted, false in ``state``,
        live), or accepted before a reasonable predecessor (as Fast Downward's landmark count)."""
        live, again = self._live(accepted)
        needed = (self._mask & ~accepted) | again
        if live:
            needed |= live & self._facts & ~state
            if live & self._dmask:
                needed |= live & self._dmask & ~self._true_disjunctive(state)
        return needed

    def count(self, needed: int) -> int:
        """The estimate for the needed landmarks ``needed``."""
        if self.unit:
            return needed.bit_count()
        cost = self.cost
        return sum(cost[i] for i in bits(needed))

    def value(self, state: int, accepted: int) -> int:
        """The estimate of ``state`` with the accepted set ``accepted``."""
        return self.count(self.needed(state, accepted))

    def preferred(self, state: int, accepted: int, needed: int, applicable: Sequence[int]) -> list[int]:
        """The applicable operators that achieve a needed fact landmark whose natural predecessors are accepted.

        Without any, those that achieve a fact of a needed disjunctive landmark (as LAMA's).
        """
        out = self._achieving(state, needed & self._facts, applicable, accepted)
        if out or not self._dis:
            return out
        facts = 0
        for bit, m, _children in self._dis:
            if needed & bit:
                facts |= m
        return self._achieving(state, facts, applicable, None) if facts else out

    def _achieving(self, state: int, targets: int, applicable: Sequence[int], accepted: int | None) -> list[int]:
        ct = self.ct
        add_mask = ct.add_mask
        cond = ct.cond
        parents = self._parents
        out: list[int] = []
        for op in applicable:
            adds = add_mask[op] & targets
            if cond[op]:
                for cmask, cadd, _cdel in cond[op]:
                    if state & cmask == cmask:
                        adds |= cadd & targets
            if accepted is None:
                if adds:
                    out.append(op)
                continue
            while adds:
                low = adds & -adds
                if not parents[low.bit_length() - 1] & ~accepted:
                    out.append(op)
                    break
                adds ^= low
        return out


__all__ = ["LandmarkCount", "Landmarks", "fact_labels"]
