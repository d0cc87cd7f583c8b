"""The input of allocation: agents, roles, candidate plans and what is already done."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from fractions import Fraction

from alica.allocation.assignment import Assignment
from alica.errors import AlicaError
from alica.model.plan import EntryPoint, Plan, Summand
from alica.model.roles import RoleSet

#: ``(plan, summand, agent, entry point) -> value``: a value in [0, 1], or <= -1 to veto.
#: It must be a pure function of its arguments (every agent must compute the same).
SummandFn = Callable[[Plan, Summand, str, EntryPoint], float]


class AllocationError(AlicaError, ValueError):
    """An allocation problem that is malformed (not one that merely has no solution)."""


@dataclass(frozen=True)
class AllocationProblem:
    """Everything the task allocation of one plan (or plan type) depends on.

    Args:
        agents: the agents to distribute, in any order.
        roles: agent -> role name in ``roleset``.
        roleset: the roles and their role-task priorities.
        plans: candidate plans in preference order (earlier wins ties).
        successes: plan name -> entry point name -> agents that already
            succeeded there; they lower the entry point's cardinality.
        old: the current assignment, for the similarity term.
        summand: evaluates the plans' utility summands; needed if a plan has any.
        allow_idle: whether agents may stay unassigned.
    """

    agents: tuple[str, ...]
    roles: Mapping[str, str]
    roleset: RoleSet
    plans: tuple[Plan, ...]
    successes: Mapping[str, Mapping[str, int]] = field(default_factory=dict)
    old: Assignment | None = None
    summand: SummandFn | None = None
    allow_idle: bool = True


@dataclass(frozen=True, slots=True)
class Team:
    """The validated, sorted view of a problem's agents.

    Args:
        agents: the agents, sorted.
        roles: the role of each agent, in the same order.
        priorities: the role-task priorities of each agent, in the same order.
    """

    agents: tuple[str, ...]
    roles: tuple[str, ...]
    priorities: tuple[Mapping[str, float], ...]


def prepare(problem: AllocationProblem) -> Team:
    """Validate the problem's agents and roles and sort the agents.

    Raises:
        AllocationError: an agent is listed twice, has no role, or its role is
            not in the role set; a success count is negative.
    """
    agents = tuple(sorted(problem.agents))
    twice = sorted({a for a, b in itertools.pairwise(agents) if a == b})
    if twice:
        raise AllocationError(f"agents listed more than once: {', '.join(twice)}")
    missing = [a for a in agents if a not in problem.roles]
    if missing:
        raise AllocationError(f"agents without a role: {', '.join(missing)}")
    known = {role.name: role for role in problem.roleset.roles}
    maps: dict[str, Mapping[str, float]] = {}
    for agent in agents:
        role = problem.roles[agent]
        if role not in known:
            available = ", ".join(r.name for r in problem.roleset.roles) or "none"
            raise AllocationError(
                f"agent '{agent}' has role '{role}', which role set '{problem.roleset.name}' "
                f"does not define (roles: {available})"
            )
        if role not in maps:
            maps[role] = known[role].priority_map
    for plan_name in sorted(problem.successes):
        for entry, count in sorted(problem.successes[plan_name].items()):
            if count < 0:
                raise AllocationError(f"negative success count {count} for {plan_name}.{entry}")
    roles = tuple(problem.roles[a] for a in agents)
    return Team(agents, roles, tuple(maps[r] for r in roles))


def priority(problem: AllocationProblem, team: Team, agent: int, task: str) -> float:
    """Pref(role(agent), task), with the role set's default for unlisted tasks.

    Args:
        problem: the problem.
        team: its prepared team.
        agent: the agent's index in ``team.agents``.
        task: the task's name.
    """
    return team.priorities[agent].get(task, problem.roleset.default_priority)


def summand_function(problem: AllocationProblem, plan: Plan) -> SummandFn | None:
    """The summand function to use for ``plan``: ``None`` if the plan has no summands.

    Raises:
        AllocationError: the plan has summands but the problem has no summand function.
    """
    if not plan.utility.summands:
        return None
    if problem.summand is None:
        names = ", ".join(s.name for s in plan.utility.summands)
        raise AllocationError(
            f"plan '{plan.name}' has utility summands ({names}) but the problem has no summand function"
        )
    return problem.summand


def exact(value: float) -> Fraction:
    """The exact rational value of a number (a float is a dyadic rational).

    Raises:
        AllocationError: the value is not a finite number.
    """
    try:
        return Fraction(value)
    except (TypeError, ValueError, OverflowError) as error:
        raise AllocationError(f"not a finite number: {value!r}") from error


def summand_value(fn: SummandFn, plan: Plan, summand: Summand, agent: str, ep: EntryPoint) -> Fraction:
    """``fn(plan, summand, agent, ep)`` as an exact fraction.

    Raises:
        AllocationError: the function returned something that is not a finite number.
    """
    value = fn(plan, summand, agent, ep)
    try:
        return exact(value)
    except AllocationError:
        raise AllocationError(
            f"summand '{summand.name}' of plan '{plan.name}' returned {value!r} for agent "
            f"'{agent}' at entry point '{ep.name}'; expected a finite number"
        ) from None


def cardinalities(problem: AllocationProblem, plan: Plan, agents: int) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Effective minimum and maximum agents per entry point.

    ``min' = max(0, min - s)`` and ``max' = max(0, max - s)`` with ``s`` the agents
    that already succeeded at the entry point; the maximum is capped at
    ``agents`` (which is never a restriction) so that it is an integer.

    Args:
        problem: the problem (for its successes).
        plan: the plan.
        agents: the number of agents.

    Returns:
        ``(minima, maxima)`` in entry point order.
    """
    done = problem.successes.get(plan.name, {})
    lows: list[int] = []
    highs: list[int] = []
    for ep in plan.entry_points:
        succeeded = done.get(ep.name, 0)
        lows.append(max(0, ep.min - succeeded))
        high = max(0.0, ep.max - succeeded)
        highs.append(agents if math.isinf(high) else min(agents, math.floor(high)))
    return tuple(lows), tuple(highs)


def normaliser(plan: Plan, agents: int) -> float:
    """N = max(1, min(plan.max_cardinality, agents)): the priority and summand divisor."""
    return max(1, min(plan.max_cardinality, agents))


def similarity_overlap(problem: AllocationProblem, plan: Plan, team: Team) -> tuple[bool, tuple[bool, ...]]:
    """Whether the similarity term is active for ``plan``, and which agents it counts.

    Returns:
        ``(active, counted)``: ``counted[i]`` tells whether ``team.agents[i]`` was
        in the old assignment (the set O).
    """
    old = problem.old
    if old is None or old.plan != plan.name or plan.utility.similarity_weight <= 0:
        return False, tuple(False for _ in team.agents)
    known = set(old.agents)
    return True, tuple(a in known for a in team.agents)
