"""Watching a generated plan run: the steps this agent finished, and the team's progress in the plan.

* :class:`StepMarks` writes ``step_done`` for the steps this agent finished
  (later steps of other tasks wait for them), with the step's effect, as a
  plan executor applies an action's effects when it completes.
* :func:`task_progress` reads where each task of the plan is from the team's
  believed states (the plan's :attr:`~alica.prophet.tasks.CreatedTasks.places`,
  never state names), and :func:`executing` whether an agent runs a step.
* :func:`stalled` tells a plan that cannot go on (a task nobody holds while an
  agent waits for it).
* :class:`PlanCheck` replans only when the check fails twice in a row (a
  teammate's message may lag behind the world).

The leader's check of the plan against the world uses these with
:func:`alica.prophet.world.remaining_fits`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from alica.engine.child import RunningPlan, WorldFacts
from alica.prophet.tasks import STEP_DONE, CreatedTasks, Step, StepKind, for_robot, step_token
from alica.prophet.world import TaskProgress


class StepMarks:
    """The steps this agent marked done in the generated plan, and those whose effect it wrote early.

    Args:
        world: the agent's replica of the world model (written to).
        me: the agent's name.
    """

    def __init__(self, world: WorldFacts, me: str) -> None:
        self.world = world
        self.me = me
        self.marked: set[str] = set()
        """Steps marked ``step_done`` (their tokens)."""
        self.effected: set[str] = set()
        """Steps under way whose effect was written early (their skills had written its positive part)."""

    def mark_done(self, node: RunningPlan | None, created: CreatedTasks | None) -> None:
        """Write ``step_done`` for the steps this agent finished in the generated plan (later steps wait for them).

        The finished step's effect (its skill plan's signature, for this agent) is written too, as a
        plan executor applies an action's effects when it completes: the skills write what they sense
        (``holding``, ``onground``), but a fact of the planning domain that no skill writes (the robot's
        ``at`` a sample it has picked up, deleted by Pickup) would otherwise keep a stale value.
        A step under way whose effect's positive part holds already is treated alike, once.

        Args:
            node: the child's running plan (``None``: none runs).
            created: the generated plan's tasks (``None``: none).
        """
        if node is None or created is None or node.plan is not created.plan or node.ep is None:
            return
        place = created.place(node.state)
        if place is None:
            return  # standing by
        world, me = self.world, self.me
        for step in created.tasks[place.task][: place.step]:
            token = step_token(created.plan.name, step.index)
            if token not in self.marked:
                self.marked.add(token)
                if token not in self.effected:
                    self.write_effect(step)
                world.assert_fact(STEP_DONE, token)
        if place.kind is StepKind.RUN and place.step < len(created.tasks[place.task]):
            # a step under way whose effects the skills wrote already (the grasp is done, the lift is not)
            # has done its work: its whole effect is written now, so that a replan before it ends (a
            # teammate's step failed) does not plan from a robot still 'at' the sample it holds
            step = created.tasks[place.task][place.step]
            token = step_token(created.plan.name, step.index)
            if token not in self.effected:
                effect = for_robot(step.effect, step.robot, me)
                if all(world.holds(fact.predicate, *fact.args) for positive, fact in effect if positive):
                    self.effected.add(token)
                    self.write_effect(step)

    def write_effect(self, step: Step) -> None:
        """Write a step's effect for this agent to the world model (deletes first)."""
        world = self.world
        effect = for_robot(step.effect, step.robot, self.me)
        for positive, fact in sorted(effect, key=lambda literal: literal[0]):
            (world.assert_fact if positive else world.retract_fact)(fact.predicate, *fact.args)


class PlanCheck:
    """The leader's check of the rest of the plan: it replans only after two failed checks in a row."""

    def __init__(self) -> None:
        self.invalid_once = False
        """Whether the last check failed."""

    def reset(self) -> None:
        """A new share is followed: its plan has not failed a check."""
        self.invalid_once = False

    def replan_reason(self, fault: str | None) -> str | None:
        """The reason to replan after a check that found ``fault`` (``None``: the plan fits), or ``None``.

        The first failed check is remembered; the second in a row replans (a stuck plan, or a world that
        changed under it). A check that passes forgets the failed one.
        """
        if fault is None:
            self.invalid_once = False
            return None
        if not self.invalid_once:
            self.invalid_once = True
            return None
        if fault.startswith("task T"):
            return f"the plan is stuck: {fault}"
        return f"the world changed under the plan: {fault}"


def executing(node: RunningPlan | None, created: CreatedTasks | None) -> bool:
    """Whether an agent runs a step of the generated plan (a better plan then no longer replaces it)."""
    if node is None or created is None or node.plan is not created.plan:
        return False
    return any(
        (place := created.place(state)) is not None and place.kind is StepKind.RUN
        for _, state in node.believed.values()
    )


def task_progress(node: RunningPlan, created: CreatedTasks) -> list[TaskProgress]:
    """Where each task of the generated plan is, from the team's believed states (the lowest agent on it counts)."""
    progress = []
    for ep, steps in zip(created.task_entry_points, created.tasks, strict=True):
        if node.succeeded.get(ep.name):
            progress.append(TaskProgress(None, len(steps), done=True))
            continue
        holders = sorted(
            (place.step if place is not None else 0, agent, place is not None and place.kind is StepKind.RUN)
            for agent, (entry, state) in node.believed.items()
            if entry == ep.name and state
            for place in (created.place(state),)
        )
        if holders:
            k, agent, running = holders[0]
            progress.append(TaskProgress(agent, k, running=running))
        else:
            progress.append(TaskProgress(None, 0))
    return progress


def stalled(
    progress: list[TaskProgress],
    order: Sequence[Sequence[int]],
    allowed: tuple[tuple[str, ...] | None, ...] = (),
    members: tuple[str, ...] = (),
) -> str | None:
    """A task nobody holds while an agent waits in a step that comes after it in the plan: replan.

    ``order[i]`` holds the plan positions of task ``i``'s steps. A step waits
    only for steps before it in the plan, so an agent whose next step comes
    after the free task's first step may wait for the free task; that is not
    stuck while an alive agent that may take the free task will be free for
    it: one that runs a step now, or whose next step comes before the free
    task's (its task does not wait for the free one; it finishes it and then
    takes the free task by the engine's reuse rule, as a team smaller than
    its tasks works). An agent that may take the free task but waits in a
    step after it never will: with the free task pinned to it alone, that is
    a deadlock. So is a free task pinned only to agents that left the team.
    """

    def position(i: int) -> float:  # where the task's next step is in the plan (its last steps finished: after all)
        steps, k = order[i], progress[i].next_step
        return steps[k] if k < len(steps) else math.inf

    free = [i for i, p in enumerate(progress) if p.agent is None and not p.done]
    if not free:
        return None
    first = min(free, key=position)
    start = position(first)
    pinned = allowed[first] if first < len(allowed) else None
    may = set(pinned if pinned is not None else members) & set(members)
    if not may and pinned is not None:
        # only robots that left the team (crashed, say, holding the block the task starts with) may start it
        return f"task T{first} has nobody, and only {', '.join(sorted(pinned))} may start it, who is not in the team"
    waiting = [
        i
        for i, p in enumerate(progress)
        if p.agent is not None and not p.running and not p.done and position(i) > start
    ]
    if not waiting:
        return None
    if any(p.agent in may and not p.done and (p.running or position(i) < start) for i, p in enumerate(progress)):
        return None
    return f"task T{first} has nobody, and the agent of task T{max(waiting)} waits for it"
