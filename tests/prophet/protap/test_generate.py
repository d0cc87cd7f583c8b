"""Algorithm 2: specs from arguments, from facts and from the paper's Appendix C, written as RDDL facts."""

from __future__ import annotations

import math

import pytest

from alica.prophet.protap import (
    USER_DEFINED,
    Action,
    Goal,
    ProblemSpec,
    Robot,
    appendix_c_spec,
    domain_text,
    instance_text,
    is_object_name,
    random_spec,
    rddl_name,
    spec_from_facts,
    write_problem,
)
from tests.prophet.protap.rddl_facts import read_facts

_ONE_GOAL = (Goal("g1", "a1", (0, 0)),)


def test_appendix_c_with_its_typos_fixed() -> None:
    facts = read_facts(instance_text(appendix_c_spec()))
    assert facts.blocks == {"non-fluents": "nf_multi_ros_robot_inst_mdp__1", "instance": "multi_ros_robot_inst_mdp__1"}
    assert facts.objects == {
        "robot": ["r1", "r2"],
        "action": ["a1", "a2", "a3"],
        "xPos": ["x1", "x2", "x3", "x4", "x5"],
        "yPos": ["y1", "y2", "y3", "y4", "y5"],
        "goal": ["g1", "g2", "g3"],
    }
    nf = facts.non_fluents
    assert {k: v for k, v in nf.items() if k[0] == "PROB_GOTO"} == {
        ("PROB_GOTO", ("r1",)): "0.9",
        ("PROB_GOTO", ("r2",)): "0.9",
    }
    assert {k[1] for k, v in nf.items() if k[0] == "DO_COST" and v == "1.0"} == {
        (r, a) for r in ("r1", "r2") for a in ("a1", "a2", "a3")
    }
    # The paper's GOTO_COST rows, indexed by cell objects (the paper wrote xGoto1, yGoto1).
    expected_goto = {
        ("x1", "y1", "x1", "y1"): "0.0",
        ("x1", "y1", "x1", "y2"): "1.0",
        ("x1", "y1", "x1", "y5"): "4.0",
        ("x1", "y1", "x2", "y2"): "1.41",
        ("x1", "y1", "x2", "y3"): "2.24",
        ("x1", "y1", "x2", "y4"): "3.16",
        ("x1", "y1", "x2", "y5"): "4.12",
        ("x5", "y5", "x4", "y1"): "4.12",
        ("x5", "y5", "x4", "y4"): "1.41",
        ("x5", "y5", "x5", "y5"): "0.0",
    }
    for args, value in expected_goto.items():
        assert nf[("GOTO_COST", args)] == value
    assert sum(1 for k in nf if k[0] == "GOTO_COST") == 25 * 25
    # GOAL_UTILITY for every goal, not g1 and g2 only.
    assert {k: v for k, v in nf.items() if k[0] == "GOAL_UTILITY"} == {
        ("GOAL_UTILITY", (g,)): "100.0" for g in ("g1", "g2", "g3")
    }
    assert {k: v for k, v in nf.items() if k[0] == "GOAL"} == {
        ("GOAL", ("g1", "a2", "x4", "y2")): "true",
        ("GOAL", ("g2", "a1", "x1", "y1")): "true",
        ("GOAL", ("g3", "a2", "x3", "y4")): "true",
    }
    # r0 -> r1, r1 -> r2, x0 -> x1.
    assert facts.init == {("robotAt", ("r1", "x4", "y1")): "true", ("robotAt", ("r2", "x1", "y2")): "true"}
    # max-nondef-actions (the paper misspelt it max-nondet-actions, with the same 4) is 2 x the robots.
    assert facts.settings == {
        "domain": "multi_ros_robot_mdp",
        "non-fluents": "nf_multi_ros_robot_inst_mdp__1",
        "max-nondef-actions": "4",
        "horizon": "10",
        "discount": "1.0",
    }


def test_appendix_c_actions_are_two_manipulation_and_one_user_defined() -> None:
    kinds = [action.kind for action in appendix_c_spec().actions]
    assert kinds == ["manipulation", "manipulation", USER_DEFINED]


def test_random_spec_is_deterministic_for_a_seed() -> None:
    assert random_spec(4, 8, 8, 6, seed=3) == random_spec(4, 8, 8, 6, seed=3)
    assert instance_text(random_spec(seed=3)) == instance_text(random_spec(seed=3))
    assert len({random_spec(2, 5, 5, 3, seed=seed).goals for seed in range(10)}) > 1


def test_random_spec_places_goals_on_distinct_cells() -> None:
    spec = random_spec(robots=3, width=3, height=3, goals=9, seed=1)
    assert sorted(goal.cell for goal in spec.goals) == [(x, y) for x in range(3) for y in range(3)]
    assert spec.max_nondef_actions == 6
    with pytest.raises(ValueError, match="distinct cells"):
        random_spec(robots=1, width=2, height=2, goals=5)


