"""Per-plan tables of exact integer contributions: U as a sum over agents.

U is additive over agents: ``U = sum_a c(a, e(a)) / D`` for one integer
denominator ``D`` per plan, where ``c(a, e)`` is agent ``a``'s share of the
priority term, the summand terms and the similarity term when it takes entry
point ``e`` (or idles). The search and the reference both add these integers,
so they compute U exactly, exactly as :func:`~alica.allocation.utility` does
with fractions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from alica.allocation.problem import (
    AllocationProblem,
    Team,
    cardinalities,
    exact,
    normaliser,
    priority,
    similarity_overlap,
    summand_function,
    summand_value,
)
from alica.allocation.utility import weight_sum
from alica.model.plan import Plan


@dataclass(frozen=True, slots=True)
class Veto:
    """Why an agent cannot take an entry point.

    Args:
        agent: index of the agent in the team.
        entry: index of the entry point in the plan.
        reason: e.g. ``priority -1`` or ``summand 'distance' = -1``.
    """

    agent: int
    entry: int
    reason: str


@dataclass(frozen=True, slots=True)
class PlanTable:
    """One candidate plan, ready to search.

    Args:
        index: the plan's position among the candidates.
        plan: the plan.
        lows: effective minimum per entry point.
        highs: effective maximum per entry point, capped at the team size.
        denominator: D, the common denominator of all contributions.
        cells: ``cells[a][j]``: the contribution of agent ``a`` at entry point
            ``j``; column ``len(plan.entry_points)`` is idle. ``None``: not
            allowed (vetoed, no capacity at all, or idling not allowed).
        vetoes: the vetoed agent-entry point pairs, for explanations.
    """

    index: int
    plan: Plan
    lows: tuple[int, ...]
    highs: tuple[int, ...]
    denominator: int
    cells: tuple[tuple[int | None, ...], ...]
    vetoes: tuple[Veto, ...]

    @property
    def idle(self) -> int:
        """The column index of idling."""
        return len(self.plan.entry_points)

    def value(self, vector: tuple[int, ...]) -> int | None:
        """The numerator of U for a complete vector of columns, ``None`` if a cell is not allowed."""
        total = 0
        for row, j in zip(self.cells, vector):
            cell = row[j]
            if cell is None:
                return None
            total += cell
        return total


def ratio(value: float) -> tuple[int, int]:
    """``value`` as ``(numerator, denominator)``, exactly.

    Raises:
        AllocationError: the value is not a finite number.
    """
    if isinstance(value, float):
        try:
            return value.as_integer_ratio()
        except (ValueError, OverflowError):
            pass
    elif isinstance(value, int):
        return value, 1
    fraction = exact(value)
    return fraction.numerator, fraction.denominator


def _coefficient(value: Fraction, denominator: int) -> int:
    return value.numerator * (denominator // value.denominator)


def build_table(problem: AllocationProblem, team: Team, index: int, plan: Plan) -> PlanTable:
    """The integer contribution table of one plan.

    Args:
        problem: the problem.
        team: its prepared team.
        index: the plan's position among the candidates.
        plan: the plan.

    Raises:
        AllocationError: a summand function is missing or returned a non-number.
    """
    n = len(team.agents)
    eps = plan.entry_points
    lows, highs = cardinalities(problem, plan, n)
    fn = summand_function(problem, plan)
    u = plan.utility
    summands = u.summands
    active, counted = similarity_overlap(problem, plan, team)
    old = problem.old

    # Raw values as exact (numerator, denominator) pairs; None where vetoed.
    pref_cache: dict[tuple[str, int], tuple[tuple[int, int] | None, str]] = {}
    prefs: list[list[tuple[int, int] | None]] = []
    svals: list[list[tuple[tuple[int, int], ...] | None]] = []
    vetoes: list[Veto] = []
    for a, agent in enumerate(team.agents):
        prow: list[tuple[int, int] | None] = []
        srow: list[tuple[tuple[int, int], ...] | None] = []
        for j, ep in enumerate(eps):
            key = (team.roles[a], j)
            cached = pref_cache.get(key)
            if cached is None:
                raw = priority(problem, team, a, ep.task)
                pair = ratio(raw)
                cached = (pair, f"priority {raw:g}") if pair[0] < 0 else (pair, "")
                pref_cache[key] = cached
            pref, reason = cached
            values: tuple[tuple[int, int], ...] = ()
            if not reason and fn is not None:
                pairs = []
                for s in summands:
                    value = summand_value(fn, plan, s, agent, ep)
                    if value <= -1:
                        reason = f"summand '{s.name}' = {float(value):g}"
                        break
                    pairs.append((value.numerator, value.denominator))
                values = tuple(pairs)
            if reason:
                vetoes.append(Veto(a, j, reason))
                prow.append(None)
                srow.append(None)
            else:
                prow.append(pref)
                srow.append(values)
        prefs.append(prow)
        svals.append(srow)

    pref_scale = math.lcm(1, *{p[1] for row in prefs for p in row if p is not None})
    sum_scales = [
        math.lcm(1, *{vals[k][1] for row in svals for vals in row if vals is not None}) for k in range(len(summands))
    ]
    weights = weight_sum(plan)
    divisor = weights if weights > 0 else Fraction(1)
    norm = exact(normaliser(plan, n))
    overlap = sum(counted)
    alpha = exact(u.priority_weight) / (norm * pref_scale * divisor)
    betas = [exact(s.weight) / (norm * scale * divisor) for s, scale in zip(summands, sum_scales)]
    gamma = exact(u.similarity_weight) / (overlap * divisor) if active and overlap else Fraction(0)
    denominator = math.lcm(alpha.denominator, gamma.denominator, *(b.denominator for b in betas))
    a_int = _coefficient(alpha, denominator)
    pref_factors = {den: a_int * (pref_scale // den) for den in {p[1] for row in prefs for p in row if p}}
    b_ints = [_coefficient(b, denominator) for b in betas]
    g_int = _coefficient(gamma, denominator)

    cells: list[tuple[int | None, ...]] = []
    for a, agent in enumerate(team.agents):
        was: str | None = None
        counts_old = active and counted[a] and old is not None
        if counts_old and old is not None:
            was = old.entry_of(agent)
        row: list[int | None] = []
        for j, ep in enumerate(eps):
            pref = prefs[a][j]
            vals = svals[a][j]
            if pref is None or vals is None or highs[j] == 0:
                row.append(None)
                continue
            cell = pref[0] * pref_factors[pref[1]]
            for b_int, (num, den), scale in zip(b_ints, vals, sum_scales):
                cell += b_int * num * (scale // den)
            if counts_old and was == ep.name:
                cell += g_int
            row.append(cell)
        if problem.allow_idle:
            row.append(g_int if counts_old and was is None else 0)
        else:
            row.append(None)
        cells.append(tuple(row))
    return PlanTable(index, plan, lows, highs, denominator, tuple(cells), tuple(vetoes))
