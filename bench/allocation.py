"""Benchmark of the exact task allocation against two exact peers.

Run with ``.venv/bin/python bench/allocation.py``. For each size (agents x
entry points) and variant (one candidate plan or a 3-plan plan type, with or
without an old assignment and similarity weight 0.2) it solves 30 random
problems with:

* ``allocate``: the A* search of :mod:`alica.allocation.search`;
* ``exhaustive``: the reference enumeration (only where it is feasible);
* ``scipy``: :func:`scipy.optimize.linear_sum_assignment` on the same additive
  problem, each entry point expanded into max' slots (its first min' slots
  carry a large bonus so that the minima are met) plus one idle slot per agent.

It prints a markdown table of median and 95th percentile times (ms; each
problem's time is the best of ``--repeat`` runs, to damp the noise of a shared
machine), median expansions, and in how many problems all solvers found the
same optimal utility (within 1e-9; or all found none).
"""

from __future__ import annotations

import argparse
import math
import random
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from alica.allocation import AllocationProblem, AllocationResult, Assignment, allocate, exhaustive
from alica.model import EntryPoint, Plan, Priority, Role, RoleSet, State, UtilityFunction

SIZES = ((5, 3), (10, 5), (20, 6), (30, 10))
ROLES = 4
SEEDS = 30
REPEAT = 3
#: The largest problem the enumeration is run on (columns ** agents).
EXHAUSTIVE_LIMIT = 5_000
#: Forbidden pairs in the assignment peer: far below any real utility.
FORBIDDEN = -1.0e6
#: Bonus of a mandatory (minimum) slot in the assignment peer.
BONUS = 1.0e3


@dataclass(frozen=True, slots=True)
class Case:
    """One benchmark problem."""

    problem: AllocationProblem
    columns: int


def _roleset(rng: random.Random, tasks: list[str]) -> RoleSet:
    roles = tuple(Role(f"R{i}", tuple(Priority(t, rng.uniform(-0.3, 1.0)) for t in tasks)) for i in range(ROLES))
    return RoleSet("Bench", roles)


def _plan(
    rng: random.Random,
    name: str,
    agents: list[str],
    roles: dict[str, str],
    roleset: RoleSet,
    width: int,
    tasks: list[str],
    similarity: float,
) -> Plan:
    """A plan with random cardinalities that a random non-vetoed witness assignment satisfies."""
    chosen = rng.sample(tasks, width)
    counts = [0] * width
    for agent in agents:
        allowed = [j for j, t in enumerate(chosen) if roleset.priority(roles[agent], t) >= 0]
        if allowed and rng.random() < 0.9:
            counts[rng.choice(allowed)] += 1
    eps = []
    for j, task in enumerate(chosen):
        low = rng.randint(0, counts[j])
        high = math.inf if rng.random() < 0.4 else float(counts[j] + rng.randint(0, 2))
        eps.append(EntryPoint(f"{name}_{task}", task, f"S{j}", low, high))
    utility = UtilityFunction(priority_weight=1.0 - similarity, similarity_weight=similarity)
    return Plan(name, tuple(eps), tuple(State(f"S{j}") for j in range(width)), utility=utility)


def make_case(seed: int, agents_count: int, width: int, plans: int, with_old: bool) -> Case:
    """A random problem with a guaranteed valid assignment for every candidate."""
    rng = random.Random(seed * 7919 + agents_count * 101 + width * 13 + plans * 3 + with_old)
    tasks = [f"T{i}" for i in range(width + 4)]
    roleset = _roleset(rng, tasks)
    agents = [f"agent{i:02d}" for i in range(agents_count)]
    roles = {a: f"R{rng.randrange(ROLES)}" for a in agents}
    similarity = 0.2 if with_old else 0.0
    candidates = tuple(_plan(rng, f"P{k}", agents, roles, roleset, width, tasks, similarity) for k in range(plans))
    old = None
    if with_old:
        first = candidates[0]
        names = [ep.name for ep in first.entry_points] + [None]
        old = Assignment.of(first.name, {a: rng.choice(names) for a in agents}, 0.0)
    problem = AllocationProblem(tuple(rng.sample(agents, len(agents))), roles, roleset, candidates, old=old)
    return Case(problem, width + 1)


