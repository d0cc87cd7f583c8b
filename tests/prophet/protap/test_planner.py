"""The ProTaP planner: allowed actions at any budget, determinism, quality against the baselines, replanning."""

from __future__ import annotations

import dataclasses
import doctest
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.prophet.protap import (
    Budget,
    PlannerPolicy,
    ProblemSpec,
    ProtapModel,
    ProtapPlanner,
    State,
    appendix_c_spec,
    evaluate,
    greedy,
    heuristic,
    planner,
    random_policy,
    random_spec,
)


@st.composite
def _small_specs(draw: st.DrawFn) -> ProblemSpec:
    robots = draw(st.integers(1, 3))
    width = draw(st.integers(1, 5))
    height = draw(st.integers(1, 5))
    spec = random_spec(
        robots=robots,
        width=width,
        height=height,
        goals=draw(st.integers(1, min(3, width * height))),
        seed=draw(st.integers(0, 2**32)),
        prob_goto=draw(st.sampled_from([0.0, 0.3, 0.9, 1.0])),
        horizon=draw(st.integers(1, 6)),
    )
    return dataclasses.replace(spec, max_nondef_actions=draw(st.integers(1, 2 * robots)))


def _assert_allowed(model: ProtapModel, state: State, joint: tuple[tuple[int, int], ...]) -> None:
    assert len(joint) == len(model.spec.robots)
    fluents = model.fluents(joint)
    assert model.violations(state, fluents) == []
    assert len(fluents) <= model.spec.max_nondef_actions


@settings(max_examples=40, deadline=None)
@given(_small_specs(), st.sampled_from([0, 1, 3, 20, 60]), st.integers(0, 1000), st.sampled_from([None, 1, 2]))
def test_every_returned_action_is_allowed(spec: ProblemSpec, trials: int, seed: int, targets: int | None) -> None:
    model = ProtapModel(spec)
    search = ProtapPlanner(model, max_targets=targets)
    rng = random.Random(seed)
    state = model.initial
    for steps in range(spec.horizon, 0, -1):
        joint = search.plan_step(state, Budget(trials=trials), rng, steps)
        _assert_allowed(model, state, joint)
        assert search.last_trials == (trials if search.heuristic.open_goals(state) else 0)
        state = model.step(state, joint, rng)[0]


@settings(max_examples=25, deadline=None)
@given(_small_specs(), st.integers(0, 1000), st.sampled_from([None, 1]))
def test_every_choice_of_the_tree_is_allowed(spec: ProblemSpec, seed: int, targets: int | None) -> None:
    """Not only the returned actions: every joint action a trial builds is allowed (checked via the choices)."""
    model = ProtapModel(spec)
    search = ProtapPlanner(model, max_targets=targets)
    rng = random.Random(seed)
    state = model.initial
    for _ in range(3):
        used = 0
        doing = 0
        joint: list[int] = []
        for slot in range(2 * len(spec.robots)):
            choices = search.choices(state, slot, used, doing, tuple(joint))
            assert choices[0] == 0
            code = rng.choice(choices)
            joint.append(code)
            if code:
                used += 1
                if slot % 2:
                    doing |= search.heuristic.completes(state, slot // 2, code)
        pairs = tuple(zip(joint[0::2], joint[1::2], strict=True))
        _assert_allowed(model, state, pairs)
        _assert_allowed(model, state, search.heuristic.complete(state, tuple(joint[: rng.randrange(len(joint) + 1)])))
        state = model.step(state, pairs, rng)[0]


def test_a_tight_bound_limits_the_choices_and_still_completes_goals() -> None:
    spec = dataclasses.replace(random_spec(robots=3, width=5, height=5, goals=3, seed=4), max_nondef_actions=2)
    model = ProtapModel(spec)
    search = ProtapPlanner(model)
    rng = random.Random(1)
    state = model.initial
    for steps in range(spec.horizon, 0, -1):
        joint = search.plan_step(state, Budget(trials=200), rng, steps)
        _assert_allowed(model, state, joint)
        state = model.step(state, joint, rng)[0]
    assert state.done == 0b111


def _episodes(model: ProtapModel, trials: int, seed: int) -> list[tuple[tuple[int, int], ...]]:
    policy = PlannerPolicy(ProtapPlanner(model), Budget(trials=trials))
    rng = random.Random(seed)
    state = model.initial
    chosen = []
    for _ in range(2 * model.spec.horizon):
        joint = policy(model, state, rng)
        chosen.append(joint)
        state = model.step(state, joint, rng)[0]
    return chosen


@settings(max_examples=10, deadline=None)
@given(_small_specs(), st.integers(0, 1000))
def test_deterministic_for_a_seed_and_a_trial_budget(spec: ProblemSpec, seed: int) -> None:
    model = ProtapModel(spec)
    assert _episodes(model, 30, seed) == _episodes(model, 30, seed)


def test_zero_budget_returns_the_heuristic_action() -> None:
    model = ProtapModel(appendix_c_spec())
    search = ProtapPlanner(model)
    assert search.plan_step(model.initial, Budget(trials=0), random.Random(0)) == search.heuristic.complete(
        model.initial
    )
    assert search.plan_step(model.initial, Budget(seconds=0.0), random.Random(0)) == search.heuristic.complete(
        model.initial
    )


def test_budget_needs_a_limit() -> None:
    with pytest.raises(ValueError):
        Budget()
    with pytest.raises(ValueError):
        Budget(trials=-1)


def test_beats_random_and_matches_greedy_on_appendix_c() -> None:
    model = ProtapModel(appendix_c_spec())
    episodes = 6
    planned = evaluate(model, PlannerPolicy(ProtapPlanner(model), Budget(trials=300)), episodes=episodes, seed=3)
    baseline = evaluate(model, greedy, episodes=episodes, seed=3)
    chance = evaluate(model, random_policy, episodes=episodes, seed=3)
    assert planned.mean > chance.mean + 1000
    # greedy averages about 2155 and never does and goes at once; the planner about 2270
    assert planned.mean >= baseline.mean - 20
    assert min(planned.totals) > 2000


class _FailFirstGoto(random.Random):
    """Outcomes of the episode: the first goto draw fails (0.99), all later ones succeed (0.0)."""

    def __init__(self) -> None:
        super().__init__(0)
        self.first = True

    def random(self) -> float:
        if self.first:
            self.first = False
            return 0.99
        return 0.0


def test_replans_after_a_failed_goto() -> None:
    model = ProtapModel(appendix_c_spec())
    search = ProtapPlanner(model)
    budget = Budget(trials=100)
    search_rng = random.Random(0)
    outcomes = _FailFirstGoto()
    state = model.initial
    total = 0.0
    failed = False
    for steps in range(model.spec.horizon, 0, -1):
        joint = search.plan_step(state, budget, search_rng, steps)
        _assert_allowed(model, state, joint)
        wanted = [goto - 1 for goto, _ in joint]
        before = outcomes.first
        state, reward = model.step(state, joint, outcomes)
        total += reward
        if before and any(goto != -1 for goto in wanted):
            robot = next(r for r, goto in enumerate(wanted) if goto != -1)
            assert state.cells[robot] != wanted[robot]  # that goto failed
            failed = True
    assert failed
    assert state.done == 0b111  # every goal done in spite of the failure
    assert total > 2000


@pytest.mark.parametrize("module", [planner, heuristic])
def test_doctests(module: object) -> None:
    failed, _ = doctest.testmod(module, verbose=False)  # type: ignore[arg-type]
    assert failed == 0
