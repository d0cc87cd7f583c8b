"""The ProTaP simulator: transitions and reward on hand-made states, the limits, the policies."""

from __future__ import annotations

import dataclasses
import random

import pytest

from alica.prophet.protap import (
    IDLE,
    NOOP,
    Action,
    Goal,
    ProblemSpec,
    ProtapModel,
    Robot,
    State,
    appendix_c_spec,
    evaluate,
    greedy,
    random_policy,
    random_spec,
)
from alica.prophet.protap.policies import run_episode


class _Fixed(random.Random):
    """A random source whose draws are given in advance."""

    def __init__(self, *draws: float) -> None:
        super().__init__(0)
        self.draws = list(draws)

    def random(self) -> float:
        return self.draws.pop(0)


def _model() -> ProtapModel:
    """Two robots on a 3x2 grid, one goal per action kind, costs that tell the terms apart."""
    spec = ProblemSpec(
        robots=(Robot("r1", (0, 0), 0.5), Robot("r2", (2, 1), 0.25)),
        actions=(Action("pick"), Action("talk", "uda")),
        goals=(Goal("g1", "pick", (1, 0), 10.0), Goal("g2", "talk", (2, 1), 7.0), Goal("g3", "pick", (1, 0), 3.0)),
        width=3,
        height=2,
        do_costs=((0.5, 2.0), (0.25, 4.0)),
        goto_unit=2.0,
    )
    return ProtapModel(spec)


def test_codes_and_cells() -> None:
    model = _model()
    assert model.n_cells == 6
    assert model.initial == State((0, 5), 0)
    assert [model.cell(i) for i in range(6)] == [(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1)]
    assert model.describe(0, model.goto((2, 1))) == "goto(r1, x3, y2)"
    assert model.describe(1, model.do("talk")) == "do(r2, talk)"
    assert model.describe(0, NOOP) == "noop"
    assert model.act(goto=(2, 1), do="talk") == (6, 8) == (model.goto((2, 1)), model.do(1))
    assert model.act() == IDLE == (NOOP, NOOP)
    assert model.describe_action(0, model.act(goto=(2, 1), do="talk")) == "goto(r1, x3, y2) + do(r1, talk)"
    assert model.describe_action(1, IDLE) == "noop"
    assert model.goto_choices(model.initial, 0) == (NOOP, 2, 3, 4, 5, 6)
    assert model.do_choices() == (NOOP, 7, 8)
    # Every goto choice with every do choice: a goto and a do in one step are allowed.
    available = model.available(model.initial, 0)
    assert available[0] == IDLE
    assert set(available) == {(goto, do) for goto in (NOOP, 2, 3, 4, 5, 6) for do in (NOOP, 7, 8)}
    assert len(available) == 6 * 3
    assert model.available(State((5, 0), 0), 1) is available  # made once per cell


def test_goto_succeeds_or_leaves_the_robot_where_it_was() -> None:
    model = _model()
    joint = (model.act(goto=(1, 0)), model.act(goto=(0, 0)))
    state, reward = model.step(model.initial, joint, _Fixed(0.49, 0.25))
    assert state == State((1, 5), 0)  # r1 succeeds (0.49 < 0.5), r2 fails (0.25 is not < 0.25) and stays
    assert reward == pytest.approx(-(2.0 * 1.0 + round(2.0 * 5**0.5, 2)))
    assert reward == model.reward(model.initial, joint)


def test_do_needs_the_robot_at_the_goal_cell_and_the_goal_action() -> None:
    model = _model()
    rng = _Fixed()
    away = model.step(model.initial, (model.act(do="pick"), IDLE), rng)[0]
    assert away.done == 0  # r1 is at (0, 0), the pick goals are at (1, 0)
    at_goals = State((1, 5), 0)
    wrong, reward = model.step(at_goals, (model.act(do="talk"), IDLE), rng)
    assert wrong.done == 0 and reward == -2.0
    both, reward = model.step(at_goals, (model.act(do="pick"), model.act(do="talk")), rng)
    assert both == State((1, 5), 0b111)  # g1 and g3 share cell and action; r2 does g2
    assert reward == -(0.5 + 4.0)


