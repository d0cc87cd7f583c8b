"""The operator's review of generated plans (IMPERA: "The control center is able to accept, decline or even modify this plan").

With review on (``EngineConfig.review``), the leader of a planning problem
does not share the first valid plan of a generation: it stops searching and
emits a ``proposal`` trace event (:func:`proposal_fields`), and the team runs
the WaitPlan until the operator decides
(:class:`~alica.engine.child.PlanDecision`, through
``AgentEngine.decide_plan``). The runtime (:mod:`alica.prophet.runtime`)
applies the decision with the helpers here:

* :func:`reordered`: the step list a ``modify`` decision keeps, in its order;
* :func:`resolve_pins`: the operator's pins as task index -> robot, checked
  against the tasks of the plan as modified and the team;
* :func:`apply_pins`: the pins on created tasks (a pinned task may only be
  taken by its robot, as :attr:`~alica.prophet.tasks.CreatedTasks.allowed` says);
* :func:`describe_proposal`: a ``proposal`` event as text, for a person.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from alica.errors import PlannerError
from alica.prophet.planner import PlanStep
from alica.prophet.tasks import CreatedTasks

#: The name of the plan whose tasks a proposal shows (its entry points are ``<name>_T<i>``).
PROPOSAL_PLAN = "{problem}_g{generation}_proposal"


class ReviewError(PlannerError):
    """An operator's change of a proposed plan that cannot be run (the message says why)."""


def reordered(steps: Sequence[PlanStep], order: Sequence[int] | None) -> tuple[PlanStep, ...]:
    """The steps an operator keeps, in the order given (``None``: all, as they are).

    Raises:
        ReviewError: an index is not a step of the plan, or names a step twice.
    """
    if order is None:
        return tuple(steps)
    seen: set[int] = set()
    for index in order:
        if not 0 <= index < len(steps):
            raise ReviewError(f"the order names step {index}, but the plan's steps are 0 to {len(steps) - 1}")
        if index in seen:
            raise ReviewError(f"the order names step {index} ({steps[index]}) twice")
        seen.add(index)
    return tuple(steps[i] for i in order)


def _task_index(created: CreatedTasks, task: str) -> int | None:
    """The index of the task an operator names: by entry point name, ``T<i>`` or ``<i>``."""
    for i, ep in enumerate(created.task_entry_points):
        if ep.name == task:
            return i
    text = task[1:] if task[:1] in ("T", "t") else task
    if text.isdigit() and int(text) < len(created.tasks):
        return int(text)
    return None


def resolve_pins(created: CreatedTasks, pins: Mapping[str, str], team: Sequence[str]) -> tuple[tuple[int, str], ...]:
    """The operator's pins as ``(task index, robot)``, sorted.

    Args:
        created: the tasks of the plan as modified.
        pins: task (entry point name, ``T<i>`` or ``<i>``) -> the robot that alone may take it.
        team: the robots the plan was made with.

    Raises:
        ReviewError: a task that does not exist, a robot not in the team, a robot that
            cannot start the task (task creation allows only others), or one task pinned twice.
    """
    out: dict[int, str] = {}
    tasks = ", ".join(f"T{i} ({ep.name})" for i, ep in enumerate(created.task_entry_points))
    for task, robot in sorted(pins.items()):
        index = _task_index(created, task)
        if index is None:
            raise ReviewError(f"pin {task} -> {robot}: the plan has no task '{task}'; its tasks: {tasks}")
        if robot not in team:
            raise ReviewError(f"pin {task} -> {robot}: '{robot}' is not in the team ({', '.join(team)})")
        allowed = created.allowed[index] if index < len(created.allowed) else None
        if allowed is not None and robot not in allowed:
            raise ReviewError(
                f"pin {task} -> {robot}: only {', '.join(allowed)} can start task T{index} in the world it was planned in"
            )
        if out.get(index, robot) != robot:
            raise ReviewError(f"pin {task} -> {robot}: task T{index} is pinned to {out[index]} already")
        out[index] = robot
    return tuple(sorted(out.items()))


def apply_pins(created: CreatedTasks, pins: Sequence[tuple[int, str]]) -> CreatedTasks:
    """``created`` with each pinned task allowed to its robot only.

    Raises:
        ReviewError: a pin names a task the plan does not have.
    """
    if not pins:
        return created
    allowed = list(created.allowed) + [None] * (len(created.tasks) - len(created.allowed))
    for index, robot in pins:
        if not 0 <= index < len(created.tasks):
            raise ReviewError(f"a pin names task T{index}, but the plan has {len(created.tasks)} tasks")
        allowed[index] = (robot,)
    return replace(created, allowed=tuple(allowed))


def task_fields(created: CreatedTasks) -> list[dict[str, Any]]:
    """The tasks of a plan as plain data: entry point, steps (indices into the plan and text), pinned robots."""
    out = []
    for i, (ep, steps) in enumerate(zip(created.task_entry_points, created.tasks, strict=True)):
        allowed = created.allowed[i] if i < len(created.allowed) else None
        out.append(
            {
                "entry_point": ep.name,
                "steps": [step.index for step in steps],
                "labels": [step.label for step in steps],
                "robots": list(allowed) if allowed is not None else None,
            }
        )
    return out


def proposal_fields(
    *,
    key: str,
    problem: str,
    generation: int,
    leader: str,
    cost: float,
    goal: str,
    steps: Sequence[PlanStep],
    created: CreatedTasks | None,
    error: str | None = None,
    decision: Mapping[str, object] | None = None,
) -> dict[str, Any]:
    """The fields of a ``proposal`` trace event.

    ``steps`` are texts such as ``(unstack c a r1)``; each task's ``steps`` index into them.
    ``error`` (with the ``decision`` that caused it) says why a change of the plan was refused.
    """
    fields: dict[str, Any] = {
        "key": key,
        "problem": problem,
        "generation": generation,
        "leader": leader,
        "cost": cost,
        "goal": goal,
        "steps": [str(step) for step in steps],
        "tasks": task_fields(created) if created is not None else [],
    }
    if error is not None:
        fields["error"] = error
    if decision is not None:
        fields["decision"] = dict(decision)
    return fields


def describe_proposal(event: Mapping[str, Any]) -> str:
    """A ``proposal`` trace event as lines a person reads (for a console or the control center)."""
    lines = [
        f"plan proposed for {event.get('problem', '?')} (generation {event.get('generation', '?')}, "
        f"leader {event.get('leader', '?')}, cost {event.get('cost', '?')})",
        f"  goal: {event.get('goal', '')}",
    ]
    steps = list(event.get("steps", ()))
    lines.extend(f"  {i}: {step}" for i, step in enumerate(steps))
    for task in event.get("tasks", ()):
        robots = task.get("robots")
        who = f" [only {', '.join(robots)}]" if robots else ""
        picked = ", ".join(f"{i} {steps[i]}" if 0 <= i < len(steps) else str(i) for i in task.get("steps", ()))
        lines.append(f"  task {task.get('entry_point', '?')}{who}: {picked}")
    if event.get("error"):
        lines.append(f"  refused change: {event['error']}")
    return "\n".join(lines)
