"""The numba kernel of :mod:`alica.prophet.search.compiled_lama` (imported only when it is used: numba takes time to load).

``run`` is LAMA's lazy search of :func:`alica.prophet.search.lama.lama_search`, step for step, over
flat arrays: states packed in ``uint64`` words in a pool with an open-addressing hash table, FF
through the kernels of :mod:`alica.prophet.search.ff_kernels` and the landmark count over dense
landmark ids.

The four open lists are bucket queues of *runs*. An expanded state's successors are written once,
as operator ids (``e_op``, 4 bytes each; the preferred ones' positions in ``p_pos``); a run is a
stretch of them with one key and one parent, and a list keeps, per key, its runs first in, first
out. The pure-Python search orders its heaps by ``(key, insertion count)``, and the successors of
one state enter with consecutive counts: taking a key's runs in order, and each run's successors in
order, is the same order, in a few bytes per successor instead of a tuple per successor and list.

It runs until a goal, until the open lists are empty, until the expansion limit, until it has done
the expansions asked for (the caller checks its deadline and reports progress between calls) or
until an array is full (the caller grows it and calls again: no step is lost).
"""
# mypy: ignore-errors

from __future__ import annotations

import numba
import numpy as np

from alica.prophet.search.ff_kernels import DEBRUIJN, DEBRUIJN_MUL, explore_levels, extract

# return codes
FOUND, EXHAUSTED, LIMIT, PAUSE, GROW, OVERFLOW = 0, 1, 2, 3, 4, 5

# scalars (an int64 array kept between calls)
S_COUNT = 0  # successors written (e_op's length)
S_PREF = 1  # preferred successors written (p_pos's length)
S_RUNS = 2  # runs made
S_PRIO = 3  # 4: each list's turns
S_SIZE = 7  # 4: each list's successors not taken yet
S_LOW = 11  # 4: each list's lowest key that may hold a run
S_BEST_FF, S_BEST_LM, S_STATES, S_PENDING, S_EXPANDED, S_EVALS, S_GOAL = 15, 16, 17, 18, 19, 20, 21
N_SCALARS = 22
PENDING_NONE, PENDING_INIT = -1, -2
INF_H = 1 << 60
DENSE = 0xFFFF
"""The first piece of a state stored as words (else it is the count of the facts that follow)."""


@numba.njit(cache=True, nogil=True)
def encode(words, enc, sparse_ok):
    """``words`` in the pool's form, written to ``enc``; its length.

    Sparse (the fact count, then the facts' ids) when that is shorter than the words, else
    :data:`DENSE` followed by the words as 16-bit pieces: each state has one form, so equal
    states compare equal.
    """
    n_words = words.shape[0]
    count = 0
    for k in range(n_words):
        w = words[k]
        while w != np.uint64(0):
            w &= w - np.uint64(1)
            count += 1
    if sparse_ok and count < 4 * n_words:
        enc[0] = count
        m = 1
        for k in range(n_words):
            w = words[k]
            while w != np.uint64(0):
                low = w & (~w + np.uint64(1))
                w ^= low
                enc[m] = (k << 6) | DEBRUIJN[np.int64(((low * DEBRUIJN_MUL) >> np.uint64(58)) & np.uint64(63))]
                m += 1
        return m
    enc[0] = DENSE
    for k in range(n_words):
        w = words[k]
        for q in range(4):
            enc[1 + 4 * k + q] = (w >> np.uint64(16 * q)) & np.uint64(0xFFFF)
    return 1 + 4 * n_words


@numba.njit(cache=True, nogil=True)
def decode(pool, start, words):
    """The words of the state stored at ``pool[start:]``."""
    n_words = words.shape[0]
    if pool[start] == DENSE:
        for k in range(n_words):
            w = np.uint64(0)
            for q in range(4):
                w |= np.uint64(pool[start + 1 + 4 * k + q]) << np.uint64(16 * q)
            words[k] = w
        return
    for k in range(n_words):
        words[k] = np.uint64(0)
    for j in range(start + 1, start + 1 + np.int64(pool[start])):
        put(words, np.int64(pool[j]))


