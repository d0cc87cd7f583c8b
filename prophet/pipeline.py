"""One pipeline from a planning problem to a validated plan: World + problem -> PDDL -> planner -> validated plan.

Both callers go through :func:`plan_problem`:

* ``alica plan FILE.yaml`` plans a problem offline, in its own ``world``, and
  runs the planner to the end (:meth:`ProblemPlanning.solve`);
* the runtime of a planning problem (:mod:`alica.prophet.runtime`) plans in
  the world read from the world model, as an anytime search that it steps a
  budget per tick (:meth:`ProblemPlanning.search`).

:func:`plan_problem` writes the problem's PDDL domain (from its elements'
signatures) and problem (the world's typed objects and facts, the goal) and
picks the planner. Every plan the planner returns is checked with
:func:`alica.prophet.validate.validate_plan` before anyone uses it, and comes
back as a :class:`ValidPlan` whose steps name the objects as the world writes
them (PDDL is case-insensitive: the planner answers in lower case). Task
creation (:func:`alica.prophet.tasks.create_tasks`) takes it from there.

Example::

    world = read_world(problem, library, facts=(), team=())  # the problem's own world
    result = plan_problem(problem, library, world).solve(time_limit=10)
    print(result.plan.steps if result.plan else result.run.status)
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, replace

from alica.errors import PlannerError
from alica.model import PlanLibrary, PlanningProblem
from alica.prophet.pddl import Domain, Problem
from alica.prophet.pddl.model import And
from alica.prophet.planner import (
    DEFAULT_MEMORY_MB,
    Done,
    Improved,
    Limits,
    Plan,
    Planner,
    PlanResult,
    PlanStep,
    Progress,
)
from alica.prophet.planners import get_planner
from alica.prophet.problem import to_pddl
from alica.prophet.validate import ValidationResult, validate_plan
from alica.prophet.world import PlanningWorld


@dataclass(frozen=True, slots=True)
class ValidPlan:
    """A plan the validator accepted.

    Attributes:
        steps: its actions, with the objects named as the world names them.
        cost: its cost, as the validator computed it.
        plan: the plan as the planner returned it (PDDL names).
    """

    steps: tuple[PlanStep, ...]
    cost: float
    plan: Plan


@dataclass(frozen=True, slots=True)
class Found:
    """The search found a plan better than every earlier one, and it is valid."""

    plan: ValidPlan
    expansions: int


@dataclass(frozen=True, slots=True)
class Rejected:
    """The planner returned a plan the validator refused (a planner's bug): it is not used."""

    reason: str
    expansions: int


#: What :meth:`ProblemPlanning.search` yields: progress, each better valid plan, refused plans, the end.
ProblemEvent = Progress | Found | Rejected | Done


@dataclass(frozen=True, slots=True)
class ProblemResult:
    """What planning a problem to the end gave.

    Attributes:
        run: the planner's run (status, times, expansions; its plan as the planner returned it).
        plan: that plan, validated; ``None`` without a plan.
    """

    run: PlanResult
    plan: ValidPlan | None


@dataclass(frozen=True, slots=True)
class ProblemPlanning:
    """A planning problem in a world, as PDDL, with the planner that plans it (made by :func:`plan_problem`).

    Attributes:
        problem: the planning problem (with the goal planned for).
        world: the world it is planned in.
        domain: the PDDL domain of the problem's elements.
        pddl: the PDDL problem of the world and the goal.
        planner: the planner.
        temporal: the domain's actions are durative (``planner: temporal``): a plan is checked as the
            temporal planner schedules it, and its cost is the makespan.
    """

    problem: PlanningProblem
    world: PlanningWorld
    domain: Domain
    pddl: Problem
    planner: Planner
    temporal: bool = False

    def validated(self, plan: Plan) -> ValidPlan:
        """``plan`` checked against the PDDL, with the world's object names.

        Raises:
            PlannerError: the plan is not valid (the message names the planner and the reason).
        """
        check = self._check_timed(plan) if self.temporal else self.check(plan.steps)
        if not check.valid:
            raise PlannerError(f"planner '{self.planner.name}' returned an invalid plan: {check.reason}")
        names = {name.lower(): name for name, _ in self.world.objects}
        steps = tuple(PlanStep(s.action, tuple(names.get(a, a) for a in s.args)) for s in plan.steps)
        return ValidPlan(steps, check.cost, plan)

    def _check_timed(self, plan: Plan) -> ValidationResult:
        """A temporal planner's plan checked with its own timing (the makespan search's), else as scheduled."""
        from alica.prophet.temporal import ScheduledPlan  # lazy: only temporal problems need it
        from alica.prophet.validate_temporal import validate_temporal_plan

        if isinstance(plan, ScheduledPlan) and plan.schedule is not None:
            return validate_temporal_plan(self.domain, self.pddl, plan.schedule.plan)
        return self.check(plan.steps)

    def check(self, steps: Sequence[PlanStep]) -> ValidationResult:
        """Validate ``steps`` (a planner's, or an operator's change of them) in the world and for the goal planned for.

        A stepwise planner's plan is the next step of a policy: its actions must apply, the goal need not hold after it.
        """
        pddl = replace(self.pddl, goal=And(())) if self.planner.stepwise else self.pddl
        if self.temporal:
            from alica.prophet.temporal import schedule  # lazy: only temporal problems need it
            from alica.prophet.validate_temporal import validate_temporal_plan

            return validate_temporal_plan(self.domain, pddl, schedule(self.domain, pddl, steps).plan)
        return validate_plan((self.domain, pddl), steps)

    def search(self, *, anytime: bool = True, limits: Limits | None = None) -> Iterator[ProblemEvent]:
        """The planner's search as events, each better plan validated (a caller budgets it between events).

        ``limits`` bound the grounding (default: the problem's ``timeout`` from now and
        :data:`~alica.prophet.planner.DEFAULT_MEMORY_MB`): a grounding that would take
        longer or need more ends the events with ``Done(TIMEOUT)`` or ``Done(MEMORY)``
        instead of blocking its caller's tick. The search after it is budgeted by the caller.

        Raises:
            PlannerError: the planner does not support what the problem needs (raised at once).
        """
        if limits is None:  # the wall-clock timeout bounds the grounding, never the search the caller budgets
            limits = Limits(self.problem.timeout, DEFAULT_MEMORY_MB, bounds_search=False)
        events = self.planner.search(self.domain, self.pddl, anytime=anytime, limits=limits)
        return self._validate_events(events)

    def _validate_events(self, events: Iterator[Progress | Improved | Done]) -> Iterator[ProblemEvent]:
        for event in events:
            if isinstance(event, Improved):
                try:
                    yield Found(self.validated(event.plan), event.expansions)
                except PlannerError as exc:
                    yield Rejected(str(exc), event.expansions)
            else:
                yield event

    def solve(self, *, time_limit: float = 60.0, anytime: bool = False, limits: Limits | None = None) -> ProblemResult:
        """Run the planner to the end or for ``time_limit`` wall seconds; the best plan, validated.

        ``limits`` (instead of ``time_limit``) bound grounding and search, and may have started earlier.

        Raises:
            PlannerError: the planner's best plan is not valid.
        """
        run = self.planner.solve(self.domain, self.pddl, time_limit=time_limit, anytime=anytime, limits=limits)
        return ProblemResult(run, self.validated(run.plan) if run.plan is not None else None)


def plan_problem(
    problem: PlanningProblem,
    library: PlanLibrary,
    world: PlanningWorld,
    *,
    planner: str | None = None,
    options: Mapping[str, object] | None = None,
    durations: Mapping[str, float] | None = None,
) -> ProblemPlanning:
    """Make the PDDL of ``problem`` in ``world`` and pick its planner (see the module docstring).

    Args:
        problem: the planning problem, with the goal to plan for.
        library: holds the skill plans of its elements.
        world: the world to plan from (:func:`alica.prophet.world.read_world`).
        planner: the planner back-end (default: the problem's own ``planner``).
        options: options of the back-end's constructor.
        durations: element name -> expected seconds, over the signatures' ``duration`` (the temporal
            planner's; measured ones, say).

    Raises:
        PlannerError: the problem cannot be written as PDDL, or the planner is unknown.
    """
    name = planner or problem.planner
    temporal = name == "temporal"
    domain, pddl = to_pddl(problem, library, world.object_types(), world.facts, temporal=temporal, durations=durations)
    chosen_options = dict(options or {})
    if name in ("builtin", "temporal"):
        # A plan file's problem keeps FF's first search (FirstSearch("ff")): the shipped missions and
        # their fault tests were built on its plans, and with LAMA's the lunar team hands its fetch to
        # another robot and replans a fenced sample without end. ``options`` may choose another. The
        # temporal planner's sequential search is the builtin planner's, so its plans are the same.
        from alica.prophet.search.anytime import FirstSearch  # lazy: the planning layer's search

        chosen_options.setdefault("first", FirstSearch("ff"))
    if temporal:
        # the team runs every step: a shorter makespan bought with more steps than the sequential
        # plan's costs it more driving and waiting than the durations tell
        chosen_options.setdefault("no_more_steps", True)
    chosen = get_planner(name, **chosen_options)
    return ProblemPlanning(problem, world, domain, pddl, chosen, temporal)
