"""The ProTaP dispatcher: each plan step's actions run at once, and the next step is planned from what happened.

Algorithm 1 of the ProTaP paper (lines 21-31) resolves every step of the plan
into its operations and calls them all asynchronously: a ``goto`` goes to the
navigation stack, a ``do`` of a manipulation action to the arm (MoveIt!), a
``do`` of a user-defined action (``uda``) to a registered service. This module
is that loop, independent of any world:

1. the policy (``choose_step``, e.g. a
   :class:`~alica.prophet.protap.planner.PlannerPolicy`) picks a joint action
   for the observed state;
2. :func:`calls` turns it into one :class:`RobotCalls` per robot: the ``do``
   (its action, its kind and the goals it serves at the robot's cell) and the
   ``goto`` (the target cell);
3. an :class:`Executor` runs one step's calls for all robots at once and
   reports per robot whether the do and the goto succeeded, the cell the robot
   was observed in afterwards and why something failed (:class:`RobotOutcome`);
4. :func:`observe` makes the next model state from those outcomes, with the
   domain's rule for ``done``, and the loop replans from it: a failed action
   is simply planned again from where the robot really is.

The rule for ``done`` is the domain's (``done'`` in ``domain.rddl``): a goal
becomes done when a robot's ``do`` of the goal's action succeeded and the
robot stood in the goal's cell at the *start* of the step, also when the same
step's ``goto`` moved it away. The cells are the observed ones, whatever the
domain would have predicted: a goto that failed half way leaves the robot in
the cell it was seen in.

The reward of a step is the domain's (:meth:`ProtapModel.reward`): the
utility of the goals done at its start minus the costs of the actions taken,
failed or not (a real robot spends the effort either way).

>>> import random
>>> from alica.prophet.protap.generate import appendix_c_spec
>>> from alica.prophet.protap.policies import greedy
>>> model = ProtapModel(appendix_c_spec())
>>> episode = run_dispatched(model, greedy, ModelExecutor(model, random.Random(0)), horizon=10)
>>> episode.all_done, len(episode.steps)
(True, 10)
"""

from __future__ import annotations

import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

from alica.prophet.protap.model import NOOP, JointAction, ProtapModel, State
from alica.prophet.protap.spec import MANIPULATION, USER_DEFINED, Cell

ChooseStep = Callable[[ProtapModel, State, random.Random], JointAction]


@dataclass(frozen=True, slots=True)
class ActionCall:
    """The ``do`` of one robot in one step.

    Attributes:
        action: the action object's name, e.g. ``a2``.
        kind: :data:`~alica.prophet.protap.spec.MANIPULATION` (to the arm) or
            :data:`~alica.prophet.protap.spec.USER_DEFINED` (to a registered service).
        cell: the cell the robot stands in at the start of the step, where the do acts.
        goals: the names of the goals of this action at that cell (done or
            not); empty when the do serves no goal there (an executor in a
            world then has nothing to act on).
    """

    action: str
    kind: str
    cell: Cell
    goals: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in (MANIPULATION, USER_DEFINED):
            raise ValueError(f"do({self.action}): unknown kind {self.kind!r}")


@dataclass(frozen=True, slots=True)
class RobotCalls:
    """What one robot is asked to do in one step: at most one do and at most one goto.

    Attributes:
        robot: the robot's position in the spec.
        name: the robot's name, e.g. ``r1``.
        start: the robot's cell at the start of the step (the observed one).
        do: the do, or ``None``.
        goto: the target cell of the goto, or ``None``.
    """

    robot: int
    name: str
    start: Cell
    do: ActionCall | None = None
    goto: Cell | None = None

    @property
    def idle(self) -> bool:
        """Whether the robot is asked nothing this step."""
        return self.do is None and self.goto is None


@dataclass(frozen=True, slots=True)
class Activity:
    """One thing an executor ran for a robot (a skill, say), for the record.

    Attributes:
        name: what ran, e.g. ``MoveToPosition``.
        status: how it ended, e.g. ``success``, ``failure``, ``timeout``, ``skipped``.
        reason: what it said when it ended.
        start: when it started (the executor's clock, e.g. simulated seconds).
        end: when it ended.
    """

    name: str
    status: str
    reason: str = ""
    start: float = 0.0
    end: float = 0.0


