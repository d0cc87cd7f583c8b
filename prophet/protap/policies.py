"""Baseline policies for the ProTaP simulator and their evaluation over episodes.

A policy maps ``(model, state, rng)`` to a joint action. :func:`greedy` sends
every robot to the nearest open goal no other robot takes and does the goal's
action there (a goto or a do per step, never both); :func:`random_policy`
draws each robot's goto and do independently among those the domain allows. :func:`evaluate` runs episodes and returns the mean
and standard deviation of the total (discounted) reward.

>>> from alica.prophet.protap.generate import appendix_c_spec
>>> from alica.prophet.protap.model import ProtapModel
>>> result = evaluate(ProtapModel(appendix_c_spec()), greedy, episodes=5, seed=0)
>>> result.mean > 2000
True
"""

from __future__ import annotations

import random
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from alica.prophet.protap.model import IDLE, NOOP, JointAction, ProtapModel, RobotAction, State

if TYPE_CHECKING:
    from alica.prophet.protap.planner import ProtapPlanner

Policy = Callable[[ProtapModel, State, random.Random], JointAction]


def greedy(model: ProtapModel, state: State, rng: random.Random) -> JointAction:
    """Each robot goes to the nearest open goal that no other robot takes, then does its action.

    Robots and open goals are matched greedily by ``GOTO_COST``: the closest
    pair first (ties: lower robot, then lower goal number), then the closest
    pair among the rest, and so on. A robot at its goal's cell does the goal's
    action, one elsewhere goes to the goal's cell, one without a goal waits.
    It is the simple "go, then do" policy of the project's reference figures:
    a robot that does at a goal does not set off to the next one in the same
    step, though the domain would allow it. ``rng`` is not used (the policy
    is deterministic).
    """
    spec = model.spec
    pairs = sorted(
        (model.spec.goto_cost(model.cell(state.cells[r]), goal.cell), r, g)
        for r in range(len(spec.robots))
        for g, goal in enumerate(spec.goals)
        if not state.done >> g & 1
    )
    joint: list[RobotAction] = [IDLE] * len(spec.robots)
    busy: set[int] = set()
    taken: set[int] = set()
    for _, robot, g in pairs:
        if robot in busy or g in taken:
            continue
        busy.add(robot)
        taken.add(g)
        goal = spec.goals[g]
        target = model.index(goal.cell)
        joint[robot] = (NOOP, model.do(goal.action)) if state.cells[robot] == target else (1 + target, NOOP)
    return tuple(joint)


def random_policy(model: ProtapModel, state: State, rng: random.Random) -> JointAction:
    """Each robot draws a goto and a do independently and uniformly, ``NOOP`` included.

    The goto among :meth:`ProtapModel.goto_choices` (no goto or any other
    cell), the do among :meth:`ProtapModel.do_choices` (no do or any action):
    every pair of :meth:`ProtapModel.available` is equally likely.
    """
    dos = model.do_choices()
    return tuple((rng.choice(model.goto_choices(state, robot)), rng.choice(dos)) for robot in range(len(state.cells)))


@dataclass(frozen=True, slots=True)
class Evaluation:
    """The total rewards of a policy's episodes, with their mean and sample standard deviation."""

    totals: tuple[float, ...]
    mean: float
    std: float


def run_episode(model: ProtapModel, policy: Policy, rng: random.Random, horizon: int | None = None) -> float:
    """The total discounted reward of one episode of ``policy`` from the initial state.

    Args:
        model: the simulator.
        policy: the policy.
        rng: the source of the policy's and the outcomes' randomness.
        horizon: the number of steps (default: the spec's horizon).
    """
    state = model.initial
    total = 0.0
    weight = 1.0
    discount = model.spec.discount
    for _ in range(model.spec.horizon if horizon is None else horizon):
        state, reward = model.step(state, policy(model, state, rng), rng)
        total += weight * reward
        weight *= discount
    return total


def evaluate(
    model: ProtapModel, policy: Policy, episodes: int = 20, horizon: int | None = None, seed: int = 0
) -> Evaluation:
    """Run ``episodes`` episodes of ``policy`` and summarise their total rewards.

    Args:
        model: the simulator.
        policy: the policy.
        episodes: the number of episodes (at least 1).
        horizon: the steps per episode (default: the spec's horizon).
        seed: the seed of the one ``random.Random`` all episodes draw from.

    Returns:
        The totals, their mean and their sample standard deviation (0 for one episode).
    """
    if episodes < 1:
        raise ValueError("episodes must be at least 1")
    rng = random.Random(seed)
    totals = tuple(run_episode(model, policy, rng, horizon) for _ in range(episodes))
    std = statistics.stdev(totals) if len(totals) > 1 else 0.0
    return Evaluation(totals, statistics.fmean(totals), std)


@dataclass
class Recorder:
    """Wraps a policy: counts the limits its joint actions break, times each step, keeps a planner's trials.

    Args:
        policy: the policy to run.
        planner: the planner behind ``policy``, if any: only its steps that
            searched (``last_trials`` > 0) are timed, and their trials kept.

    Attributes:
        breaks: limits broken (:meth:`ProtapModel.violations`) over every joint action chosen.
        seconds: the time of each step timed.
        trials: the planner's trials of each step that searched.
    """

    policy: Policy
    planner: ProtapPlanner | None = None
    breaks: int = 0
    seconds: list[float] = field(default_factory=list)
    trials: list[int] = field(default_factory=list)

    def __call__(self, model: ProtapModel, state: State, rng: random.Random) -> JointAction:
        """The wrapped policy's joint action, counted and timed."""
        start = time.perf_counter()
        joint = self.policy(model, state, rng)
        elapsed = time.perf_counter() - start
        searched = self.planner.last_trials if self.planner is not None else None
        if searched is None or searched:
            self.seconds.append(elapsed)
        if searched:
            self.trials.append(int(searched))
        self.breaks += len(model.violations(state, model.fluents(joint)))
        return joint