@numba.njit(cache=True, nogil=True)
def state_hash(enc, m):
    h = np.uint64(14695981039346656037)
    for k in range(m):
        h ^= np.uint64(enc[k])
        h *= np.uint64(1099511628211)
    h ^= h >> np.uint64(29)
    return h


@numba.njit(cache=True, nogil=True)
def lookup(table, pool, offsets, enc, m):
    """The pool index of the encoded state ``enc[:m]`` (or -1) and the table slot where it is or would go."""
    mask = np.uint64(table.shape[0] - 1)
    slot = np.int64(state_hash(enc, m) & mask)
    while True:
        sid = table[slot]
        if sid < 0:
            return -1, slot
        start = offsets[sid]
        if offsets[sid + 1] - start == m:
            same = True
            for k in range(m):
                if pool[start + k] != enc[k]:
                    same = False
                    break
            if same:
                return sid, slot
        slot = (slot + 1) & np.int64(mask)


@numba.njit(cache=True, nogil=True)
def rehash(table, pool, offsets, n_states):
    """Fill an empty (all -1) ``table`` with the pool's first ``n_states`` states."""
    mask = np.uint64(table.shape[0] - 1)
    for sid in range(n_states):
        start = offsets[sid]
        slot = np.int64(state_hash(pool[start:], offsets[sid + 1] - start) & mask)
        while table[slot] >= 0:
            slot = (slot + 1) & np.int64(mask)
        table[slot] = sid


@numba.njit(cache=True, nogil=True)
def has(words, f):
    return (words[f >> 6] >> np.uint64(f & 63)) & np.uint64(1) != 0


@numba.njit(cache=True, nogil=True)
def put(words, f):
    words[f >> 6] |= np.uint64(1) << np.uint64(f & 63)


@numba.njit(cache=True, nogil=True)
def lm_progress(parent_acc, acc, words, lm_fact, par_ptr, par_idx, dis_ptr, dis_idx, n_fact_lms):
    """The accepted set after reaching ``words`` from a state whose accepted set is ``parent_acc``."""
    for k in range(acc.shape[0]):
        acc[k] = parent_acc[k]
    for i in range(n_fact_lms):
        if has(parent_acc, i) or not has(words, lm_fact[i]):
            continue
        ok = True
        for j in range(par_ptr[i], par_ptr[i + 1]):
            if not has(parent_acc, par_idx[j]):
                ok = False
                break
        if ok:
            put(acc, i)
    for d in range(dis_ptr.shape[0] - 1):
        i = n_fact_lms + d
        if has(parent_acc, i):
            continue
        for j in range(dis_ptr[d], dis_ptr[d + 1]):
            if has(words, dis_idx[j]):
                put(acc, i)
                break


@numba.njit(cache=True, nogil=True)
def lm_needed(acc, words, needed, lm_fact, lm_goal, gn_ptr, gn_idx, dis_ptr, dis_idx, n_fact_lms, r_ptr, r_idx):
    """Fill ``needed`` (landmark bits) and return how many: not accepted, accepted before a reasonable
    predecessor, or accepted, live and false."""
    n_lms = lm_goal.shape[0]
    for k in range(needed.shape[0]):
        needed[k] = np.uint64(0)
    count = 0
    for i in range(n_lms):
        if not has(acc, i):
            put(needed, i)
            count += 1
            continue
        early = False
        if i < n_fact_lms:
            for j in range(r_ptr[i], r_ptr[i + 1]):
                if not has(acc, r_idx[j]):
                    early = True
                    break
        if early:
            put(needed, i)
            count += 1
            continue
        live = lm_goal[i]
        if not live:
            for j in range(gn_ptr[i], gn_ptr[i + 1]):
                if not has(acc, gn_idx[j]):
                    live = True
                    break
        if not live:
            continue
        if i < n_fact_lms:
            false_now = not has(words, lm_fact[i])
        else:
            d = i - n_fact_lms
            false_now = True
            for j in range(dis_ptr[d], dis_ptr[d + 1]):
                if has(words, dis_idx[j]):
                    false_now = False
                    break
        if false_now:
            put(needed, i)
            count += 1
    return count


