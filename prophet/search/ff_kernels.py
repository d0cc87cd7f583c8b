"""The numba kernels of :mod:`alica.prophet.search.jit` (imported only when it is used: importing numba takes time).

``explore``: generalised Dijkstra for h_add from a state (boolean array over the
facts), keeping each fact's cost and supporter, stopping once every goal is
reached; its heap holds ``cost << SHIFT | fact`` keys, so ties go to the lower
fact id as with the pure-Python ``(cost, fact)`` tuples. ``extract``: the
relaxed plan from the goals through the supporters, its estimate, and its
actions applicable in the state, in the pure-Python extraction's order.
"""
# mypy: ignore-errors

from __future__ import annotations

import numba
import numpy as np

SHIFT = 24
LOW = (1 << SHIFT) - 1
DEBRUIJN_MUL = np.uint64(0x03F79D71B4CB0A89)
DEBRUIJN = np.zeros(64, dtype=np.int64)
"""The bit index of ``low`` (a power of two) is ``DEBRUIJN[(low * DEBRUIJN_MUL) >> 58]``."""
for _i in range(64):
    DEBRUIJN[((1 << _i) * 0x03F79D71B4CB0A89 >> 58) & 63] = _i
BIG = 1 << 38
"""Unreached (costs stay far below it; fact ids below 2**SHIFT)."""


@numba.njit(cache=True, nogil=True)
def push(heap, size, key):
    i = size
    heap[i] = key
    while i > 0:
        up = (i - 1) >> 1
        if heap[up] <= key:
            break
        heap[i] = heap[up]
        i = up
    heap[i] = key
    return size + 1


@numba.njit(cache=True, nogil=True)
def pop(heap, size):
    top = heap[0]
    size -= 1
    last = heap[size]
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and heap[child + 1] < heap[child]:
            child += 1
        if heap[child] >= last:
            break
        heap[i] = heap[child]
        i = child
    heap[i] = last
    return top, size


@numba.njit(cache=True, nogil=True)
def explore(state, is_goal, npre, pre_of_ptr, pre_of_idx, add_ptr, add_idx, cost, zero, cost_f, sup, unsat, acc, heap):
    # heap keys: cost << SHIFT | fact, so that ties go to the lower fact id as with (cost, fact) tuples
    n = state.shape[0]
    goals_left = 0
    for f in range(n):
        cost_f[f] = BIG
        sup[f] = -1
        if is_goal[f] and not state[f]:
            goals_left += 1
    for a in range(npre.shape[0]):
        unsat[a] = npre[a]
        acc[a] = 0
    size = 0
    for f in range(n):
        if state[f]:
            cost_f[f] = 0
            size = push(heap, size, f)
    for k in range(zero.shape[0]):
        a = zero[k]
        c = cost[a]
        for j in range(add_ptr[a], add_ptr[a + 1]):
            g = add_idx[j]
            if c < cost_f[g]:
                cost_f[g] = c
                sup[g] = a
                size = push(heap, size, (c << SHIFT) | g)
    if goals_left == 0:
        return True
    while size > 0:
        key, size = pop(heap, size)
        c = key >> SHIFT
        f = key & LOW
        if c != cost_f[f]:
            continue
        if is_goal[f] and not state[f]:
            goals_left -= 1
            if goals_left == 0:
                return True
        for k in range(pre_of_ptr[f], pre_of_ptr[f + 1]):
            a = pre_of_idx[k]
            left = unsat[a] - 1
            unsat[a] = left
            acc[a] += c
            if left == 0:
                ac = acc[a] + cost[a]
                for j in range(add_ptr[a], add_ptr[a + 1]):
                    g = add_idx[j]
                    if ac < cost_f[g]:
                        cost_f[g] = ac
                        sup[g] = a
                        size = push(heap, size, (ac << SHIFT) | g)
    return goals_left == 0


@numba.njit(cache=True, nogil=True)
def extract(state, goals, sup, pre_ptr, pre_idx, cost, unit, used, done, out):
    n = state.shape[0]
    for f in range(n):
        done[f] = state[f]
    for a in range(used.shape[0]):
        used[a] = False
    stack = [0]
    stack.pop()
    for k in range(goals.shape[0]):
        g = goals[k]
        if not state[g]:
            stack.append(g)
    h = 0
    n_out = 0
    while len(stack) > 0:
        g = stack.pop()
        if done[g]:
            continue
        done[g] = True
        a = sup[g]
        if used[a]:
            continue
        used[a] = True
        h += 1 if unit else cost[a]
        applicable = True
        for j in range(pre_ptr[a], pre_ptr[a + 1]):
            if not state[pre_idx[j]]:
                applicable = False
                break
        if applicable:
            out[n_out] = a
            n_out += 1
        for j in range(pre_ptr[a], pre_ptr[a + 1]):
            p = pre_idx[j]
            if not done[p]:
                stack.append(p)
    return h, n_out


REACHED, UNREACHED, PAST_LEVELS = 1, 0, -1
"""What the level pass of :func:`explore_levels` ends with."""


