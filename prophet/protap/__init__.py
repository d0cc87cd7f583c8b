"""ProTaP: the paper's RDDL domain (fixed), problem generation (Algorithm 2), a fast simulator, a planner, a dispatcher.

>>> spec = random_spec(robots=2, width=5, height=5, goals=3, seed=0)
>>> model = ProtapModel(spec)
>>> evaluate(model, greedy, episodes=2, seed=1).mean > 0
True
"""

from __future__ import annotations

from alica.prophet.protap.dispatch import (
    ActionCall,
    Activity,
    Episode,
    Executor,
    ModelExecutor,
    RobotCalls,
    RobotOutcome,
    StepRecord,
    calls,
    observe,
    run_dispatched,
)
from alica.prophet.protap.generate import (
    appendix_c_spec,
    domain_text,
    instance_text,
    random_spec,
    spec_from_facts,
    write_problem,
)
from alica.prophet.protap.heuristic import Determinisation
from alica.prophet.protap.model import IDLE, NOOP, JointAction, ProtapModel, RobotAction, State
from alica.prophet.protap.planner import Budget, PlannerPolicy, ProtapPlanner
from alica.prophet.protap.policies import Evaluation, Policy, Recorder, evaluate, greedy, random_policy
from alica.prophet.protap.spec import (
    MANIPULATION,
    USER_DEFINED,
    Action,
    Cell,
    Goal,
    ProblemSpec,
    Robot,
    is_object_name,
    rddl_name,
)

__all__ = [
    "IDLE",
    "MANIPULATION",
    "NOOP",
    "USER_DEFINED",
    "Action",
    "ActionCall",
    "Activity",
    "Budget",
    "Cell",
    "Determinisation",
    "Episode",
    "Evaluation",
    "Executor",
    "Goal",
    "JointAction",
    "ModelExecutor",
    "PlannerPolicy",
    "Policy",
    "ProblemSpec",
    "ProtapModel",
    "ProtapPlanner",
    "Recorder",
    "Robot",
    "RobotAction",
    "RobotCalls",
    "RobotOutcome",
    "State",
    "StepRecord",
    "appendix_c_spec",
    "calls",
    "domain_text",
    "evaluate",
    "greedy",
    "instance_text",
    "is_object_name",
    "observe",
    "random_policy",
    "random_spec",
    "rddl_name",
    "run_dispatched",
    "spec_from_facts",
    "write_problem",
]
