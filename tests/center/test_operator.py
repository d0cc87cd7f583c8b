"""The operator's input (goals, facts, decisions) and the live hub between a team and the server."""

from __future__ import annotations

import json
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.center import operator
from alica.app.center.live import LiveHub
from alica.app.center.team_view import TeamView
from alica.errors import AlicaError
from alica.io import load_library, plans_dir

KNOWN = operator.problems(load_library(plans_dir() / "blocksworld" / "mission.yaml"))


def test_the_problems_of_a_plan_file_name_their_goal_and_predicates() -> None:
    stack = KNOWN["StackBlocks"]
    assert stack["goal"] == "on(a, b) and on(b, c) and ontable(c)"
    assert stack["predicates"] == {"clear": 1, "ontable": 1, "handempty": 1, "holding": 2, "on": 2}


@pytest.mark.parametrize(
    ("goal", "column", "says"),
    [
        ("on(a, b) and", 13, "expected a term"),
        ("on(a b)", 6, "expected ')'"),
        ("on(a, b) and onn(b, c)", 14, "'onn' is no predicate"),
        ("on(a)", 1, "takes 2 arguments"),
        ("on(a, b) or on(b, a)", 1, "not a literal"),
        ("   ", 1, "empty"),
    ],
)
def test_a_bad_goal_is_reported_at_its_column(goal: str, column: int, says: str) -> None:
    checked = operator.check_goal(KNOWN, "StackBlocks", goal)
    assert checked["ok"] is False
    assert checked["column"] == column
    assert says in checked["error"]


def test_a_good_goal_lists_its_literals_and_an_unknown_problem_is_named() -> None:
    assert operator.check_goal(KNOWN, "StackBlocks", "on(a, b) and not clear(b)") == {
        "ok": True,
        "literals": ["on(a, b)", "not clear(b)"],
    }
    unknown = operator.check_goal(KNOWN, "Stack", "on(a, b)")
    assert unknown["ok"] is False and "Stack" in unknown["error"] and unknown["hint"] == "StackBlocks"


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet="onabc(), !=andortk_1", max_size=40))
def test_any_text_typed_as_a_goal_gets_an_answer_with_a_column_inside_it(text: str) -> None:
    checked = operator.check_goal(KNOWN, "StackBlocks", text)
    if checked["ok"]:
        assert len(checked["literals"]) >= 1
    else:
        assert 1 <= checked["column"] <= len(text) + 1
        assert checked["error"]
    json.dumps(checked)  # the page gets it as JSON


def test_facts_are_literals() -> None:
    assert operator.check_facts("found(s1) and not stuck(scout)")["literals"] == ["found(s1)", "not stuck(scout)"]
    assert operator.check_facts("")["ok"] is False
    assert operator.check_facts("found(s1) or found(s2)")["ok"] is False


def test_a_decision_is_checked_field_by_field() -> None:
    body = {"problem": "P", "generation": 3, "action": "modify", "order": [2, 0], "pins": {"T0": "r2"}}
    assert operator.decision(body) == ("P", 3, "modify", (2, 0), {"T0": "r2"})
    assert operator.decision({"problem": "P", "generation": 1, "action": "accept"}) == ("P", 1, "accept", None, {})
    for bad, says in [
        ({"generation": 1, "action": "accept"}, "problem"),
        ({"problem": "P", "generation": True, "action": "accept"}, "generation"),
        ({"problem": "P", "generation": 1, "action": "later"}, "action"),
        ({"problem": "P", "generation": 1, "action": "modify", "order": ["a"]}, "order"),
        ({"problem": "P", "generation": 1, "action": "modify", "pins": {"T0": 2}}, "pins"),
    ]:
        with pytest.raises(AlicaError, match=says):
            operator.decision(bad)