def test_instance_facts_of_a_random_spec() -> None:
    spec = random_spec(robots=3, width=4, height=2, goals=2, seed=7, prob_goto=0.75, horizon=12, discount=0.9)
    facts = read_facts(instance_text(spec))
    assert facts.objects["xPos"] == ["x1", "x2", "x3", "x4"] and facts.objects["yPos"] == ["y1", "y2"]
    assert facts.settings["max-nondef-actions"] == "6"
    assert facts.settings["horizon"] == "12" and facts.settings["discount"] == "0.9"
    assert {v for k, v in facts.non_fluents.items() if k[0] == "PROB_GOTO"} == {"0.75"}
    goals = {k[1] for k in facts.non_fluents if k[0] == "GOAL"}
    assert goals == {(g.name, g.action, f"x{g.cell[0] + 1}", f"y{g.cell[1] + 1}") for g in spec.goals}
    robots = {k[1] for k in facts.init}
    assert robots == {(r.name, f"x{r.cell[0] + 1}", f"y{r.cell[1] + 1}") for r in spec.robots}
    for (name, args), value in facts.non_fluents.items():
        if name == "GOTO_COST":
            a = (int(args[0][1:]), int(args[1][1:]))
            b = (int(args[2][1:]), int(args[3][1:]))
            assert float(value) == pytest.approx(round(math.dist(a, b), 2))


def test_spec_from_world_model_facts() -> None:
    spec = spec_from_facts(
        {"scout-1": (0, 0), "Carrier 2": (4, 4)},
        [
            {"name": "rock 7", "action": "drill", "cell": (2, 3), "utility": 50},
            {"name": "base", "action": "report", "cell": [0, 4]},
        ],
        width=5,
        height=5,
        user_actions=["report", "wave"],
        prob_goto={"scout-1": 0.8, "Carrier 2": 1.0},
    )
    assert [(r.name, r.cell, r.prob_goto) for r in spec.robots] == [
        ("scout_1", (0, 0), 0.8),
        ("Carrier_2", (4, 4), 1.0),
    ]
    assert spec.actions == (Action("drill"), Action("report", USER_DEFINED), Action("wave", USER_DEFINED))
    assert spec.goals == (Goal("rock_7", "drill", (2, 3), 50.0), Goal("base", "report", (0, 4), 100.0))
    assert spec.max_nondef_actions == 4
    facts = read_facts(instance_text(spec))
    assert ("GOAL", ("rock_7", "drill", "x3", "y4")) in facts.non_fluents


def test_spec_from_facts_refuses_what_rddl_cannot_say() -> None:
    with pytest.raises(ValueError, match="outside the grid"):
        spec_from_facts({"r1": (5, 0)}, [{"name": "g", "action": "a", "cell": (0, 0)}], width=5, height=5)
    with pytest.raises(ValueError, match="used twice"):
        spec_from_facts(
            {"r-1": (0, 0), "r 1": (1, 1)}, [{"name": "g", "action": "a", "cell": (0, 0)}], width=2, height=2
        )


@pytest.mark.parametrize("name", ["done", "if", "Bernoulli", "sum", "det", "x__1", "1r", "r_", "a-b", "", "goto"])
def test_keywords_and_bad_names_are_refused(name: str) -> None:
    assert not is_object_name(name)
    with pytest.raises(ValueError, match="valid RDDL object name"):
        ProblemSpec(robots=(Robot(name, (0, 0)),), actions=(Action("a1"),), goals=_ONE_GOAL, width=1, height=1)


@pytest.mark.parametrize(
    ("text", "name"), [("scout-1", "scout_1"), ("if", "o_if"), ("3rd", "o_3rd"), ("__", "o"), ("a__b", "a_b")]
)
def test_rddl_name_makes_valid_names(text: str, name: str) -> None:
    assert rddl_name(text) == name
    assert is_object_name(name)


def test_names_must_be_distinct_across_types() -> None:
    with pytest.raises(ValueError, match="'x1' used twice"):
        ProblemSpec(robots=(Robot("x1", (0, 0)),), actions=(Action("a1"),), goals=_ONE_GOAL, width=1, height=1)


def test_a_problem_needs_robots_actions_and_goals() -> None:
    with pytest.raises(ValueError, match="no robots; no actions; no goals"):
        ProblemSpec(robots=(), actions=(), goals=(), width=1, height=1)


def test_write_problem_writes_the_domain_and_the_instance(tmp_path) -> None:  # type: ignore[no-untyped-def]
    spec = random_spec(seed=2)
    domain, instance = write_problem(spec, tmp_path / "out")
    assert domain.read_text(encoding="utf-8") == domain_text()
    assert instance.read_text(encoding="utf-8") == instance_text(spec)
    assert "domain multi_ros_robot_mdp" in domain_text()
