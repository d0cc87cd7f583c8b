"""The world a planning problem is planned from, and the check that a running plan still fits the world.

**World** (IMPERA 7.1) is read from first-order facts: the problem's own
``world`` for offline use, else the facts of the shared world model. Only
facts of the domain's predicates count. At run time the world is planned
with every alive team member as a robot (the objects of the type of the
skills' ``?r`` parameter), each with its own facts: a robot that holds a
block when the team replans is part of the world, and the plan may use it.
Facts of other robots (crashed members, opponents) are left out. Objects get
their types from the predicates they appear in (``clear(a)`` makes ``a`` a
``block``), from the problem's ``objects`` and from the world model's typed
objects. At run time the problem's ``objects`` are fixed things the team
knows without seeing them (the collection point ``g``); every other goal
object must be mentioned by a fact to be planned for.

While the team executes a generated plan, :func:`remaining_fits` simulates
what is left of it (each task's remaining steps, run by the agent holding the
task) from the current facts. A running step counts as under way whatever
its precondition says now: its skill may have changed part of the world
already (a grasp takes the sample off the ground before the lift), or have
just finished while the teammate's message lags behind; it fails by itself
when it cannot go on. An unmet precondition of a step not started yet, or a
goal not reached at the end, means the world changed under the plan (or a
task's new holder cannot go on from where its last holder stopped).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from alica.errors import AlicaError, PlannerError
from alica.lang import literals
from alica.lang.fact import Fact
from alica.model import PlanLibrary, PlanningProblem
from alica.prophet.problem import offline_world, predicate_types
from alica.prophet.tasks import Literal, Step, apply_effect, for_robot, holds


@dataclass(frozen=True, slots=True)
class PlanningWorld:
    """A world to plan from.

    Attributes:
        objects: ``(name, type)`` pairs, sorted.
        facts: the facts that hold, sorted.
        robots: the robots the plan may use, sorted.
        left_out: facts about robots outside the team that were left out (a
            block an opponent holds is missing from the world, say).
        outside: the objects in those facts that no kept fact mentions (the blocks opponents
            hold), and the goal's objects that no fact mentions (a block falling), sorted: the
            team does not plan for them.
        others: the robots outside the team the facts name (opponents, crashed members), sorted.
        fixed: the problem's own objects (a fixed place such as the collection point ``g``), sorted.
    """

    objects: tuple[tuple[str, str], ...]
    facts: tuple[Fact, ...]
    robots: tuple[str, ...] = ()
    left_out: int = 0
    outside: tuple[str, ...] = ()
    others: tuple[str, ...] = ()
    fixed: tuple[str, ...] = ()

    def object_types(self) -> dict[str, str]:
        """Object name -> type."""
        return dict(self.objects)


def goal_literals(problem: PlanningProblem) -> tuple[Literal, ...]:
    """The goal as ground literals.

    Raises:
        PlannerError: the goal is not a conjunction of literals.
    """
    try:
        found = literals(problem.goal.text)
    except AlicaError as exc:
        raise PlannerError(
            f"the goal of '{problem.name}' must be a conjunction of literals to be planned with: {exc}"
        ) from None
    return tuple((positive, Fact(name, tuple(str(a) for a in args))) for positive, name, args in found if name != "=")


def read_world(
    problem: PlanningProblem,
    library: PlanLibrary,
    facts: Iterable[Fact | tuple[object, ...]],
    team: Iterable[str],
    typed_objects: Mapping[str, Iterable[object]] | None = None,
) -> PlanningWorld:
    """The world the team plans from (see the module docstring).

    Args:
        problem: the planning problem.
        library: holds its elements' signatures.
        facts: true facts (:class:`~alica.lang.fact.Fact` values, or the world model's flat
            ``(predicate, *args)`` tuples); ignored when the problem has its own ``world``.
        team: the alive team members: the robots of the plan.
        typed_objects: type -> objects, e.g. from the world model.

    Raises:
        PlannerError: the problem's elements or goal cannot be planned with.
    """
    predicates = predicate_types(problem, library)
    robot_type = _robot_type(problem, library)
    offline = problem.world is not None
    declared: dict[str, str] = {}
    if offline:
        declared, given = offline_world(problem)
        source: Iterable[Fact | tuple[object, ...]] = given
    else:
        source = facts
    members = tuple(sorted(set(team)))
    fixed = {v.name: (v.type if v.type != "any" else "object") for v in problem.objects}
    known_types = {t.lower() for arity in predicates.values() for t in arity} | set(fixed.values())
    # objects known to be no robots: a predicate may take a robot or a sample in the same place (at/2)
    not_robots = set(fixed) | {
        str(o)
        for type_name, objects in (typed_objects or {}).items()
        if type_name.lower() in known_types and type_name != robot_type
        for o in objects
    }
    kept: set[Fact] = set()
    left_out = 0
    outside: set[str] = set()
    others: set[str] = set()
    for item in source:
        fact = Fact.of(item)
        name = fact.predicate
        args = tuple(str(a) for a in fact.args)
        arity = predicates.get(name.lower())
        if arity is None or len(args) != len(arity):
            continue
        if not offline and any(
            kind == robot_type and arg not in members and arg not in not_robots
            for arg, kind in zip(args, arity, strict=True)
        ):
            others.update(
                arg
                for arg, kind in zip(args, arity, strict=True)
                if kind == robot_type and arg not in members and arg not in not_robots
            )
            if len(args) > 1:  # a relation of an outside robot with an object (not just its own state)
                left_out += 1
                outside.update(arg for arg, kind in zip(args, arity, strict=True) if kind != robot_type)
            continue
        kept.add(Fact(name, args))
    types: dict[str, str] = dict(sorted(declared.items()))
    # objects the problem declares (a fixed place such as the collection point g) are known without being seen
    if not offline:
        types.update(fixed)
    if not offline and robot_type is not None:
        types.update(dict.fromkeys(members, robot_type))
    # the world model's typed objects, of the types the domain knows (not its frontiers, say)
    for type_name, objects in sorted((typed_objects or {}).items()):
        if type_name.lower() not in known_types:
            continue
        for obj in objects:
            if offline or type_name != robot_type:
                types.setdefault(str(obj), type_name)
    # what the facts say before what the goal says: a predicate may take different types in different
    # signatures (at(?r, ?x) of a robot, at(?x, ?l) of a sample), and a fact names the object as it is now
    for fact in sorted(kept):
        for value, type_name in zip(fact.args, predicates[fact.predicate.lower()], strict=True):
            types.setdefault(str(value), type_name)
    for _, goal_fact in goal_literals(problem):
        for value, type_name in zip(goal_fact.args, predicates.get(goal_fact.predicate.lower(), ()), strict=False):
            types.setdefault(str(value), type_name)
    robots = tuple(sorted(n for n, k in types.items() if k == robot_type)) if offline else members
    if not offline:
        mentioned = {str(a) for fact in kept for a in fact.args}
        # an object of a left-out relation that facts of the team still mention is planned for: a robot
        # that crashed standing at a sample (at(r, s)) leaves it on the ground (onground(s)); one an
        # opponent holds is mentioned by nothing else (clear(b) and ontable(b) went with the grasp)
        # and a place the problem declares is never held: a robot that crashed standing at it leaves it there
        outside -= mentioned | set(fixed)
        # a goal object no fact mentions (a block falling, out of sight) is not planned for until it is seen again
        outside.update(
            str(a)
            for _, goal_fact in goal_literals(problem)
            for a in goal_fact.args
            if str(a) not in mentioned and a not in members and str(a) not in fixed
        )
    return PlanningWorld(
        tuple(sorted(types.items())),
        tuple(sorted(kept)),
        robots,
        left_out,
        tuple(sorted(outside)),
        tuple(sorted(others)),
        tuple(sorted(fixed)) if not offline else (),
    )


def reachable_goal(goal: Sequence[Literal], outside: Iterable[str], fixed: Iterable[str] = ()) -> tuple[Literal, ...]:
    """The goal literals not tied to any of the ``outside`` objects (those robots outside the team hold).

    The team cannot plan for a block an opponent holds; it plans for the
    rest of the goal meanwhile and replans once the block is free again. A
    literal is tied to an outside object when it names it, or names an
    object of a literal tied to it: with ``on(d, f)`` and ``on(g, d)`` in
    the goal and ``f`` held, both are left out. Building ``g`` on ``d`` now
    would put up a stack that has to come down again once ``d`` can go onto
    ``f``. The ``fixed`` objects (places the problem declares, such as the
    collection point ``g``) tie nothing: with ``at(a, g)`` and ``at(b, g)``
    in the goal and ``a`` held, ``b`` still goes to ``g``.
    """
    anchors = {str(a) for a in fixed}
    tied = set(outside)
    grew = True
    while grew:
        grew = False
        for literal in goal:
            names = {str(a) for a in literal[1][1]}
            if names & tied and not names - anchors <= tied:
                tied |= names - anchors
                grew = True
    return tuple(literal for literal in goal if not tied.intersection(literal[1][1]))


def _robot_type(problem: PlanningProblem, library: PlanLibrary) -> str | None:
    for name in problem.elements:
        signature = library.plans[name].signature
        if signature is not None:
            for variable in signature.parameters:
                if variable.name == "?r":
                    return variable.type if variable.type != "any" else "object"
    return None


@dataclass(frozen=True, slots=True)
class TaskProgress:
    """How far one task of a generated plan is, as the team's claims say.

    Attributes:
        agent: the agent holding the task (None: nobody yet).
        next_step: index into the task's steps of the first step not finished.
        running: whether that step runs now (its effects may hold already or not yet).
        done: whether the task succeeded.
    """

    agent: str | None
    next_step: int
    running: bool = False
    done: bool = False


def remaining_fits(
    tasks: Sequence[Sequence[Step]],
    progress: Sequence[TaskProgress],
    facts: Iterable[Fact],
    start_world: Iterable[Fact],
    goal: Sequence[Literal],
    robots: Sequence[str] = (),
) -> str | None:
    """Whether what is left of a generated plan still reaches the goal from ``facts``.

    Args:
        tasks: the steps of each task.
        progress: one entry per task.
        facts: the facts that hold now.
        start_world: the world the plan was made from (gives a fresh robot's facts).
        goal: the goal literals.
        robots: the robots of the plan; a task nobody holds yet is run by a stand-in with the
            start facts of the first of them (the planned robot first) that could start it, or
            when none could, by the planned robot itself after its earlier steps.

    Returns:
        ``None`` when it fits, else what does not.
    """
    state = set(facts)
    start = tuple(start_world)
    remaining: list[tuple[int, Step, str, bool]] = []
    for i, (task, where) in enumerate(zip(tasks, progress, strict=True)):
        if where.done or where.next_step >= len(task):
            continue
        who = where.agent
        if who is None:
            # nobody holds the task yet: a robot as it was at the start, the planned one if it could start the task
            who = f"~T{i}"
            first = task[where.next_step]
            planned = first.robot
            options = [planned, *(r for r in robots if r != planned)]
            own = (
                {Fact(name, tuple(who if a == r else a for a in args)) for name, args in start if r in args}
                for r in options
            )
            mine = [lit for lit in for_robot(first.pre, planned, who) if who in lit[1][1]]
            fresh = next((facts for facts in own if holds(mine, facts)), None)
            if fresh is None:
                # no robot as it was at the start could: the planned robot will, once its earlier steps are done
                # (it put its block down first, say), and takes the task then
                who = planned
            else:
                state.update(fresh)
        for k in range(where.next_step, len(task)):
            remaining.append((task[k].index, task[k], who, where.running and k == where.next_step))
    for _, step, who, running in sorted(remaining, key=lambda item: item[0]):
        pre = for_robot(step.pre, step.robot, who)
        effect = for_robot(step.effect, step.robot, who)
        if holds(pre, state) or running:
            # a running step is under way: its skill has changed part of the world already (a grasp
            # took the sample off the ground before the lift) and fails by itself when it cannot go on
            apply_effect(state, effect)
        else:
            return f"step {step.label} of {who} cannot run: {_unmet(pre, state)} does not hold"
    if not holds(goal, state):
        return f"the plan no longer reaches the goal: {_unmet(goal, state)} would not hold"
    return None


def _unmet(wanted: Sequence[Literal], state: set[Fact]) -> str:
    positive, (name, args) = next(item for item in wanted if (item[1] in state) != item[0])
    return f"{'' if positive else 'not '}{name}({', '.join(str(a) for a in args)})"
