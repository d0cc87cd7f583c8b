"""Constraint queries of one agent's engine: plan variables solved at run time, the same on every agent.

A behaviour whose parameter is bound to a plan variable (``frontier:
frontier`` in the child reference, ``$frontier`` in the behaviour) receives
the value the constraint solver gives this agent; a skill may also ask
through its context (:meth:`SkillContext.solve`).

* **The problem** of a query is collected from the running plan tree, from the
  root down to the plan that asks (:func:`alica.solver.query.collect`): every
  plan's constraints, the bindings unifying a child's variables with its
  parent's, and ``agents(E)`` from who is believed to be where.
* **Every agent solves the whole team's problem** with a seed taken from the
  plan instances and who is where, so agents with the same view compute the
  same values. The solution is also written to the shared world model
  (``solution(plan key)``, with a time to live); an agent whose view gives the
  same problem takes the team's solution when it still satisfies every hard
  constraint, and otherwise starts its search from it.
* **Solved again** when the problem changes (a teammate joins, leaves or
  crashes; candidates appear or vanish) or the solution no longer satisfies
  the constraints (a robot moved), checked every ``RECHECK`` seconds; a
  behaviour whose values changed is restarted with the new ones.
* **No solution** (infeasible, or none within the time budget) is a status,
  not an exception: the behaviour that needs the values fails with the
  reason, so the state's ``failed`` transitions fire.

Each solve is traced (event ``solve``: status, this plan's values of every
agent, utility, time).

:class:`Solving` reads the agent's shared context (:class:`~alica.engine.parts.AgentContext`)
and its world model, nothing else of the engine. What a query returns
(:class:`~alica.engine.parts.SolveResult`, :class:`~alica.engine.parts.NoSolution`)
lives in :mod:`alica.engine.parts`, below the behaviours that see it; it is
re-exported here.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from alica.engine.parts import AgentContext, NoSolution, SolveResult
from alica.errors import AlicaError
from alica.model import ChildRef
from alica.solver import Solution, Var, check, solve
from alica.solver.problem import Problem
from alica.solver.query import Level, Query, QueryError, collect, digest
from alica.worldmodel import WorldModelLike

if TYPE_CHECKING:
    from alica.engine.node import PlanNode
    from alica.engine.slot import Slot

__all__ = ["RECHECK", "SHARE_TTL", "TIME_BUDGET", "NoSolution", "SolveResult", "Solving", "binding_names"]

#: Seconds between two checks of a solution in use (problem changed? constraints still hold?).
RECHECK = 0.5
#: Seconds a solution shared through the world model stays there without being written again.
SHARE_TTL = 10.0
#: The time budget of one solve, in seconds (the best solution so far is used when it runs out).
TIME_BUDGET = 1.0

_IDENT = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*$")


@dataclass
class _Cached:
    query: Query
    solution: Solution
    checked_at: float
    shared_at: float = 0.0


def _encode(values: Mapping[Var, object]) -> tuple[tuple[str, str, object], ...]:
    return tuple(sorted(((v.name, v.agent or "", _plain(value)) for v, value in values.items()), key=str))


def _plain(value: object) -> object:
    if isinstance(value, (list, tuple)):
        return tuple(_plain(item) for item in value)
    if isinstance(value, float) or hasattr(value, "dtype"):
        return float(value)  # type: ignore[arg-type]
    return value


class Solving:
    """The constraint queries of one engine (see the module docstring).

    Args:
        ctx: the agent's name, clock, team view, formulas, belief, counters and trace.
        world_model: the agent's world model, which shares each solution with the team.
    """

    def __init__(self, ctx: AgentContext, world_model: WorldModelLike) -> None:
        self.ctx = ctx
        self.world_model = world_model
        self.cache: dict[str, _Cached] = {}
        self.watched: dict[int, tuple[Slot, dict[str, object]]] = {}
        self.next_check = 0.0
        self._last: tuple[PlanNode, float, Query] | None = None

    # -- the problem ------------------------------------------------------

    def levels(self, node: PlanNode) -> list[Level]:
        """The running plans from the root down to ``node``, as the query sees them."""
        me = self.ctx.name
        chain: list[PlanNode] = []
        current: PlanNode | None = node
        while current is not None:
            chain.append(current)
            current = current.slot.parent if current.slot is not None else None
        chain.reverse()
        alive = set(self.ctx.team.alive())
        levels = []
        for plan_node in chain:
            places = {a: e for a, e in plan_node.believed.items() if a in alive and a != me}
            places[me] = (plan_node.ep, plan_node.state)
            bindings = binding_names(plan_node.slot.ref) if plan_node.slot is not None else {}
            levels.append(Level(plan_node.key_text, plan_node.plan, places, bindings))
        return levels

    def _collect(self, node: PlanNode, names: tuple[str, ...]) -> Query:
        """The query of ``node`` now; collected once per plan node, moment and view (binding a child asks twice)."""
        ctx = self.ctx
        now = ctx.now()
        levels = self.levels(node)
        view = digest(levels)
        last = self._last
        if last is not None and last[0] is node and last[1] == now and last[2].digest == view:
            query = last[2]
            depth = len(levels) - 1
            if all((depth, name) in query.names for name in names):
                return query
        query = collect(levels, ctx.belief.at(node), registry=ctx.formulas.registry, names=names)
        self._last = (node, now, query)
        return query

    def solvable(self, node: PlanNode, name: str) -> bool:
        """Whether ``name`` is a variable of ``node``'s plan that the solver gives values to (it has a type)."""
        return any(v.name == name and v.type != "any" for v in node.plan.variables)

    # -- queries ----------------------------------------------------------

    def query(self, node: PlanNode, names: tuple[str, ...] = ()) -> SolveResult:
        """The solution of the constraints of the plan tree down to ``node``, by ``node``'s variable names."""
        now = self.ctx.now()
        try:
            query = self._collect(node, names)
        except QueryError as exc:
            return SolveResult("infeasible", {}, {}, math.nan, str(exc))
        cached = self.cache.get(node.key_text)
        if cached is not None and self._still_good(cached, query, now):
            solution = cached.solution
            if solution.status == "solved" and now >= cached.shared_at:
                # agents whose searches differed (a time budget ran out) converge on the team's solution
                cached.shared_at = now + RECHECK
                adopted = self._adopt(node, query, solution)
                if adopted is not None:
                    cached.solution = solution = adopted
        else:
            solution = self._solve(node, query, cached)
            self.cache[node.key_text] = _Cached(query, solution, now)
        return self._result(node, query, solution)

    def values(self, node: PlanNode, names: tuple[str, ...]) -> dict[str, object]:
        """This agent's values of ``names`` (variables of ``node``'s plan).

        Raises:
            NoSolution: the constraints have no solution now.
        """
        result = self.query(node, names)
        if not result.ok:
            raise NoSolution(f"no values for {', '.join(names)} in plan '{node.plan.name}': {result.reason}")
        missing = [n for n in names if n not in result.values]
        if missing:
            raise NoSolution(f"the solver gave no value to {', '.join(missing)} in plan '{node.plan.name}'")
        return {n: result.values[n] for n in names}

    def _still_good(self, cached: _Cached, query: Query, now: float) -> bool:
        if cached.query.digest != query.digest or cached.query.problem.variables != query.problem.variables:
            return False
        if cached.solution.status != "solved":
            return now - cached.checked_at < RECHECK  # try again after a while: the world may have changed
        if now - cached.checked_at < RECHECK:
            return True
        cached.checked_at = now
        checked = _checked(query.problem, cached.solution.values)
        return checked is not None and all(checked[0].values())

    def _solve(self, node: PlanNode, query: Query, cached: _Cached | None) -> Solution:
        problem = query.problem
        shared = self._shared(node, query)
        checked = _checked(problem, shared) if shared is not None else None
        if shared is not None and checked is not None and all(checked[0].values()):
            solution = Solution("solved", shared, checked[1], checked[0], False, 0.0, "the team's solution")
            self._trace(node, query, solution, "shared")
            return solution
        start = shared
        if start is None and cached is not None and cached.solution.status == "solved":
            start = {v: x for v, x in cached.solution.values.items() if v in set(problem.variables)}
        try:
            solution = solve(problem, time_limit=TIME_BUDGET, start=start or None)
        except AlicaError as exc:  # a formula that cannot be read here: no values, with the reason
            solution = Solution("infeasible", {}, math.nan, {}, False, 0.0, str(exc))
        self.ctx.count("solves")
        if solution.status == "solved":
            self.world_model.set(
                "solution", node.key_text, value=(query.digest, _encode(solution.values)), ttl=SHARE_TTL
            )
        self._trace(node, query, solution, "solved")
        return solution

    def _adopt(self, node: PlanNode, query: Query, own: Solution) -> Solution | None:
        """The team's solution for the same view when it differs from ``own`` and satisfies the constraints."""
        stored = self.world_model.get("solution", node.key_text)
        if not isinstance(stored, tuple) or len(stored) != 2 or stored[0] != query.digest:
            return None
        shared = self._shared(node, query)
        if shared is None or shared == dict(own.values):
            return None
        checked = _checked(query.problem, shared)
        if checked is None or not all(checked[0].values()):
            return None
        solution = Solution("solved", shared, checked[1], checked[0], False, 0.0, "the team's solution")
        self._trace(node, query, solution, "shared")
        return solution

    def _shared(self, node: PlanNode, query: Query) -> dict[Var, object] | None:
        """The team's solution of this plan instance from the world model, when it covers this problem's variables."""
        stored = self.world_model.get("solution", node.key_text)
        if not isinstance(stored, tuple) or len(stored) != 2:
            return None
        _digest, entries = stored
        by_key = {(name, agent or None): value for name, agent, value in entries}
        values: dict[Var, object] = {}
        for var in query.problem.variables:
            key = (var.name, var.agent)
            if key not in by_key:
                return None
            values[var] = by_key[key]
        return values

    def _result(self, node: PlanNode, query: Query, solution: Solution) -> SolveResult:
        me = self.ctx.name
        local = query.local(_depth(node))
        team: dict[str, dict[str, object]] = {}
        for var, value in solution.values.items():
            name = local.get(var.name)
            if name is None:
                continue
            team.setdefault(var.agent or "", {})[name] = value
        own = dict(team.get("", {}))
        own.update(team.get(me, {}))
        return SolveResult(solution.status, own, team, solution.utility, solution.reason)

    def _trace(self, node: PlanNode, query: Query, solution: Solution, how: str) -> None:
        values: dict[str, dict[str, object]] = {}
        for var, value in sorted(solution.values.items(), key=lambda item: (item[0].agent or "", item[0].name)):
            values.setdefault(var.agent or "", {})[var.name] = _plain(value)
        self.ctx.emit(
            "solve",
            key=node.key_text,
            status=solution.status,
            how=how,
            values=values,
            utility=None if math.isnan(solution.utility) else round(solution.utility, 9),
            time_ms=round(solution.time_s * 1000, 3) if how == "solved" else 0.0,
            reason=solution.reason if solution.status != "solved" else "",
        )

    # -- behaviours bound to solved variables -------------------------------

    def bound_names(self, node: PlanNode, slot_bindings: Mapping[str, str]) -> dict[str, str]:
        """Child variable -> ``node``'s solved variable, for the bindings that read one.

        A variable of ``node``'s plan is solved when it has a type, its own parent
        did not bind it, and a constraint of the running plan tree reads it.
        """
        typed = {c: p for c, p in slot_bindings.items() if p not in node.env and self.solvable(node, p)}
        if not typed:
            return {}
        try:
            query = self._collect(node, ())
        except QueryError:
            return typed  # it is solved, and the query says why it has no values
        depth = _depth(node)
        solved = {name for (level, name) in query.names if level == depth}
        return {c: p for c, p in typed.items() if p in solved}

    def track(self, slot: Slot) -> None:
        """Restart ``slot``'s behaviour when the solved values it was started with change."""
        names = self.bound_names(slot.parent, binding_names(slot.ref))
        if names:
            self.watched[id(slot)] = (slot, {child: slot.env.get(child) for child in names})

    def asker(self, slot: Slot) -> Callable[[tuple[str, ...]], SolveResult]:
        """The query function of the skill of ``slot`` (``context.solve``): by the behaviour's variable names."""
        to_parent = binding_names(slot.ref)

        def ask(names: tuple[str, ...]) -> SolveResult:
            wanted = {name: to_parent.get(name, name) for name in names}
            result = self.query(slot.parent, tuple(sorted(set(wanted.values()))))
            back = {parent: child for child, parent in wanted.items()}

            def rename(values: Mapping[str, object]) -> dict[str, object]:
                return {back.get(k, k): v for k, v in values.items()}

            team = {agent: rename(values) for agent, values in result.team.items()}
            return SolveResult(result.status, rename(result.values), team, result.utility, result.reason)

        return ask

    def unwatch(self, slot: Slot) -> None:
        """The slot stopped."""
        self.watched.pop(id(slot), None)

    def refresh(self, now: float) -> None:
        """Every ``RECHECK`` seconds: solve again where needed; restart behaviours whose values changed."""
        if now < self.next_check or not self.watched:
            return
        self.next_check = now + RECHECK
        for slot, values in list(self.watched.values()):
            node = slot.parent
            if node.status.done or node.state is None:
                self.unwatch(slot)
                continue
            names = self.bound_names(node, binding_names(slot.ref))
            try:
                fresh = self.values(node, tuple(sorted(set(names.values()))))
            except NoSolution as exc:
                self.unwatch(slot)
                slot.fail_unsolved(str(exc))
                continue
            new = {child: fresh[parent] for child, parent in names.items()}
            if new != values:
                self.watched[id(slot)] = (slot, new)
                slot.restart_with(new, now)


def binding_names(ref: ChildRef) -> dict[str, str]:
    """Child variable -> parent variable, for the bindings of ``ref`` whose value is a bare variable name."""
    out: dict[str, str] = {}
    for binding in ref.bindings:
        match = _IDENT.match(binding.value)
        if match:
            out[binding.variable] = match.group(1)
    return out


def _depth(node: PlanNode) -> int:
    depth = 0
    while node.slot is not None:
        node = node.slot.parent
        depth += 1
    return depth


def _checked(problem: Problem, values: Mapping[Var, object]) -> tuple[dict[str, bool], float] | None:
    """Which hard constraints hold at ``values`` and the utility there; ``None`` when they cannot be read."""
    try:
        return check(problem, values)
    except AlicaError:
        return None
