"""Mutex groups of a ground task: sets of facts of which at most one holds in any reachable state.

A simplified form of Helmert's invariant synthesis, checked on the ground operators. A *candidate*
is a set of (predicate, parameter position) pairs: for each object ``o``, its group holds the facts
of those predicates whose argument at the parameter position is ``o`` (with ``None``, one group of
all the predicates' facts). Candidates come from the operators themselves: where an operator adds
a fact and deletes another sharing an object, the two predicates with that object's positions are
one candidate (``at(?obj, ?loc)`` and ``in(?obj, ?vehicle)`` in logistics), and a candidate an
operator unbalances grows by the predicate that operator deletes. A candidate is an invariant when

* the initial state holds at most one fact of each group, and
* every operator adds at most one fact of a group, and only while it deletes another fact of the
  group that its preconditions require (it moves the group's one fact, never adds a second),

so, by induction over any plan, every reachable state holds at most one fact of each group: two
facts of a group are mutex. Tasks with when-effects or derived predicates get no groups (the check
above does not cover them).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from alica.prophet.ground import GroundTask

Atom = tuple[str, int | None]
"""A candidate's part: a predicate and the position of the group's parameter (``None``: no parameter)."""

SAMPLES_PER_ACTION = 3
"""Ground operators per action name whose add and delete effects propose candidates."""
MAX_ATOMS = 4
"""The most predicates a candidate joins."""
MAX_CANDIDATES = 300
"""The most candidates tried on one task."""


def _parse(fact: str) -> tuple[str, tuple[str, ...]]:
    parts = fact.strip("()").split()
    return parts[0], tuple(parts[1:])


def candidates(task: GroundTask, parsed: Sequence[tuple[str, tuple[str, ...]]]) -> list[frozenset[Atom]]:
    """The candidates the operators propose (see the module docstring), in a fixed order; ``parsed`` holds
    each fact's predicate and arguments."""
    seen: dict[str, int] = {}
    found: dict[frozenset[Atom], None] = {}
    for op in task.operators:
        if seen.get(op.action, 0) >= SAMPLES_PER_ACTION:
            continue
        seen[op.action] = seen.get(op.action, 0) + 1
        deleted = [d for d in op.delete if d in op.pre]
        for a in op.add:
            pa, aa = parsed[a]
            for d in deleted:
                pd, ad = parsed[d]
                found.setdefault(frozenset({(pa, None), (pd, None)}), None)
                for i, x in enumerate(aa):
                    for j, y in enumerate(ad):
                        if x == y:
                            found.setdefault(frozenset({(pa, i), (pd, j)}), None)
    return list(found)


def _groups(parsed: Sequence[tuple[str, tuple[str, ...]]], candidate: frozenset[Atom]) -> list[int]:
    """Per fact, the index of its group under ``candidate`` (-1: in none)."""
    where: dict[str, list[int | None]] = {}
    for pred, pos in candidate:
        where.setdefault(pred, []).append(pos)
    keys: dict[tuple[str, ...], int] = {}
    out = [-1] * len(parsed)
    for f, (pred, args) in enumerate(parsed):
        positions = where.get(pred)
        if positions is None:
            continue
        if len(positions) > 1:  # the same predicate twice: two parameters for one fact, not covered
            return []
        pos = positions[0]
        if pos is not None and pos >= len(args):
            return []
        key = () if pos is None else (args[pos],)
        out[f] = keys.setdefault(key, len(keys))
    return out


def _check(
    task: GroundTask, parsed: Sequence[tuple[str, tuple[str, ...]]], candidate: frozenset[Atom], group: list[int]
) -> tuple[bool, list[frozenset[Atom]]]:
    """Whether the candidate (its group of each fact: ``group``) is an invariant; if not, the larger
    candidates that might be: the first unbalanced add, joined by a deleted precondition's predicate."""
    counts: dict[int, int] = {}
    for f in task.init:
        g = group[f]
        if g >= 0:
            counts[g] = counts.get(g, 0) + 1
            if counts[g] > 1:
                return False, []
    predicates = {pred for pred, _ in candidate}
    unparametrised = next(iter(candidate))[1] is None
    for op in task.operators:
        added: dict[int, int] = {}
        for a in op.add:
            g = group[a]
            if g >= 0 and a not in op.pre:
                if g in added:
                    return False, []
                added[g] = a
        if not added:
            continue
        pre = set(op.pre)
        for g, a in added.items():
            if any(group[d] == g and d != a and d in pre for d in op.delete):
                continue
            pa, aa = parsed[a]
            pos = next(p for pred, p in candidate if pred == pa)
            obj = None if pos is None else aa[pos]
            larger: list[frozenset[Atom]] = []
            for d in op.delete:
                pd, ad = parsed[d]
                if d not in pre or pd in predicates:
                    continue
                if unparametrised:
                    larger.append(candidate | {(pd, None)})
                else:
                    larger += [candidate | {(pd, j)} for j, x in enumerate(ad) if x == obj]
            return False, larger
    return True, []


def mutex_groups(task: GroundTask) -> list[frozenset[int]]:
    """The task's mutex groups (facts, two or more each), from the candidates that are invariants.

    A candidate that fails on an operator that adds one of its facts while deleting a precondition
    of another predicate is tried again with that predicate joined (at most :data:`MAX_ATOMS`
    predicates, :data:`MAX_CANDIDATES` candidates tried): so ``at(?crate, ?place)`` grows into
    ``at``, ``lifting(?hoist, ?crate)`` and ``in(?crate, ?truck)`` in depot.
    """
    if task.axioms or any(op.conditional for op in task.operators):
        return []
    parsed = [_parse(f) for f in task.facts]
    out: dict[frozenset[int], None] = {}
    todo = candidates(task, parsed)
    tried: set[frozenset[Atom]] = set(todo)
    while todo and len(tried) <= MAX_CANDIDATES:
        candidate = todo.pop(0)
        group = _groups(parsed, candidate)
        if not group:
            continue
        holds, larger = _check(task, parsed, candidate, group)
        if not holds:
            for more in larger:
                if len(more) <= MAX_ATOMS and more not in tried:
                    tried.add(more)
                    todo.append(more)
            continue
        members: dict[int, list[int]] = {}
        for f, g in enumerate(group):
            if g >= 0:
                members.setdefault(g, []).append(f)
        for facts in members.values():
            if len(facts) > 1:
                out.setdefault(frozenset(facts), None)
    return list(out)


class Mutexes:
    """Pairwise mutex tests over a task's mutex groups.

    Args:
        groups: the mutex groups (fact ids).
        n_facts: the number of facts.
    """

    def __init__(self, groups: Sequence[frozenset[int]], n_facts: int) -> None:
        self.groups = list(groups)
        self._of: list[int] = [0] * n_facts  # per fact, a bitset of the other facts it is mutex with
        for group in self.groups:
            m = 0
            for f in group:
                m |= 1 << f
            for f in group:
                self._of[f] |= m & ~(1 << f)

    def mutex(self, a: int, b: int) -> bool:
        """Whether facts ``a`` and ``b`` never hold together (as far as the groups tell)."""
        return bool(self._of[a] >> b & 1)

    def mutex_with(self, a: int) -> int:
        """The facts mutex with fact ``a``, as a bitset."""
        return self._of[a]


__all__ = ["Mutexes", "candidates", "mutex_groups"]