def test_utility_counts_the_goals_done_at_the_start_of_each_step() -> None:
    model = _model()
    state = State((1, 5), 0b101)
    nxt, reward = model.step(state, (IDLE, model.act(do="talk")), _Fixed())
    assert reward == 10.0 + 3.0 - 4.0
    assert nxt.done == 0b111
    assert model.step(nxt, (IDLE, IDLE), _Fixed())[1] == 20.0
    assert model.is_done(nxt, 1) and not model.is_done(state, 1)


def test_a_robot_can_goto_and_do_in_one_step_and_the_do_acts_where_it_stood() -> None:
    model = _model()
    at_goals = State((1, 5), 0)  # r1 at the pick goals (1, 0), r2 at the talk goal (2, 1)
    # r1 does pick at (1, 0) and sets off to (0, 1); r2 drives to (1, 0) while doing talk at (2, 1).
    joint = (model.act(goto=(0, 1), do="pick"), model.act(goto=(1, 0), do="talk"))
    assert model.violations(at_goals, model.fluents(joint)) == []
    nxt, reward = model.step(at_goals, joint, _Fixed(0.0, 0.0))
    assert nxt == State((3, 1), 0b111)
    assert reward == pytest.approx(-(round(2.0 * 2**0.5, 2) + 0.5 + round(2.0 * 2**0.5, 2) + 4.0))
    assert reward == pytest.approx(model.reward(at_goals, joint))
    # A robot that arrives at a goal's cell in this step does not do the goal in this step.
    away = State((0, 5), 0)
    arrived, _ = model.step(away, (model.act(goto=(1, 0), do="pick"), IDLE), _Fixed(0.0))
    assert arrived == State((1, 5), 0)
    # The do acts at the start cell also when the goto fails.
    stay, _ = model.step(at_goals, (model.act(goto=(0, 1), do="pick"), IDLE), _Fixed(0.99))
    assert stay == State((1, 5), 0b101)


def test_fluents_lists_a_joint_action_and_refuses_misplaced_codes() -> None:
    model = _model()
    joint = (model.act(goto=(2, 1), do="pick"), model.act(do="talk"))
    assert model.fluents(joint) == [(0, 6), (0, 7), (1, 8)]
    assert model.fluents((IDLE, IDLE)) == []
    with pytest.raises(ValueError, match="robot 0"):
        model.fluents(((model.do("pick"), model.goto((2, 1))), IDLE))  # swapped
    with pytest.raises(ValueError, match="robot 1"):
        model.fluents((IDLE, (model.goto((2, 1)), model.goto((1, 1)))))  # two gotos in one pair


def test_many_goals_use_the_summed_utility() -> None:
    spec = random_spec(robots=1, width=5, height=4, goals=18, seed=0, utility=2.0)
    model = ProtapModel(spec)
    assert model.utility(State((0,), (1 << 18) - 1)) == 36.0


