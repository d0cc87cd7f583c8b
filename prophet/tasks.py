"""Task creation (IMPERA Sections 7.3-7.4): a single-agent plan becomes a multi-agent ALICA plan.

1. **Parallelise** (Algorithms 2-3): the plan's actions are taken in order;
   an action opens a new task if its precondition holds for a *new* robot
   (the team's state before the action, with the robot's own facts those of a
   robot that has done nothing yet) and the action's robot is not in the
   middle of something (its own facts are those it started with: it holds
   nothing it picked up), else it joins the task of the robot's
   previous action (the last task, in a single-agent plan). The plan may name
   several robots (when the world is planned with every team member, as the
   runtime does, a robot may hold a block already): a task whose first action
   only some robots could start now is *pinned* to them (``CreatedTasks.allowed``);
   the engine vetoes every other agent for it.
2. **Role-task priorities** (Eq. 9): task ``i`` of ``n`` gets ``T_i = 1 - i/n``,
   scaled for each role by the role's priority ``p`` for the planning
   problem's entry point; a role that cannot take one of the task's skills
   (a negative priority for that skill's task) gets -1.
3. **Cardinalities**: min = the largest of the task's skills' minima, max =
   the smallest of their maxima. A task one robot can do gets the minimum 0
   on its entry point (it stays success-required): a team smaller than the
   number of tasks then runs them one after the other, an agent whose task
   succeeded taking the next one (the engine's reuse rule). Task ``i`` only
   depends on tasks ``0..i``, and the priorities prefer the earlier tasks, so
   the tasks that are held can always go on.
4. **Utility** (Eq. 10-12): weights ``w_t = x/n``, ``w_p = x/(n+1)^2``,
   ``w_s = x/(n+1)^3`` for task coverage, priorities and similarity; ``x``
   cancels when the weights are normalised to sum to 1, and the threshold is
   the normalised ``w_s``: the team switches only for a gain of more than that.
   When tasks start at a work site, a ``Proximity`` summand (weight
   ``w_s / (n + 1)``) prefers the robots nearest to where their tasks start
   (see :func:`generic_utility`).

The generated plan: one entry point per task, and per task a chain of
states, each waiting until its step's precondition holds in the world model
(another task may have to act first) and until the earlier steps of other
tasks on the same objects are done (``step_done`` facts, which the runtime
writes), then running the step's skill plan with its variables bound; a
failed step ends the task in a failure state (the runtime then replans).
With a WaitPlan, one more entry point, :data:`STANDBY` (min 0, no maximum,
not success-required), holds the agents no task needs: its one state runs
the WaitPlan, so they keep out of the way of those who work (IMPERA 8.2: "in
WaitPlan, every agent drives to a free position, so as not to disturb other
tasks"). It counts nothing for coverage and has the smallest priority, so an
agent stands by only when no task has room for it, and leaves it for a task
that frees up just as an idle agent would. When the WaitPlan declares the
variables ``near`` and ``guard``, the wait states and success states of the
tasks run it too (see :func:`build_plan`): an agent waits near its next
step's work site, and guards what its task finished.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from enum import Enum

from alica.errors import PlannerError
from alica.lang import literal_text, literals
from alica.lang.fact import Fact
from alica.model import (
    Binding,
    ChildRef,
    Condition,
    ConditionKind,
    EntryPoint,
    Plan,
    PlanLibrary,
    Priority,
    RoleSet,
    State,
    StateKind,
    Summand,
    Task,
    Transition,
    UtilityFunction,
)
from alica.prophet.planner import PlanStep

#: A ground literal: whether the fact holds (``True``) or not.
Literal = tuple[bool, Fact]
#: The robot parameter of skill signatures: the agent that runs the skill.
ROBOT = "?r"


@dataclass(frozen=True, slots=True)
class Step:
    """One action of the single-agent plan, with its skill plan and bindings."""

    index: int
    skill: Plan
    bindings: tuple[tuple[str, str], ...]
    pre: tuple[Literal, ...]
    effect: tuple[Literal, ...]
    robot: str = ""
    """The robot the planner chose for the step (its ``?r``)."""

    @property
    def label(self) -> str:
        """``Pickup(a)``."""
        args = ", ".join(v for k, v in self.bindings)
        return f"{self.skill.name}({args})"


class StepKind(Enum):
    """What an agent does in a state of a generated plan."""

    WAIT = "wait"
    """Waits until its step can run (the step's precondition, the earlier steps on the same objects)."""
    RUN = "run"
    """Runs its step's skill plan."""
    DONE = "done"
    """Finished every step of its task (a success state)."""
    FAILED = "failed"
    """A step of its task failed (a failure state)."""


@dataclass(frozen=True, slots=True)
class Place:
    """Where a state of a generated plan is in the tasks: the task, the step, and what the agent does there.

    Attributes:
        task: the task's index.
        step: the index (in the task's steps) of the first step not finished: the step that waits or runs,
            the number of steps when the task is done, 0 in the failure state (the runtime replans anyway).
        kind: waiting, running, done or failed.
    """

    task: int
    step: int
    kind: StepKind


@dataclass(frozen=True, slots=True)
class CreatedTasks:
    """The result of task creation.

    Attributes:
        tasks: the steps of each task, in order.
        plan: the generated multi-agent plan.
        task_defs: the new tasks of the task repository.
        roleset: the role set with priorities for the new tasks.
        allowed: per task, the robots that may take it (``None``: any).
        places: state name -> where it is in the tasks, for every state of a task
            (the standby state is in none); the runtime reads progress from it.
    """

    tasks: tuple[tuple[Step, ...], ...]
    plan: Plan
    task_defs: tuple[Task, ...]
    roleset: RoleSet
    allowed: tuple[tuple[str, ...] | None, ...] = ()
    places: Mapping[str, Place] = field(default_factory=dict)

    @property
    def task_entry_points(self) -> tuple[EntryPoint, ...]:
        """The entry points of the tasks, in task order (the standby entry point left out)."""
        return self.plan.entry_points[: len(self.tasks)]

    def place(self, state: str | None) -> Place | None:
        """Where ``state`` is in the tasks (``None``: not a state of a task, e.g. standing by)."""
        return self.places.get(state) if state is not None else None

    def priorities(self) -> dict[str, tuple[Priority, ...]]:
        """Role -> the priorities of the generated plan's tasks (Eq. 9), for the engine's allocation."""
        tasks = {ep.task for ep in self.plan.entry_points}
        return {role.name: tuple(p for p in role.priorities if p.task in tasks) for role in self.roleset.roles}

    def pins(self) -> dict[str, tuple[str, ...]]:
        """Entry point name -> the robots allowed to take it, for the pinned tasks."""
        return {
            ep.name: allowed
            for ep, allowed in zip(self.plan.entry_points, self.allowed, strict=False)
            if allowed is not None
        }


def _ground(text: str | None, subst: Mapping[str, str], where: str) -> tuple[Literal, ...]:
    if not text:
        return ()
    out = []
    for positive, name, args in literals(text):
        out.append((positive, Fact(name, tuple(subst.get(str(a), str(a)) for a in args))))
    return tuple(out)


def _robots(robots: str | Sequence[str]) -> tuple[str, ...]:
    return (robots,) if isinstance(robots, str) else tuple(robots)


def steps_of(plan_steps: Sequence[PlanStep], library: PlanLibrary, robots: str | Sequence[str]) -> list[Step]:
    """The plan's actions as steps of skill plans; ``robots`` are the objects the planner may use for ``?r``.

    Raises:
        PlannerError: an action names no skill plan with a signature, has the
            wrong number of arguments, or a robot that is not one of ``robots``.
    """
    team = _robots(robots)
    by_name = {p.name.lower(): p for p in library.plans.values() if p.signature is not None}
    out = []
    for i, step in enumerate(plan_steps):
        skill = by_name.get(step.action.lower())
        if skill is None or skill.signature is None:
            raise PlannerError(f"plan step {i + 1} '{step}' names no skill plan with a planning signature")
        params = [v.name for v in skill.signature.parameters]
        if len(params) != len(step.args):
            raise PlannerError(
                f"plan step {i + 1} '{step}': skill plan '{skill.name}' takes {len(params)} parameters ({', '.join(params)})"
            )
        subst = dict(zip(params, step.args, strict=True))
        bindings = tuple((p.lstrip("?"), a) for p, a in zip(params, step.args, strict=True) if p != ROBOT)
        robot = subst.get(ROBOT, team[0])
        if robot not in team:
            raise PlannerError(
                f"plan step {i + 1} '{step}' is for robot '{robot}', which is not one of the plan's robots ({', '.join(team)})"
            )
        sig = skill.signature
        pre = _ground(sig.precondition.text if sig.precondition else None, subst, skill.name)
        eff = _ground(sig.effect.text if sig.effect else None, subst, skill.name)
        out.append(Step(i, skill, bindings, pre, eff, robot))
    return out


def holds(literals_: Iterable[Literal], state: set[Fact] | frozenset[Fact]) -> bool:
    """Whether every literal holds in the closed world ``state``."""
    return all((fact in state) == positive for positive, fact in literals_)


def apply_effect(state: set[Fact], effect: Iterable[Literal]) -> None:
    """Apply an effect to ``state``: deletes first, then adds."""
    for positive, fact in effect:
        if not positive:
            state.discard(fact)
    for positive, fact in effect:
        if positive:
            state.add(fact)


def for_robot(literal_set: Iterable[Literal], robot: str, other: str) -> list[Literal]:
    """The literals with ``robot`` replaced by ``other``."""
    return [
        (positive, Fact(name, tuple(other if a == robot else a for a in args)))
        for positive, (name, args) in literal_set
    ]


def parallelise(steps: Sequence[Step], init: Iterable[Fact], robots: str | Sequence[str]) -> list[list[Step]]:
    """Algorithms 2-3: split the steps into tasks.

    A step opens a new task when its precondition holds for a robot that has
    done nothing yet (some robot with its initial facts) in the team's state
    before the step, and the step's own robot is not in the middle of
    something (its own facts are those it started with); else it joins the
    task of the robot's previous step. So a robot that picked a sample up
    also carries it: driving to the collection point is not a new task for
    another robot with an empty hand.
    """
    return _parallelise(steps, init, _robots(robots))[0]


def _parallelise(
    steps: Sequence[Step], init: Iterable[Fact], team: tuple[str, ...]
) -> tuple[list[list[Step]], list[tuple[str, ...] | None]]:
    start = set(init)
    members = set(team)
    fresh = {r: {f for f in start if r in f[1]} for r in team}
    state = set(start)
    tasks: list[list[Step]] = []
    allowed: list[tuple[str, ...] | None] = []
    task_of: dict[str, int] = {}
    for step in steps:
        shared = {f for f in state if not members.intersection(f[1])}
        able = tuple(
            r
            for r in team
            if holds(
                for_robot(step.pre, step.robot, r), shared | _own_facts(r, team, task_of, step.robot, fresh, state)
            )
        )
        # a robot in the middle of something (its own facts are not those it started with: it holds a
        # sample it picked up) goes on with its own task, even where a new robot could start the step
        own_now = {f for f in state if step.robot in f[1]}
        busy = step.robot in task_of and own_now != fresh.get(step.robot, set())
        if not tasks or (able and not busy):
            tasks.append([step])
            # who may take the task: the robots whose initial facts let them start it, and the planner's own robot
            may = {r for r in team if holds(for_robot(step.pre, step.robot, r), shared | fresh[r])} | (
                {step.robot} & members
            )
            allowed.append(tuple(sorted(may)) if may and may != members else None)
            task_of[step.robot] = len(tasks) - 1
        else:
            tasks[task_of.get(step.robot, len(tasks) - 1)].append(step)
        apply_effect(state, step.effect)
    return tasks, allowed


def _by_robot(steps: Sequence[Step]) -> tuple[list[list[Step]], list[tuple[str, ...] | None]]:
    """One task per robot, its steps in plan order, pinned to it (tasks in the order of their first step)."""
    tasks: dict[str, list[Step]] = {}
    for step in steps:
        tasks.setdefault(step.robot, []).append(step)
    return list(tasks.values()), [(robot,) for robot in tasks]


def _own_facts(
    robot: str,
    team: tuple[str, ...],
    acted: Mapping[str, int],
    mover: str,
    fresh: Mapping[str, set[Fact]],
    state: set[Fact],
) -> set[Fact]:
    """The facts a robot could start the next step with, for Algorithms 2-3.

    A robot that has done nothing yet has its initial facts. With one robot
    (IMPERA's stand-in) every step is judged for a new robot with those facts.
    In a world of several robots, one that has acted has the facts its steps
    left it with (a block it held at the start and has put down is gone), and
    the robot of the step itself is not new: its step continues its own task.
    """
    if len(team) == 1 or robot not in acted:
        return fresh[robot]
    if robot == mover:
        return set()
    return {f for f in state if robot in f[1]}


def _cardinality(task: Sequence[Step]) -> tuple[int, float]:
    lows, highs = [], []
    for step in task:
        ep = step.skill.entry_points[0]
        lows.append(ep.min)
        highs.append(ep.max)
    low, high = max(lows), min(highs)
    return max(1, low), max(high, float(max(1, low)))


#: The entry point (and state) of a generated plan for the agents no task needs.
STANDBY = "Standby"


def generic_utility(n: int, standby: bool = False, sites: Sequence[tuple[str, str]] = ()) -> UtilityFunction:
    """Eq. 10-12, normalised: coverage w_t, priority w_p, similarity w_s; the threshold is w_s.

    With ``standby`` the coverage counts the agents of the tasks only (not those standing by).
    With ``sites`` (entry point, the object where its task starts), a fourth
    summand, ``Proximity``, adds each agent's :func:`~alica.lang.prelude.closeness`
    to the site of the entry point it takes: of two assignments that cover the
    same tasks, the one whose robots are nearer to where their tasks start
    wins. Its weight ``w_s / (n + 1)`` keeps it below the similarity of one
    agent even with one agent per task, so it never makes a running team switch
    tasks, and below the smallest difference of priorities, so it never puts a
    later task before an earlier one.
    """
    n = max(1, n)
    wt, wp, ws = 1.0 / n, 1.0 / (n + 1) ** 2, 1.0 / (n + 1) ** 3
    wd = ws / (n + 1) if sites else 0.0
    total = wt + wp + ws + wd
    wt, wp, ws, wd = wt / total, wp / total, ws / total, wd / total
    coverage = f'entry != "{STANDBY}"' if standby else "1"
    summands = [Summand("Coverage", wt, coverage)]
    if sites:
        cases = ", ".join(f'"{entry}", "{site}"' for entry, site in sites)
        summands.append(Summand(PROXIMITY, wd, f'closeness(self, choose(entry, {cases}, ""))'))
    return UtilityFunction(priority_weight=wp, summands=tuple(summands), similarity_weight=ws, threshold=ws)


#: The summand of a generated plan that prefers, for a task, the robots nearest to where it starts.
PROXIMITY = "Proximity"


#: The world-model predicate an agent asserts when it finished a step of a generated plan.
STEP_DONE = "step_done"


def step_token(plan: str, index: int) -> str:
    """The argument of ``step_done`` for step ``index`` (0-based, in plan order) of generated plan ``plan``."""
    return f"{plan}_s{index}"


def conjunction(literal_set: Iterable[Literal]) -> str:
    """Ground literals as a formula: ``on(a, b) and not clear(c)``."""
    return " and ".join(literal_text(positive, name, args) for positive, (name, args) in literal_set)


def _condition(pre: Sequence[Literal], robot: str, after: Sequence[str] = ()) -> Condition | None:
    parts = [conjunction(for_robot(pre, robot, "self"))] if pre else []
    parts.extend(f"{STEP_DONE}({token})" for token in after)
    return Condition(ConditionKind.TRANSITION, " and ".join(parts)) if parts else None


def _objects(step: Step) -> set[str]:
    return {str(a) for _, (_, args) in step.pre + step.effect for a in args if a != step.robot}


def _predecessors(tasks: Sequence[Sequence[Step]]) -> dict[int, list[int]]:
    """Per step (plan index): the latest earlier step of another task touching each of its objects.

    Steps on the same blocks run in plan order: two robots never work on the same stack at once.
    """
    task_of = {s.index: i for i, task in enumerate(tasks) for s in task}
    ordered = sorted((s for task in tasks for s in task), key=lambda s: s.index)
    last: dict[str, int] = {}
    out: dict[int, list[int]] = {}
    for step in ordered:
        before = set()
        for obj in _objects(step):
            h = last.get(obj)
            if h is not None and task_of[h] != task_of[step.index]:
                before.add(h)
            last[obj] = step.index
        out[step.index] = sorted(before)
    return out


def work_site(step: Step) -> str | None:
    """The object where ``step`` is carried out: the first object its precondition names outside the robot's own facts.

    ``Stack(x, y)``: ``y`` (``holding(r, x)`` is the robot's own); ``Unstack(x, y)`` and ``Pickup(x)``: ``x``;
    ``Putdown(x)``: none (anywhere free).
    """
    for positive, (_, args) in step.pre:
        if positive and args and step.robot not in args:
            return str(args[0])
    return None


def placed_object(step: Step) -> str | None:
    """The object ``step`` leaves in the world: its first object, ``None`` when the robot holds something after it.

    ``Stack(x, y)`` and ``Putdown(x)``: ``x``; ``Pickup(x)`` and ``Unstack(x, y)``: none (``holding(r, x)``).
    Whether the plan is done with it or a later step stacks onto it or takes it
    again, opponents must leave it alone: a guard keeps them off a finished
    part of the goal, off a tower still growing, and off a block put down for
    a later step.
    """
    if not step.bindings or any(
        positive and step.robot in args and set(args) - {step.robot} for positive, (_, args) in step.effect
    ):
        return None  # the robot holds something of the step after it (holding(r, x))
    return step.bindings[0][1]


def _standby_ref(standby: str, variables: frozenset[str], **values: str | None) -> ChildRef:
    """The WaitPlan as a child, with the variables it declares bound to the values given."""
    bind = tuple(Binding(var, value) for var, value in values.items() if var in variables and value is not None)
    return ChildRef(standby, bind)


def build_plan(
    name: str,
    tasks: Sequence[Sequence[Step]],
    robot: str | None = None,
    standby: str | None = None,
    standby_variables: Iterable[str] = (),
    settled: Iterable[str] = (),
) -> tuple[Plan, tuple[Task, ...], dict[str, Place]]:
    """The multi-agent plan of the tasks (see the module docstring); ``standby`` names the WaitPlan.

    When the WaitPlan declares the variable ``near`` (``standby_variables``),
    an agent that waits for its next step runs the WaitPlan with ``near`` bound
    to the step's work site (:func:`work_site`); when it declares ``guard``,
    an agent whose task is done runs it with ``guard`` bound to what its last
    step placed (:func:`placed_object`), so that it can keep opponents
    off that stack (a finished part of the goal, a tower still growing, or a
    block put down for a later step); the agents standing by get ``guard`` bound to
    the objects of ``settled`` (those of the world) that no step touches,
    space-separated (each guards the nearest one no one else guards).

    Returns:
        The plan, its tasks, and where each state of a task is (:attr:`CreatedTasks.places`).
    """
    entry_points, states, transitions, task_defs = [], [], [], []
    places: dict[str, Place] = {}
    sites: list[tuple[str, str]] = []
    after = _predecessors(tasks)
    waits = frozenset(standby_variables) if standby is not None else frozenset()
    by_index = sorted((s for task in tasks for s in task), key=lambda s: s.index)
    for i, task in enumerate(tasks):
        task_name = f"{name}_T{i}"
        task_defs.append(Task(task_name, description=", ".join(s.label for s in task)))
        low, high = _cardinality(task)
        first = f"T{i}_Wait0"
        site = work_site(task[0])
        if site is not None:
            sites.append((task_name, site))
        entry_points.append(
            EntryPoint(task_name, task_name, first, min=low if low > 1 else 0, max=high, success_required=True)
        )
        for k, step in enumerate(task):
            wait, run = f"T{i}_Wait{k}", f"T{i}_S{k}_{step.skill.name}"
            following = f"T{i}_Wait{k + 1}" if k + 1 < len(task) else f"T{i}_Done"
            places[wait] = Place(i, k, StepKind.WAIT)
            places[run] = Place(i, k, StepKind.RUN)
            wait_children = (
                (_standby_ref(standby, waits, near=work_site(step)),) if standby is not None and "near" in waits else ()
            )
            states.append(State(wait, children=wait_children, description=f"wait until {step.label} can run"))
            bind = tuple(Binding(var, value) for var, value in step.bindings)
            states.append(State(run, children=(ChildRef(step.skill.name, bind),), description=step.label))
            transitions.append(
                Transition(
                    f"{wait}->{run}",
                    wait,
                    run,
                    _condition(step.pre, robot or step.robot, [step_token(name, h) for h in after[step.index]]),
                )
            )
            transitions.append(
                Transition(f"{run}->{following}", run, following, Condition(ConditionKind.TRANSITION, "succeeded"))
            )
            transitions.append(
                Transition(f"{run}->T{i}_Failed", run, f"T{i}_Failed", Condition(ConditionKind.TRANSITION, "failed"))
            )
        last = task[-1]
        done_children = (
            (_standby_ref(standby, waits, guard=placed_object(last)),)
            if standby is not None and "guard" in waits
            else ()
        )
        states.append(State(f"T{i}_Done", StateKind.SUCCESS, children=done_children))
        states.append(State(f"T{i}_Failed", StateKind.FAILURE))
        places[f"T{i}_Done"] = Place(i, len(task), StepKind.DONE)
        places[f"T{i}_Failed"] = Place(i, 0, StepKind.FAILED)
    if standby is not None:
        task_name = f"{name}_{STANDBY}"
        task_defs.append(Task(task_name, description=f"stand by in {standby} while no task needs the agent"))
        entry_points.append(EntryPoint(STANDBY, task_name, STANDBY, min=0, success_required=False))
        untouched = " ".join(sorted(set(settled) - {o for step in by_index for o in _objects(step)}))
        ref = _standby_ref(standby, waits, guard=untouched or None)
        states.append(State(STANDBY, children=(ref,), description=f"keep out of the way ({standby})"))
    plan = Plan(
        name,
        tuple(entry_points),
        tuple(states),
        tuple(transitions),
        utility=generic_utility(len(tasks), standby is not None, sites),
        description=f"generated by pRoPhEt MAS from a plan of {sum(len(t) for t in tasks)} steps in {len(tasks)} task(s)",
    )
    return plan, tuple(task_defs), places


def role_priorities(
    roleset: RoleSet, tasks: Sequence[Sequence[Step]], task_defs: Sequence[Task], entry_task: str
) -> RoleSet:
    """Eq. 9: ``T_i = 1 - i/n`` scaled by each role's priority ``p`` for the problem's entry task; -1 if a skill is vetoed."""
    n = len(tasks)
    roles = []
    for role in roleset.roles:
        p = roleset.priority(role.name, entry_task)
        extra = []
        for i, (task, tdef) in enumerate(zip(tasks, task_defs[:n], strict=True)):
            vetoed = p < 0 or any(roleset.priority(role.name, s.skill.entry_points[0].task) < 0 for s in task)
            extra.append(Priority(tdef.name, -1.0 if vetoed else round((1.0 - i / n) * p, 9)))
        for tdef in task_defs[n:]:  # the standby task: below every task
            extra.append(Priority(tdef.name, -1.0 if p < 0 else round(p / (10 * n), 9)))
        kept = tuple(q for q in role.priorities if q.task not in {t.name for t in task_defs})
        roles.append(replace(role, priorities=kept + tuple(extra)))
    return replace(roleset, roles=tuple(roles))


def create_tasks(
    name: str,
    plan_steps: Sequence[PlanStep],
    library: PlanLibrary,
    init: Iterable[Fact],
    robots: str | Sequence[str],
    roleset: RoleSet,
    entry_task: str,
    standby: str | None = None,
    *,
    per_robot: bool = False,
) -> CreatedTasks:
    """Turn a single-agent plan into tasks, a multi-agent plan and role-task priorities (the module docstring says how).

    Args:
        name: the generated plan's name.
        plan_steps: the planner's plan.
        library: holds the skill plans the steps name.
        init: the world the plan starts from, as ``(predicate, args)`` facts.
        robots: the robot objects of the plan (``?r``): one for a single-agent
            plan, the team's members when the world was planned with all of them.
        roleset: the team's role set.
        entry_task: the task through which the team runs the planning problem.
        standby: the planning problem's WaitPlan, run by the agents no task needs (none: they idle).
        per_robot: instead of Algorithms 2-3, one task per robot the plan names, with that robot's
            steps in plan order, pinned to it: the plan of a stepwise planner (ProTaP) says who does what.

    Raises:
        PlannerError: the plan is empty or names unknown skills.
    """
    if not plan_steps:
        raise PlannerError("an empty plan makes no tasks: the goal already holds")
    team = _robots(robots)
    init = tuple(init)  # read twice: by the parallelisation and for the objects to guard
    steps = steps_of(plan_steps, library, team)
    tasks, allowed = _by_robot(steps) if per_robot else _parallelise(steps, init, team)
    wait_plan = library.plans.get(standby) if standby is not None else None
    variables = tuple(v.name for v in wait_plan.variables) if wait_plan is not None else ()
    members = set(team)
    objects = {str(a) for _, args in init for a in args if a not in members}
    plan, task_defs, places = build_plan(name, tasks, standby=standby, standby_variables=variables, settled=objects)
    return CreatedTasks(
        tuple(tuple(t) for t in tasks),
        plan,
        task_defs,
        role_priorities(roleset, tasks, task_defs, entry_task),
        tuple(allowed),
        places,
    )


def emit_yaml(created: CreatedTasks, imports: Sequence[str] = ()) -> str:
    """The generated plan and its tasks as a YAML plan file, for a person to read (``--emit-plan``).

    Args:
        created: the result of :func:`create_tasks`.
        imports: plan files the generated plan needs (the skill plans), relative to where it is written.
    """
    from alica.io import dump_document
    from alica.model import Declaration, Document

    done = Declaration(STEP_DONE, 1, "step_done(s): an agent finished step s of the generated plan")
    document = Document(imports=tuple(imports), predicates=(done,), tasks=created.task_defs, plans=(created.plan,))
    header = "# Generated by pRoPhEt MAS: " + "; ".join(
        f"T{i}: " + ", ".join(s.label for s in task) for i, task in enumerate(created.tasks)
    )
    return header + "\n" + dump_document(document, "yaml")
