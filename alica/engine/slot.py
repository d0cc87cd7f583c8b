"""A child of an agent's current state: a behaviour, or a plan with its repair stages.

Repair of a failed plan (IMPERA/ALICA failure handling), per child:

1. **retry**: the first failure of a plan restarts it: every local agent goes
   back to the initial state of its entry point and the plan is allocated again;
2. **replace**: the second failure drops the plan and allocates the next-best
   alternative of the plan type (each alternative gets its own retry);
3. **propagate**: when no alternative is left the child fails; the state's
   ``failed`` conditions hold, and if no transition of the state handles it the
   plan that holds the state fails in turn.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from alica.engine.status import ChildStatus
from alica.model import Behaviour, ChildRef, Plan, PlanningProblem, PlanType

if TYPE_CHECKING:
    from alica.engine.behaviours import BehaviourRunner
    from alica.engine.node import PlanNode
    from prophet.runtime import ProblemRuntime


class Slot:
    """One child of the state a plan node is in.

    Args:
        parent: the plan node whose current state holds the child.
        ref: the child reference of the model (name and bindings).
        env: the child's variable bindings, evaluated when the state was entered.
    """

    __slots__ = ("element", "env", "failed_plans", "failures", "next_try", "node", "parent", "reason", "ref", "revision", "runner", "runtime", "status")

    def __init__(self, parent: PlanNode, ref: ChildRef, env: dict[str, object]) -> None:
        self.parent = parent
        self.ref = ref
        self.element = parent.engine.library.abstract(ref.name)
        self.env = env
        self.node: PlanNode | None = None
        self.runner: BehaviourRunner | None = None
        self.status = ChildStatus.WAITING
        self.reason = ""
        self.failures: dict[str, int] = {}
        self.failed_plans: list[str] = []
        self.next_try = 0.0
        self.runtime: ProblemRuntime | None = None
        if isinstance(self.element, PlanningProblem):
            from prophet.runtime import ProblemRuntime

            self.runtime = ProblemRuntime(self)
        self.revision = self.runtime.revision if self.runtime is not None else 0

    @property
    def name(self) -> str:
        """The child's name, as conditions such as ``succeeded(X)`` use it."""
        return self.ref.name

    @property
    def is_behaviour(self) -> bool:
        """Whether the child is a behaviour (else a plan, plan type or planning problem)."""
        return isinstance(self.element, Behaviour)

    def candidates(self) -> tuple[Plan, ...]:
        """The plans this child may run now, in preference order, failed ones left out.

        A planning problem runs what its runtime says: the WaitPlan, the
        generated plan or the AlternativePlan (:mod:`prophet.runtime`).
        """
        library = self.parent.engine.library
        element = self.element
        if self.runtime is not None:
            return tuple(p for p in self.runtime.wanted() if p.name not in self.failed_plans)
        if isinstance(element, Plan):
            names: tuple[str, ...] = (element.name,)
        elif isinstance(element, PlanType):
            names = element.plans
        else:
            return ()
        return tuple(library.plans[n] for n in names if n not in self.failed_plans)

    def startable(self, plans: tuple[Plan, ...], keep: Plan | None = None) -> tuple[Plan, ...]:
        """The plans whose pre-condition holds now (``keep`` is kept regardless: it already runs)."""
        engine = self.parent.engine
        belief = engine.belief_for(self.parent)
        return tuple(p for p in plans if p is keep or engine.formulas.holds(p.pre.text if p.pre else None, belief, self.env))

    # -- life ----------------------------------------------------------

    def start(self, now: float, only: Plan | None = None) -> None:
        """Allocate the agents of the parent state to this plan child and start it."""
        engine = self.parent.engine
        candidates = (only,) if only is not None else self.candidates()
        usable = self.startable(candidates)
        if not usable:
            self._wait(now, "no plan whose pre-condition holds" if candidates else "no plan left")
            return
        node = engine.start_plan(self, usable, now)
        if node is None:
            self._wait(now, self.reason)
            return
        self.node = node
        self.status = ChildStatus.RUNNING
        self.reason = ""

    def _wait(self, now: float, reason: str) -> None:
        """Not startable now: try again after a broadcast interval (teammates or the world may change)."""
        self.status = ChildStatus.WAITING
        self.reason = reason
        self.next_try = now + self.parent.engine.config.broadcast_interval

    def visit(self, now: float) -> None:
        """Run the rules of the child plan, repair it when it failed (behaviours are ticked elsewhere)."""
        if self.runner is not None:
            self.status = self.runner.status
            self.reason = self.runner.reason
            return
        runtime = self.runtime
        if runtime is not None and self._follow(runtime, now):
            return
        if self.status is ChildStatus.FAILURE:
            return
        if self.node is None:
            if now >= self.next_try:
                self.start(now)
            return
        node = self.node
        node.visit(now)
        if node.status is not ChildStatus.FAILURE:
            self.status = runtime.child_status(node) if runtime is not None else node.status
        elif runtime is not None and runtime.is_generated(node.plan):
            # a step failed: back to the WaitPlan, the leader replans (not the generic repair)
            node.stop()
            self.node = None
            runtime.execution_failed(node, now)
            self.revision = runtime.revision
            self.start(now)
        else:
            self._repair(node, now)

    def _follow(self, runtime: ProblemRuntime, now: float) -> bool:
        """Let the planning problem's runtime decide what runs; ``True`` when the child is finished."""
        runtime.update(now)
        if runtime.revision != self.revision:
            self.revision = runtime.revision
            if self.node is not None:
                self.node.stop()
                self.node = None
            self.status = ChildStatus.WAITING
            self.start(now)
        outcome = runtime.outcome()
        if outcome is None:
            return False
        self.status = outcome
        self.reason = runtime.reason
        return True

    def _repair(self, node: PlanNode, now: float) -> None:
        engine = self.parent.engine
        plan = node.plan
        node.stop()
        self.node = None
        count = self.failures[plan.name] = self.failures.get(plan.name, 0) + 1
        if count == 1:
            engine.emit("repair", key=node.key_text, stage="retry", plan=plan.name, reason=node.reason)
            self.start(now, only=plan)
            return
        self.failed_plans.append(plan.name)
        if self.candidates():
            engine.emit("repair", key=node.key_text, stage="replace", plan=plan.name, reason=node.reason)
            self.start(now)
            if self.node is not None:
                return
        engine.emit("repair", key=node.key_text, stage="propagate", plan=plan.name, reason=node.reason)
        self.status = ChildStatus.FAILURE
        self.reason = f"plan '{plan.name}' failed: {node.reason}"

    def stop(self) -> None:
        """Stop the child and everything below it (the agent leaves the state)."""
        if self.runner is not None:
            self.runner.stop()
        if self.node is not None:
            self.node.stop()
        if self.runtime is not None:
            self.runtime.stop()
