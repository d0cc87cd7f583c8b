"""What the demos share: counting the steps of generated plans, and the generated plan as YAML."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from alica.engine import AgentEngine, SimulatedTeam
    from alica.prophet.tasks import CreatedTasks

__all__ = ["StepCounter", "plan_yaml_text", "planning_leader"]


@dataclass(slots=True)
class _Step:
    """A step an agent is executing: the key of its step plan's node, and the task it belongs to."""

    key: str
    task: tuple[str, str]


class StepCounter:
    """Counts what the trace says: the steps and tasks each agent carried out, plans made, replans.

    A step starts when an agent allocates itself to one of the problem's
    elements (``Pickup``, ``Stack``, ...) below the planning problem, and is
    carried out when that step plan succeeds. A task is an entry point of a
    generated plan; an agent carried it out when it carried out a step of it.
    """

    def __init__(self, elements: Iterable[str], problem: str) -> None:
        self.elements = frozenset(elements)
        self.problem = problem
        self.steps: dict[str, int] = {}
        self.tasks: dict[str, set[tuple[str, str]]] = {}
        self.running: dict[str, _Step] = {}
        self.task_of: dict[str, tuple[str, str]] = {}
        self.plans: set[tuple[str, int]] = set()
        self.replans = 0
        self.plan_length = 0
        self.gave_up = ""
        """Why the problem last failed (the team ran its AlternativePlan), if it did."""

    def __call__(self, event: dict[str, Any]) -> None:
        kind = event["event"]
        agent = str(event.get("agent"))
        key = str(event.get("key", ""))
        if kind == "allocation" and "plan" in event:
            plan = str(event["plan"])
            if key.rsplit("/", 1)[-1] == self.problem:  # the plan that runs under the problem: the task is its entry
                entries = event.get("entries", {})
                if (
                    agent in entries
                ):  # (an agent also reports teammates' allocations: those leave its own task as it is)
                    self.task_of[agent] = (plan, str(entries[agent]))
                    self.running.pop(agent, None)
            elif plan in self.elements and f"/{self.problem}/" in key and agent in self.task_of:
                self.running[agent] = _Step(key, self.task_of[agent])
        elif kind == "success" and event.get("plan") in self.elements:
            step = self.running.get(agent)
            if step is not None and step.key == key:
                self._carried_out(agent, self.running.pop(agent))
        elif kind == "replan":
            self.replans += 1
        elif kind == "planner" and event.get("what") == "plan":
            self.plans.add((key, int(event.get("generation", 0))))
            self.plan_length = int(event.get("steps", 0))
        elif kind == "problem" and event.get("phase") == "alternative" and event.get("reason"):
            self.gave_up = str(event["reason"])

    def _carried_out(self, agent: str, step: _Step) -> None:
        self.steps[agent] = self.steps.get(agent, 0) + 1
        self.tasks.setdefault(agent, set()).add(step.task)

    def finish(self, team: SimulatedTeam, facts: Iterable[tuple[object, ...]]) -> None:
        """Count the steps still running at the end whose effects hold in the world (the goal came true mid-step)."""
        from alica.lang import literals

        holds = set(facts)
        for agent, step in sorted(self.running.items()):
            engine = team.engines.get(agent)
            node = next((n for n in engine.index.values() if n.key_text == step.key), None) if engine else None
            signature = node.plan.signature if node is not None else None
            if node is None or signature is None or signature.effect is None:
                continue
            values: dict[str, object] = {
                v.name: node.env.get(v.name.lstrip("?"), agent if v.type == "robot" else None)
                for v in signature.parameters
            }
            effect = [
                (positive, pred, tuple(values.get(str(a), a) for a in args))
                for positive, pred, args in literals(signature.effect.text)
            ]
            if all(((pred, *args) in holds) == positive for positive, pred, args in effect):
                self._carried_out(agent, self.running.pop(agent))


def planning_leader(team: SimulatedTeam) -> AgentEngine | None:
    """A running agent that made a plan for a planning problem (the leader), or None."""
    from alica.prophet import latest_plans

    running = [e for e in team.running() if latest_plans(e)]
    return running[0] if running else None


def plan_yaml_text(created: CreatedTasks, mission: Path, out: Path | None) -> str:
    """The generated plan as YAML, importing the ``mission`` file from where it is written (``out``):
    a shipped mission as ``alica:plans/...``, so the file stays valid wherever it is moved."""
    from alica.io import import_reference
    from alica.prophet.tasks import emit_yaml

    return emit_yaml(created, imports=(import_reference(mission, out if out is not None else Path.cwd()),))