@numba.njit(cache=True, nogil=True)
def lm_preferred(
    succ, n_succ, acc, needed, pref, add_ptr, add_idx, lm_of_fact, par_ptr, par_idx, dis_of_fact, n_fact_lms
):
    """Mark in ``pref`` the applicable operators the landmark count prefers (see ``LandmarkCount.preferred``)."""
    found = False
    for k in range(n_succ):
        o = succ[k]
        for j in range(add_ptr[o], add_ptr[o + 1]):
            i = lm_of_fact[add_idx[j]]
            if i < 0 or not has(needed, i):
                continue
            ok = True
            for q in range(par_ptr[i], par_ptr[i + 1]):
                if not has(acc, par_idx[q]):
                    ok = False
                    break
            if ok:
                pref[o] = True
                found = True
                break
    if found:
        return
    for k in range(n_succ):
        o = succ[k]
        for j in range(add_ptr[o], add_ptr[o + 1]):
            d = dis_of_fact[add_idx[j]]
            if d >= 0 and has(needed, n_fact_lms + d):
                pref[o] = True
                break


@numba.njit(cache=True, nogil=True)
def applicable(words, succ, always, watch_words, watch_ptr, watch_idx, pre_ptr, pre_idx):
    """The applicable operators in the order of ``CompiledTask.applicable``; their number."""
    n = 0
    for k in range(always.shape[0]):
        succ[n] = always[k]
        n += 1
    for wi in range(words.shape[0]):
        s = words[wi] & watch_words[wi]
        f = wi * 64
        while s != np.uint64(0):
            if s & np.uint64(1):
                for j in range(watch_ptr[f], watch_ptr[f + 1]):
                    o = watch_idx[j]
                    ok = True
                    for q in range(pre_ptr[o], pre_ptr[o + 1]):
                        if not has(words, pre_idx[q]):
                            ok = False
                            break
                    if ok:
                        succ[n] = o
                        n += 1
            s >>= np.uint64(1)
            f += 1
    return n


@numba.njit(cache=True, nogil=True)
def take(which, heads, tails, run_pos, run_end, run_parent, run_next, sc):
    """Take the next successor of list ``which`` (not empty): its parent and its position."""
    key = sc[S_LOW + which]
    while heads[which, key] == 0:
        key += 1
    sc[S_LOW + which] = key
    r = heads[which, key] - 1
    pos = run_pos[r]
    run_pos[r] = pos + 1
    if pos + 1 == run_end[r]:
        nxt = run_next[r]
        heads[which, key] = nxt
        if nxt == 0:
            tails[which, key] = 0
    sc[S_SIZE + which] -= 1
    return run_parent[r], pos


@numba.njit(cache=True, nogil=True)
def add_run(which, key, start, end, parent, heads, tails, run_pos, run_end, run_parent, run_next, sc):
    """Append the successors ``start:end`` of ``parent`` to list ``which`` under ``key``."""
    r = sc[S_RUNS]
    sc[S_RUNS] = r + 1
    run_pos[r] = start
    run_end[r] = end
    run_parent[r] = parent
    run_next[r] = 0
    last = tails[which, key]
    if last == 0:
        heads[which, key] = r + 1
    else:
        run_next[last - 1] = r + 1
    tails[which, key] = r + 1
    if key < sc[S_LOW + which]:
        sc[S_LOW + which] = key
    sc[S_SIZE + which] += end - start


