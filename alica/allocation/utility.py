"""U of one complete assignment, computed exactly.

Every input (priorities, summand values, weights) is taken as the exact
rational number it denotes (a float is a dyadic rational), and U is computed
with rational arithmetic. The tie rule's fixed-point key ``round(U * 10**9)``
is therefore exact: it does not depend on the order of a floating-point sum,
so every agent, whatever the order it enumerates things in, gets the same key.
The float returned is U correctly rounded.
"""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction

from alica.allocation.problem import (
    AllocationProblem,
    Team,
    cardinalities,
    exact,
    normaliser,
    prepare,
    priority,
    similarity_overlap,
    summand_function,
    summand_value,
)
from alica.model.plan import Plan

#: The fixed-point scale of the tie rule: utilities are compared as ``round(U * SCALE)``.
SCALE = 10**9

#: The utility of an invalid or vetoed assignment.
INVALID = -1.0


def fixed_point(numerator: int, denominator: int) -> int:
    """``round(numerator / denominator * SCALE)`` exactly, halves to even like :func:`round`.

    Args:
        numerator: any integer.
        denominator: a positive integer.
    """
    quotient, remainder = divmod(numerator * SCALE, denominator)
    twice = 2 * remainder
    if twice > denominator or (twice == denominator and quotient % 2 == 1):
        quotient += 1
    return quotient


def weight_sum(plan: Plan) -> Fraction:
    """w0 + sum(w_i) + ws, exactly; U is divided by it when it is positive."""
    u = plan.utility
    total = exact(u.priority_weight) + exact(u.similarity_weight)
    for s in u.summands:
        total += exact(s.weight)
    return total


def utility_fraction(
    problem: AllocationProblem, plan: Plan, entries: Mapping[str, str | None], team: Team | None = None
) -> Fraction | None:
    """U of a complete assignment as an exact fraction, ``None`` if invalid or vetoed.

    Args:
        problem: the problem (agents, roles, successes, old assignment, summands).
        plan: the plan the assignment is for.
        entries: agent -> entry point name, ``None`` for idle.
        team: the prepared team, if already computed.

    Raises:
        AllocationError: the problem is malformed.
    """
    team = team if team is not None else prepare(problem)
    fn = summand_function(problem, plan)
    n = len(team.agents)
    if len(entries) != n or any(a not in entries for a in team.agents):
        return None
    index = {ep.name: i for i, ep in enumerate(plan.entry_points)}
    lows, highs = cardinalities(problem, plan, n)
    counts = [0] * len(plan.entry_points)
    chosen: list[int | None] = []
    for agent in team.agents:
        name = entries[agent]
        if name is None:
            if not problem.allow_idle:
                return None
            chosen.append(None)
            continue
        if name not in index:
            return None
        counts[index[name]] += 1
        chosen.append(index[name])
    if any(not lo <= c <= hi for c, lo, hi in zip(counts, lows, highs)):
        return None
    active, counted = similarity_overlap(problem, plan, team)
    u = plan.utility
    pri = Fraction(0)
    sums = [Fraction(0)] * len(u.summands)
    kept = 0
    for i, (agent, j) in enumerate(zip(team.agents, chosen)):
        if active and counted[i] and problem.old is not None:
            was = problem.old.entry_of(agent)
            kept += (was is None) if j is None else (was == plan.entry_points[j].name)
        if j is None:
            continue
        ep = plan.entry_points[j]
        pref = exact(priority(problem, team, i, ep.task))
        if pref < 0:
            return None
        pri += pref
        if fn is not None:
            for k, s in enumerate(u.summands):
                value = summand_value(fn, plan, s, agent, ep)
                if value <= -1:
                    return None
                sums[k] += value
    norm = exact(normaliser(plan, n))
    total = exact(u.priority_weight) * pri / norm
    for s, value in zip(u.summands, sums):
        total += exact(s.weight) * value / norm
    overlap = sum(counted)
    if active and overlap:
        total += exact(u.similarity_weight) * Fraction(kept, overlap)
    weights = weight_sum(plan)
    return total / weights if weights > 0 else total


def utility(problem: AllocationProblem, plan: Plan, entries: Mapping[str, str | None]) -> float:
    """U of one complete assignment; -1 if it is invalid or vetoed.

    Invalid: an agent of the problem is missing or an unknown agent is listed,
    an entry point is unknown, an agent idles although idling is not allowed,
    or an entry point's count is outside its effective cardinality.

    Args:
        problem: the problem (agents, roles, successes, old assignment, summands).
        plan: the plan the assignment is for.
        entries: agent -> entry point name, ``None`` for idle.

    Returns:
        U, correctly rounded from its exact value, or -1.

    Raises:
        AllocationError: the problem is malformed, e.g. the plan has summands and
            the problem has no summand function.
    """
    value = utility_fraction(problem, plan, entries)
    return INVALID if value is None else float(value)