def assignment_peer(problem: AllocationProblem) -> float | None:
    """The optimal utility by a rectangular assignment per plan (floats, from the definition)."""
    agents = sorted(problem.agents)
    n = len(agents)
    best: float | None = None
    for plan in problem.plans:
        u = plan.utility
        norm = max(1, min(plan.max_cardinality, n))
        weights = u.priority_weight + u.similarity_weight + sum(s.weight for s in u.summands)
        scale = 1.0 / weights if weights > 0 else 1.0
        old = problem.old
        active = old is not None and old.plan == plan.name and u.similarity_weight > 0
        overlap = [a for a in agents if old is not None and a in old.agents] if active else []
        kept = u.similarity_weight / len(overlap) if overlap else 0.0

        def keep(agent: str, entry: str | None) -> float:
            return kept if agent in overlap and old is not None and old.entry_of(agent) == entry else 0.0

        columns: list[tuple[int | None, bool]] = []  # (entry index or None for idle, mandatory)
        for j, ep in enumerate(plan.entry_points):
            low = ep.min
            high = n if math.isinf(ep.max) else min(n, int(ep.max))
            columns += [(j, True)] * low + [(j, False)] * max(0, high - low)
        if problem.allow_idle:
            columns += [(None, False)] * n
        if len(columns) < n:
            continue
        value = np.full((n, len(columns)), FORBIDDEN)
        for a, agent in enumerate(agents):
            role = problem.roles[agent]
            for c, (j, mandatory) in enumerate(columns):
                if j is None:
                    value[a, c] = keep(agent, None) * scale
                    continue
                ep = plan.entry_points[j]
                pref = problem.roleset.priority(role, ep.task)
                if pref >= 0:
                    value[a, c] = (u.priority_weight * pref / norm + keep(agent, ep.name)) * scale
                    value[a, c] += BONUS if mandatory else 0.0
        rows, cols = linear_sum_assignment(value, maximize=True)
        picked = value[rows, cols]
        mandatory_slots = sum(1 for _, m in columns if m)
        if (picked <= FORBIDDEN / 2).any() or sum(1 for c in cols if columns[c][1]) < mandatory_slots:
            continue
        total = float(picked.sum()) - BONUS * mandatory_slots
        if best is None or total > best + 1e-12:
            best = total
    return best


def _timed(fn: Callable[[], object], repeat: int) -> tuple[float, object]:
    """The best time of ``repeat`` runs in ms, and the result."""
    best = math.inf
    result: object = None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        best = min(best, (time.perf_counter() - start) * 1000.0)
    return best, result


def _utility(result: object) -> float | None:
    if not isinstance(result, AllocationResult) or result.assignment is None:
        return None
    return result.assignment.utility


def _stats(times: list[float]) -> str:
    ordered = sorted(times)
    p95 = ordered[min(len(ordered) - 1, math.ceil(0.95 * len(ordered)) - 1)]
    return f"{statistics.median(ordered):.2f} / {p95:.2f}"


def run(seeds: int, repeat: int) -> None:
    """Solve every case and print the table."""
    print(
        "| agents x EPs | plans | old + sim 0.2 | allocate ms (median / p95) | expansions (median) "
        "| exhaustive ms (median / p95) | scipy ms (median / p95) | agree |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for agents_count, width in SIZES:
        for plans in (1, 3):
            for with_old in (False, True):
                ours: list[float] = []
                expansions: list[int] = []
                reference: list[float] = []
                peer: list[float] = []
                agree = 0
                for seed in range(seeds):
                    case = make_case(seed, agents_count, width, plans, with_old)
                    elapsed, found = _timed(lambda: allocate(case.problem), repeat)
                    ours.append(elapsed)
                    if isinstance(found, AllocationResult):
                        expansions.append(found.expansions)
                    mine = _utility(found)
                    values = [mine]
                    if case.columns**agents_count <= EXHAUSTIVE_LIMIT:
                        elapsed, expected = _timed(lambda: exhaustive(case.problem), repeat)
                        reference.append(elapsed)
                        values.append(_utility(expected))
                    elapsed, other = _timed(lambda: assignment_peer(case.problem), repeat)
                    peer.append(elapsed)
                    values.append(other)
                    known = [v for v in values if v is not None]
                    same_none = all(v is None for v in values)
                    if same_none or (len(known) == len(values) and max(known) - min(known) <= 1e-9):
                        agree += 1
                print(
                    f"| {agents_count}x{width} | {plans} | {'yes' if with_old else 'no'} | {_stats(ours)} "
                    f"| {statistics.median(expansions):.0f} | {_stats(reference) if reference else '-'} "
                    f"| {_stats(peer)} | {agree}/{seeds} |"
                )


def main() -> None:
    """Command line: ``--seeds`` problems per row, ``--repeat`` runs per problem."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--seeds", type=int, default=SEEDS, help=f"problems per row (default {SEEDS})")
    parser.add_argument("--repeat", type=int, default=REPEAT, help=f"runs per problem, best kept (default {REPEAT})")
    args = parser.parse_args()
    run(args.seeds, args.repeat)


if __name__ == "__main__":
    main()
