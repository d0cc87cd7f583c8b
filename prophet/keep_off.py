"""A robot whose step failed is kept off that step for a while.

Allocation prefers the robot nearest to where a task starts, so after a failed step the replanned
task that holds the same step goes to the same robot again: a robot boxed in near a corner, or one
whose grasp keeps failing from where it stands, would try it until the problem gives up. The leader
remembers each failed step that could still run (the robot failed it, not a world that changed under
it) with its robot (:class:`KeepOff`) for :data:`KEEP_OFF_S` seconds and
shares the pairs with its plans (:attr:`~alica.prophet.board.PlanShare.barred`); every agent then
leaves that robot out of the tasks that hold the step (:func:`bar`), as it leaves robots out of a
pinned task. Where that leaves a task nobody who can take it (the robot holds the block the task
needs, the team is that robot alone, or the others' roles cannot do the task's skills), the task keeps
its robots: a retry by the same robot beats no robot at all.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace

from alica.lang.fact import Fact
from alica.model import Priority
from alica.prophet.tasks import CreatedTasks, Step, apply_effect, for_robot, holds

KEEP_OFF_S = 60.0
"""How long a robot stays off a step that failed with it (simulated seconds): about the time the rest
of the team needs for a few steps, long enough for another robot to take it."""


class KeepOff:
    """The leader's failed steps: (robot, step label) -> until when the robot stays off the step."""

    def __init__(self, hold_s: float = KEEP_OFF_S) -> None:
        self.hold_s = hold_s
        self.until: dict[tuple[str, str], float] = {}

    def failed(self, robot: str, step: str, now: float) -> None:
        """``robot``'s step ``step`` (its label, ``Unstack(c, a)``) failed at ``now``."""
        if robot and step:
            self.until[(robot, step)] = now + self.hold_s

    def active(self, now: float) -> tuple[tuple[str, str], ...]:
        """The (robot, step) pairs still kept off at ``now``, sorted (the older ones are forgotten)."""
        self.until = {pair: until for pair, until in self.until.items() if until > now}
        return tuple(sorted(self.until))


def bar(
    created: CreatedTasks,
    barred: Sequence[tuple[str, str]],
    robots: Sequence[str],
    roles: Mapping[str, str] | None = None,
    world: Iterable[Fact] | None = None,
) -> CreatedTasks:
    """``created`` with each barred robot left out of the tasks that hold its barred step.

    A task keeps its robots where leaving them out would leave it none that can take it (with
    ``roles``, robot -> role: a robot whose role's priority for the task is negative cannot; with
    ``world``, the facts the plan starts from: a robot whose own facts there do not let it run the
    task's steps cannot either, say with its hand full: :func:`_fits`), see the module docstring; an
    entry that is not a pair of strings is ignored.
    """
    if not barred:
        return created
    allowed = list(created.allowed) + [None] * (len(created.tasks) - len(created.allowed))
    priorities = created.priorities()
    facts = frozenset(world) if world is not None else None
    changed = False
    for index, task in enumerate(created.tasks):
        labels = {step.label for step in task}
        off = {pair[0] for pair in barred if _pair(pair) and pair[1] in labels}
        if not off:
            continue
        pinned = allowed[index]
        candidates = pinned if pinned is not None else tuple(robots)
        kept = tuple(robot for robot in candidates if robot not in off)
        able = kept
        if roles is not None:
            task_name = created.task_defs[index].name
            able = tuple(r for r in kept if _priority(priorities.get(roles.get(r, ""), ()), task_name) >= 0)
        if not able or (facts is not None and not any(_fits(task, r, facts) for r in able)):
            continue  # nobody else can take it (by role, or from where it is now): the robot keeps it
        if kept and kept != candidates:
            allowed[index] = kept
            changed = True
    return replace(created, allowed=tuple(allowed)) if changed else created


def _fits(task: Sequence[Step], robot: str, facts: frozenset[Fact]) -> bool:
    """Whether ``robot`` could run ``task``'s steps from ``facts`` as far as its own facts go (its hand,
    where it is): each step's literals naming the robot hold, after the effects of the steps before."""
    state = set(facts)
    for step in task:
        own = [literal for literal in for_robot(step.pre, step.robot, robot) if robot in literal[1].args]
        if not holds(own, state):
            return False
        apply_effect(state, for_robot(step.effect, step.robot, robot))
    return True


def _priority(priorities: Sequence[Priority], task: str) -> float:
    """A role's priority for ``task`` (-1 where it has none: the role cannot take it)."""
    return next((p.value for p in priorities if p.task == task), -1.0)


def _pair(value: object) -> bool:
    """Whether a barred entry is a (robot, step) pair of strings (a share comes from the network)."""
    return isinstance(value, tuple) and len(value) == 2 and all(isinstance(part, str) for part in value)


__all__ = ["KEEP_OFF_S", "KeepOff", "bar"]
