"""FF with h_add supporters compiled by numba, for large ground tasks.

The pure-Python explorations of :class:`~alica.prophet.search.heuristics.Relaxed`
touch every reachable relaxed action once per evaluation: on a task with
tens of thousands of operators (parking) that is a few hundred evaluations
a second at best. Here the same generalised Dijkstra (h_add, supporters
kept) and the same relaxed plan extraction run as numba-compiled functions
over flat arrays (CSR lists of preconditions, adds and users per fact), and
give the same estimates and helpful operators as the pure-Python ones (the
same heap order, the same extraction order).

Loading numba and the kernels costs about 0.7 s per process (measured: 0.3 s
the import, 0.35 s the first call of a cached kernel; the compiled code is
cached on disk, ``cache=True``, and the first run on a machine compiles for a
few seconds more), which most tasks never earn back: a search done in half a
second does not wait for it. So :class:`SwitchingFF` starts in pure Python
and switches only once the compiled FF would have saved that much on the
evaluations done (a rent-or-buy rule, by the clock), and only if numba imports. On parking
(25,000 relaxed actions) the compiled FF does about 4,000 evaluations a second
against 75 in pure Python; on visitall (3,500) 3,600 against 360.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
from collections.abc import Callable, Sequence
from glob import glob
from time import perf_counter
from typing import Any

from alica.prophet.planner import Limits
from alica.prophet.search.heuristics import INF, Relaxed

JIT_LOAD_S = 0.65
"""What loading numba and the kernels costs a process (seconds; measured 0.6-0.7 s)."""
NUMBA_IMPORT_BYTES = 70 << 20
"""The resident memory numba's import adds to a process (measured 51-69 MB)."""
KERNEL_BYTES = 70 << 20
"""What the first call of a kernel module cached on disk adds (measured 54-61 MB: LLVM's code and tables)."""
COMPILE_BYTES = 160 << 20
"""What the first call adds where the disk cache is cold (a fresh install): numba compiles, and LLVM keeps
what it compiled with (measured 142 MB for the LAMA kernels with FF's, and 9 s)."""
NUMBA_BYTES = NUMBA_IMPORT_BYTES + KERNEL_BYTES
"""What loading numba and a cached kernel module adds to a process."""
JIT_CALL_S = 20e-6
"""The fixed cost of one compiled evaluation (the state's conversion, the calls), seconds."""

_kernels: tuple[Any, Any] | None = None


def _compile() -> tuple[Any, Any]:
    """The two kernels (h_add exploration, relaxed plan extraction), loaded once per process."""
    global _kernels
    if _kernels is None:
        from alica.prophet.search import ff_kernels

        _kernels = (ff_kernels.explore, ff_kernels.extract)
    return _kernels


def available() -> bool:
    """Whether numba can be imported here."""
    return importlib.util.find_spec("numba") is not None


def kernel_source(module: str) -> str | None:
    """The source file of kernel module ``alica.prophet.search.<module>``, found without importing it."""
    spec = importlib.util.find_spec(f"alica.prophet.search.{module}")
    return None if spec is None or spec.origin is None else os.path.realpath(spec.origin)


def kernels_cached(module: str, entry: str) -> bool:
    """Whether numba's disk cache holds the kernel ``entry`` of ``alica.prophet.search.<module>``, newer than
    its source. numba keeps it under ``NUMBA_CACHE_DIR`` where that is set, else beside the source
    (``__pycache__``) or, where that is read-only, in the user's cache folder; an index found nowhere counts
    as cold."""
    source = kernel_source(module)
    if source is None:
        return False
    folder = os.path.dirname(source)
    subpath = f"{os.path.basename(folder)}_{hashlib.sha1(folder.encode()).hexdigest()}"  # numba's naming
    if os.environ.get("NUMBA_CACHE_DIR"):
        folders = [os.path.join(os.environ["NUMBA_CACHE_DIR"], subpath)]
    else:
        user = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        folders = [os.path.join(folder, "__pycache__"), os.path.join(user, "numba", subpath)]
    name = f"{module}.{entry}-*.py{sys.version_info.major}{sys.version_info.minor}.nbi"
    try:
        mtime = os.stat(source).st_mtime
        return any(os.stat(index).st_mtime >= mtime for where in folders for index in glob(os.path.join(where, name)))
    except OSError:
        return False


