"""pyRDDLGym, an independent RDDL simulator, checks the domain, the generated instances and the simulator.

Skipped, with the reason printed, when pyRDDLGym (a ``test`` extra) does not import.
"""

from __future__ import annotations

import dataclasses
import random
import statistics
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from alica.prophet.protap import (
    NOOP,
    JointAction,
    Policy,
    ProblemSpec,
    ProtapModel,
    State,
    appendix_c_spec,
    evaluate,
    greedy,
    random_policy,
    random_spec,
    write_problem,
)

pyRDDLGym = pytest.importorskip("pyRDDLGym", reason="pyRDDLGym does not import: pip install 'pyRDDLGym>=2.7,<3'")


def _deterministic(spec: ProblemSpec) -> ProblemSpec:
    return dataclasses.replace(spec, robots=tuple(dataclasses.replace(r, prob_goto=1.0) for r in spec.robots))


SPECS = {
    "appendix-c": appendix_c_spec(),
    "1x1-grid": random_spec(robots=1, width=1, height=1, goals=1, seed=0),
    "3-robots-4x3": random_spec(robots=3, width=4, height=3, goals=5, seed=3, prob_goto=0.7),
    "4-robots-8x8": random_spec(robots=4, width=8, height=8, goals=6, seed=0),
    "2-robots-6x2-discounted": random_spec(robots=2, width=6, height=2, goals=4, seed=9, discount=0.95, horizon=7),
}


def _env(spec: ProblemSpec, folder: Path) -> Any:
    domain, instance = write_problem(spec, folder)
    with warnings.catch_warnings():
        # pyRDDLGym warns that it cannot turn the "== 1" state invariant into box bounds.
        warnings.simplefilter("ignore")
        return pyRDDLGym.make(str(domain), str(instance), enforce_action_constraints=True)


def _gym_fluents(model: ProtapModel, fluents: list[tuple[int, int]]) -> dict[str, bool]:
    spec = model.spec
    action: dict[str, bool] = {}
    for robot, code in fluents:
        name = spec.robots[robot].name
        if code <= model.n_cells:
            x, y = model.cell(code - 1)
            action[f"goto___{name}__{spec.x_names[x]}__{spec.y_names[y]}"] = True
        else:
            action[f"do___{name}__{spec.actions[code - model.n_cells - 1].name}"] = True
    return action


def _gym_action(model: ProtapModel, joint: JointAction) -> dict[str, bool]:
    return _gym_fluents(model, model.fluents(joint))


def _state(model: ProtapModel, obs: dict[str, Any]) -> State:
    spec = model.spec
    cells = []
    for robot in spec.robots:
        at = [
            model.index((x, y))
            for x, xn in enumerate(spec.x_names)
            for y, yn in enumerate(spec.y_names)
            if obs[f"robotAt___{robot.name}__{xn}__{yn}"]
        ]
        assert len(at) == 1, f"{robot.name} stands in {len(at)} cells"
        cells.append(at[0])
    done = sum(1 << g for g, goal in enumerate(spec.goals) if obs[f"done___{goal.name}"])
    return State(tuple(cells), done)


def _chained(model: ProtapModel, state: State, rng: random.Random) -> JointAction:
    """Greedy, but a robot that does at a goal also sets off to the nearest other open goal's cell."""
    joint = list(greedy(model, state, rng))
    for robot, (_, do) in enumerate(joint):
        here = state.cells[robot]
        targets = sorted(
            (model.spec.goto_cost(model.cell(here), goal.cell), model.index(goal.cell))
            for g, goal in enumerate(model.spec.goals)
            if not model.is_done(state, g) and model.index(goal.cell) != here
        )
        if do and targets:
            joint[robot] = (1 + targets[0][1], do)
    return tuple(joint)


def _mixed(model: ProtapModel, state: State, rng: random.Random) -> JointAction:
    """Greedy, greedy that goes on while it does, or random (a goto and a do per robot): every kind of action."""
    policy = rng.choice((greedy, _chained, random_policy))
    return policy(model, state, rng)


def _episodes(
    env: Any, model: ProtapModel, episodes: int, seed: int
) -> Iterator[tuple[State, JointAction, float, State]]:
    rng = random.Random(seed)
    for episode in range(episodes):
        obs, _ = env.reset(seed=seed + episode)
        state = _state(model, obs)
        assert state == model.initial
        for step in range(model.spec.horizon):
            joint = _mixed(model, state, rng)
            obs, reward, _, truncated, _ = env.step(_gym_action(model, joint))
            # pyRDDLGym truncates at the horizon, and also when a state invariant breaks.
            assert truncated == (step == model.spec.horizon - 1)
            after = _state(model, obs)
            yield state, joint, float(reward), after
            state = after


@pytest.mark.parametrize("name", sorted(SPECS))
def test_pyrddlgym_parses_grounds_and_simulates_every_generated_problem(name: str, tmp_path: Path) -> None:
    spec = SPECS[name]
    env = _env(spec, tmp_path)
    model = ProtapModel(spec)
    assert env.horizon == spec.horizon
    assert env.max_allowed_actions == spec.max_nondef_actions
    steps = list(_episodes(env, model, episodes=5, seed=1))
    assert len(steps) == 5 * spec.horizon
    for state, joint, _, after in steps:
        assert model.violations(state, model.fluents(joint)) == []
        assert after.done & state.done == state.done  # goals stay done


