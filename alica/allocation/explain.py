"""Why no assignment exists: messages a person can act on."""

from __future__ import annotations

from itertools import combinations

from alica.allocation.problem import AllocationProblem, Team, cardinalities
from alica.allocation.table import PlanTable
from alica.model.plan import Plan

#: Hall's condition is checked over subsets of at most this many entry points with a minimum.
_MAX_SUBSET_ENTRIES = 12


def _agent(team: Team, a: int) -> str:
    return f"{team.agents[a]} ({team.roles[a]})"


def _names(team: Team, agents: list[int]) -> str:
    return ", ".join(_agent(team, a) for a in agents) if agents else "none"


def _vetoed_at(team: Team, table: PlanTable, entry: int) -> str:
    parts = [f"{_agent(team, v.agent)}: {v.reason}" for v in table.vetoes if v.entry == entry]
    return "; ".join(parts)


def _skipped(problem: AllocationProblem, team: Team, plan: Plan) -> str:
    lows, _ = cardinalities(problem, plan, len(team.agents))
    parts = ", ".join(f"{ep.name} {lo}" for ep, lo in zip(plan.entry_points, lows) if lo)
    agents = ", ".join(team.agents) or "none"
    count = len(team.agents)
    return (
        f"needs at least {sum(lows)} agents (minimum per entry point, after successes: {parts}) "
        f"but only {count} {'is' if count == 1 else 'are'} available ({agents}); add agents or lower the minima"
    )


def _stuck_agents(problem: AllocationProblem, team: Team, table: PlanTable) -> list[str]:
    messages = []
    for a, row in enumerate(table.cells):
        if any(cell is not None for cell in row):
            continue
        reasons = []
        for j, ep in enumerate(table.plan.entry_points):
            veto = next((v.reason for v in table.vetoes if v.agent == a and v.entry == j), "")
            reasons.append(f"{ep.name}: {veto or 'no places left'}")
        messages.append(
            f"agent {_agent(team, a)} can take no entry point and idling is not allowed "
            f"({'; '.join(reasons) or 'the plan has no entry points'})"
        )
    return messages


def _unfillable(team: Team, table: PlanTable) -> list[str]:
    messages = []
    for j, ep in enumerate(table.plan.entry_points):
        need = table.lows[j]
        able = [a for a, row in enumerate(table.cells) if row[j] is not None]
        if need > len(able):
            vetoed = _vetoed_at(team, table, j)
            messages.append(
                f"entry point '{ep.name}' (task {ep.task}) needs {need} agent(s) but only {len(able)} "
                f"can take it ({_names(team, able)})" + (f"; vetoed: {vetoed}" if vetoed else "")
            )
    return messages


def _hall(team: Team, table: PlanTable) -> list[str]:
    needed = [j for j, lo in enumerate(table.lows) if lo]
    if len(needed) > _MAX_SUBSET_ENTRIES:
        return []
    for size in range(2, len(needed) + 1):
        for subset in combinations(needed, size):
            able = [a for a, row in enumerate(table.cells) if any(row[j] is not None for j in subset)]
            need = sum(table.lows[j] for j in subset)
            if need > len(able):
                names = ", ".join(f"'{table.plan.entry_points[j].name}'" for j in subset)
                vetoes = "; ".join(f"{table.plan.entry_points[j].name}: {_vetoed_at(team, table, j)}" for j in subset)
                return [
                    f"entry points {names} need {need} agents together but only {len(able)} can take "
                    f"any of them ({_names(team, able)}); vetoed: {vetoes}"
                ]
    return []


def _capacity(problem: AllocationProblem, team: Team, table: PlanTable) -> list[str]:
    if problem.allow_idle or sum(table.highs) >= len(team.agents):
        return []
    parts = ", ".join(f"{ep.name} {h}" for ep, h in zip(table.plan.entry_points, table.highs))
    return [
        f"idling is not allowed, so all {len(team.agents)} agents must take an entry point, "
        f"but the entry points take at most {sum(table.highs)} (maximum per entry point, after successes: {parts})"
    ]


def plan_reason(problem: AllocationProblem, team: Team, plan: Plan, table: PlanTable | None) -> str:
    """Why ``plan`` has no valid, non-vetoed assignment.

    Args:
        problem: the problem.
        team: its prepared team.
        plan: the candidate plan.
        table: its contribution table, ``None`` if the plan was skipped for lack of agents.
    """
    if table is None:
        return _skipped(problem, team, plan)
    messages = _stuck_agents(problem, team, table) + _unfillable(team, table) + _capacity(problem, team, table)
    if not messages:
        messages = _hall(team, table)
    if not messages:
        messages = [
            "no combination meets every entry point's minimum and maximum without a veto "
            f"(minima {list(table.lows)}, maxima {list(table.highs)}, idling "
            f"{'allowed' if problem.allow_idle else 'not allowed'})"
        ]
    return "; ".join(messages)


def explain(problem: AllocationProblem, team: Team, tables: list[PlanTable | None]) -> str:
    """A message saying why no candidate plan has a valid, non-vetoed assignment.

    Args:
        problem: the problem.
        team: its prepared team.
        tables: per candidate plan its table, ``None`` if it was skipped.
    """
    if not problem.plans:
        return "no candidate plans"
    reasons = [
        f"plan '{plan.name}' {plan_reason(problem, team, plan, table)}" for plan, table in zip(problem.plans, tables)
    ]
    if len(reasons) == 1:
        return f"no valid assignment: {reasons[0]}"
    return "no valid assignment for any candidate plan: " + " | ".join(reasons)
