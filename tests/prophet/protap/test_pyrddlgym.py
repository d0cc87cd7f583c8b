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


def _gym_action(model: ProtapModel, joint: JointAction) -> dict[str, bool]:
    spec = model.spec
    action: dict[str, bool] = {}
    for robot, code in model.pairs(joint):
        name = spec.robots[robot].name
        if code <= model.n_cells:
            x, y = model.cell(code - 1)
            action[f"goto___{name}__{spec.x_names[x]}__{spec.y_names[y]}"] = True
        else:
            action[f"do___{name}__{spec.actions[code - model.n_cells - 1].name}"] = True
    return action


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


def _mixed(model: ProtapModel, state: State, rng: random.Random) -> JointAction:
    """Greedy half of the time (goals get done), random otherwise (every kind of action)."""
    return greedy(model, state, rng) if rng.random() < 0.5 else random_policy(model, state, rng)


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
        assert model.violations(state, model.pairs(joint)) == []
        assert after.done & state.done == state.done  # goals stay done


@pytest.mark.parametrize("name", sorted(SPECS))
def test_simulator_agrees_with_pyrddlgym_step_by_step(name: str, tmp_path: Path) -> None:
    spec = _deterministic(SPECS[name])
    env = _env(spec, tmp_path)
    model = ProtapModel(spec)
    count = 0
    done_steps = 0
    for state, joint, reward, after in _episodes(env, model, episodes=800 // spec.horizon, seed=2):
        mine, my_reward = model.step(state, joint, random.Random(0))
        assert mine == after, (state, [model.describe(r, c) for r, c in enumerate(joint)])
        assert my_reward == pytest.approx(reward, abs=1e-9)
        count += 1
        done_steps += mine.done != state.done
    assert count >= 790
    assert done_steps > 0  # the runs complete goals, not only move


def test_the_stochastic_gotos_agree_in_distribution(tmp_path: Path) -> None:
    spec = appendix_c_spec()
    env = _env(spec, tmp_path)
    model = ProtapModel(spec)
    rng = random.Random(0)
    totals = []
    for episode in range(150):
        obs, _ = env.reset(seed=episode)
        total = 0.0
        for _ in range(spec.horizon):
            obs, reward, *_ = env.step(_gym_action(model, greedy(model, _state(model, obs), rng)))
            total += float(reward)
        totals.append(total)
    mine = evaluate(model, greedy, episodes=3000, seed=0)
    error = (statistics.variance(totals) / len(totals) + mine.std**2 / 3000) ** 0.5
    assert abs(statistics.fmean(totals) - mine.mean) < 4 * error


def test_pyrddlgym_refuses_what_the_limits_checker_reports(tmp_path: Path) -> None:
    spec = appendix_c_spec()
    env = _env(spec, tmp_path)
    model = ProtapModel(spec)
    state = model.initial
    broken = [
        [(0, model.goto((3, 1))), (0, model.do("a1"))],  # two actions of one robot
        [(0, model.goto((3, 1))), (0, model.goto((2, 1)))],  # two gotos of one robot
        [(1, model.goto((0, 1)))],  # goto to the robot's own cell
    ]
    for pairs in broken:
        assert model.violations(state, pairs)
        joint = [NOOP, NOOP]
        action: dict[str, bool] = {}
        for robot, code in pairs:
            joint[robot] = code
            action.update(_gym_action(model, tuple(joint)))
        env.reset(seed=0)
        with pytest.raises(ValueError, match="not satisfied"):
            env.step(action)


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
