"""LAMA's first search compiled: the same search as :func:`~alica.prophet.search.lama.lama_search`, per state in numba.

On large tasks the pure-Python search spends its time in FF's exploration, in the successor
generation and in its open lists, whose ``(key, count, state, operator, g)`` tuples hold the
memory: logistics with 50 packages (23,000 operators) expanded about 1,000 states a second and
took 1.5 GB. Here :func:`alica.prophet.search.lama_kernels.run` does the whole search per state:
states in a pool of 16-bit pieces with a hash table, the four open lists as bucket queues of runs
of successors (4 bytes a successor, see :mod:`~alica.prophet.search.lama_kernels`), FF and the
landmark count over flat arrays. It gives the same plan as the pure-Python search (the same
evaluations, the same preferred operators, the same tie-breaking: tested).

It covers what LAMA's first search meets on STRIPS-like tasks: no derived predicates, no
when-effects, no tie-breaking seed, greedy or a weight that is a multiple of 0.5 (the keys stay
exact integers). :func:`first_plan` runs the pure-Python search first, for as many expansions as
would take about as long as loading numba and the kernel, and only then the compiled one, from
the start; where :data:`EXPANSIONS_PER_STEP` times FF's estimate of the initial state (a guess of
the expansions a greedy search needs) is already past that budget, it starts compiled. Both rules
are deterministic: the same task always switches at the same expansion, so a simulated run that
counts expansions stays the same. One more rule holds where the memory bound covers the whole
process (``alica plan``): when the room left under it is less than what loading numba and the kernel
costs (:func:`~alica.prophet.search.jit.numba_bytes`: more where numba must compile it first, on a
fresh install), the pure-Python search goes on alone.

Between calls of the kernel (every :data:`~alica.prophet.search.gbfs.CHECK_EVERY` expansions, or at
the next progress event) the deadline and the memory bound of the run are checked: the memory is
the arrays' own size, which is what the search holds.
"""

from __future__ import annotations

from collections.abc import Generator
from typing import Any

from alica.prophet.planner import LimitReached, Progress
from alica.prophet.search.encoding import AxiomTask, CompiledTask, bits
from alica.prophet.search.gbfs import Stats
from alica.prophet.search.heuristics import INF, Evaluator, Relaxed
from alica.prophet.search.jit import JIT_LOAD_S, CompiledFF, available, numba_bytes, room_for_numba
from alica.prophet.search.lama import lama_search
from alica.prophet.search.landmarks import LandmarkCount

KERNEL_LOAD_S = JIT_LOAD_S + 0.35
"""What loading the search kernel costs a process, numba's import included (seconds, from a disk cache)."""
PYTHON_S_PER_ACTION = 0.5e-6
"""A pure-Python expansion's cost per relaxed action (FF's exploration dominates; measured 0.2-0.75 µs).

About twice the present cost (40 µs + 0.25 µs per relaxed action fits eleven IPC and Rovers problems
within 25 %), which makes the switch come early. The fitted model was tried: it keeps Rovers p20 and
driverlog p08 in pure Python (0.86 s and 0.77 s instead of 1.43 s and 1.24 s) but sends visitall p20
and p22 and depot p04 through a later switch (1.7-1.8 s instead of 0.8 s; 1.83 s instead of 1.66 s),
worse on the IPC suite as a whole, so these values stay."""
PYTHON_S_PER_EXPANSION = 60e-6
"""A pure-Python expansion's fixed cost (successors, open lists, the landmark count)."""
DEFAULT_BUDGET = 2 << 30
"""The bytes the arrays are sized for without a memory bound (mapped, not used, until written)."""
INITIAL_STATES = 1 << 12
"""The fewest states the pool holds at first (it grows by :data:`GROWTH`)."""
INITIAL_ENTRIES = 1 << 16
"""The fewest successors (and runs) the arrays hold at first."""
WEIGHTED_KEYS = 1 << 16
"""The keys ``2g + 2wh`` a weighted search's lists hold (beyond them the pure-Python search takes over)."""
LEVELS = 1 << 14
"""FF's cost levels in the kernel's bucket queue (an exploration past them uses the heap)."""
EXPANSIONS_PER_STEP = 4
"""The expansions a greedy search is expected to need per step of FF's estimate of the initial state, at
least (measured on the large set: gripper about 1, satellite about 8, miconic 11, logistics 70-100)."""
GROWTH = 1.5
"""How much a full array grows."""
KERNEL = ("lama_kernels", "run")
"""The kernel module and its entry (:func:`~alica.prophet.search.jit.numba_bytes`)."""


