"""The ProTaP dispatch loop with fake executors: what is called, what becomes done, and replanning after a failure."""

from __future__ import annotations

import doctest
import random
from collections.abc import Sequence

import pytest

from alica.prophet.protap import (
    IDLE,
    MANIPULATION,
    USER_DEFINED,
    Action,
    ActionCall,
    Goal,
    ModelExecutor,
    ProblemSpec,
    ProtapModel,
    Robot,
    RobotCalls,
    RobotOutcome,
    State,
    appendix_c_spec,
    calls,
    greedy,
    observe,
    random_policy,
    random_spec,
    run_dispatched,
)
from alica.prophet.protap import dispatch as dispatch_module
from alica.prophet.protap.policies import run_episode


def _model() -> ProtapModel:
    """A 3x1 corridor: r1 at (0, 0), r2 at (2, 0); g1 = a1 (manipulation) at (1, 0), g2 = a2 (uda) at (2, 0)."""
    spec = ProblemSpec(
        robots=(Robot("r1", (0, 0)), Robot("r2", (2, 0))),
        actions=(Action("a1", MANIPULATION), Action("a2", USER_DEFINED)),
        goals=(Goal("g1", "a1", (1, 0)), Goal("g2", "a2", (2, 0))),
        width=3,
        height=1,
        horizon=5,
    )
    return ProtapModel(spec)


def _ok(call: RobotCalls) -> RobotOutcome:
    """Everything asked succeeds: the robot ends in its goto's target, or where it started."""
    cell = call.goto if call.goto is not None else call.start
    return RobotOutcome(
        call.robot, cell, None if call.do is None else True, None if call.goto is None else True, "", ()
    )


class Scripted:
    """A fake executor: every call succeeds but the ones listed fail (the robot then stays, or ends in ``cell``).

    ``fail`` maps ``(step, robot name, "goto" | "do")`` to the cell the robot is seen in after a failed
    goto (``None``: where it started); the calls of every step are kept in ``seen``.
    """

    def __init__(self, fail: dict[tuple[int, str, str], tuple[int, int] | None]) -> None:
        self.fail = fail
        self.step = 0
        self.seen: list[tuple[RobotCalls, ...]] = []

    def execute(self, step_calls: Sequence[RobotCalls]) -> list[RobotOutcome]:
        self.seen.append(tuple(step_calls))
        out = []
        for call in step_calls:
            outcome = _ok(call)
            if call.goto is not None and (self.step, call.name, "goto") in self.fail:
                seen_at = self.fail[(self.step, call.name, "goto")]
                cell = call.start if seen_at is None else seen_at
                outcome = RobotOutcome(call.robot, cell, outcome.do_ok, False, "blocked", ())
            if call.do is not None and (self.step, call.name, "do") in self.fail:
                outcome = RobotOutcome(call.robot, outcome.cell, False, outcome.goto_ok, "dropped it", ())
            out.append(outcome)
        self.step += 1
        return out


def test_calls_name_each_robots_do_with_its_kind_and_the_goals_at_its_start_cell() -> None:
    model = _model()
    state = State((model.index((1, 0)), model.index((2, 0))), 0)
    joint = (model.act(goto=(2, 0), do="a1"), model.act(do="a2"))
    r1, r2 = calls(model, state, joint)
    assert r1 == RobotCalls(0, "r1", (1, 0), ActionCall("a1", MANIPULATION, (1, 0), ("g1",)), (2, 0))
    assert r2 == RobotCalls(1, "r2", (2, 0), ActionCall("a2", USER_DEFINED, (2, 0), ("g2",)), None)
    # a do where no goal of its action lies serves no goal; a robot asked nothing is idle
    away, idle = calls(model, model.initial, (model.act(do="a2"), IDLE))
    assert away.do == ActionCall("a2", USER_DEFINED, (0, 0), ()) and away.goto is None
    assert idle.idle and idle.start == (2, 0)
    with pytest.raises(ValueError, match="one \\(goto, do\\) pair per robot"):
        calls(model, state, (IDLE,))


def test_a_goal_is_done_only_by_a_successful_do_at_its_cell_at_the_start_of_the_step() -> None:
    model = _model()
    at_g1 = State((model.index((1, 0)), model.index((2, 0))), 0)
    # r1 does a1 at g1's cell and drives off in the same step: done, and r1 is where it was seen
    joint = (model.act(goto=(0, 0), do="a1"), IDLE)
    after = observe(model, at_g1, joint, [RobotOutcome(0, (0, 0), True, True), RobotOutcome(1, (2, 0))])
    assert after == State((model.index((0, 0)), model.index((2, 0))), 0b01)
    # the same do failed: not done
    failed = observe(model, at_g1, joint, [RobotOutcome(0, (0, 0), False, True), RobotOutcome(1, (2, 0))])
    assert failed.done == 0
    # a do at another cell does nothing, even when its goto brings the robot to the goal's cell
    start = model.initial  # r1 at (0, 0)
    joint = (model.act(goto=(1, 0), do="a1"), IDLE)
    moved = observe(model, start, joint, [RobotOutcome(0, (1, 0), True, True), RobotOutcome(1, (2, 0))])
    assert moved.done == 0 and model.cell_of(moved, 0) == (1, 0)
    # a do of another action at the goal's cell does nothing either; done goals stay done
    joint = (IDLE, model.act(do="a1"))
    other = observe(model, State(start.cells, 0b01), joint, [RobotOutcome(0, (0, 0)), RobotOutcome(1, (2, 0), True)])
    assert other.done == 0b01


