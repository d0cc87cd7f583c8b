"""The engine's collaborators on their own, each with stand-ins for the narrow interface it is given.

None of them holds the engine (issue 36): the belief base reads a plan's context through
``PlanContext``, the synchronisation table needs a plan, the child-runtime host needs the shared
context and ``Operated``, allocation needs the shared context and ``Nodes``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import pytest

from alica.clock import ManualClock
from alica.engine import EngineConfig, PlanDecision
from alica.engine.allocate import Allocator
from alica.engine.belief import AgentBelief
from alica.engine.conditions import Formulas
from alica.engine.generated import GeneratedPlans
from alica.engine.hosting import EngineHost
from alica.engine.node import NodeParts, PlanNode
from alica.engine.parts import AgentContext
from alica.engine.runner import pick_roleset
from alica.engine.sync import SyncTable, SyncTalk
from alica.engine.team import TeamView
from alica.engine.tree import PlanTree
from alica.errors import AlicaError
from alica.lang import FactBase
from alica.model import Plan, PlanLibrary
from alica.worldmodel import WorldModel
from tests.engine.helpers import library

PLANS = """
predicates: [grasped/1]
behaviours:
  - {name: Hold, skill: Wait}
plans:
  - name: Solo
    entry_points:
      - {task: Work, state: Busy, min: 1, max: 1}
    states:
      - {name: Busy, transitions: [{to: Done, condition: "grasped(a)"}]}
      - {name: Done, kind: success}
  - name: Lift
    entry_points:
      - {task: Work, state: GraspA, min: 1, max: 1}
      - {task: Help, state: GraspB, min: 1, max: 1}
    synchronisations:
      - {name: Together, transitions: [UpA, UpB], talk_timeout: 0.1, sync_timeout: 1.0}
    states:
      - name: GraspA
        children: [Hold]
        transitions:
          - {to: LiftedA, condition: "grasped(a)", name: UpA, sync: Together}
      - name: GraspB
        children: [Hold]
        transitions:
          - {to: LiftedB, condition: "grasped(b)", name: UpB, sync: Together}
      - {name: LiftedA, kind: success}
      - {name: LiftedB, kind: success}
"""


@dataclass
class Events:
    """A stand-in trace: the events, in order."""

    seen: list[tuple[str, dict[str, object]]] = field(default_factory=list)

    def __call__(self, event: str, **fields: object) -> None:
        self.seen.append((event, fields))

    def kinds(self) -> list[str]:
        return [event for event, _ in self.seen]


def _context(roster: Mapping[str, str], me: str = "a") -> tuple[AgentContext, Events, ManualClock]:
    clock = ManualClock()
    team = TeamView(me, roster, clock.now(), 3.0)
    belief = AgentBelief(me, FactBase(), team, FactBase(), clock.now)
    events = Events()
    ctx = AgentContext(me, clock.now, EngineConfig(), team, Formulas(), belief, {}, events)
    return ctx, events, clock


@pytest.fixture
def lib(tmp_path) -> PlanLibrary:
    return library(tmp_path, PLANS)


# -- the belief base reads a plan's context, not a plan node ------------------------------------


@dataclass
class Context:
    """A stand-in ``PlanContext``: a plan whose children all succeeded, entered at 2 s."""

    plan: Plan
    believed: dict[str, tuple[str | None, str | None]]
    state_entered_at: float = 2.0

    def children_status(self, want: str) -> bool:
        return want == "success"

    def child_status(self, name: str, want: str) -> bool:
        return name == "Hold" and want == "success"


def test_the_belief_base_reads_the_plan_it_is_looking_at(lib):
    clock = ManualClock(5.0)
    team = TeamView("a", {"a": "Worker", "b": "Helper"}, 0.0, 3.0)
    belief = AgentBelief("a", FactBase(), team, FactBase(), clock.now)
    assert belief.lookup("elapsed", ()) is None  # no plan looked at
    context = Context(lib.plans["Lift"], {"a": ("Work", "GraspA"), "b": ("Help", "GraspB")})
    assert belief.at(context) is belief and belief.node is context
    assert belief.lookup("elapsed", ()) == 3.0
    assert belief.lookup("succeeded", ()) is True and belief.lookup("failed", ()) is False
    assert belief.lookup("succeeded", ("Hold",)) is True
    assert belief.lookup("in_task", ("b", "Help")) is True and belief.lookup("in_state", ("a", "GraspB")) is False


# -- the synchronisation table -------------------------------------------------------------


def test_the_sync_table_keeps_one_process_per_instance_and_synchronisation(lib):
    lift = lib.plans["Lift"]
    table = SyncTable("a", period=0.1)
    process = table.process(("Lift",), lift, "Together")
    assert table.process(("Lift",), lift, "Together") is process
    assert process.expiry == pytest.approx(0.4)  # four ticks: longer than four talk timeouts of 0.1 s
    process.update_mine("UpA", True, 0.0)
    (talk,) = table.talk(0.0)
    assert (talk.sender, talk.key, talk.transition, talk.holds) == ("a", ("Lift",), "UpA", True)
    assert table.talk(0.05) == []  # nothing new within the talk timeout
    table.drop(("Lift",))
    assert table.processes == {}


def test_the_sync_table_takes_rows_only_for_synchronisations_of_the_plan(lib):
    lift = lib.plans["Lift"]
    table = SyncTable("a", period=0.1)
    table.receive(SyncTalk("b", ("Lift",), "Elsewhere", "UpB", True, (), 0.0), lift, 0.0)
    assert table.processes == {}
    table.receive(SyncTalk("b", ("Lift",), "Together", "UpB", True, (), 0.0), lift, 0.0)
    assert set(table.processes[(("Lift",), "Together")].rows) == {"b"}


# -- the child-runtime host reads the agent through Operated ------------------------------


@dataclass
class Agent:
    """A stand-in ``Operated``: what a child runtime's host may read of the agent."""

    library: PlanLibrary
    generated: GeneratedPlans
    world_model: WorldModel
    overrides: dict[str, dict[str, str]] = field(default_factory=dict)
    decisions: dict[str, list[tuple[int, PlanDecision]]] = field(default_factory=dict)
    sent: list[tuple[str, object]] = field(default_factory=list)

    def publish(self, topic: str, payload: object) -> None:
        self.sent.append((topic, payload))