@pytest.mark.parametrize("name", sorted(SPECS))
def test_simulator_agrees_with_pyrddlgym_step_by_step(name: str, tmp_path: Path) -> None:
    spec = _deterministic(SPECS[name])
    env = _env(spec, tmp_path)
    model = ProtapModel(spec)
    count = 0
    done_steps = 0
    go_on_steps = 0
    for state, joint, reward, after in _episodes(env, model, episodes=800 // spec.horizon, seed=2):
        mine, my_reward = model.step(state, joint, random.Random(0))
        assert mine == after, (state, [model.describe_action(r, a) for r, a in enumerate(joint)])
        assert my_reward == pytest.approx(reward, abs=1e-9)
        count += 1
        done_steps += mine.done != state.done
        # A robot completes a goal at its start cell and moves on in the same step.
        go_on_steps += any(
            goto
            and do
            and not model.is_done(state, g)
            and model.index(goal.cell) == state.cells[r]
            and model.do(goal.action) == do
            for r, (goto, do) in enumerate(joint)
            for g, goal in enumerate(spec.goals)
        )
    assert count >= 790
    assert done_steps > 0  # the runs complete goals, not only move
    if len(spec.goals) > 1:
        assert go_on_steps > 0  # ... also with a goto and a do of one robot in one step


@pytest.mark.parametrize("policy", [greedy, _chained], ids=["greedy", "do-and-go-on"])
def test_the_stochastic_gotos_agree_in_distribution(policy: Policy, tmp_path: Path) -> None:
    spec = appendix_c_spec()
    env = _env(spec, tmp_path)
    model = ProtapModel(spec)
    rng = random.Random(0)
    totals = []
    for episode in range(150):
        obs, _ = env.reset(seed=episode)
        total = 0.0
        for _ in range(spec.horizon):
            obs, reward, *_ = env.step(_gym_action(model, policy(model, _state(model, obs), rng)))
            total += float(reward)
        totals.append(total)
    mine = evaluate(model, policy, episodes=3000, seed=0)
    error = (statistics.variance(totals) / len(totals) + mine.std**2 / 3000) ** 0.5
    assert abs(statistics.fmean(totals) - mine.mean) < 4 * error


def test_pyrddlgym_refuses_what_the_limits_checker_reports(tmp_path: Path) -> None:
    spec = appendix_c_spec()
    env = _env(spec, tmp_path)
    model = ProtapModel(spec)
    state = model.initial
    broken = [
        [(0, model.goto((3, 1))), (0, model.goto((2, 1)))],  # two gotos of one robot
        [(1, model.do("a1")), (1, model.do("a3"))],  # two dos of one robot
        [(1, model.goto((0, 1)))],  # goto to the robot's own cell
    ]
    for fluents in broken:
        assert model.violations(state, fluents)
        env.reset(seed=0)
        with pytest.raises(ValueError, match="not satisfied"):
            env.step(_gym_fluents(model, fluents))
    # A goto and a do of one robot, for both robots (4 = max-nondef-actions): allowed.
    allowed = [(0, model.goto((3, 1))), (0, model.do("a2")), (1, model.goto((0, 0))), (1, model.do("a3"))]
    assert model.violations(state, allowed) == []
    env.reset(seed=0)
    env.step(_gym_fluents(model, allowed))


def _random_fluents(model: ProtapModel, state: State, rng: random.Random) -> list[tuple[int, int]]:
    """0 to 2 gotos (now and then to the robot's own cell) and 0 to 2 dos per robot."""
    fluents = []
    for robot in range(len(state.cells)):
        for _ in range(rng.choice((0, 1, 1, 2))):
            cell = state.cells[robot] if rng.random() < 0.15 else rng.randrange(model.n_cells)
            fluents.append((robot, 1 + cell))
        fluents.extend((robot, rng.choice(model.do_choices()[1:])) for _ in range(rng.choice((0, 1, 1, 2))))
    return fluents


@pytest.mark.parametrize("bound", [None, 3])
def test_pyrddlgym_refuses_exactly_what_the_limits_checker_reports(bound: int | None, tmp_path: Path) -> None:
    spec = _deterministic(appendix_c_spec())
    if bound is not None:
        spec = dataclasses.replace(spec, max_nondef_actions=bound)
    env = _env(spec, tmp_path)
    model = ProtapModel(spec)
    rng = random.Random(7)
    refused = allowed = 0
    for _ in range(300):
        obs, _ = env.reset(seed=0)
        for _ in range(rng.randrange(3)):  # from later states too (greedy stays within a bound of 2 or more)
            obs, *_ = env.step(_gym_action(model, greedy(model, _state(model, obs), rng)))
        state = _state(model, obs)
        fluents = _random_fluents(model, state, rng)
        reported = model.violations(state, fluents)
        try:
            obs, reward, *_ = env.step(_gym_fluents(model, fluents))
        except ValueError:
            assert reported, [model.describe(r, c) for r, c in fluents]
            refused += 1
            continue
        assert not reported, reported
        allowed += 1
        # What pyRDDLGym takes is a joint action of the simulator, with the same outcome.
        joint = [[NOOP, NOOP] for _ in spec.robots]
        for robot, code in fluents:
            joint[robot][0 if model.is_goto(code) else 1] = code
        mine, my_reward = model.step(state, tuple((goto, do) for goto, do in joint), random.Random(0))
        assert mine == _state(model, obs)
        assert my_reward == pytest.approx(float(reward), abs=1e-9)
    assert refused > 50 and allowed > 50


def test_pyrddlgym_rejects_a_robot_in_no_cell(tmp_path: Path) -> None:
    spec = appendix_c_spec()
    domain, instance = write_problem(spec, tmp_path)
    text = instance.read_text(encoding="utf-8").replace("robotAt(r2, x1, y2) = true;", "")
    instance.write_text(text, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = pyRDDLGym.make(str(domain), str(instance), enforce_action_constraints=True)
    env.reset(seed=0)
    # pyRDDLGym checks the state invariants after each step and ends the episode when one breaks.
    assert env.step({})[3] is True
    assert not env.sampler.check_state_invariants(silent=True)
