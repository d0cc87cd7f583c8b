"""Exact search over finite (and integer) variables: branch and bound with forward checking.

The constraints and utilities are ground into pieces (:mod:`alica.solver.ground`)
and every piece over a small enough product of domains becomes a table
(:mod:`alica.solver.tables`). Tables over the same variables are merged (hard ones
with ``and``, utilities with ``+``). Then:

* **Filtering.** One-variable tables cut the domains before the search. After each
  assignment, every hard table with one variable left unassigned cuts that
  variable's domain (forward checking); an empty domain ends the branch.
* **Bound.** The utility reached so far plus, for every table not yet fully
  assigned, its largest entry over the values still allowed. It never
  underestimates what a branch can reach (admissible), so a branch whose bound is
  not above the best found is cut without losing the optimum.
* **Order.** The variable with the fewest values left goes first (ties: the
  problem's order); its values are tried best utility first, so the first
  solution is already a good one.
* Pieces too large for a table (or reading continuous variables, see
  :mod:`alica.solver.mixed`) are checked, and added, once all their finite
  variables are assigned; a utility piece that has no table counts as unbounded
  until then, which weakens the bound.

The order of the search depends only on the problem, never on the clock: the time
limit only cuts it short, and then the best assignment so far is returned with
``optimal=False``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from alica.solver.ground import Piece, Reading, Variables, check_piece, value_of
from alica.solver.problem import Finite, Integer, ProblemError, Var
from alica.solver.tables import TABLE_LIMIT, TableMaker

#: A leaf hook: given the finite assignment, the extra utility and values it adds, or None when it fails.
Leaf = Callable[[dict[Var, object]], tuple[float, dict[Var, object]] | None]

_EPS = 1e-9


def finite_values(var: Var) -> np.ndarray:
    """The values of a finite or integer variable, as an object array."""
    domain = var.domain
    if isinstance(domain, Finite):
        values: Sequence[object] = domain.values
    elif isinstance(domain, Integer):
        if domain.high - domain.low > TABLE_LIMIT:
            raise ProblemError(f"integer variable {var!r} has more than {TABLE_LIMIT} values")
        values = range(domain.low, domain.high + 1)
    else:
        raise ProblemError(f"{var!r} is not a finite variable")
    out = np.empty(len(values), dtype=object)
    for i, value in enumerate(values):
        out[i] = value
    return out


@dataclass
class Outcome:
    """What the search found."""

    values: dict[Var, object] | None
    utility: float
    complete: bool
    nodes: int
    extra: dict[Var, object] = field(default_factory=dict)


class _Timeout(Exception):
    pass


class FiniteSearch:
    """Branch and bound over the finite variables of ground pieces.

    Args:
        variables: the finite variables searched.
        hard: ground constraint pieces.
        soft: ground utility pieces.
        names: the problem's variables by name.
        reading: belief base of the problem (with any fixed values).
        registry: registered functions.
        open_vars: variables not searched here (continuous); pieces reading them go to ``leaf``.
        leaf: called at every full assignment that passes the finite checks.
    """

    def __init__(
        self,
        variables: Sequence[Var],
        hard: Sequence[Piece],
        soft: Sequence[Piece],
        names: Variables,
        reading: Reading,
        registry: object,
        *,
        open_vars: frozenset[Var] = frozenset(),
        leaf: Leaf | None = None,
    ) -> None:
        self.vars = list(variables)
        self.index = {v: i for i, v in enumerate(self.vars)}
        shared: dict[object, np.ndarray] = {}
        self.domains: dict[Var, np.ndarray] = {}
        for v in self.vars:  # equal domains share one array, so tables memoise across variables
            try:
                if v.domain not in shared:
                    shared[v.domain] = finite_values(v)
                self.domains[v] = shared[v.domain]
            except TypeError:  # unhashable values
                self.domains[v] = finite_values(v)
        self.reading = reading
        self.registry = registry
        self.leaf = leaf
        maker = TableMaker(reading, registry, names, self.domains)  # type: ignore[arg-type]
        self.infeasible_reason = ""
        n = len(self.vars)
        self.masks = [np.ones(len(self.domains[v]), dtype=bool) for v in self.vars]
        hard_tables: dict[tuple[int, ...], np.ndarray] = {}
        soft_tables: dict[tuple[int, ...], np.ndarray] = {}
        self.constant = 0.0
        self.late_hard: list[tuple[tuple[int, ...], Piece]] = []
        self.late_soft: list[tuple[tuple[int, ...], Piece]] = []
        for pieces, tables, utility in ((hard, hard_tables, False), (soft, soft_tables, True)):
            for piece in pieces:
                if any(d in open_vars for d in piece.deps):
                    continue  # the leaf hook checks it
                axes = tuple(self.index[d] for d in piece.deps)
                size = int(np.prod([len(self.domains[self.vars[a]]) for a in axes])) if axes else 1
                if size > TABLE_LIMIT:
                    (self.late_soft if utility else self.late_hard).append((axes, piece))
                    continue
                table = maker.table(piece, [self.vars[a] for a in axes], utility=utility)
                if axes in tables:
                    tables[axes] = tables[axes] + table if utility else tables[axes] & table
                else:
                    tables[axes] = table
        self.fallbacks = maker.fallbacks
        self.feasible_at_all = True
        for axes, table in hard_tables.items():
            if not axes:
                if not bool(table):
                    self.feasible_at_all = False
                    self.infeasible_reason = "a constraint without variables is false"
            elif len(axes) == 1:
                self.masks[axes[0]] &= table
        if not all(m.any() for m in self.masks):
            self.feasible_at_all = False
            empty = [repr(self.vars[i]) for i, m in enumerate(self.masks) if not m.any()]
            self.infeasible_reason = (
                self.infeasible_reason or f"no value of {', '.join(empty)} satisfies its constraints"
            )
        self.unary = [np.zeros(len(self.domains[v])) for v in self.vars]
        self.multi_soft: list[tuple[tuple[int, ...], np.ndarray]] = []
        for axes, table in soft_tables.items():
            if not axes:
                self.constant += float(table)
            elif len(axes) == 1:
                self.unary[axes[0]] = self.unary[axes[0]] + table
            else:
                self.multi_soft.append((axes, table))
        self.multi_hard = [(axes, table) for axes, table in hard_tables.items() if len(axes) > 1]
        self.hard_of: list[list[tuple[tuple[int, ...], np.ndarray]]] = [[] for _ in range(n)]
        for axes, table in self.multi_hard:
            for a in axes:
                self.hard_of[a].append((axes, table))
        self.late_hard_at: list[list[Piece]] = [[] for _ in range(n + 1)]
        self.late_soft_at: list[list[Piece]] = [[] for _ in range(n + 1)]
        self.unbounded = bool(self.late_soft) or leaf is not None
        self.best: dict[Var, object] | None = None
        self.best_extra: dict[Var, object] = {}
        self.best_utility = -np.inf
        self.nodes = 0

    # -- search --------------------------------------------------------

    def run(self, deadline: float, clock: Callable[[], float]) -> Outcome:
        """Search until done or ``deadline`` (a ``clock()`` time)."""
        if not self.feasible_at_all:
            return Outcome(None, float("nan"), True, 0)
        assigned = [-1] * len(self.vars)
        self.deadline, self.clock = deadline, clock
        try:
            self._branch(assigned, [m.copy() for m in self.masks], self.constant)
            complete = True
        except _Timeout:
            complete = False
        return Outcome(
            self.best,
            self.best_utility if self.best is not None else float("nan"),
            complete,
            self.nodes,
            self.best_extra,
        )

    def _bound(self, assigned: list[int], masks: list[np.ndarray]) -> float:
        if self.unbounded:
            return np.inf
        total = 0.0
        for i, a in enumerate(assigned):
            if a < 0:
                total += float(self.unary[i][masks[i]].max())
        for axes, table in self.multi_soft:
            index = tuple(np.array([assigned[a]]) if assigned[a] >= 0 else np.flatnonzero(masks[a]) for a in axes)
            total += float(table[np.ix_(*index)].max())
        return total

    def _multi_value(self, assigned: list[int]) -> float:
        return sum(float(table[tuple(assigned[a] for a in axes)]) for axes, table in self.multi_soft)

    def _branch(self, assigned: list[int], masks: list[np.ndarray], gained: float) -> None:
        self.nodes += 1
        if self.nodes % 256 == 0 and self.clock() > self.deadline:
            raise _Timeout
        free = [i for i, a in enumerate(assigned) if a < 0]
        if not free:
            self._leaf(assigned, gained)
            return
        var = min(free, key=lambda i: (int(masks[i].sum()), i))
        candidates = np.flatnonzero(masks[var])
        gains = self.unary[var][candidates]
        order = candidates[np.argsort(-gains, kind="stable")]
        others = 0.0
        if not self.unbounded and not self.multi_soft:
            others = sum(float(self.unary[i][masks[i]].max()) for i in free if i != var)
        for value in order:
            value = int(value)
            here = gained + float(self.unary[var][value])
            if not self.unbounded and not self.multi_soft and here + others <= self.best_utility + _EPS:
                break  # values come best first: no later one can do better
            assigned[var] = value
            child = self._filter(var, value, assigned, masks)
            if child is not None and (self.unbounded or here + self._bound(assigned, child) > self.best_utility + _EPS):
                self._branch(assigned, child, here)
            assigned[var] = -1

    def _filter(self, var: int, value: int, assigned: list[int], masks: list[np.ndarray]) -> list[np.ndarray] | None:
        child = list(masks)
        for axes, table in self.hard_of[var]:
            open_axes = [a for a in axes if assigned[a] < 0]
            if len(open_axes) > 1:
                continue
            index = tuple(slice(None) if assigned[a] < 0 else assigned[a] for a in axes)
            cut = table[index]
            if not open_axes:
                if not bool(cut):
                    return None
                continue
            target = open_axes[0]
            new = child[target] & cut
            if not new.any():
                return None
            child[target] = new
        return child

    def _leaf(self, assigned: list[int], gained: float) -> None:
        values: dict[Var, object] = {v: self.domains[v][assigned[i]] for i, v in enumerate(self.vars)}
        total = gained + self._multi_value(assigned)
        if self.late_hard or self.late_soft:
            reading = self.reading.with_values(values)
            for _, piece in self.late_hard:
                if not check_piece(piece, reading, self.registry):  # type: ignore[arg-type]
                    return
            total += sum((value_of(piece, reading, self.registry) for _, piece in self.late_soft), 0.0)  # type: ignore[arg-type]
        extra: dict[Var, object] = {}
        if self.leaf is not None:
            found = self.leaf(values)
            if found is None:
                return
            more, extra = found
            total += more
        if total > self.best_utility + _EPS or self.best is None:
            self.best, self.best_utility, self.best_extra = values, total, extra