def eligible(ct: CompiledTask, relaxed: Relaxed, weight: float | None, seed: int | None) -> bool:
    """Whether the compiled search runs this task (see the module docstring) and numba imports here."""
    if isinstance(ct, AxiomTask) or relaxed.has_rules or any(ct.cond) or seed is not None:
        return False
    if weight is not None and (2 * weight != int(2 * weight) or weight <= 0):
        return False
    return available() and len(ct.pre) > 0


def python_budget(relaxed: Relaxed) -> int:
    """The expansions the pure-Python search gets first: about :data:`KERNEL_LOAD_S` of its time."""
    per = PYTHON_S_PER_EXPANSION + PYTHON_S_PER_ACTION * len(relaxed.r_pre)
    return max(1, int(KERNEL_LOAD_S / per))


def first_plan(
    ct: CompiledTask,
    relaxed: Relaxed,
    ff: Evaluator,
    lmcount: LandmarkCount,
    stats: Stats,
    *,
    weight: float | None = None,
    seed: int | None = None,
) -> Generator[Progress, None, tuple[list[int] | None, bool]]:
    """LAMA's first search: pure Python on small searches, compiled beyond (see the module docstring)."""
    if not eligible(ct, relaxed, weight, seed) or not room_for_numba(stats.limits, *KERNEL):
        return (yield from lama_search(ct, ff, lmcount, stats, weight=weight, seed=seed))
    budget = python_budget(relaxed)
    # a greedy search expands several times as many states as its plan is long, which FF's estimate of the
    # initial state guesses: past the budget, the pure-Python start would only delay the compiled search
    if EXPANSIONS_PER_STEP * relaxed.ff_unit(ct.init)[0] < budget:
        plan, exhausted = yield from lama_search(ct, ff, lmcount, stats, weight=weight, max_expansions=budget)
        if plan is not None or exhausted:
            return plan, exhausted
    return (yield from compiled_lama_search(ct, relaxed, lmcount, stats, weight=weight))