def test_violations_name_each_broken_limit() -> None:
    model = _model()
    state = model.initial
    assert model.violations(state, []) == []
    assert model.violations(state, [(0, model.goto((1, 1))), (1, model.do("talk")), (1, NOOP)]) == []
    # One goto and one do of one robot: allowed (the paper's per-robot limits).
    assert model.violations(state, [(0, model.goto((1, 1))), (0, model.do("pick"))]) == []
    two_gotos = model.violations(state, [(0, model.goto((1, 1))), (0, model.goto((2, 0)))])
    assert two_gotos == ["robot r1 takes 2 gotos (at most 1)"]
    two_dos = model.violations(state, [(1, model.do("pick")), (1, model.do("talk")), (1, model.goto((0, 0)))])
    assert two_dos == ["robot r2 takes 2 dos (at most 1)"]
    both = model.violations(
        state, [(0, model.goto((1, 1))), (0, model.goto((2, 0))), (0, model.do("pick")), (0, model.do("talk"))]
    )
    assert both == ["robot r1 takes 2 gotos (at most 1)", "robot r1 takes 2 dos (at most 1)"]
    assert model.violations(state, [(0, model.goto((0, 0)))]) == ["goto(r1, x1, y1): goto to the robot's own cell"]
    assert model.violations(state, [(2, 1), (0, 99)]) == ["unknown action 99 of robot 0", "unknown action 1 of robot 2"]
    assert model.spec.max_nondef_actions == 4
    full = (model.act(goto=(1, 1), do="pick"), model.act(goto=(0, 0), do="talk"))
    assert model.violations(state, model.fluents(full)) == []  # 4 fluents, 2 x 2 robots
    tight = ProtapModel(dataclasses.replace(model.spec, max_nondef_actions=3))
    assert tight.violations(state, tight.fluents(full)) == ["4 actions exceed max-nondef-actions = 3"]
    assert model.violations(state, [(0, 2), (0, 2)]) == []  # one fluent, given twice


def test_policies_stay_within_the_limits() -> None:
    model = ProtapModel(random_spec(robots=4, width=6, height=6, goals=5, seed=4))
    rng = random.Random(1)
    for policy in (greedy, random_policy):
        state = model.initial
        for _ in range(200):
            joint = policy(model, state, rng)
            assert model.violations(state, model.fluents(joint)) == []
            state = model.step(state, joint, rng)[0]


def test_greedy_goes_to_the_nearest_free_goal_then_does_it() -> None:
    model = ProtapModel(appendix_c_spec())
    state = model.initial  # r1 at (3, 0) next to g1 at (3, 1); r2 at (0, 1) next to g2 at (0, 0)
    assert greedy(model, state, random.Random()) == (model.act(goto=(3, 1)), model.act(goto=(0, 0)))
    there = State((model.index((3, 1)), model.index((0, 0))), 0)
    # At the goals: do, without setting off to the next goal in the same step ("go, then do").
    assert greedy(model, there, random.Random()) == (model.act(do="a2"), model.act(do="a1"))
    # g1 and g2 done: the robot nearer to g3 at (2, 3) takes it, the other waits.
    assert greedy(model, State(there.cells, 0b011), random.Random()) == (model.act(goto=(2, 3)), IDLE)
    assert greedy(model, State(there.cells, 0b111), random.Random()) == (IDLE, IDLE)


def test_deterministic_greedy_episode_total() -> None:
    spec = dataclasses.replace(appendix_c_spec(), robots=(Robot("r1", (3, 0), 1.0), Robot("r2", (0, 1), 1.0)))
    model = ProtapModel(spec)
    # Steps 1-2: both go (1 + 1) and do (1 + 1); step 3: r1 goes to g3 (sqrt(5) = 2.24) while 200 is paid;
    # step 4: r1 does g3 (1), 200 paid; steps 5-10: 300 each.
    expected = -2 - 2 + (200 - 2.24) + (200 - 1) + 6 * 300
    assert run_episode(model, greedy, random.Random(0)) == pytest.approx(expected)


def test_evaluation_is_deterministic_for_a_seed() -> None:
    model = ProtapModel(appendix_c_spec())
    first = evaluate(model, random_policy, episodes=20, seed=5)
    assert first == evaluate(model, random_policy, episodes=20, seed=5)
    assert first != evaluate(model, random_policy, episodes=20, seed=6)
    assert len(first.totals) == 20
    assert evaluate(model, greedy, episodes=1).std == 0.0
    with pytest.raises(ValueError):
        evaluate(model, greedy, episodes=0)


def test_the_reference_greedy_reward_on_appendix_c() -> None:
    # The notes' figure: 2152.6 +- 73.6 over 20 episodes; the mean over 20 episodes varies by about 25.
    result = evaluate(ProtapModel(appendix_c_spec()), greedy, episodes=200, seed=0)
    assert result.mean == pytest.approx(2152.6, abs=40)
