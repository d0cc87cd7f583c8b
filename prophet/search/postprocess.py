"""Plan post-processing: cut state loops and drop redundant actions.

Both keep a plan valid and never raise its cost. Loop removal cuts every
segment that returns to an earlier state; greedy action elimination removes
one action, then every later action that is no longer applicable, and keeps
the shorter plan if it still reaches the goal (repeated until nothing changes).
"""

from __future__ import annotations

from alica.prophet.search.encoding import CompiledTask


def remove_loops(ct: CompiledTask, ops: list[int]) -> list[int]:
    """The plan without the segments that come back to an earlier state."""
    states = [ct.init]
    kept: list[int] = []
    index = {ct.init: 0}
    for op in ops:
        s = ct.successor(states[-1], op)
        at = index.get(s)
        if at is not None:
            for dropped in states[at + 1 :]:
                del index[dropped]
            del states[at + 1 :]
            del kept[at:]
            continue
        kept.append(op)
        states.append(s)
        index[s] = len(states) - 1
    return kept


def eliminate_actions(ct: CompiledTask, ops: list[int], *, max_rounds: int = 5) -> list[int]:
    """Greedy action elimination (see the module docstring)."""
    cost = ct.cost
    pre_mask = ct.pre_mask
    successor = ct.successor
    for _ in range(max_rounds):
        changed = False
        i = 0
        state = ct.init
        while i < len(ops):
            s = state
            kept = ops[:i]
            for op in ops[i + 1 :]:
                m = pre_mask[op]
                if s & m == m:
                    s = successor(s, op)
                    kept.append(op)
            if ct.is_goal(s) and (sum(cost[o] for o in kept), len(kept)) < (sum(cost[o] for o in ops), len(ops)):
                ops = kept
                changed = True
                continue
            state = ct.successor(state, ops[i])
            i += 1
        if not changed:
            break
    return ops


def improve(ct: CompiledTask, ops: list[int]) -> list[int]:
    """Loop removal, then action elimination."""
    return eliminate_actions(ct, remove_loops(ct, ops))