def numba_bytes(module: str, entry: str) -> int:
    """The resident memory using kernel module ``module`` still adds to this process: numba's import unless
    it is loaded, and the module's first call (:data:`KERNEL_BYTES`, or :data:`COMPILE_BYTES` with a cold
    disk cache) unless it is loaded."""
    more = 0 if "numba" in sys.modules else NUMBA_IMPORT_BYTES
    if f"alica.prophet.search.{module}" not in sys.modules:
        more += KERNEL_BYTES if kernels_cached(module, entry) else COMPILE_BYTES
    return more


def room_for_numba(limits: Limits | None, module: str = "ff_kernels", entry: str = "explore") -> bool:
    """Whether using kernel module ``module`` fits under a memory bound on the whole process (``alica
    plan``'s): :func:`numba_bytes` left. Without such a bound, always."""
    if limits is None or not limits.whole_process:
        return True
    room = limits.room_bytes()
    return room is None or room >= numba_bytes(module, entry)


class CompiledFF:
    """FF with h_add supporters over ``relaxed``'s relaxed actions, compiled (see the module docstring).

    Args:
        relaxed: the relaxed task.
        costs: the relaxed actions' costs in the exploration (default: their own).
        unit: count the relaxed plan's actions (else sum their costs).
    """

    def __init__(self, relaxed: Relaxed, costs: Sequence[int] | None = None, unit: bool = True) -> None:
        import numpy as np

        self._np = np
        self.explore, self.extract = _compile()
        n = len(relaxed.is_goal)
        self.n = n
        self.nbytes = (n + 7) // 8
        r_pre, r_add = relaxed.r_pre, relaxed.r_add
        i64 = np.int64
        self.is_goal = np.array(relaxed.is_goal, dtype=np.bool_)
        self.goals = np.array([f for f in range(n) if relaxed.is_goal[f]], dtype=i64)
        self.npre = np.array([len(p) for p in r_pre], dtype=i64)
        self.pre_ptr = np.zeros(len(r_pre) + 1, dtype=i64)
        self.pre_ptr[1:] = np.cumsum(self.npre)
        self.pre_idx = np.array([f for p in r_pre for f in p], dtype=i64)
        self.add_ptr = np.zeros(len(r_add) + 1, dtype=i64)
        self.add_ptr[1:] = np.cumsum([len(a) for a in r_add])
        self.add_idx = np.array([f for a in r_add for f in a], dtype=i64)
        pre_of = relaxed.pre_of
        self.pre_of_ptr = np.zeros(n + 1, dtype=i64)
        self.pre_of_ptr[1:] = np.cumsum([len(u) for u in pre_of])
        self.pre_of_idx = np.array([a for u in pre_of for a in u], dtype=i64)
        self.cost = np.array(relaxed.r_cost if costs is None else costs, dtype=i64)
        self.zero = np.array(relaxed.zero, dtype=i64)
        # what the relaxed plan sums: 1 per operator and 0 per derived-predicate rule (as the pure-Python
        # extraction counts), or the exploration's costs
        self.counted = np.array(relaxed.r_unit, dtype=i64) if unit else self.cost
        self.r_op = relaxed.r_op
        self.goal_mask = relaxed.goal_mask
        self.cost_f = np.zeros(n, dtype=i64)
        self.sup = np.zeros(n, dtype=i64)
        self.unsat = np.zeros(len(r_pre), dtype=i64)
        self.acc = np.zeros(len(r_pre), dtype=i64)
        self.used = np.zeros(len(r_pre), dtype=np.bool_)
        self.done = np.zeros(n, dtype=np.bool_)
        self.out = np.zeros(max(1, n), dtype=i64)
        self.heap = np.zeros(n + len(self.add_idx) + 1, dtype=i64)  # every push improves a fact's cost

    def state_array(self, state: int) -> Any:
        """``state`` as a boolean array over the facts."""
        np = self._np
        raw = np.frombuffer(state.to_bytes(self.nbytes, "little"), dtype=np.uint8)
        return np.unpackbits(raw, bitorder="little")[: self.n].view(np.bool_)

    def __call__(self, state: int) -> tuple[float, list[int]]:
        gm = self.goal_mask
        if state & gm == gm:
            return 0, []
        s = self.state_array(state)
        ok = self.explore(
            s,
            self.is_goal,
            self.npre,
            self.pre_of_ptr,
            self.pre_of_idx,
            self.add_ptr,
            self.add_idx,
            self.cost,
            self.zero,
            self.cost_f,
            self.sup,
            self.unsat,
            self.acc,
            self.heap,
        )
        if not ok:
            return INF, []
        h, n_out = self.extract(
            s, self.goals, self.sup, self.pre_ptr, self.pre_idx, self.counted, False, self.used, self.done, self.out
        )
        r_op = self.r_op
        preferred: list[int] = []
        for a in self.out[:n_out].tolist():
            op = r_op[a]
            if op >= 0 and op not in preferred:
                preferred.append(op)
        return int(h), preferred


