"""The team engine: one ALICA engine per agent, ticked in simulated or real time.

* :class:`AgentEngine` runs one agent's plan tree (:mod:`alica.engine.node`):
  rules, allocation, repair, synchronised transitions, the team view.
* :class:`SimulatedTeam` runs a whole team in lock step over a simulated
  network with faults (loss, delay, partitions, crashes).
* Behaviours are py_trees behaviours built from skills
  (:mod:`alica.engine.behaviours`); :mod:`alica.testing` has scripted doubles.
* A child whose plans are only known at run time (a planning problem) runs
  what a child runtime decides (:mod:`alica.engine.child`); implementations
  such as pRoPhEt MAS are given through :attr:`EngineConfig.children`.
"""

from alica.engine.agent import AgentEngine
from alica.engine.behaviours import BehaviourRunner, SkillBinder, SkillContext, SkillFactory
from alica.engine.child import (
    ChildFactory,
    ChildHost,
    ChildKind,
    ChildKinds,
    ChildRuntime,
    ChildSlot,
    PlanDecision,
    RunningPlan,
)
from alica.engine.config import EngineConfig
from alica.engine.runner import SimulatedTeam, pick_roleset
from alica.engine.show import running_tree
from alica.engine.status import ChildStatus
from alica.engine.team import Claim, TeamMessage, TeamView
from alica.engine.trace import JsonlTrace, Trace, TraceRecorder, read_trace, trace_header

__all__ = [
    "AgentEngine",
    "BehaviourRunner",
    "ChildFactory",
    "ChildHost",
    "ChildKind",
    "ChildKinds",
    "ChildRuntime",
    "ChildSlot",
    "ChildStatus",
    "Claim",
    "EngineConfig",
    "JsonlTrace",
    "PlanDecision",
    "RunningPlan",
    "SimulatedTeam",
    "SkillBinder",
    "SkillContext",
    "SkillFactory",
    "TeamMessage",
    "TeamView",
    "Trace",
    "TraceRecorder",
    "pick_roleset",
    "read_trace",
    "running_tree",
    "trace_header",
]
