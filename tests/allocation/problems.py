"""Random allocation problems for the property tests, built from the model dataclasses."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from hypothesis import strategies as st

from alica.allocation import AllocationProblem, Assignment
from alica.model import EntryPoint, Plan, Priority, Role, RoleSet, State, Summand, UtilityFunction

TASKS = ("T0", "T1", "T2", "T3")
AGENT_NAMES = ("a", "b", "c10", "c2", "d", "e", "zed", "Z")
PRIORITIES = (-1.0, -0.5, -0.01, 0.0, 0.1, 0.25, 0.5, 0.5, 0.9, 0.9, 1.0, 1 / 3)
SUMMAND_VALUES = (-1.0, -2.0, -0.5, 0.0, 0.2, 0.5, 1.0, 1 / 3, 2 / 3)
WEIGHTS = (0.0, 0.1, 0.2, 0.5, 0.8, 1.0, 1 / 3)


@dataclass(frozen=True)
class SummandTable:
    """A summand function backed by a table; missing keys are 0."""

    values: Mapping[tuple[str, str, str, str], float]

    def __call__(self, plan: Plan, summand: Summand, agent: str, ep: EntryPoint) -> float:
        return self.values.get((plan.name, summand.name, agent, ep.name), 0.0)


def priority_values() -> st.SearchStrategy[float]:
    """Priorities in [-1, 1], mostly from a small set so that ties happen."""
    return st.one_of(st.sampled_from(PRIORITIES), st.floats(-1, 1, allow_nan=False))


@st.composite
def rolesets(draw: st.DrawFn) -> RoleSet:
    """1-3 roles with priorities for some of the tasks and a default."""
    count = draw(st.integers(1, 3))
    roles = []
    for i in range(count):
        tasks = draw(st.lists(st.sampled_from(TASKS), unique=True, max_size=len(TASKS)))
        roles.append(Role(f"R{i}", tuple(Priority(t, draw(priority_values())) for t in tasks)))
    return RoleSet("Random", tuple(roles), default_priority=draw(st.sampled_from((0.0, 0.5, 0.2, -1.0))))


@st.composite
def plans(draw: st.DrawFn, name: str) -> Plan:
    """A plan with 1-4 entry points of random cardinality and a random utility function."""
    count = draw(st.integers(1, 4))
    eps = []
    for i in range(count):
        low = draw(st.sampled_from((0, 0, 1, 1, 1, 2, 3)))
        high = draw(st.one_of(st.just(math.inf), st.integers(max(0, low - 1), low + 3).map(float)))
        eps.append(EntryPoint(f"E{i}", draw(st.sampled_from(TASKS)), f"S{i}", low, high))
    summands = tuple(Summand(f"f{k}", draw(st.sampled_from(WEIGHTS)), "table") for k in range(draw(st.integers(0, 2))))
    utility = UtilityFunction(
        priority_weight=draw(st.sampled_from(WEIGHTS)),
        summands=summands,
        similarity_weight=draw(st.sampled_from(WEIGHTS)),
    )
    return Plan(name, tuple(eps), tuple(State(f"S{i}") for i in range(count)), utility=utility)


@st.composite
def problems(draw: st.DrawFn, max_agents: int = 6) -> AllocationProblem:
    """A random problem: 1-6 agents, 1-3 candidate plans, successes, old assignment, summands."""
    roleset = draw(rolesets())
    size = draw(st.sampled_from(range(1, max_agents + 1)))
    agents = tuple(draw(st.lists(st.sampled_from(AGENT_NAMES), min_size=size, max_size=size, unique=True)))
    roles = {a: draw(st.sampled_from([r.name for r in roleset.roles])) for a in agents}
    candidates = tuple(draw(plans(f"P{i}")) for i in range(draw(st.integers(1, 3))))
    successes = {
        p.name: {ep.name: draw(st.integers(0, 2)) for ep in p.entry_points if draw(st.booleans())}
        for p in candidates
        if draw(st.booleans())
    }
    old = None
    if draw(st.booleans()):
        plan = draw(st.sampled_from(candidates))
        names = draw(st.lists(st.sampled_from(AGENT_NAMES), unique=True, max_size=len(AGENT_NAMES)))
        choices = [None, *(ep.name for ep in plan.entry_points), "Gone"]
        old = Assignment.of(plan.name, {a: draw(st.sampled_from(choices)) for a in names}, 0.0)
    values = {}
    for p in candidates:
        for s in p.utility.summands:
            for a in agents:
                for ep in p.entry_points:
                    if draw(st.booleans()):
                        values[(p.name, s.name, a, ep.name)] = draw(st.sampled_from(SUMMAND_VALUES))
    return AllocationProblem(
        agents=agents,
        roles=roles,
        roleset=roleset,
        plans=candidates,
        successes=successes,
        old=old,
        summand=SummandTable(values),
        allow_idle=draw(st.sampled_from((True, False))),
    )
