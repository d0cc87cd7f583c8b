"""The child-runtime seam (alica.engine.child) with a toy runtime: no planner, only what the engine offers.

The toy runtime stands in for pRoPhEt MAS: under the planning problem Solve it
runs the WaitPlan Park until the leader (the lowest agent in the state) sends
"go" on the toy's own topic; then every agent registers the same generated
plan and the team runs it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import pytest

from alica.engine import EngineConfig
from alica.engine.child import ChildHost, ChildSlot, ChildStatus, RunningPlan
from alica.errors import AlicaError
from alica.model import (
    ChildRef,
    Condition,
    ConditionKind,
    EntryPoint,
    Plan,
    PlanningProblem,
    State,
    StateKind,
    Transition,
    UtilityFunction,
)
from alica.testing import ScriptedSkill, scripted
from tests.engine.helpers import library, team

PROBLEM = """
predicates: [done/0]
behaviours:
  - {name: Hold, skill: Wait}
  - {name: Job, skill: Work}
  - {name: Probe, skill: Check}
plans:
  - name: Step
    signature: {parameters: [], precondition: "not done", effect: "done"}
    entry_points: [{task: Work, state: Stepping, min: 1, max: 1}]
    states:
      - {name: Stepping, children: [Hold]}
  - name: Park
    entry_points: [{task: Watch, state: Parked, min: 1, max: "*"}]
    states:
      - {name: Parked, children: [Hold]}
  - name: Inspect
    entry_points: [{task: Help, state: Probing, min: 1, max: "*"}]
    states:
      - {name: Probing, children: [Probe], transitions: [{to: Probed, condition: succeeded}]}
      - {name: Probed, kind: success}
  - name: Top
    entry_points: [{task: Default, state: Solve, min: 1, max: "*"}]
    states:
      - name: Solve
        children: [Solve]
        transitions:
          - {to: Done, condition: "succeeded(Solve)"}
      - {name: Done, kind: success}
problems:
  - name: Solve
    elements: [Step]
    wait_plan: Park
    goal: "done"
