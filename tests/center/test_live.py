"""The live control center of a running team, end to end: ``alica run --center`` in a process, its API and WebSocket.

A blocks-world team in pybullet plans at run time under ``--review``: the
operator's decisions go through the HTTP API and come back as events.
"""

from __future__ import annotations

import pytest

from tests.center.live_run import BLOCKS, TOKEN, live_run, serving


def _proposal(generation: int, error: bool = False):  # type: ignore[no-untyped-def]
    return lambda e: e["event"] == "proposal" and e["generation"] == generation and ("error" in e) == error


def test_the_operator_declines_changes_pins_and_accepts_a_plan_then_sets_a_goal() -> None:
    with live_run(*BLOCKS, "--review", "--speed", "8", "--time-limit", "400") as live:
        hello = live.connect()
        assert hello["type"] == "hello"
        assert hello["meta"]["mode"] == "live"
        assert hello["meta"]["agents"] == ["r1", "r2"]
        assert hello["meta"]["problems"]["StackBlocks"]["predicates"]["on"] == 2

        first = live.until(_proposal(1))
        assert first["steps"] and first["tasks"]
        assert not any(e["event"] == "planner" and e.get("what") == "plan" for e in live.events)  # nothing runs

        # the goal is checked as typed: the error's column
        status, check = live.request("api/check", {"problem": "StackBlocks", "goal": "on(a, b) and"})
        assert status == 200 and check["ok"] is False and check["column"] == 13

        # decline: the leader plans again
        assert live.request("api/decide", {"problem": "StackBlocks", "generation": 1, "action": "decline"})[0] == 200
        second = live.until(_proposal(2))
        assert any(e["event"] == "operator" and e["what"] == "decline" and e["generation"] == 1 for e in live.events)

        # a decision for an old generation changes nothing
        assert live.request("api/decide", {"problem": "StackBlocks", "generation": 1, "action": "accept"})[0] == 200
        live.until(lambda e: e["event"] == "note" and "generation" in e.get("message", ""))
        assert not any(e["event"] == "planner" and e.get("what") == "plan" for e in live.events)

        # a change that breaks the plan is refused with the validator's reason, and nothing runs
        order = list(range(len(second["steps"])))[1:]
        status, _ = live.request(
            "api/decide", {"problem": "StackBlocks", "generation": 2, "action": "modify", "order": order}
        )
        assert status == 200
        refused = live.until(_proposal(2, error=True))
        assert "invalid" in refused["error"] or "does not hold" in refused["error"]

        # the plan with its first task pinned to r2 runs
        task = second["tasks"][0]["entry_point"]
        body = {
            "problem": "StackBlocks",
            "generation": 2,
            "action": "modify",
            "order": list(range(len(second["steps"]))),
            "pins": {task: "r2"},
        }
        assert live.request("api/decide", body)[0] == 200
        shared = live.until(lambda e: e["event"] == "planner" and e.get("what") == "plan" and e["generation"] == 2)
        taken = live.until(
            lambda e: (
                e["event"] == "allocation"
                and e["agent"] == "r2"
                and any(v.endswith("_T0") for v in e["entries"].values())
            )
        )
        assert taken["entries"]["r2"].endswith("_T0")
        running = live.until_state(lambda s: "StackBlocks" in s["operator"]["running"])
        assert running["operator"]["running"]["StackBlocks"]["generation"] == shared["generation"]
        assert running["operator"]["proposals"] == {}

        # the operator sets facts and a new goal: the leader plans for it and proposes
        assert live.request("api/facts", {"facts": "checked(a)"})[0] == 200
        live.until(lambda e: e["event"] == "operator" and e["what"] == "facts" and e["facts"] == ["checked(a)"])
        goal = "on(c, a) and ontable(a)"
        assert live.request("api/goal", {"problem": "StackBlocks", "goal": goal})[0] == 200
        live.until(lambda e: e["event"] == "operator" and e["what"] == "goal" and e["goal"] == goal)
        proposal = live.until(lambda e: e["event"] == "proposal" and e["goal"] == goal)
        assert proposal["generation"] > 2


def test_the_live_api_refuses_bad_input_and_requests_without_the_token() -> None:
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    with live_run(*BLOCKS, "--review", "--time-limit", "60") as live:
        assert live.request("", token=None)[0] == 403
        assert live.request("api/state", token=None)[0] == 403
        assert live.request("api/goal", {"problem": "StackBlocks", "goal": "on(a, b)"}, token="wrong")[0] == 403
        with pytest.raises(InvalidStatus) as refused:
            connect("ws" + live.base[len("http") :] + "ws", open_timeout=20)
        assert refused.value.response.status_code == 403

        status, page = live.request("")
        assert status == 200 and "alica control center: live" in page
        status, answer = live.request("api/goal", {"problem": "StackBlocks", "goal": "onn(a, b)"})
        assert status == 400 and answer["column"] == 1 and "onn" in answer["error"]
        status, answer = live.request("api/goal", {"problem": "Nope", "goal": "on(a, b)"})
        assert status == 400 and "Nope" in answer["error"]
        status, answer = live.request("api/facts", {"facts": "found(s1) or found(s2)"})
        assert status == 400 and "not a literal" in answer["error"]
        status, answer = live.request("api/decide", {"problem": "StackBlocks", "generation": "1", "action": "accept"})
        assert status == 400 and "generation" in answer["error"]
        status, answer = live.request("api/decide", {"problem": "StackBlocks", "generation": 1, "action": "maybe"})
        assert status == 400 and "action" in answer["error"]
        status, answer = live.request(
            "api/decide", {"problem": "StackBlocks", "generation": 1, "action": "accept", "order": [0]}
        )
        assert status == 400 and "modify" in answer["error"]
        status, answer = live.request("api/events?since=x")
        assert status == 400
        status, trees = live.request("api/trees")
        assert status == 200 and "BlocksWorldMission" in trees["trees"]
        assert TOKEN not in live.request("api/meta")[1]["file"]


def test_a_demo_serves_its_run_live_and_the_page_shows_the_end() -> None:
    with live_run(
        "blocksworld", "--robots", "1", "--blocks", "2", "--seed", "1", "--speed", "50", command="demo"
    ) as live:
        live.connect()
        over = live.until_state(lambda s: not s["status"]["running"], timeout=120)
        assert over["status"]["summary"]["success"] is True
        assert set(over["agents"]) == {"r1"}
        assert over["world"] == "blocks" and over["objects"]
        assert any(e["event"] == "pose" for e in live.events)
        status, answer = live.request("api/facts", {"facts": "found(a)"})
        assert status == 409 and "over" in answer["error"]


def test_with_json_the_address_goes_to_standard_error_and_standard_output_stays_json() -> None:
    import json

    argv = ["demo", "blocksworld", "--robots", "1", "--blocks", "2", "--seed", "1", "--speed", "50", "--json"]
    with serving([*argv, "--center", "--center-port", "0"], stream="stderr") as (_, process):
        assert process.stdout is not None
        summary = json.loads(process.stdout.readline())  # the run's JSON line, written when the run ends
        assert summary["success"] is True