class SwitchingFF:
    """An FF evaluator that starts in pure Python and moves to :class:`CompiledFF` once that pays.

    Both give the same estimates and helpful operators, so where the switch
    happens changes the run's speed only, never its result (which is why it
    may go by the clock). It is a rent-or-buy rule: the switch comes once the
    compiled FF would have saved as much as loading numba costs
    (:data:`JIT_LOAD_S`) on the evaluations done so far, a compiled evaluation
    taking about :data:`JIT_CALL_S` plus a twentieth of the pure-Python time
    (measured: a pure-Python evaluation costs 0.2-0.75 microseconds per relaxed
    action on driverlog, depot, elevators, satellite, visitall, pipesworld and
    parking). Parking (13 ms an evaluation) switches after about 50
    evaluations, visitall's larger grids (1 ms) after about 650, driverlog (90
    microseconds) after about 10,000, which few of its searches need; tasks
    whose evaluations take less than ``JIT_CALL_S`` never switch.

    Args:
        relaxed: the relaxed task.
        python: the pure-Python evaluator it stands for (``relaxed.ff_add_unit`` or ``relaxed.ff_unit``).
        costs: the exploration's costs of that evaluator (``None``: the relaxed actions' own).
        load_s: the savings (seconds) before the switch.
        limits: the run's limits: no switch where loading numba would pass a bound on the whole
            process (:func:`room_for_numba`).
    """

    def __init__(
        self,
        relaxed: Relaxed,
        python: Callable[[int], tuple[float, list[int]]],
        costs: Sequence[int] | None = None,
        load_s: float = JIT_LOAD_S,
        limits: Limits | None = None,
    ) -> None:
        self.relaxed = relaxed
        self.limits = limits
        self.python = python
        self.costs = costs
        self.compiled: CompiledFF | None = None
        self._left = load_s if available() else INF
        self.evaluate = python

    def __call__(self, state: int) -> tuple[float, list[int]]:
        if self.compiled is not None or self._left == INF:
            return self.evaluate(state)
        start = perf_counter()
        result = self.python(state)
        self._left -= 0.95 * (perf_counter() - start) - JIT_CALL_S
        if self._left <= 0:
            if not room_for_numba(self.limits):
                self._left = INF
                return result
            try:
                compiled = CompiledFF(self.relaxed, self.costs, unit=True)
                compiled(state)  # numba compiles (or loads) here: a failure keeps the pure-Python FF
            except Exception:  # any numba or LLVM error: the search goes on in pure Python
                self._left = INF
                return result
            self.compiled = compiled
            self.evaluate = compiled
        return result


__all__ = [
    "COMPILE_BYTES",
    "JIT_CALL_S",
    "JIT_LOAD_S",
    "KERNEL_BYTES",
    "NUMBA_BYTES",
    "NUMBA_IMPORT_BYTES",
    "CompiledFF",
    "SwitchingFF",
    "available",
    "kernel_source",
    "kernels_cached",
    "numba_bytes",
    "room_for_numba",
]