@numba.njit(cache=True, nogil=True, inline="always")
def _push_level(rec, head, n_rec, g, c, top):
    """Fact ``g`` onto level ``c``'s list of records; returns the records used and the highest level."""
    rec[n_rec, 0] = g
    rec[n_rec, 1] = head[c]
    head[c] = n_rec
    if c > top:
        top = c
        head[head.shape[0] - 1] = top
    return n_rec + 1, top


@numba.njit(cache=True, nogil=True)
def _levels(
    state,
    is_goal,
    npre,
    pre_of_ptr,
    pre_of_idx,
    add_ptr,
    add_idx,
    cost,
    zero,
    cost_f,
    sup,
    unsat,
    acc,
    rec,
    head,
    level,
):
    """The level pass of :func:`explore_levels`: ``REACHED``, ``UNREACHED``, or ``PAST_LEVELS`` (its levels
    emptied) when a cost passes the levels."""
    n = state.shape[0]
    n_levels = head.shape[0] - 1
    for c in range(head[n_levels] + 1):
        head[c] = -1
    head[n_levels] = 0
    goals_left = 0
    for f in range(n):
        cost_f[f] = BIG
        sup[f] = -1
        if is_goal[f] and not state[f]:
            goals_left += 1
    for a in range(npre.shape[0]):
        unsat[a] = npre[a]
        acc[a] = 0
    n_rec = 0
    top = 0
    for f in range(n):
        if state[f]:
            cost_f[f] = 0
            rec[n_rec, 0] = f
            rec[n_rec, 1] = head[0]
            head[0] = n_rec
            n_rec += 1
    for k in range(zero.shape[0]):
        a = zero[k]
        c = cost[a]
        for j in range(add_ptr[a], add_ptr[a + 1]):
            g = add_idx[j]
            if c < cost_f[g]:
                if c >= n_levels:
                    return PAST_LEVELS
                cost_f[g] = c
                sup[g] = a
                n_rec, top = _push_level(rec, head, n_rec, g, c, top)
    if goals_left == 0:
        return REACHED
    c = 0
    while c <= top:
        lo = n
        hi = -1
        r = head[c]
        while r >= 0:
            f = rec[r, 0]
            if cost_f[f] == c:
                w = f >> 6
                level[w] |= np.uint64(1) << np.uint64(f & 63)
                if w < lo:
                    lo = w
                if w > hi:
                    hi = w
            r = rec[r, 1]
        for w in range(lo, hi + 1):
            bitsw = level[w]
            if bitsw == np.uint64(0):
                continue
            level[w] = np.uint64(0)
            while bitsw != np.uint64(0):
                low = bitsw & (~bitsw + np.uint64(1))
                bitsw ^= low
                f = (w << 6) | DEBRUIJN[np.int64(((low * DEBRUIJN_MUL) >> np.uint64(58)) & np.uint64(63))]
                if is_goal[f] and not state[f]:
                    goals_left -= 1
                    if goals_left == 0:
                        for w2 in range(w + 1, hi + 1):
                            level[w2] = np.uint64(0)
                        return REACHED
                for k in range(pre_of_ptr[f], pre_of_ptr[f + 1]):
                    a = pre_of_idx[k]
                    left = unsat[a] - 1
                    unsat[a] = left
                    acc[a] += c
                    if left == 0:
                        ac = acc[a] + cost[a]
                        for j in range(add_ptr[a], add_ptr[a + 1]):
                            g = add_idx[j]
                            if ac < cost_f[g]:
                                if ac >= n_levels:
                                    for w2 in range(w, hi + 1):
                                        level[w2] = np.uint64(0)
                                    return PAST_LEVELS
                                cost_f[g] = ac
                                sup[g] = a
                                n_rec, top = _push_level(rec, head, n_rec, g, ac, top)
        c += 1
    return REACHED if goals_left == 0 else UNREACHED


@numba.njit(cache=True, nogil=True)
def explore_levels(
    state,
    is_goal,
    npre,
    pre_of_ptr,
    pre_of_idx,
    add_ptr,
    add_idx,
    cost,
    zero,
    cost_f,
    sup,
    unsat,
    acc,
    heap,
    rec,
    head,
    level,
):
    """``explore`` for costs of at least 1, with a bucket per cost level instead of the heap.

    Every action costs at least 1, so nothing joins the level being processed; each level's
    facts are taken in increasing fact id, the heap's order, so costs, supporters and the early
    stop are the same as ``explore``'s. ``rec`` holds (fact, next) records of the pushes, ``head``
    each level's first record and, last, the highest level the previous call used (its levels are
    emptied first), ``level`` the facts of one level as a bitset (all 0 between calls). A cost past
    the levels goes over to ``explore`` (with ``heap``). Returns whether the goals are reached.
    """
    found = _levels(
        state,
        is_goal,
        npre,
        pre_of_ptr,
        pre_of_idx,
        add_ptr,
        add_idx,
        cost,
        zero,
        cost_f,
        sup,
        unsat,
        acc,
        rec,
        head,
        level,
    )
    if found == PAST_LEVELS:
        return explore(
            state, is_goal, npre, pre_of_ptr, pre_of_idx, add_ptr, add_idx, cost, zero, cost_f, sup, unsat, acc, heap
        )
    return found == REACHED