@dataclass(frozen=True, slots=True)
class RobotOutcome:
    """What happened to one robot's calls in one step.

    Attributes:
        robot: the robot's position in the spec.
        cell: the cell the robot was observed in after the step.
        do_ok: whether the do succeeded; ``None`` without a do.
        goto_ok: whether the goto succeeded; ``None`` without a goto.
        reason: why the do or the goto failed (empty when nothing failed).
        activities: what the executor ran for the robot, in order (may be empty).
    """

    robot: int
    cell: Cell
    do_ok: bool | None = None
    goto_ok: bool | None = None
    reason: str = ""
    activities: tuple[Activity, ...] = ()

    @property
    def failures(self) -> int:
        """How many of the robot's actions failed this step (0, 1 or 2)."""
        return int(self.do_ok is False) + int(self.goto_ok is False)


class Executor(Protocol):
    """Runs one step's calls for all robots at once (the paper's asynchronous calls of one plan step).

    An executor returns when every call of the step has ended (or was stopped
    at the executor's own time bound, which counts as failed), one
    :class:`RobotOutcome` per robot in the order of ``calls``; idle robots get
    one too (their observed cell).
    """

    def execute(self, calls: Sequence[RobotCalls]) -> Sequence[RobotOutcome]:
        """Run ``calls`` (one per robot) at once and say what happened to each robot."""
        ...


def calls(model: ProtapModel, state: State, joint: JointAction) -> tuple[RobotCalls, ...]:
    """The calls of one step: ``joint`` taken in ``state``, one :class:`RobotCalls` per robot.

    Raises:
        ValueError: ``joint`` has not one pair per robot, or a pair is not
            ``(goto code or NOOP, do code or NOOP)`` (see :meth:`ProtapModel.fluents`).
    """
    spec = model.spec
    if len(joint) != len(spec.robots):
        raise ValueError(f"a joint action has one (goto, do) pair per robot: {len(spec.robots)}, got {len(joint)}")
    model.fluents(joint)  # checks the codes
    out = []
    for robot, (goto, do) in enumerate(joint):
        start = model.cell_of(state, robot)
        do_call = None
        if do != NOOP:
            position = do - model.n_cells - 1
            action = spec.actions[position]
            mask = model.goal_mask[state.cells[robot]][position]
            goals = tuple(goal.name for g, goal in enumerate(spec.goals) if mask >> g & 1)
            do_call = ActionCall(action.name, action.kind, start, goals)
        target = model.cell(goto - 1) if goto != NOOP else None
        out.append(RobotCalls(robot, spec.robots[robot].name, start, do_call, target))
    return tuple(out)


def observe(model: ProtapModel, state: State, joint: JointAction, results: Sequence[RobotOutcome]) -> State:
    """The next model state after ``joint`` was taken in ``state`` and ``results`` came back.

    The robots' cells are the observed ones. A goal becomes done when a
    robot's do of the goal's action succeeded and the robot stood in the
    goal's cell in ``state`` (the start of the step), as ``done'`` of the
    domain reads ``robotAt``, not ``robotAt'``; goals done stay done.

    Raises:
        ValueError: not one outcome per robot in robot order, or an observed
            cell off the grid.
    """
    spec = model.spec
    if len(results) != len(spec.robots) or any(result.robot != r for r, result in enumerate(results)):
        raise ValueError(f"an executor reports one outcome per robot, in robot order ({len(spec.robots)} robots)")
    done = state.done
    offset = model.n_cells + 1
    cells = []
    for robot, ((_, do), result) in enumerate(zip(joint, results, strict=True)):
        if not spec.inside(result.cell):
            raise ValueError(f"robot {spec.robots[robot].name} observed at {result.cell}, off the grid")
        cells.append(model.index(result.cell))
        if do != NOOP and result.do_ok:
            done |= model.goal_mask[state.cells[robot]][do - offset]
    return State(tuple(cells), done)


@dataclass(frozen=True, slots=True)
class StepRecord:
    """One dispatched step.

    Attributes:
        step: the step's number, from 0.
        state: the observed state at its start.
        joint: the joint action taken.
        actions: each robot's action in RDDL notation (``noop`` for none).
        outcomes: what happened to each robot.
        reward: the domain's reward of the step (:meth:`ProtapModel.reward`).
        next_state: the observed state after it.
    """

    step: int
    state: State
    joint: JointAction
    actions: tuple[str, ...]
    outcomes: tuple[RobotOutcome, ...]
    reward: float
    next_state: State

    @property
    def failures(self) -> int:
        """The actions of the step that failed."""
        return sum(outcome.failures for outcome in self.outcomes)


