"""pRoPhEt MAS: planning problems filled in at run time.

* :func:`plan_problem` (:mod:`alica.prophet.pipeline`): a planning problem in a
  world -> PDDL -> a planner -> a validated plan, offline or anytime;
* :mod:`alica.prophet.tasks`: a single-agent plan becomes a multi-agent ALICA plan;
* :mod:`alica.prophet.runtime`: the runtime of a planning-problem child in each
  agent's engine, plugged in with :data:`PLANNING` or :func:`engine_config`
  (:mod:`alica.prophet.plugin`);
* :mod:`alica.prophet.planners`: the planner back-ends by name.

The names below are imported on first use, so that ``alica.prophet.pddl`` and
the planners load without the engine.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from alica.prophet.pipeline import ProblemPlanning, ProblemResult, ValidPlan, plan_problem
    from alica.prophet.plugin import PLANNING, Planning, PlanningAgent, engine_config, latest_plans, made_plans
    from alica.prophet.runtime import ProblemRuntime, SearchBudget

_HOME = {
    "ProblemPlanning": "pipeline",
    "ProblemResult": "pipeline",
    "ValidPlan": "pipeline",
    "plan_problem": "pipeline",
    "PLANNING": "plugin",
    "Planning": "plugin",
    "PlanningAgent": "plugin",
    "engine_config": "plugin",
    "latest_plans": "plugin",
    "made_plans": "plugin",
    "ProblemRuntime": "runtime",
    "SearchBudget": "runtime",
}

__all__ = [
    "PLANNING",
    "Planning",
    "PlanningAgent",
    "ProblemPlanning",
    "ProblemResult",
    "ProblemRuntime",
    "SearchBudget",
    "ValidPlan",
    "engine_config",
    "latest_plans",
    "made_plans",
    "plan_problem",
]


def __getattr__(name: str) -> object:
    module = _HOME.get(name)
    if module is None:
        raise AttributeError(f"module 'alica.prophet' has no attribute '{name}'")
    return getattr(importlib.import_module(f"alica.prophet.{module}"), name)
