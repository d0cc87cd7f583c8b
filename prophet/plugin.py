"""pRoPhEt MAS plugged into the engine: the child kind for planning problems, and the conveniences to use it.

The engine knows nothing of planning: it is given :data:`PLANNING` (or a
:class:`Planning` with another search budget) for the model element type
:class:`~alica.model.PlanningProblem` through its configuration, and runs
every planning-problem child through the seam of :mod:`alica.engine.child`::

    from alica.prophet import engine_config

    team = SimulatedTeam(library, "BlocksWorldMission", agents, config=engine_config(frequency=10.0))

Each agent's engine attaches the kind once and gets a :class:`PlanningAgent`:
the agent's :class:`~alica.prophet.board.PlanBoard` (fed with every message on
:data:`~alica.prophet.board.PLAN_TOPIC`) and the factory of a
:class:`~alica.prophet.runtime.ProblemRuntime` for each planning-problem child
the agent enters.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from alica.engine.child import ChildHost, ChildKinds, ChildSlot, PlanKey
from alica.engine.config import EngineConfig
from alica.model import PlanningProblem
from alica.prophet.board import PLAN_TOPIC, PlanBoard
from alica.prophet.magic.team import TeamMagic
from alica.prophet.runtime import ProblemRuntime, SearchBudget
from alica.prophet.tasks import CreatedTasks


@dataclass(frozen=True, slots=True)
class Planning:
    """pRoPhEt MAS as the engine's child kind for planning problems (an :class:`alica.engine.child.ChildKind`).

    Attributes:
        budget: how much the leader searches per tick.
        topic: the team topic of plan shares and replan requests.
    """

    budget: SearchBudget = field(default_factory=SearchBudget)
    topic: str | None = PLAN_TOPIC
    parallel: bool = False
    """MAGiC: the leader splits its search over the agents in the problem's state (:mod:`alica.prophet.magic.team`)."""

    def __call__(self, host: ChildHost) -> PlanningAgent:
        """Attach to one agent's engine."""
        return PlanningAgent(host, self.budget, parallel=self.parallel)


class PlanningAgent:
    """One agent's pRoPhEt MAS: its plan board, and the runtimes of the planning problems it enters.

    Args:
        host: what the agent's engine offers.
        budget: the leader's search budget per tick.
    """

    def __init__(self, host: ChildHost, budget: SearchBudget, *, parallel: bool = False) -> None:
        self.host = host
        self.budget = budget
        self.board = PlanBoard()
        self.magic = TeamMagic(host, budget.expansions, budget.seconds) if parallel else None
        host.counters.setdefault("replans", 0)

    def __call__(self, slot: ChildSlot) -> ProblemRuntime:
        """The runtime of a planning-problem child (the agent enters its state)."""
        return ProblemRuntime(self.host, slot, self.board, self.budget, self.magic)

    def receive(self, payload: object, now: float) -> None:
        """A plan share, a replan request or a MAGiC message arrived."""
        if self.magic is not None and self.magic.receive(payload):
            return
        self.board.receive(payload, now)


#: pRoPhEt MAS with the default search budget (1000 expansions per tick).
PLANNING = Planning()


def engine_config(
    config: EngineConfig | None = None,
    *,
    planner_expansions: int = 1000,
    planner_seconds: float | None = None,
    parallel_planning: bool = False,
    **settings: Any,
) -> EngineConfig:
    """An engine configuration with pRoPhEt MAS plugged in for planning problems.

    Args:
        config: the configuration to extend (default: the engine's defaults).
        planner_expansions: the leader's search budget per tick, in expansions
            (deterministic: the same run plans the same way).
        planner_seconds: a wall-time budget per tick instead (for real robots);
            ``None`` uses ``planner_expansions``.
        parallel_planning: MAGiC: the leader splits each search over the agents in
            the planning problem's state, each searching one share with its own budget
            (:mod:`alica.prophet.magic.team`); the first valid plan wins.
        **settings: other :class:`~alica.engine.config.EngineConfig` settings.

    Raises:
        ValueError: a setting is out of range.
    """
    base = config or EngineConfig()
    planning = Planning(SearchBudget(planner_expansions, planner_seconds), parallel=parallel_planning)
    return replace(base, children={**base.children, PlanningProblem: planning}, **settings)


def latest_plans(engine: ChildKinds) -> Mapping[PlanKey, CreatedTasks]:
    """The latest plan generated for each planning problem an agent's engine ran (kept after it ended).

    Args:
        engine: an agent's engine (:class:`alica.engine.AgentEngine`).
    """
    agent = engine.child_kind(PlanningProblem)
    return agent.board.latest if isinstance(agent, PlanningAgent) else {}


def made_plans(engine: ChildKinds) -> Sequence[tuple[int, int, CreatedTasks]]:
    """``(generation, version, plan)`` of every plan generated for the problems an agent's engine ran, in the order it took them up.

    Args:
        engine: an agent's engine (:class:`alica.engine.AgentEngine`).
    """
    agent = engine.child_kind(PlanningProblem)
    return tuple(agent.board.made) if isinstance(agent, PlanningAgent) else ()
