"""A grounded task compiled for fast search: states as ``int`` bitsets.

Fact ``i`` is bit ``i`` of a state. An operator becomes masks so that it is
applicable in ``state`` when ``state & pre == pre`` and leads to
``(state & ~delete) | add``. Static facts (never added or deleted) are
compiled away: static true facts leave the preconditions, operators that need a
static false fact are dropped, and so are operators a relaxed exploration from
the initial state never reaches. Successors are generated through a watch
index: every operator watches one of its (fluent) preconditions, so a state
only tests the operators watching one of its true facts.

A task with derived predicates compiles to an :class:`AxiomTask`: its states
hold the basic and the derived facts, and its successor (and initial state)
recompute the derived facts from the basic ones, layer by layer (each layer
to its fixpoint, negated derived facts of lower layers read as final), so
that ``applicable`` and ``is_goal`` read derived facts like any other. A task
without them keeps the plain :class:`CompiledTask` (no cost on that path).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from alica.prophet.ground import GroundTask

CondEffect = tuple[int, int, int]
"""A compiled when-effect: (condition mask, add mask, delete mask)."""


def bits(state: int) -> list[int]:
    """The fact ids set in ``state``, in increasing order."""
    out: list[int] = []
    append = out.append
    while state:
        low = state & -state
        append(low.bit_length() - 1)
        state ^= low
    return out


def mask(ids: Sequence[int]) -> int:
    """The bitset with the given fact ids set."""
    m = 0
    for i in ids:
        m |= 1 << i
    return m


@dataclass(slots=True)
class CompiledTask:
    """A task ready for search (see the module docstring).

    Attributes:
        task: the grounded task it was compiled from.
        n_facts: number of facts (bits).
        init: the initial state (fluent facts only: states never hold static facts).
        goal_mask: the fluent goal facts as a mask.
        goal: the goal fact ids (fluent or not).
        source: per compiled operator, its index in ``task.operators``.
        pre: per operator, the fluent precondition fact ids.
        pre_mask: per operator, ``pre`` as a mask.
        add: per operator, the added fact ids.
        add_mask: per operator, the add mask.
        del_mask: per operator, the delete mask minus the add mask.
        cost: per operator, its cost.
        cond: per operator, its compiled when-effects (empty for most).
        cond_raw: per operator, its when-effects as (condition ids, add ids, delete ids).
        watch: per fact, the operators that watch it.
        always: operators without fluent preconditions.
        watch_mask: the facts some operator watches.
        unit_cost: whether every operator costs 1.
        solvable_relaxed: whether the relaxed task reaches the goal.
    """

    task: Any
    n_facts: int
    init: int
    goal_mask: int
    goal: tuple[int, ...]
    source: list[int]
    pre: list[tuple[int, ...]]
    pre_mask: list[int]
    add: list[tuple[int, ...]]
    add_mask: list[int]
    del_mask: list[int]
    cost: list[int]
    cond: list[tuple[CondEffect, ...]]
    cond_raw: list[tuple[tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...]], ...]]
    watch: list[list[int]]
    always: list[int]
    watch_mask: int
    unit_cost: bool
    solvable_relaxed: bool

    def applicable(self, state: int) -> list[int]:
        """The operators applicable in ``state``, in a fixed order."""
        pre_mask = self.pre_mask
        watch = self.watch
        out = [op for op in self.always if state & pre_mask[op] == pre_mask[op]]
        append = out.append
        s = state & self.watch_mask
        while s:
            low = s & -s
            for op in watch[low.bit_length() - 1]:
                m = pre_mask[op]
                if state & m == m:
                    append(op)
            s ^= low
        return out

    def successor(self, state: int, op: int) -> int:
        """The state after applying the (applicable) operator ``op`` in ``state``."""
        conds = self.cond[op]
        if not conds:
            return (state & ~self.del_mask[op]) | self.add_mask[op]
        add = self.add_mask[op]
        delete = self.del_mask[op]
        for cmask, cadd, cdel in conds:
            if state & cmask == cmask:
                add |= cadd
                delete |= cdel
        return (state & ~(delete & ~add)) | add

    def is_goal(self, state: int) -> bool:
        """Whether ``state`` satisfies the goal."""
        return state & self.goal_mask == self.goal_mask

    def plan_cost(self, ops: Sequence[int]) -> int:
        """The summed cost of a sequence of compiled operators."""
        cost = self.cost
        return sum(cost[op] for op in ops)


@dataclass(slots=True)
class AxiomTask(CompiledTask):
    """A compiled task with derived facts (see the module docstring).

    Attributes:
        derived_mask: the derived facts.
        axioms: per compiled axiom, ``(head, fluent positive body, negated derived body, layer)``.
        relaxed_axioms: the rules the delete relaxation uses, ``(head, fluent body)``: the task's
            ``relaxed_axioms`` (negated derived facts read through their ``(not@p ...)`` facts, which
            have rules of their own).
        layers: per layer in increasing order, the axioms checked first (no positive body fact of
            their own layer) and, per fact of the layer, the axioms to check once it holds.
    """

    derived_mask: int = 0
    relaxed_axioms: list[tuple[int, tuple[int, ...]]] = field(default_factory=list)
    axioms: list[tuple[int, tuple[int, ...], tuple[int, ...], int]] = field(default_factory=list)
    layers: list[tuple[list[int], dict[int, list[int]]]] = field(default_factory=list)
    ax_pre: list[int] = field(default_factory=list)
    ax_neg: list[int] = field(default_factory=list)
    ax_head: list[int] = field(default_factory=list)

    def closure(self, state: int) -> int:
        """``state`` (basic facts) with the derived facts that follow from them."""
        ax_pre = self.ax_pre
        ax_neg = self.ax_neg
        ax_head = self.ax_head
        axioms = self.axioms
        for first, triggers in self.layers:
            queue: list[int] = []
            for a in first:
                m = ax_pre[a]
                if state & m == m and not state & ax_neg[a]:
                    h = ax_head[a]
                    if not state & h:
                        state |= h
                        queue.append(axioms[a][0])
            while queue:
                for a in triggers.get(queue.pop(), ()):
                    m = ax_pre[a]
                    if state & m == m and not state & ax_neg[a]:
                        h = ax_head[a]
                        if not state & h:
                            state |= h
                            queue.append(axioms[a][0])
        return state

    def successor(self, state: int, op: int) -> int:
        """The state after ``op``, its derived facts recomputed."""
        return self.closure(CompiledTask.successor(self, state, op) & ~self.derived_mask)


def _axiom_parts(
    axioms: list[tuple[int, tuple[int, ...], tuple[int, ...], int]],
) -> list[tuple[list[int], dict[int, list[int]]]]:
    """The layers of :class:`AxiomTask` (axioms as (head, positive body, negated body, layer))."""
    layer_of = {head: layer for head, _, _, layer in axioms}
    out: dict[int, tuple[list[int], dict[int, list[int]]]] = {}
    for a, (_head, pos, _neg, layer) in enumerate(axioms):
        first, triggers = out.setdefault(layer, ([], {}))
        own = [f for f in pos if layer_of.get(f) == layer]
        if not own:
            first.append(a)
        for f in own:
            triggers.setdefault(f, []).append(a)
    return [out[k] for k in sorted(out)]


def _changing_derived(axioms: Sequence[Any], derived: frozenset[int], fluent: list[bool]) -> set[int]:
    """The derived facts that may change: those with a rule reading a changing basic fact or such a derived fact.

    The others (no rule, or rules over static facts and such derived facts only) keep the value
    they have in the initial state: they are compiled away like static facts.
    """
    readers: dict[int, list[int]] = {}
    changing: set[int] = set()
    for a in axioms:
        for f in (*a.pos, *a.neg):
            if f in derived:
                readers.setdefault(f, []).append(a.head)
            elif fluent[f]:
                changing.add(a.head)
    stack = list(changing)
    while stack:
        for head in readers.get(stack.pop(), ()):
            if head not in changing:
                changing.add(head)
                stack.append(head)
    return changing


def _reachable(n_facts: int, init: set[int], pres: list[tuple[int, ...]], adds: list[tuple[int, ...]]) -> list[bool]:
    """Which relaxed actions a relaxed exploration from ``init`` reaches."""
    users: list[list[int]] = [[] for _ in range(n_facts)]
    left = [len(p) for p in pres]
    for a, p in enumerate(pres):
        for f in p:
            users[f].append(a)
    reached = [False] * len(pres)
    seen = [False] * n_facts
    stack = sorted(init)
    for f in stack:
        seen[f] = True
    for a, n in enumerate(left):
        if n == 0:
            reached[a] = True
            for g in adds[a]:
                if not seen[g]:
                    seen[g] = True
                    stack.append(g)
    while stack:
        f = stack.pop()
        for a in users[f]:
            left[a] -= 1
            if left[a] == 0:
                reached[a] = True
                for g in adds[a]:
                    if not seen[g]:
                        seen[g] = True
                        stack.append(g)
    return reached


def _keep_relevant(task: Any, cand: list[int], keep: list[bool], fluent: list[bool]) -> None:
    """Backward relevance from the goal (tasks without when-effects only).

    Drops (in ``keep``) the operators that add no relevant fact, and turns the
    irrelevant facts into non-fluent ones so that states never hold them: a
    plan stays a plan without the dropped operators, whose only effects are
    on facts no goal or kept precondition mentions.
    """
    n = len(fluent)
    adders: list[list[int]] = [[] for _ in range(n)]
    for k, i in enumerate(cand):
        if keep[k]:
            for f in task.operators[i].add:
                if fluent[f]:
                    adders[f].append(k)
    relevant = [False] * n
    stack = [f for f in task.goal if fluent[f]]
    for f in stack:
        relevant[f] = True
    used = [False] * len(cand)
    while stack:
        f = stack.pop()
        for k in adders[f]:
            if used[k]:
                continue
            used[k] = True
            for p in task.operators[cand[k]].pre:
                if fluent[p] and not relevant[p]:
                    relevant[p] = True
                    stack.append(p)
    for k in range(len(cand)):
        keep[k] = keep[k] and used[k]
    for f in range(n):
        fluent[f] = fluent[f] and relevant[f]


def compile_task(task: GroundTask) -> CompiledTask:
    """Compile a grounded task (``GroundTask`` shape) for search."""
    n = len(task.facts)
    init_set = set(task.init)
    # A fact is fluent if some operator really deletes it (a delete its own add
    # does not override), or if it is false initially and some operator adds it.
    fluent = [False] * n
    for op in task.operators:
        adds = set(op.add)
        for f in op.delete:
            if f not in adds:
                fluent[f] = True
        for f in op.add:
            if f not in init_set:
                fluent[f] = True
        for _cond, cadd, cdel in op.conditional:
            for f in cdel:
                if f not in adds:
                    fluent[f] = True
            for f in cadd:
                if f not in init_set:
                    fluent[f] = True

    task_axioms = task.axioms
    derived = task.derived
    for f in _changing_derived(task_axioms, derived, fluent):  # recomputed in every state
        fluent[f] = True

    def usable(ids: Sequence[int]) -> bool:
        return all(fluent[f] or f in init_set for f in ids)

    # Candidate operators: static preconditions hold; relaxed actions include when-effects.
    cand: list[int] = []
    for i, op in enumerate(task.operators):
        if usable(op.pre):
            cand.append(i)
    r_pre: list[tuple[int, ...]] = []
    r_add: list[tuple[int, ...]] = []
    r_of: list[int] = []
    main: list[int] = []
    for k, i in enumerate(cand):
        op = task.operators[i]
        fpre = tuple(f for f in op.pre if fluent[f])
        main.append(len(r_pre))
        r_pre.append(fpre)
        r_add.append(tuple(f for f in op.add if fluent[f]))
        r_of.append(k)
        for when, cadd, _cdel in op.conditional:
            if usable(when):
                r_pre.append(tuple(sorted(set(fpre) | {f for f in when if fluent[f]})))
                r_add.append(tuple(f for f in cadd if fluent[f]))
                r_of.append(k)
    n_ops = len(r_pre)
    ax_cand = [
        a
        for a in task_axioms
        if fluent[a.head] and usable(a.pos) and not any(not fluent[f] and f in init_set for f in a.neg)
    ]
    for a in ax_cand:  # negated derived bodies count as true in the relaxation
        r_pre.append(tuple(f for f in a.pos if fluent[f]))
        r_add.append((a.head,))
    reached = _reachable(n, init_set, r_pre, r_add)
    keep_cand = [reached[a] for a in main]
    relaxed_facts = set(init_set)
    for r, ok in enumerate(reached[:n_ops]):
        if ok and keep_cand[r_of[r]]:
            relaxed_facts.update(r_add[r])
    for r, ok in enumerate(reached[n_ops:], n_ops):
        if ok:
            relaxed_facts.update(r_add[r])
    kept_axioms = [(a.head, r_pre[n_ops + k], a.neg, a.layer) for k, a in enumerate(ax_cand) if reached[n_ops + k]]
    if not task_axioms and not any(task.operators[i].conditional for i in cand):
        _keep_relevant(task, cand, keep_cand, fluent)

    source: list[int] = []
    pre: list[tuple[int, ...]] = []
    pre_mask: list[int] = []
    add: list[tuple[int, ...]] = []
    add_mask: list[int] = []
    del_mask: list[int] = []
    cost: list[int] = []
    cond: list[tuple[CondEffect, ...]] = []
    cond_raw: list[tuple[tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...]], ...]] = []
    for k, i in enumerate(cand):
        if not keep_cand[k]:
            continue
        op = task.operators[i]
        fpre = tuple(f for f in op.pre if fluent[f])
        source.append(i)
        pre.append(fpre)
        pre_mask.append(mask(fpre))
        fadd = tuple(f for f in op.add if fluent[f])
        add.append(fadd)
        am = mask(fadd)
        dm = mask([f for f in op.delete if fluent[f]])
        add_mask.append(am)
        del_mask.append(dm & ~am)
        cost.append(int(op.cost))
        raw = tuple(
            (tuple(f for f in c if fluent[f]), tuple(f for f in a if fluent[f]), tuple(f for f in d if fluent[f]))
            for c, a, d in op.conditional
            if usable(c)
        )
        cond_raw.append(raw)
        cond.append(tuple((mask(c), mask(a), mask(d)) for c, a, d in raw))

    # Watch index: each operator watches its precondition used by the fewest operators.
    uses = [0] * n
    for p in pre:
        for f in p:
            uses[f] += 1
    watch: list[list[int]] = [[] for _ in range(n)]
    always: list[int] = []
    for op_id, p in enumerate(pre):
        if not p:
            always.append(op_id)
        else:
            watch[min(p, key=lambda f: (uses[f], f))].append(op_id)
    watch_mask = mask([f for f in range(n) if watch[f]])
    goal = tuple(task.goal)
    kind = AxiomTask if task_axioms else CompiledTask
    ct = kind(
        task=task,
        n_facts=n,
        init=mask([f for f in sorted(init_set) if fluent[f]]),
        goal_mask=mask([f for f in goal if fluent[f] or f not in init_set]),  # a static false goal: never
        goal=goal,
        source=source,
        pre=pre,
        pre_mask=pre_mask,
        add=add,
        add_mask=add_mask,
        del_mask=del_mask,
        cost=cost,
        cond=cond,
        cond_raw=cond_raw,
        watch=watch,
        always=always,
        watch_mask=watch_mask,
        unit_cost=all(c == 1 for c in cost),
        solvable_relaxed=all(f in relaxed_facts for f in goal),
    )
    if isinstance(ct, AxiomTask):
        ct.derived_mask = mask(sorted(f for f in derived if fluent[f]))
        ct.axioms = kept_axioms
        ct.layers = _axiom_parts(kept_axioms)
        ct.ax_pre = [mask(p) for _, p, _, _ in kept_axioms]
        ct.ax_neg = [mask(g) for _, _, g, _ in kept_axioms]
        ct.ax_head = [1 << h for h, _, _, _ in kept_axioms]
        relaxed = task.relaxed_axioms
        ct.relaxed_axioms = [(h, tuple(f for f in p if fluent[f])) for h, p in relaxed if fluent[h] and usable(p)]
        ct.init = ct.closure(ct.init & ~ct.derived_mask)
    return ct