def test_the_host_shows_a_child_runtime_the_agent_and_nothing_more(lib):
    ctx, events, _ = _context({"a": "Worker"})
    roleset = pick_roleset(lib, ["Worker"])
    agent = Agent(lib, GeneratedPlans(roleset), WorldModel("a"))
    host = EngineHost(ctx, agent, "plans")
    assert (host.name, host.library, host.roleset, host.review) == ("a", lib, roleset, False)
    agent.overrides = {"P": {"goal": "done"}}  # replaced, as a restarted agent's team does: read live
    agent.decisions = {"P": [(1, PlanDecision("accept"))]}
    assert host.override("P") == {"goal": "done"} and host.override("Q") == {}
    assert list(host.decisions("P")) == [(1, PlanDecision("accept"))] and list(host.decisions("Q")) == []
    host.publish("board")
    host.emit("plan", generation=1)
    host.counters["replans"] = 2
    host.world.assert_fact("grasped", "a")
    assert agent.sent == [("plans", "board")] and events.seen == [("plan", {"generation": 1})]
    assert ctx.stats == {"replans": 2} and host.world.holds("grasped", "a")
    host.register_plan(lib.plans["Solo"], {}, {"Work": ("a",)})
    assert agent.generated.pins == {"Solo": {"Work": ("a",)}}
    with pytest.raises(TypeError, match="not a plan this engine runs"):
        host.holds("true", object())  # type: ignore[arg-type]
    with pytest.raises(AlicaError, match="owns no topic"):
        EngineHost(ctx, agent, None).publish("board")


# -- allocation makes nodes through Nodes, and keeps what succeeded for a restart -----------


class Refuse:
    """Stand-ins for the parts a plan without children never calls."""

    def bind(self, node: object, ref: object) -> dict[str, object]:
        raise AssertionError("no child to bind")

    def runner(self, slot: object) -> object:
        raise AssertionError("no behaviour to run")

    def runtime(self, slot: object) -> object:
        raise AssertionError("no child runtime")

    def track(self, slot: object) -> None:
        raise AssertionError("no solved values")

    def unwatch(self, slot: object) -> None:
        raise AssertionError("no solved values")


def _allocation(lib: PlanLibrary) -> tuple[Allocator, PlanTree, Events, AgentContext]:
    ctx, events, _ = _context({"a": "Worker"})
    generated = GeneratedPlans(pick_roleset(lib, ["Worker"]))
    tree = PlanTree(lib, generated)
    allocator = Allocator(ctx, tree, generated)
    refuse = Refuse()
    tree.attach(NodeParts(ctx, tree, allocator, refuse, refuse, refuse, SyncTable("a", 0.1)))  # type: ignore[arg-type]
    return allocator, tree, events, ctx


def test_allocation_starts_a_plan_through_the_tree_it_is_given(lib):
    allocator, tree, events, ctx = _allocation(lib)
    assert allocator.members(None) == ("a",)
    node = allocator.start(None, (lib.plans["Solo"],), {"self": "a"}, 0.0)
    assert isinstance(node, PlanNode) and tree.get(("Solo",)) is node
    assert (node.ep, node.state) == ("Work", "Busy")
    assert ctx.stats == {"allocations": 1} and events.kinds() == ["allocation"]
    assert tree.news and tree.inputs == 1  # the node entered its state: the team hears of it
    assert [c.plan for c in tree.claims(node)] == ["Solo"]


def test_a_plan_restarted_for_want_of_agents_keeps_what_succeeded(lib):
    allocator, tree, _, _ = _allocation(lib)
    node = allocator.start(None, (lib.plans["Solo"],), {"self": "a"}, 0.0)
    assert node is not None
    node.enter_state("Done", 1.0)
    assert node.succeeded == {"Work": {"a"}}
    allocator.carry(node)
    node.stop()
    assert tree.get(("Solo",)) is None
    again = allocator.start(None, (lib.plans["Solo"],), {"self": "a"}, 2.0)
    assert again is not None and again.succeeded == {"Work": {"a"}} and allocator.carried == {}


def test_the_tree_needs_its_parts_before_it_makes_a_node(lib):
    tree = PlanTree(lib, GeneratedPlans(pick_roleset(lib, ["Worker"])))
    with pytest.raises(AlicaError, match="attach"):
        tree.new_node(("Solo",), None, lib.plans["Solo"], {}, 0.0)
    assert tree.out_transitions(lib.plans["Solo"], "Busy") is tree.out_transitions(lib.plans["Solo"], "Busy")