def test_observe_takes_the_observed_cells_and_refuses_outcomes_that_do_not_fit() -> None:
    model = _model()
    joint = (model.act(goto=(2, 0)), IDLE)
    # the goto failed half way: the robot is where it was seen, not where the domain would leave it
    halfway = observe(model, model.initial, joint, [RobotOutcome(0, (1, 0), None, False), RobotOutcome(1, (2, 0))])
    assert model.cell_of(halfway, 0) == (1, 0)
    with pytest.raises(ValueError, match="one outcome per robot"):
        observe(model, model.initial, joint, [RobotOutcome(0, (1, 0))])
    with pytest.raises(ValueError, match="off the grid"):
        observe(model, model.initial, joint, [RobotOutcome(0, (5, 0)), RobotOutcome(1, (2, 0))])


@pytest.mark.parametrize("seed", range(5))
def test_observe_follows_the_domain_when_outcomes_are_sampled_from_it(seed: int) -> None:
    """With the domain's own outcomes (ModelExecutor), observe makes the state the simulator makes."""
    model = ProtapModel(random_spec(robots=3, width=4, height=4, goals=4, seed=seed))
    policy_rng = random.Random(seed)
    state = model.initial
    for _ in range(30):
        joint = random_policy(model, state, policy_rng)
        expected, _ = model.step(state, joint, random.Random(seed))
        outcomes = ModelExecutor(model, random.Random(seed)).execute(calls(model, state, joint))
        state = observe(model, state, joint, outcomes)
        assert state == expected


def test_dispatching_with_the_domains_outcomes_gives_the_simulators_episode() -> None:
    model = ProtapModel(appendix_c_spec())
    episode = run_dispatched(model, greedy, ModelExecutor(model, random.Random(3)))
    assert episode.total == run_episode(model, greedy, random.Random(3))
    assert len(episode.steps) == model.spec.horizon and episode.all_done
    assert episode.goals_done == len(model.spec.goals)
    failed_gotos = sum(outcome.goto_ok is False for step in episode.steps for outcome in step.outcomes)
    assert episode.failures == failed_gotos


def test_a_failed_goto_is_planned_again_from_where_the_robot_stayed() -> None:
    model = _model()
    executor = Scripted({(0, "r1", "goto"): None})
    episode = run_dispatched(model, greedy, executor, horizon=4)
    first, second = executor.seen[0][0], executor.seen[1][0]
    assert first.goto == (1, 0) and episode.steps[0].outcomes[0].goto_ok is False
    assert second.start == (0, 0) and second.goto == (1, 0)  # the same goto again, from the same cell
    assert episode.steps[0].outcomes[0].reason == "blocked" and episode.failures == 1
    # r1 arrives at step 1 and does g1 at step 2; r2 does g2 at once
    assert [step.next_state.done for step in episode.steps] == [0b10, 0b10, 0b11, 0b11]
    assert episode.all_done
    # the reward is the domain's: the failed goto's cost is paid, utility from the step after a goal is done
    assert episode.steps[0].reward == -2.0 and episode.steps[1].reward == 100.0 - 1.0
    assert episode.total == sum(step.reward for step in episode.steps)


def test_a_goto_that_ends_half_way_is_replanned_from_the_cell_the_robot_was_seen_in() -> None:
    spec = ProblemSpec(
        robots=(Robot("r1", (0, 0)),), actions=(Action("a1"),), goals=(Goal("g1", "a1", (4, 0)),), width=5, height=1
    )
    model = ProtapModel(spec)
    executor = Scripted({(0, "r1", "goto"): (2, 0)})
    episode = run_dispatched(model, greedy, executor, horizon=3)
    assert [step[0].start for step in executor.seen] == [(0, 0), (2, 0), (4, 0)]
    assert [step[0].goto for step in executor.seen] == [(4, 0), (4, 0), None]
    assert episode.steps[1].reward == -2.0  # the second goto costs the distance from where the robot was seen
    assert episode.all_done and episode.failures == 1


def test_a_failed_do_is_done_again_and_counts_only_when_it_succeeds() -> None:
    model = _model()
    start = State((model.index((1, 0)), model.index((2, 0))), 0)  # both robots at their goals
    executor = Scripted({(0, "r1", "do"): None})
    episode = run_dispatched(model, greedy, executor, horizon=3, start=start)
    assert [call.do.action for call in executor.seen[0] if call.do is not None] == ["a1", "a2"]
    assert episode.steps[0].next_state.done == 0b10  # r2's uda counted, r1's dropped manipulation not
    assert executor.seen[1][0].do == ActionCall("a1", MANIPULATION, (1, 0), ("g1",))  # retried at once
    assert episode.steps[1].next_state.done == 0b11 and episode.failures == 1 and episode.all_done


def test_doctests() -> None:
    failed, _ = doctest.testmod(dispatch_module, verbose=False)
    assert failed == 0