class _Team:
    def __init__(self) -> None:
        self.goals: list[tuple[str, str]] = []

    def set_goal(self, problem: str, goal: str) -> str:
        if problem != "P":
            raise AlicaError(f"no planning problem named '{problem}'")
        self.goals.append((problem, goal))
        return "set"


def _hub() -> LiveHub:
    header = {"agents": {"r1": {"role": "Worker", "plan": "Top"}}, "world": "none"}
    return LiveHub(header, TeamView(header))


def test_the_hub_copies_events_stamps_them_and_folds_them_into_the_state() -> None:
    hub = _hub()
    event: dict[str, Any] = {"t": 0.5, "agent": "r1", "event": "allocation", "key": "Top", "plan": "Top"}
    event["entries"] = {"r1": "Work"}
    hub(event)
    event["plan"] = "changed after the hub took it"
    hub.tick(0.6)
    found, walls, count = hub.since(0)
    assert count == 1 and found[0]["plan"] == "Top" and len(walls) == 1
    state = json.loads(hub.snapshot_json())
    assert state["t"] == 0.6
    assert state["agents"]["r1"]["task"] == "Work"
    assert state["status"]["running"] is True
    assert hub.since(1) == ([], [], 1)


def test_operator_actions_run_on_the_teams_thread_and_answer_with_their_result_or_error() -> None:
    hub, team = _hub(), _Team()
    done = hub.submit(lambda t: t.set_goal("P", "on(a, b)"))
    refused = hub.submit(lambda t: t.set_goal("Q", "on(a, b)"))
    assert not done.done()  # nothing happens until the team's loop runs the queue
    hub.run_commands(team)
    assert done.result(timeout=0) == "set"
    with pytest.raises(AlicaError, match="Q"):
        refused.result(timeout=0)
    assert team.goals == [("P", "on(a, b)")]


def test_after_the_run_the_hub_refuses_operator_actions_and_shows_the_summary() -> None:
    hub = _hub()
    waiting = hub.submit(lambda t: t.set_goal("P", "x"))
    hub.finish({"success": True})
    with pytest.raises(AlicaError, match="over"):
        waiting.result(timeout=0)
    with pytest.raises(AlicaError, match="over"):
        hub.submit(lambda t: None).result(timeout=0)
    state = json.loads(hub.snapshot_json())
    assert state["status"] == {"running": False, "t": 0.0, "summary": {"success": True}}


def test_the_view_folds_the_operators_side() -> None:
    view = TeamView({})
    proposal = {"t": 1.0, "agent": "r1", "event": "proposal", "problem": "P", "generation": 1, "leader": "r1"}
    view.apply({**proposal, "cost": 2, "goal": "on(a, b)", "steps": ["(s1)", "(s2)"], "tasks": []})
    view.apply({"t": 1.5, "agent": "operator", "event": "operator", "what": "goal", "problem": "P", "goal": "on(a, b)"})
    assert view.snapshot()["operator"]["proposals"]["P"]["steps"] == ["(s1)", "(s2)"]
    old = view.copy()
    view.apply({"t": 2.0, "agent": "operator", "event": "operator", "what": "accept", "problem": "P", "generation": 0})
    assert "P" in view.snapshot()["operator"]["proposals"]  # an answer to another generation
    view.apply({"t": 2.0, "agent": "operator", "event": "operator", "what": "accept", "problem": "P", "generation": 1})
    shared = {"t": 2.1, "agent": "r1", "event": "planner", "what": "plan", "key": "Top/S/P", "generation": 1}
    view.apply({**shared, "version": 1, "cost": 2, "steps": 2})
    side = view.snapshot()["operator"]
    assert side["proposals"] == {}
    assert side["goals"] == {"P": "on(a, b)"}
    assert side["running"]["P"] == {"generation": 1, "version": 1, "cost": 2, "steps": 2, "t": 2.1, "leader": "r1"}
    assert "P" in old.snapshot()["operator"]["proposals"]  # a checkpoint keeps its own
    assert "operator" not in view.snapshot()["agents"]