@dataclass(frozen=True, slots=True)
class Episode:
    """A dispatched episode.

    Attributes:
        steps: the steps, in order.
        total: the total discounted reward.
        failures: the actions that failed, over all steps.
        goals_done: how many goals were done at the end.
        all_done: whether every goal was done at the end.
        final: the observed state at the end.
    """

    steps: tuple[StepRecord, ...]
    total: float
    failures: int
    goals_done: int
    all_done: bool
    final: State


def run_dispatched(
    model: ProtapModel,
    choose_step: ChooseStep,
    executor: Executor,
    horizon: int | None = None,
    *,
    rng: random.Random | None = None,
    start: State | None = None,
    on_step: Callable[[StepRecord], None] | None = None,
) -> Episode:
    """Run one episode: choose a joint action, dispatch it, observe, and again, ``horizon`` times.

    Every step is chosen from the state observed after the last one, so a
    failed action is planned again from where the robots really are. Steps
    with nothing to do (every goal done, say) are dispatched too (an executor
    returns at once for idle robots), so the reward is comparable with the
    domain simulator's over the same horizon.

    Args:
        model: the domain of the problem.
        choose_step: any policy ``(model, state, rng) -> joint action``
            (:class:`~alica.prophet.protap.planner.PlannerPolicy`,
            :func:`~alica.prophet.protap.policies.greedy`, a
            :class:`~alica.prophet.protap.policies.Recorder`, ...).
        executor: runs each step's calls.
        horizon: the number of steps (default: the spec's horizon).
        rng: handed to ``choose_step`` (default: ``random.Random(0)``).
        start: the observed state to start from (default: the model's initial state).
        on_step: called with every step's record as soon as the step ended (progress, logs).

    Returns:
        The episode's steps, total discounted reward, failed actions and goals done.

    Raises:
        ValueError: an executor's outcomes that do not fit the robots or the grid.
    """
    steps = model.spec.horizon if horizon is None else horizon
    rng = random.Random(0) if rng is None else rng
    state = model.initial if start is None else start
    discount = model.spec.discount
    weight = 1.0
    total = 0.0
    records: list[StepRecord] = []
    for step in range(steps):
        joint = choose_step(model, state, rng)
        outcomes = tuple(executor.execute(calls(model, state, joint)))
        next_state = observe(model, state, joint, outcomes)
        reward = model.reward(state, joint)
        record = StepRecord(
            step,
            state,
            joint,
            tuple(model.describe_action(robot, action) for robot, action in enumerate(joint)),
            outcomes,
            reward,
            next_state,
        )
        records.append(record)
        if on_step is not None:
            on_step(record)
        total += weight * reward
        weight *= discount
        state = next_state
    done = state.done.bit_count()
    return Episode(
        tuple(records),
        total,
        sum(record.failures for record in records),
        done,
        done == len(model.spec.goals),
        state,
    )


class ModelExecutor:
    """An :class:`Executor` that samples the outcomes from the domain's own probabilities.

    A goto succeeds with the robot's ``PROB_GOTO`` (one draw per goto, in robot
    order, as :meth:`ProtapModel.step` draws), a do always succeeds. Dispatched
    with it, an episode follows the domain simulator's transitions: a stand-in
    for a world in tests and dry runs.

    Args:
        model: the domain.
        rng: the source of the gotos' outcomes.
    """

    def __init__(self, model: ProtapModel, rng: random.Random) -> None:
        self.model = model
        self.rng = rng

    def execute(self, calls: Sequence[RobotCalls]) -> list[RobotOutcome]:
        """Every do succeeds; every goto succeeds with its robot's probability, else the robot stays."""
        out = []
        for call in calls:
            cell, goto_ok = call.start, None
            if call.goto is not None:
                goto_ok = self.rng.random() < self.model.spec.robots[call.robot].prob_goto
                if goto_ok:
                    cell = call.goto
            reason = "" if goto_ok is not False else "the goto failed (sampled)"
            out.append(RobotOutcome(call.robot, cell, None if call.do is None else True, goto_ok, reason))
        return out
