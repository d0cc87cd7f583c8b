"""The search against the reference enumeration, on random problems."""

from __future__ import annotations

import dataclasses
import itertools
import math

from hypothesis import given, settings
from hypothesis import strategies as st

from alica.allocation import AllocationProblem, allocate, exhaustive, utility
from alica.allocation.flow import solve
from alica.allocation.problem import prepare
from alica.allocation.table import build_table
from alica.model import Plan
from tests.allocation.problems import problems


@settings(max_examples=600)
@given(problems())
def test_search_equals_enumeration(problem: AllocationProblem) -> None:
    found = allocate(problem)
    expected = exhaustive(problem)
    if expected.assignment is None:
        assert found.assignment is None
        assert found.why and expected.why
        return
    assert found.assignment is not None, found.why
    assert found.assignment.plan == expected.assignment.plan
    assert found.assignment.entries == expected.assignment.entries
    assert found.assignment.utility == expected.assignment.utility
    plan = next(p for p in problem.plans if p.name == found.assignment.plan)
    assert utility(problem, plan, found.assignment.as_dict()) == found.assignment.utility


@settings(max_examples=100)
@given(problems(), st.randoms(use_true_random=False))
def test_agent_order_does_not_matter(problem: AllocationProblem, rng: object) -> None:
    agents = list(problem.agents)
    rng.shuffle(agents)  # type: ignore[attr-defined]
    shuffled = dataclasses.replace(problem, agents=tuple(reversed(agents)))
    assert allocate(shuffled).assignment == allocate(problem).assignment


def _spec_utility(problem: AllocationProblem, plan: Plan, entries: dict[str, str | None]) -> float:
    """U straight from the definition, in floats: an independent check of the exact code."""
    agents = sorted(problem.agents)
    n = len(agents)
    done = problem.successes.get(plan.name, {})
    for ep in plan.entry_points:
        count = sum(1 for a in agents if entries[a] == ep.name)
        s = done.get(ep.name, 0)
        if not max(0, ep.min - s) <= count <= max(0, ep.max - s):
            return -1.0
    if not problem.allow_idle and any(entries[a] is None for a in agents):
        return -1.0
    norm = max(1, min(plan.max_cardinality, n))
    u = plan.utility
    pri = 0.0
    sums = [0.0] * len(u.summands)
    for a in agents:
        if entries[a] is None:
            continue
        ep = plan.entry_point(entries[a])
        pref = problem.roleset.priority(problem.roles[a], ep.task)
        if pref < 0:
            return -1.0
        pri += pref
        for k, s in enumerate(u.summands):
            value = problem.summand(plan, s, a, ep)  # type: ignore[misc]
            if value <= -1:
                return -1.0
            sums[k] += value
    total = u.priority_weight * pri / norm + sum(s.weight * v / norm for s, v in zip(u.summands, sums))
    old = problem.old
    if old is not None and old.plan == plan.name and u.similarity_weight > 0:
        both = [a for a in agents if a in old.agents]
        if both:
            kept = sum(1 for a in both if entries[a] == old.entry_of(a))
            total += u.similarity_weight * kept / len(both)
    weights = u.priority_weight + sum(s.weight for s in u.summands) + u.similarity_weight
    return total / weights if weights > 0 else total


@settings(max_examples=150)
@given(problems(max_agents=4))
def test_utility_matches_definition_and_table(problem: AllocationProblem) -> None:
    team = prepare(problem)
    for index, plan in enumerate(problem.plans):
        table = build_table(problem, team, index, plan)
        columns = range(len(plan.entry_points) + 1)
        for vector in itertools.product(columns, repeat=len(team.agents)):
            entries = {
                a: (None if j == len(plan.entry_points) else plan.entry_points[j].name)
                for a, j in zip(team.agents, vector)
            }
            value = utility(problem, plan, entries)
            assert math.isclose(value, _spec_utility(problem, plan, entries), abs_tol=1e-12)
            cells = table.value(vector)
            if value != -1.0:
                assert cells is not None
                assert cells / table.denominator == value


@settings(max_examples=200)
@given(problems(max_agents=5))
def test_relaxation_is_the_plan_optimum_and_its_prices_are_tight(problem: AllocationProblem) -> None:
    team = prepare(problem)
    n = len(team.agents)
    for index, plan in enumerate(problem.plans):
        table = build_table(problem, team, index, plan)
        width = len(plan.entry_points)
        best = None
        for vector in itertools.product(range(width + 1), repeat=n):
            counts = [vector.count(j) for j in range(width)]
            if all(lo <= c <= hi for c, lo, hi in zip(counts, table.lows, table.highs)):
                value = table.value(vector)
                if value is not None and (best is None or value > best):
                    best = value
        relaxation = solve(table)
        if best is None:
            assert relaxation is None
            continue
        assert relaxation is not None
        assert relaxation.basis.total == best == table.value(relaxation.basis.columns)
        # The Lagrangian bound with the prices is exact at the root.
        prices = relaxation.prices
        lows, highs = relaxation.lows, relaxation.highs
        bound = sum(max(cell - price for cell, price in zip(row, prices) if cell is not None) for row in table.cells)
        bound += sum(p * (hi if p > 0 else lo) for p, lo, hi in zip(prices, lows, highs) if p)
        assert bound == best
