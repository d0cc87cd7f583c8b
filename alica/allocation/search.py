"""The exact best assignment by best-first (A*) search over partial assignments.

A node fixes the first ``k`` agents (sorted by id) of one candidate plan: its
*prefix* is their column vector (entry point index; ``len(entry_points)`` for
idle). Its children fix agent ``k`` at each column it may take. A node's key
is the largest fixed-point utility ``round(U * 10**9)`` among its valid
completions, or an upper bound of it; a complete node's key is its own.

Pop order: highest key, then earlier plan, then lexicographically smallest
prefix. Claim: the first complete node popped is the optimum under the tie
rule (highest key, earlier plan, smallest column vector).

Proof. Let g* be the optimum. Until g* is popped, some node n on g*'s path
(g* itself or an ancestor) is on the frontier: the roots are pushed and
expanding a node of the path pushes the next one, because nodes are dropped
only (a) without a valid completion, (b) with a key below that of a known
valid assignment (so below g*'s), or (c) at a column larger than the column
of the parent's basis (see below): the kept child then holds a completion
with the parent's key, which is >= the key of everything in the larger
child's subtree, and which is lexicographically smaller, so nothing there
beats it and g* is not there. Keys are admissible: key(n) >= key(g*).
Suppose a complete node g != g* is popped while n waits. Then key(g) >=
key(n) >= key(g*) >= key(g) (g* is optimal), so the keys are equal; then
plan(g) <= plan(n) = plan(g*), and a smaller plan would make g better than
g*, so the plans are equal. Frontier nodes are never ancestors of each other
(a node leaves the frontier when it is expanded, before its children enter)
and g is complete, so neither prefix extends the other: they differ at a
position both have, and the first such position i decides the pop order:
g[i] < n[i] = g*[i]. So g's vector is lexicographically smaller than g*'s and
g beats g* on the tie rule: a contradiction.

Keys. Each plan is first solved without the tie rule (:mod:`alica.allocation.flow`):
its exact best value, an optimal assignment (a *basis*) and dual prices. The
best key achieved over the plans is a floor: nodes below it are dropped, and
plans whose optimistic key is below it are not solved at all. Every node
carries a basis, an optimal assignment among its completions, so its key is
exact: the child that keeps the parent basis' column inherits it; a child at
a smaller column first passes the cheap bound of :mod:`alica.allocation.bound`
(O(entry points), from tables built once per plan) and then gets its own basis
by one longest path (:func:`~alica.allocation.flow.fix`). With exact keys the
winning plan is expanded straight down: one expansion per agent.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

from alica.allocation.assignment import AllocationResult, Assignment
from alica.allocation.bound import Suffix, node_key, suffix_tables
from alica.allocation.explain import explain
from alica.allocation.flow import Basis, Relaxation, fix, move_arcs, solve
from alica.allocation.problem import AllocationProblem, cardinalities, prepare, summand_function
from alica.allocation.table import PlanTable, build_table
from alica.allocation.utility import fixed_point
from alica.model.plan import Plan

#: A frontier entry: (-key, plan index, prefix, value of the prefix, agents per entry point, basis).
_Node = tuple[int, int, tuple[int, ...], int, tuple[int, ...], Basis]


@dataclass(slots=True)
class _Candidate:
    """A plan being searched: its table, relaxation and (once needed) bound tables."""

    table: PlanTable
    relaxation: Relaxation
    suffix: Suffix | None = None

    def bounds(self) -> Suffix:
        """The bound tables, built on first use."""
        if self.suffix is None:
            self.suffix = suffix_tables(self.table, self.relaxation.prices)
        return self.suffix


def skipped(problem: AllocationProblem, plan: Plan, agents: int) -> bool:
    """Whether ``plan`` is skipped: its effective minima need more than ``agents`` agents."""
    return sum(cardinalities(problem, plan, agents)[0]) > agents


def _optimistic(table: PlanTable) -> int | None:
    """The key of every agent's best allowed contribution: no assignment of the plan is above it.

    Returns:
        The key, ``None`` if some agent has no allowed column.
    """
    total = 0
    for row in table.cells:
        allowed = [cell for cell in row if cell is not None]
        if not allowed:
            return None
        total += max(allowed)
    return fixed_point(total, table.denominator)


def _solve(tables: list[PlanTable | None]) -> tuple[list[_Candidate | None], int | None]:
    """Solve the candidates' relaxations, best optimistic key first.

    A plan whose optimistic key is below the best key already achieved cannot
    win and is not solved.

    Returns:
        Per plan its candidate (``None``: skipped, infeasible or beaten) and the
        best key achieved (``None`` if no plan has a valid assignment).
    """
    candidates: list[_Candidate | None] = [None] * len(tables)
    hopes = [
        (key, index)
        for index, table in enumerate(tables)
        if table is not None and (key := _optimistic(table)) is not None
    ]
    floor: int | None = None
    for hope, index in sorted(hopes, key=lambda pair: (-pair[0], pair[1])):
        if floor is not None and hope < floor:
            break
        table = tables[index]
        relaxation = solve(table) if table is not None else None
        if table is None or relaxation is None:
            continue
        candidates[index] = _Candidate(table, relaxation)
        key = fixed_point(relaxation.basis.total, table.denominator)
        floor = key if floor is None else max(floor, key)
    return candidates, floor


def allocate(problem: AllocationProblem) -> AllocationResult:
    """The exact best assignment over all candidate plans.

    Equal to :func:`~alica.allocation.exhaustive` on every input, much faster.

    Args:
        problem: the allocation problem.

    Returns:
        The optimal assignment and the number of nodes expanded, or no
        assignment and why.

    Raises:
        AllocationError: the problem is malformed (see :func:`~alica.allocation.problem.prepare`).
    """
    team = prepare(problem)
    n = len(team.agents)
    for plan in problem.plans:
        summand_function(problem, plan)
    tables: list[PlanTable | None] = [
        None if skipped(problem, plan, n) else build_table(problem, team, index, plan)
        for index, plan in enumerate(problem.plans)
    ]
    candidates, floor = _solve(tables)
    if floor is None:
        return AllocationResult(None, 0, explain(problem, team, tables))
    frontier: list[_Node] = []
    for index, candidate in enumerate(candidates):
        if candidate is None:
            continue
        basis = candidate.relaxation.basis
        key = fixed_point(basis.total, candidate.table.denominator)
        if key >= floor:
            frontier.append((-key, index, (), 0, (0,) * len(candidate.table.plan.entry_points), basis))
    heapq.heapify(frontier)
    allow_idle = problem.allow_idle
    expansions = 0
    while frontier:
        negative, index, prefix, value, counts, basis = heapq.heappop(frontier)
        candidate = candidates[index]
        if candidate is None:  # pragma: no cover - only candidates have nodes
            continue
        table = candidate.table
        depth = len(prefix)
        if depth == n:
            names = [None if j == table.idle else table.plan.entry_points[j].name for j in prefix]
            assignment = Assignment(table.plan.name, tuple(zip(team.agents, names)), value / table.denominator)
            return AllocationResult(assignment, expansions)
        expansions += 1
        kept = basis.columns[depth]
        highs = table.highs
        arcs = None
        for j, cell in enumerate(table.cells[depth][: kept + 1]):
            if cell is None:
                continue
            if j < len(counts):
                if counts[j] >= highs[j]:
                    continue
                child = counts[:j] + (counts[j] + 1,) + counts[j + 1 :]
            else:
                child = counts
            path = prefix + (j,)
            if j == kept:
                heapq.heappush(frontier, (negative, index, path, value + cell, child, basis))
                continue
            bound = node_key(table, candidate.bounds(), depth + 1, child, value + cell, allow_idle)
            if bound is None or bound < floor:
                continue
            if arcs is None:
                arcs = move_arcs(table, basis.columns, range(depth + 1, n), len(table.cells[depth]))
            fixed = fix(table, candidate.relaxation, basis, depth, j, arcs)
            if fixed is None:
                continue
            key = fixed_point(fixed.total, table.denominator)
            if key >= floor:
                heapq.heappush(frontier, (-key, index, path, value + cell, child, fixed))
    return AllocationResult(None, expansions, explain(problem, team, tables))  # pragma: no cover
