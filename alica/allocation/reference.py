"""The reference allocation: enumerate every complete assignment.

Exponential; for tests and small problems. It defines what
:func:`~alica.allocation.allocate` must return, with the simplest code that
applies the tie rule: candidates in plan order, vectors in lexicographic
order, and a later assignment replaces the best only with a strictly larger
fixed-point utility.
"""

from __future__ import annotations

from itertools import product

from alica.allocation.assignment import AllocationResult, Assignment
from alica.allocation.explain import explain
from alica.allocation.problem import AllocationProblem, cardinalities, prepare, summand_function
from alica.allocation.table import PlanTable, build_table
from alica.allocation.utility import fixed_point


def exhaustive(problem: AllocationProblem) -> AllocationResult:
    """The best assignment by enumeration.

    Args:
        problem: the allocation problem.

    Returns:
        The optimal assignment under the tie rule and the number of complete
        assignments enumerated, or no assignment and why.

    Raises:
        AllocationError: the problem is malformed.
    """
    team = prepare(problem)
    n = len(team.agents)
    for plan in problem.plans:
        summand_function(problem, plan)
    tables: list[PlanTable | None] = []
    best: tuple[int, PlanTable, tuple[int, ...], int] | None = None
    enumerated = 0
    for index, plan in enumerate(problem.plans):
        lows, highs = cardinalities(problem, plan, n)
        if sum(lows) > n:
            tables.append(None)
            continue
        table = build_table(problem, team, index, plan)
        tables.append(table)
        choices = [[j for j, cell in enumerate(row) if cell is not None] for row in table.cells]
        for vector in product(*choices):
            enumerated += 1
            counts = [0] * (len(plan.entry_points) + 1)
            for j in vector:
                counts[j] += 1
            if any(not lo <= c <= hi for c, lo, hi in zip(counts, lows, highs)):
                continue
            value = table.value(vector)
            if value is None:  # pragma: no cover - choices hold allowed cells only
                continue
            key = fixed_point(value, table.denominator)
            if best is None or key > best[0]:
                best = (key, table, vector, value)
    if best is None:
        return AllocationResult(None, enumerated, explain(problem, team, tables))
    _, table, vector, value = best
    names = [None if j == table.idle else table.plan.entry_points[j].name for j in vector]
    assignment = Assignment(table.plan.name, tuple(zip(team.agents, names)), value / table.denominator)
    return AllocationResult(assignment, enumerated)