@numba.njit(cache=True, nogil=True)
def run(task, ff, lms, search, sc, budget, max_expansions, boost, w2, greedy, lm_pref, bound):
    """LAMA's lazy search (see the module docstring); returns one of the codes above. Successors whose
    ``g`` reaches ``bound`` are not inserted (the anytime restarts' pruning)."""
    (
        init,
        goal_words,
        always,
        watch_words,
        watch_ptr,
        watch_idx,
        pre_ptr,
        pre_idx,
        add_ptr,
        add_idx,
        del_ptr,
        del_idx,
        cost,
    ) = task
    (
        is_goal,
        goals,
        npre,
        pre_of_ptr,
        pre_of_idx,
        r_add_ptr,
        r_add_idx,
        r_cost,
        zero,
        counted,
        r_pre_ptr,
        r_pre_idx,
        r_op,
        cost_f,
        sup,
        unsat,
        acc_a,
        fheap,
        used,
        done,
        out,
        state_b,
        rec,
        head,
        level,
    ) = ff
    (
        init_acc,
        lm_fact,
        lm_of_fact,
        lm_goal,
        par_ptr,
        par_idx,
        gn_ptr,
        gn_idx,
        dis_ptr,
        dis_idx,
        dis_of_fact,
        n_fact_lms,
        r_ptr,
        r_idx,
    ) = lms
    (
        pool,
        offsets,
        pool_acc,
        pool_parent,
        pool_op,
        pool_g,
        table,
        e_op,
        p_pos,
        run_pos,
        run_end,
        run_parent,
        run_next,
        heads,
        tails,
        words,
        acc,
        needed,
        succ,
        pref,
        keys,
        enc,
    ) = search
    sparse_ok = state_b.shape[0] < DENSE
    n_facts = state_b.shape[0]
    n_words = init.shape[0]
    n_ops = cost.shape[0]
    n_keys = heads.shape[1]
    done_here = 0
    while True:
        # room for one more state and all its successors, before anything changes
        n_states = sc[S_STATES]
        if (
            n_states + 1 >= pool_parent.shape[0]
            or offsets[n_states] + enc.shape[0] >= pool.shape[0]
            or 2 * (n_states + 1) > table.shape[0]
            or sc[S_COUNT] + n_ops >= e_op.shape[0]
            or sc[S_PREF] + n_ops >= p_pos.shape[0]
            or sc[S_RUNS] + 4 * n_ops >= run_pos.shape[0]
        ):
            return GROW
        pending = sc[S_PENDING]
        sc[S_PENDING] = PENDING_NONE
        if pending == PENDING_NONE:
            which = -1
            for i in range(4):
                if sc[S_SIZE + i] > 0 and (which < 0 or sc[S_PRIO + i] < sc[S_PRIO + which]):
                    which = i
            if which < 0:
                return EXHAUSTED
            sc[S_PRIO + which] += 1
            p, pos = take(which, heads, tails, run_pos, run_end, run_parent, run_next, sc)
            op = e_op[pos] if which == 0 or which == 2 else e_op[p_pos[pos]]
        else:  # the initial state
            p = -1
            op = -1
        if p < 0:
            for k in range(n_words):
                words[k] = init[k]
            for k in range(acc.shape[0]):
                acc[k] = init_acc[k]
            g = 0
        else:
            decode(pool, offsets[p], words)
            for j in range(del_ptr[op], del_ptr[op + 1]):
                f = del_idx[j]
                words[f >> 6] &= ~(np.uint64(1) << np.uint64(f & 63))
            for j in range(add_ptr[op], add_ptr[op + 1]):
                put(words, add_idx[j])
            g = pool_g[p] + cost[op]
        m = encode(words, enc, sparse_ok)
        sid, slot = lookup(table, pool, offsets, enc, m)
        if sid >= 0:
            continue
        if p >= 0:
            lm_progress(pool_acc[p], acc, words, lm_fact, par_ptr, par_idx, dis_ptr, dis_idx, n_fact_lms)
        sid = n_states
        sc[S_STATES] = n_states + 1
        table[slot] = sid
        start = offsets[sid]
        for k in range(m):
            pool[start + k] = enc[k]
        offsets[sid + 1] = start + m
        for k in range(acc.shape[0]):
            pool_acc[sid, k] = acc[k]
        pool_parent[sid] = p
        pool_op[sid] = op
        pool_g[sid] = g
        goal = True
        for k in range(n_words):
            if words[k] & goal_words[k] != goal_words[k]:
                goal = False
                break
        if goal:
            sc[S_GOAL] = sid
            return FOUND
        for f in range(n_facts):
            state_b[f] = has(words, f)
        sc[S_EVALS] += 1
        reached = explore_levels(
            state_b,
            is_goal,
            npre,
            pre_of_ptr,
            pre_of_idx,
            r_add_ptr,
            r_add_idx,
            r_cost,
            zero,
            cost_f,
            sup,
            unsat,
            acc_a,
            fheap,
            rec,
            head,
            level,
        )
        if not reached:
            continue
        h_ff, n_out = extract(state_b, goals, sup, r_pre_ptr, r_pre_idx, counted, False, used, done, out)
        h_lm = lm_needed(
            acc, words, needed, lm_fact, lm_goal, gn_ptr, gn_idx, dis_ptr, dis_idx, n_fact_lms, r_ptr, r_idx
        )
        sc[S_EXPANDED] += 1
        if sc[S_EXPANDED] > max_expansions:
            return LIMIT
        n_succ = applicable(words, succ, always, watch_words, watch_ptr, watch_idx, pre_ptr, pre_idx)
        improved = False
        if h_ff < sc[S_BEST_FF]:
            sc[S_BEST_FF] = h_ff
            improved = True
        if h_lm < sc[S_BEST_LM]:
            sc[S_BEST_LM] = h_lm
            improved = True
        if improved:
            sc[S_PRIO + 1] -= boost
            sc[S_PRIO + 3] -= boost
        for k in range(n_out):
            o = r_op[out[k]]
            if o >= 0:
                pref[o] = True
        if lm_pref:
            lm_preferred(
                succ, n_succ, acc, needed, pref, add_ptr, add_idx, lm_of_fact, par_ptr, par_idx, dis_of_fact, n_fact_lms
            )
        kept = 0  # the successors under the bound, in order
        for k in range(n_succ):
            if g + cost[succ[k]] < bound:
                succ[kept] = succ[k]
                kept += 1
            else:
                pref[succ[k]] = False
        n_succ = kept
        # the successors once, then runs of equal keys in each list (greedy: one run per list)
        start = sc[S_COUNT]
        pstart = sc[S_PREF]
        for k in range(n_succ):
            o = succ[k]
            e_op[start + k] = o
            if greedy:
                k_ff = h_ff
                k_lm = h_lm
            else:
                g2 = 2 * (g + cost[o])
                k_ff = g2 + w2 * h_ff
                k_lm = g2 + w2 * h_lm
            if k_ff >= n_keys or k_lm >= n_keys:
                return OVERFLOW
            keys[k, 0] = k_ff
            keys[k, 1] = k_lm
        n_pref = 0
        for k in range(n_succ):
            if pref[succ[k]]:
                p_pos[pstart + n_pref] = start + k
                keys[n_pref, 2] = keys[k, 0]
                keys[n_pref, 3] = keys[k, 1]
                n_pref += 1
        sc[S_COUNT] = start + n_succ
        sc[S_PREF] = pstart + n_pref
        for which in range(4):
            col = 0 if which == 0 else (2 if which == 1 else (1 if which == 2 else 3))
            n = n_succ if which == 0 or which == 2 else n_pref
            base = start if which == 0 or which == 2 else pstart
            k = 0
            while k < n:
                key = keys[k, col]
                end = k + 1
                while end < n and keys[end, col] == key:
                    end += 1
                add_run(which, key, base + k, base + end, sid, heads, tails, run_pos, run_end, run_parent, run_next, sc)
                k = end
        for k in range(n_succ):
            pref[succ[k]] = False
        for k in range(n_out):
            o = r_op[out[k]]
            if o >= 0:
                pref[o] = False
        done_here += 1
        if done_here >= budget:
            return PAUSE