"""
CONFIG = {"frequency": 10.0, "broadcast_interval": 0.1, "team_timeout": 0.5, "assignment_protection": 0.3}
TOPIC = "toy/go"


def generated(child: str, version: int) -> Plan:
    """A plan made at run time: every agent runs ``child`` (a behaviour or a plan), then succeeds."""
    return Plan(
        f"Gen{version}",
        (EntryPoint("Work", "Work", "Run", min=1, max=float("inf")),),
        (State("Run", children=(ChildRef(child),)), State("Ok", StateKind.SUCCESS), State("Bad", StateKind.FAILURE)),
        (
            Transition("ok", "Run", "Ok", Condition(ConditionKind.TRANSITION, "succeeded")),
            Transition("bad", "Run", "Bad", Condition(ConditionKind.TRANSITION, "failed")),
        ),
        utility=UtilityFunction(),
    )


class ToyRuntime:
    """Runs the WaitPlan until "go", then a generated plan; regenerates it when it fails."""

    def __init__(self, host: ChildHost, slot: ChildSlot, factory: ToyFactory) -> None:
        self.host, self.slot, self.factory = host, slot, factory
        self.revision = 0
        self.reason = ""
        self.plan: Plan | None = None
        self.version = 0

    def wanted(self) -> tuple[Plan, ...]:
        return (self.plan,) if self.plan is not None else (self.host.library.plans["Park"],)

    def bindings(self) -> dict[str, object]:
        return {}

    def outcome(self) -> ChildStatus | None:
        return None

    def child_status(self, node: RunningPlan) -> ChildStatus:
        return node.status if self.is_generated(node.plan) else ChildStatus.RUNNING

    def is_generated(self, plan: Plan) -> bool:
        return plan is self.plan

    def may_retry_in(self, plan: Plan) -> bool:
        return not self.is_generated(plan)

    def execution_failed(self, node: RunningPlan, now: float) -> None:
        self.host.counters["toy_failures"] += 1
        self.host.emit("toy", what="failed", plan=node.plan.name)
        self._adopt(self.factory.child)

    def update(self, now: float) -> None:
        members = self.slot.members()
        if self.plan is None and now >= 0.3 and members[0] == self.host.name and not self.factory.sent:
            self.factory.sent = True
            self.host.publish(("go", self.slot.key, self.factory.child))
            self._adopt(self.factory.child)
        for _, key, child in self.factory.inbox:
            if key == self.slot.key and self.plan is None:
                self._adopt(child)

    def _adopt(self, child: str) -> None:
        if self.plan is not None:
            self.host.unregister_plan(self.plan.name)
        self.version += 1
        self.plan = generated(child if self.version == 1 else "Job", self.version)
        self.host.register_plan(self.plan, {}, {})
        self.revision += 1

    def stop(self) -> None:
        if self.plan is not None:
            self.host.unregister_plan(self.plan.name)


class ToyFactory:
    def __init__(self, host: ChildHost, child: str) -> None:
        self.host, self.child = host, child
        self.inbox: list[tuple[str, Any, str]] = []
        self.sent = False
        host.counters.setdefault("toy_failures", 0)

    def __call__(self, slot: ChildSlot) -> ToyRuntime:
        return ToyRuntime(self.host, slot, self)

    def receive(self, payload: object, now: float) -> None:
        if isinstance(payload, tuple) and payload[0] == "go":
            self.inbox.append(payload)


class Toy:
    """The toy child kind; ``child`` is what the first generated plan runs."""

    topic = TOPIC

    def __init__(self, child: str = "Job") -> None:
        self.child = child
        self.factories: dict[str, ToyFactory] = {}

    def __call__(self, host: ChildHost) -> ToyFactory:
        self.factories[host.name] = factory = ToyFactory(host, self.child)
        return factory


class FailFirst:
    """A skill factory whose first ``count`` behaviours fail, the later ones succeed."""

    def __init__(self, count: int) -> None:
        self.count = count
        self.made = 0

    def __call__(self, name: str, params: Mapping[str, object], context: Any) -> ScriptedSkill:
        self.made += 1
        return ScriptedSkill(name, ["running", "failure" if self.made <= self.count else "success"])


def toy_team(tmp_path, skills: Mapping[str, Any], kind: Toy) -> Any:
    lib = library(tmp_path, PROBLEM)
    config = EngineConfig(**CONFIG, children={PlanningProblem: kind})
    return team(lib, "Top", {"w": "Worker", "h": "Helper"}, dict(skills), config=config)


def test_the_child_runtime_decides_what_runs_and_its_messages_reach_the_team(tmp_path):
    kind = Toy()
    skills = {"Wait": scripted(["running"]), "Work": scripted(["running", "success"])}
    sim, trace = toy_team(tmp_path, skills, kind)
    sim.run(ticks=2)
    for engine in sim.engines.values():
        assert engine.root.slots[0].node.plan.name == "Park"  # the WaitPlan, as the runtime said
        assert engine.children.factory(PlanningProblem) is kind.factories[engine.name]
    summary = sim.run(until_done=True, max_time=10)
    assert summary["success"]
    assert trace.of("allocation", agent="w", plan="Gen1") and trace.of("allocation", agent="h", plan="Gen1")
    # h is the leader (lowest name): w adopted the plan from h's message on the toy's own topic
    assert kind.factories["h"].sent and not kind.factories["w"].sent
    assert [p[0] for p in kind.factories["w"].inbox] == ["go"]
    assert kind.factories["h"].inbox == []  # a sender does not hear itself
    # a generated plan is allocatable while registered, and forgotten when the agent leaves the state
    assert all("Gen1" not in e.generated.plans for e in sim.engines.values())


def test_a_failed_generated_plan_goes_to_the_runtime_not_to_the_repair(tmp_path):
    kind = Toy()
    skills = {"Wait": scripted(["running"]), "Work": FailFirst(2)}
    sim, trace = toy_team(tmp_path, skills, kind)
    summary = sim.run(until_done=True, max_time=10)
    assert summary["success"]
    assert summary["agents"]["h"]["toy_failures"] >= 1
    assert trace.of("toy", what="failed", plan="Gen1")
    assert not [e for e in trace.of("repair") if e["plan"].startswith("Gen")]  # no generic retry of the plan


def test_a_plan_failing_inside_a_generated_plan_is_not_retried_when_the_runtime_says_so(tmp_path):
    kind = Toy(child="Inspect")
    skills = {"Wait": scripted(["running"]), "Work": scripted(["running", "success"]), "Check": scripted(["failure"])}
    sim, trace = toy_team(tmp_path, skills, kind)
    summary = sim.run(until_done=True, max_time=10)
    assert summary["success"]
    # the generated plan's own 'failed' transition sees Inspect's failure before any repair (continueOnFailure)
    assert not [e for e in trace.of("repair") if e["plan"] == "Inspect"]
    assert trace.of("transition", name="bad")


def test_the_operator_setting_reaches_the_runtime_through_the_host(tmp_path):
    kind = Toy()
    sim, _ = toy_team(tmp_path, {"Wait": scripted(["running"]), "Work": scripted(["running"])}, kind)
    engine = sim.engines["w"]
    engine.set_problem("Solve", goal="done and ready")
    host = kind.factories["w"].host
    assert dict(host.override("Solve")) == {"goal": "done and ready"}
    assert dict(kind.factories["h"].host.override("Solve")) == {}
    with pytest.raises(AlicaError, match="no planning problem named 'Nope'"):
        engine.set_problem("Nope", goal="x")


def test_a_planning_problem_without_a_child_kind_is_a_clear_error_when_the_team_is_built(tmp_path):
    lib = library(tmp_path, PROBLEM)
    with pytest.raises(AlicaError) as caught:
        team(lib, "Top", {"w": "Worker"}, {"Wait": scripted(["running"])}, config=EngineConfig(**CONFIG))
    message = str(caught.value)
    assert "'Top' holds the PlanningProblem 'Solve'" in message
    assert "alica.prophet.PLANNING" in message and "engine_config" in message


def test_a_plan_tree_without_planning_problems_needs_no_child_kind(tmp_path):
    lib = library(tmp_path, PROBLEM)
    sim, _ = team(lib, "Inspect", {"w": "Worker"}, {"Check": scripted(["success"])}, config=EngineConfig(**CONFIG))
    assert sim.run(until_done=True, max_time=5)["success"]


def test_children_are_keyed_by_model_element_type():
    with pytest.raises(ValueError, match="keyed by model element type"):
        EngineConfig(children={"PlanningProblem": Toy()})  # type: ignore[dict-item]