class _Arrays:
    """The kernel's arguments: the task, FF and the landmarks (read only), the search's growing arrays."""

    def __init__(
        self,
        ct: CompiledTask,
        relaxed: Relaxed,
        lmcount: LandmarkCount,
        weight: float | None,
        memory_bytes: float | None = None,
    ) -> None:
        import numpy as np

        from alica.prophet.search import lama_kernels as k

        self.np, self.k = np, k
        n = ct.n_facts
        n_words = max(1, (n + 63) // 64)
        self.n_words = n_words
        n_ops = len(ct.pre)
        i32, i64 = np.int32, np.int64

        def words(m: int) -> Any:
            return np.frombuffer(m.to_bytes(8 * n_words, "little"), dtype=np.uint64).copy()

        def csr(rows: list[list[int]] | list[tuple[int, ...]]) -> tuple[Any, Any]:
            ptr = np.zeros(len(rows) + 1, dtype=i64)
            ptr[1:] = np.cumsum([len(r) for r in rows])
            return ptr, np.array([x for r in rows for x in r], dtype=i64)

        watch_mask = 0
        for f, ops in enumerate(ct.watch):
            if ops:
                watch_mask |= 1 << f
        pre_ptr, pre_idx = csr(ct.pre)
        add_ptr, add_idx = csr(ct.add)
        del_ptr, del_idx = csr([bits(m) for m in ct.del_mask])
        watch_ptr, watch_idx = csr(ct.watch)
        self.task = (
            words(ct.init),
            words(ct.goal_mask),
            np.array(ct.always, dtype=i64),
            words(watch_mask),
            watch_ptr,
            watch_idx,
            pre_ptr,
            pre_idx,
            add_ptr,
            add_idx,
            del_ptr,
            del_idx,
            np.array(ct.cost, dtype=i64),
        )
        cf = CompiledFF(relaxed, relaxed.r_unit, unit=True)  # LAMA's FF: every operator 1
        self.ff = (
            cf.is_goal,
            cf.goals,
            cf.npre,
            cf.pre_of_ptr,
            cf.pre_of_idx,
            cf.add_ptr,
            cf.add_idx,
            cf.cost,
            cf.zero,
            cf.counted,
            cf.pre_ptr,
            cf.pre_idx,
            np.array(relaxed.r_op, dtype=i64),
            cf.cost_f,
            cf.sup,
            cf.unsat,
            cf.acc,
            cf.heap,
            cf.used,
            cf.done,
            cf.out,
            np.zeros(n, dtype=np.bool_),
            np.zeros((cf.heap.shape[0], 2), dtype=i64),
            np.full(LEVELS + 1, -1, dtype=i64),  # the levels, then the highest the last call used
            np.zeros(n_words, dtype=np.uint64),
        )
        lm = lmcount.landmarks
        facts = bits(lm.mask)
        dense = {f: i for i, f in enumerate(facts)}
        n_fact = len(facts)
        n_lms = n_fact + len(lm.disjunctive)

        def ids(m: int) -> list[int]:
            return [dense[b] if b < n else n_fact + b - n for b in bits(m)]

        lm_of_fact = np.full(n, -1, dtype=i64)
        for f, i in dense.items():
            lm_of_fact[f] = i
        dis_of_fact = np.full(n, -1, dtype=i64)
        for d, m in enumerate(lm.disjunctive):
            for f in bits(m):
                dis_of_fact[f] = d
        par_ptr, par_idx = csr([ids(lm.parents[f]) for f in facts])
        r_ptr, r_idx = csr([ids(lm.reasonable[f]) for f in facts])
        gn_ptr, gn_idx = csr([ids(lm.gn_children[f]) for f in facts] + [ids(c) for c in lm.disjunctive_children])
        dis_ptr, dis_idx = csr([bits(m) for m in lm.disjunctive])
        self.n_lm_words = max(1, (n_lms + 63) // 64)
        init_acc = 0
        for f in bits(lmcount.initial):
            init_acc |= 1 << dense[f]
        self.lms = (
            np.frombuffer(init_acc.to_bytes(8 * self.n_lm_words, "little"), dtype=np.uint64).copy(),
            np.array(facts, dtype=i64),
            lm_of_fact,
            np.array([bool(lm.goal_mask >> f & 1) for f in facts] + [False] * len(lm.disjunctive), dtype=np.bool_),
            par_ptr,
            par_idx,
            gn_ptr,
            gn_idx,
            dis_ptr,
            dis_idx,
            dis_of_fact,
            n_fact,
            r_ptr,
            r_idx,
        )
        # Room by the memory bound: np.zeros maps zero pages that count only once written, so the
        # arrays start as large as the bound allows and rarely grow (a growth copies)
        budget = DEFAULT_BUDGET if memory_bytes is None else memory_bytes
        state_bytes = 2 * (4 * n_words + 1) + 8 * self.n_lm_words + 32
        states = max(INITIAL_STATES, int(budget * 0.15) // state_bytes)
        entries = max(INITIAL_ENTRIES, 4 * n_ops, int(budget * 0.4) // 4)
        runs = max(INITIAL_ENTRIES, 8 * n_ops, int(budget * 0.1) // 24)
        self.pool = np.zeros(states * (4 * n_words + 1), dtype=np.uint16)
        self.offsets = np.zeros(states + 1, dtype=i64)
        self.pool_acc = np.zeros((states, self.n_lm_words), dtype=np.uint64)
        self.pool_parent = np.zeros(states, dtype=i32)
        self.pool_op = np.zeros(states, dtype=i32)
        self.pool_g = np.zeros(states, dtype=i64)
        self.table = np.full(1 << 14, -1, dtype=i64)
        self.e_op = np.zeros(entries, dtype=i32)
        self.p_pos = np.zeros(max(INITIAL_ENTRIES, 4 * n_ops, int(budget * 0.1) // 8), dtype=i64)
        self.run_pos = np.zeros(runs, dtype=i64)
        self.run_end = np.zeros(runs, dtype=i64)
        self.run_parent = np.zeros(runs, dtype=i32)
        self.run_next = np.zeros(runs, dtype=i32)
        # keys: greedy ones are estimates (at most the relaxed actions or the landmarks); weighted ones
        # 2g + 2wh, past which the pure-Python search takes over
        n_keys = max(len(relaxed.r_pre), n_lms) + 2 if weight is None else WEIGHTED_KEYS
        self.heads = np.zeros((4, n_keys), dtype=i32)
        self.tails = np.zeros((4, n_keys), dtype=i32)
        size = max(1, n_ops + len(ct.always))
        self.scratch = (
            np.zeros(n_words, dtype=np.uint64),
            np.zeros(self.n_lm_words, dtype=np.uint64),
            np.zeros(self.n_lm_words, dtype=np.uint64),
            np.zeros(size, dtype=i64),
            np.zeros(max(1, n_ops), dtype=np.bool_),
            np.zeros((size, 4), dtype=i64),
            np.zeros(4 * n_words + 1, dtype=np.uint16),
        )
        self.sc = np.zeros(k.N_SCALARS, dtype=i64)
        self.sc[k.S_BEST_FF] = self.sc[k.S_BEST_LM] = k.INF_H
        self.sc[k.S_PENDING] = k.PENDING_INIT
        self.greedy = weight is None
        self.w2 = 0 if weight is None else int(2 * weight)
        self.n_ops = n_ops

    def search(self) -> tuple[Any, ...]:
        return (*self._grown(), self.heads, self.tails, *self.scratch)

    def _grown(self) -> tuple[Any, ...]:
        return (
            self.pool,
            self.offsets,
            self.pool_acc,
            self.pool_parent,
            self.pool_op,
            self.pool_g,
            self.table,
            self.e_op,
            self.p_pos,
            self.run_pos,
            self.run_end,
            self.run_parent,
            self.run_next,
        )

    def nbytes(self) -> int:
        """What the search's arrays hold in the parts written (the task's and FF's are small beside them)."""
        k, sc = self.k, self.sc
        states = int(sc[k.S_STATES])
        per_state = self.pool_acc.itemsize * self.n_lm_words + 4 + 4 + 8 + 8
        return int(
            2 * self.offsets[states]
            + per_state * states
            + self.table.nbytes
            + 4 * sc[k.S_COUNT]
            + 8 * sc[k.S_PREF]
            + 24 * sc[k.S_RUNS]
            + self.heads.nbytes
            + self.tails.nbytes
        )

    def grow(self) -> None:
        """Grow what the kernel found full (it asked before changing anything)."""
        np, k, sc = self.np, self.k, self.sc
        n_states = int(sc[k.S_STATES])
        if n_states + 1 >= self.pool_parent.shape[0]:
            size = int(self.pool_parent.shape[0] * GROWTH) + 1
            self.offsets = _resized(np, self.offsets, size + 1)
            self.pool_acc = _resized(np, self.pool_acc, size)
            self.pool_parent = _resized(np, self.pool_parent, size)
            self.pool_op = _resized(np, self.pool_op, size)
            self.pool_g = _resized(np, self.pool_g, size)
        need = int(self.offsets[n_states]) + 4 * self.n_words + 1
        if need >= self.pool.shape[0]:
            self.pool = _resized(np, self.pool, int(need * GROWTH))
        if 2 * (n_states + 1) > self.table.shape[0]:
            self.table = np.full(2 * self.table.shape[0], -1, dtype=np.int64)
            k.rehash(self.table, self.pool, self.offsets, n_states)
        need = int(sc[k.S_COUNT]) + self.n_ops
        if need >= self.e_op.shape[0]:
            self.e_op = _resized(np, self.e_op, int(need * GROWTH))
        need = int(sc[k.S_PREF]) + self.n_ops
        if need >= self.p_pos.shape[0]:
            self.p_pos = _resized(np, self.p_pos, int(need * GROWTH))
        need = int(sc[k.S_RUNS]) + 4 * self.n_ops
        if need >= self.run_pos.shape[0]:
            size = int(need * GROWTH)
            self.run_pos = _resized(np, self.run_pos, size)
            self.run_end = _resized(np, self.run_end, size)
            self.run_parent = _resized(np, self.run_parent, size)
            self.run_next = _resized(np, self.run_next, size)

    def trace(self) -> list[int]:
        """The operators from the initial state to the goal state the kernel found."""
        sid = int(self.sc[self.k.S_GOAL])
        ops: list[int] = []
        while self.pool_parent[sid] >= 0:
            ops.append(int(self.pool_op[sid]))
            sid = int(self.pool_parent[sid])
        ops.reverse()
        return ops


def _resized(np: Any, array: Any, size: int) -> Any:
    """``array`` with its first axis grown to ``size`` (the new part zero)."""
    out = np.zeros((size, *array.shape[1:]), dtype=array.dtype)
    out[: array.shape[0]] = array
    return out


def compiled_lama_search(
    ct: CompiledTask,
    relaxed: Relaxed,
    lmcount: LandmarkCount,
    stats: Stats,
    *,
    weight: float | None = None,
    boost: int = 1000,
    max_expansions: float = INF,
    landmark_preferred: bool = True,
    bound: float = INF,
) -> Generator[Progress, None, tuple[list[int] | None, bool]]:
    """:func:`~alica.prophet.search.lama.lama_search` compiled (see the module docstring); the same results.

    Raises:
        ValueError: the task or the weight is not one the kernel covers (:func:`eligible`).
    """
    if not eligible(ct, relaxed, weight, None):
        raise ValueError("the compiled LAMA search covers STRIPS tasks without derived predicates or when-effects")
    room = None if stats.limits is None else stats.limits.room_bytes()
    if room is not None and stats.limits is not None and stats.limits.whole_process:
        room = max(0.0, room - numba_bytes(*KERNEL))
    arrays = _Arrays(ct, relaxed, lmcount, weight, room)
    k = arrays.k
    sc = arrays.sc
    stats.compiled = True
    limit = (1 << 62) if max_expansions == INF else int(max_expansions)
    while True:
        before_exp, before_eval = int(sc[k.S_EXPANDED]), int(sc[k.S_EVALS])
        step = max(1, min(stats.next_check, stats.next_progress) - stats.expansions)
        code = k.run(
            arrays.task,
            arrays.ff,
            arrays.lms,
            arrays.search(),
            sc,
            step,
            limit,
            boost,
            arrays.w2,
            arrays.greedy,
            landmark_preferred,
            (1 << 62) if bound == INF else int(bound),
        )
        stats.expansions += int(sc[k.S_EXPANDED]) - before_exp
        stats.evaluations += int(sc[k.S_EVALS]) - before_eval
        if code == k.FOUND:
            return arrays.trace(), False
        if code == k.EXHAUSTED:
            return None, True
        if code == k.LIMIT:
            return None, False
        if code == k.OVERFLOW:  # a weighted key past the lists' keys: the pure-Python search has no such bound
            return (
                yield from lama_search(
                    ct,
                    relaxed.ff_unit,
                    lmcount,
                    stats,
                    weight=weight,
                    boost=boost,
                    max_expansions=max_expansions,
                    landmark_preferred=landmark_preferred,
                    bound=bound,
                )
            )
        limits = stats.limits
        if limits is not None and (code == k.GROW or stats.expansions >= stats.next_check):
            # a growth copies arrays: at most what they hold, written anew beside the old ones
            held = arrays.nbytes() + (limits.resident() if code == k.GROW else 0)
            try:
                limits.check("searching", held, done=f"{stats.expansions} expansions")
            except LimitReached as exc:
                exc.expansions = stats.expansions
                raise
        if code == k.GROW:
            arrays.grow()
        if stats.progress_due():
            yield Progress(stats.expansions)


__all__ = ["compiled_lama_search", "eligible", "first_plan", "python_budget"]
