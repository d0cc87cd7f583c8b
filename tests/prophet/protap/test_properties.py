"""Property-based tests: every spec the generator makes is valid, and its instance says what the spec says."""

from __future__ import annotations

import doctest
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.prophet.protap import (
    ProtapModel,
    generate,
    instance_text,
    is_object_name,
    model,
    policies,
    random_policy,
    random_spec,
    rddl_name,
    spec,
    spec_from_facts,
)
from tests.prophet.protap.rddl_facts import read_facts


@st.composite
def _specs(draw: st.DrawFn):  # type: ignore[no-untyped-def]
    width = draw(st.integers(1, 9))
    height = draw(st.integers(1, 9))
    return random_spec(
        robots=draw(st.integers(1, 5)),
        width=width,
        height=height,
        goals=draw(st.integers(1, min(8, width * height))),
        seed=draw(st.integers(0, 2**32)),
        manipulation_actions=draw(st.integers(0, 3)),
        user_actions=draw(st.integers(1, 2)),
        prob_goto=draw(st.floats(0.0, 1.0)),
    )


@settings(max_examples=60, deadline=None)
@given(_specs())
def test_generated_specs_are_valid(made) -> None:  # type: ignore[no-untyped-def]
    assert made.problems() == []
    cells = [goal.cell for goal in made.goals]
    assert len(set(cells)) == len(cells)
    assert all(made.inside(cell) for cell in cells)
    assert all(made.inside(robot.cell) for robot in made.robots)
    names = made.object_names()
    assert all(is_object_name(name) for name in names)
    assert len(set(names)) == len(names)
    assert made.max_nondef_actions == 2 * len(made.robots)
    assert read_facts(instance_text(made)).settings["max-nondef-actions"] == str(2 * len(made.robots))


@settings(max_examples=30, deadline=None)
@given(_specs())
def test_instance_text_says_what_the_spec_says(made) -> None:  # type: ignore[no-untyped-def]
    facts = read_facts(instance_text(made))
    assert facts.objects["robot"] == [robot.name for robot in made.robots]
    assert facts.objects["goal"] == [goal.name for goal in made.goals]
    assert {args for (name, args) in facts.non_fluents if name == "GOAL"} == {
        (g.name, g.action, f"x{g.cell[0] + 1}", f"y{g.cell[1] + 1}") for g in made.goals
    }
    assert {args for (_, args) in facts.init} == {
        (r.name, f"x{r.cell[0] + 1}", f"y{r.cell[1] + 1}") for r in made.robots
    }
    assert sum(1 for (name, _) in facts.non_fluents if name == "GOTO_COST") == (made.width * made.height) ** 2


@settings(max_examples=30, deadline=None)
@given(_specs(), st.integers(0, 1000))
def test_simulated_states_stay_on_the_grid(made, seed: int) -> None:  # type: ignore[no-untyped-def]
    sim = ProtapModel(made)
    rng = random.Random(seed)
    state = sim.initial
    for _ in range(20):
        joint = random_policy(sim, state, rng)
        assert sim.violations(state, sim.fluents(joint)) == []
        nxt, reward = sim.step(state, joint, rng)
        assert reward == pytest.approx(sim.reward(state, joint))
        assert all(0 <= cell < sim.n_cells for cell in nxt.cells)
        assert nxt.done & state.done == state.done
        state = nxt


@given(st.text(max_size=20))
def test_rddl_name_always_gives_a_valid_name(text: str) -> None:
    assert is_object_name(rddl_name(text))


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.tuples(st.integers(0, 5), st.integers(0, 5)), min_size=1, max_size=4),
    st.lists(
        st.tuples(st.integers(0, 5), st.integers(0, 5), st.sampled_from(["pick", "drop", "say"])),
        min_size=1,
        max_size=5,
    ),
)
def test_world_model_facts_give_valid_specs(robots: list[tuple[int, int]], goals: list[tuple[int, int, str]]) -> None:
    made = spec_from_facts(
        [(f"robot {i}", cell) for i, cell in enumerate(robots)],
        [{"name": f"goal #{i}", "action": action, "cell": (x, y)} for i, (x, y, action) in enumerate(goals)],
        width=6,
        height=6,
        user_actions=["say"],
    )
    assert made.problems() == []
    assert [robot.cell for robot in made.robots] == robots
    assert len(made.goals) == len(goals)


@pytest.mark.parametrize("module", [spec, generate, model, policies])
def test_the_docstring_examples_hold(module: object) -> None:
    failed, _ = doctest.testmod(module, verbose=False)  # type: ignore[arg-type]
    assert failed == 0
