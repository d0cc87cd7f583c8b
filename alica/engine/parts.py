"""What the parts of one agent's engine share, declared below all of them.

The engine (:mod:`alica.engine.agent`) is built from collaborators: the plan
tree (:mod:`alica.engine.tree`) with its nodes and slots
(:mod:`alica.engine.node`, :mod:`alica.engine.slot`), allocation
(:mod:`alica.engine.allocate`), constraint queries
(:mod:`alica.engine.solving`), the start of a state's children
(:mod:`alica.engine.launch`) and the child-runtime host
(:mod:`alica.engine.hosting`). None of them holds the engine. Each is given
:class:`AgentContext`, the few values every part reads (the agent's name, its
clock, settings, team view, formulas and belief base, counters and trace), and
for anything more a small Protocol declared in its own module, which another
collaborator (or the engine) satisfies structurally. This module sits below
them all, so the engine's modules import each other in one direction only.

It also holds the two values a skill sees of the constraint solver
(:class:`SolveResult`, :class:`NoSolution`), which behaviours and plan nodes
use without importing the solver's engine side.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, MutableMapping
from dataclasses import dataclass
from typing import Protocol

from alica.engine.belief import AgentBelief
from alica.engine.conditions import Formulas
from alica.engine.config import EngineConfig
from alica.engine.team import TeamView
from alica.errors import AlicaError

__all__ = ["AgentContext", "Emit", "NoSolution", "SolveResult"]


class Emit(Protocol):
    """Sends one trace event to the engine's observers (:meth:`AgentEngine.emit <alica.engine.agent.AgentEngine.emit>`)."""

    def __call__(self, event: str, **fields: object) -> None:
        """Send event ``event`` with ``fields``."""
        ...


@dataclass(frozen=True, slots=True)
class AgentContext:
    """What every part of one agent's engine reads: made once by the engine, never replaced.

    Attributes:
        name: the agent's name (its id in the team).
        now: the current (simulated) time.
        config: the engine's settings.
        team: the agent's view of its team (who is alive, what each claims).
        formulas: the compiled formulas of the plans.
        belief: the agent's belief base (:meth:`AgentBelief.at` looks at a plan node's context).
        stats: the agent's counters (``ticks``, ``allocations``, ``solves``, ...), reported in the run's summary.
        emit: sends a trace event.
    """

    name: str
    now: Callable[[], float]
    config: EngineConfig
    team: TeamView
    formulas: Formulas
    belief: AgentBelief
    stats: MutableMapping[str, int]
    emit: Emit

    def count(self, counter: str) -> None:
        """Add one to ``counter``."""
        self.stats[counter] = self.stats.get(counter, 0) + 1


class NoSolution(AlicaError):
    """The constraints of a query have no solution (or none was found in the time budget)."""


@dataclass(frozen=True)
class SolveResult:
    """What a constraint query returns (:meth:`SkillContext.solve <alica.engine.behaviours.SkillContext.solve>`).

    Attributes:
        status: ``solved``, ``infeasible`` or ``timeout``.
        values: this agent's values, by the asking plan's variable names.
        team: every agent's per-agent values and the static ones (under ``""``), by the same names.
        utility: the utility of the solution (``nan`` when not solved).
        reason: why there is no solution (empty when solved).
    """

    status: str
    values: Mapping[str, object]
    team: Mapping[str, Mapping[str, object]]
    utility: float
    reason: str = ""

    @property
    def ok(self) -> bool:
        """Whether there are values."""
        return self.status == "solved"
