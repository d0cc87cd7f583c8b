"""The operator's commands as an agent of a team of processes applies them, and the feed's history.

``apply_command`` runs on a real engine of a blocks-world team (simulated, not
ticked); :class:`CenterFeed` and :class:`CenterLink` talk over zenoh on
loopback, every wait bounded by a queue's time-out.
"""

from __future__ import annotations

import queue
import time
from typing import Any

from alica.app.cli_agent import apply_command
from alica.comm.center_feed import CenterFeed, CenterLink
from alica.comm.zenoh_transport import ZenohTransport, free_endpoints
from alica.engine import PlanDecision, SimulatedTeam
from alica.io import Loader, plans_dir
from alica.prophet import engine_config


def _engine() -> tuple[Any, list[dict[str, Any]]]:
    library = Loader().load(plans_dir() / "blocksworld" / "mission.yaml")
    events: list[dict[str, Any]] = []
    team = SimulatedTeam(
        library,
        "BlocksWorldMission",
        {"r1": "Manipulator"},
        config=engine_config(review=True),
        observers=[events.append],
    )
    return team.engines["r1"], events


def test_an_agent_applies_a_goal_facts_and_a_decision() -> None:
    engine, events = _engine()
    apply_command(engine, {"what": "goal", "problem": "StackBlocks", "goal": "on(c, a)"})
    assert engine.overrides["StackBlocks"]["goal"] == "on(c, a)"
    apply_command(engine, {"what": "facts", "facts": [[True, "checked", ["a"]], [False, "clear", ["b"]]]})
    assert engine.world_model.holds("checked", "a")
    apply_command(engine, {"what": "decision", "problem": "StackBlocks", "generation": 2, "action": "accept"})
    assert engine.decisions["StackBlocks"] == [(2, PlanDecision("accept"))]
    pins = {"what": "decision", "problem": "StackBlocks", "generation": 3, "action": "modify", "order": [1, 0]}
    apply_command(engine, {**pins, "pins": {"T0": "r1"}})
    assert engine.decisions["StackBlocks"][-1] == (3, PlanDecision("modify", (1, 0), {"T0": "r1"}))
    assert not [e for e in events if e["event"] == "note"]
    applied = [{k: v for k, v in e.items() if k != "t"} for e in events if e["event"] == "operator"]
    assert applied == [  # the agent's trace holds what it applied
        {
            "agent": "r1",
            "event": "operator",
            "what": "goal",
            "problem": "StackBlocks",
            "goal": "on(c, a)",
            "applied": True,
        },
        {"agent": "r1", "event": "operator", "what": "facts", "facts": ["checked(a)", "not clear(b)"], "applied": True},
        {
            "agent": "r1",
            "event": "operator",
            "what": "accept",
            "problem": "StackBlocks",
            "generation": 2,
            "applied": True,
        },
        {
            "agent": "r1",
            "event": "operator",
            "what": "modify",
            "problem": "StackBlocks",
            "generation": 3,
            "applied": True,
            "order": [1, 0],
            "pins": {"T0": "r1"},
        },
    ]


def test_an_agent_refuses_what_it_cannot_apply_with_a_note() -> None:
    engine, events = _engine()
    bad = [
        {"what": "goal", "problem": "Nope", "goal": "on(a, b)"},
        {"what": "decision", "problem": "Nope", "generation": 1, "action": "accept"},
        {"what": "decision", "problem": "StackBlocks", "generation": 1, "action": "maybe"},
        {"what": "decision", "problem": "StackBlocks", "generation": True, "action": "accept"},
        {"what": "facts", "facts": [["on", "a"]]},
        {"what": "reboot"},
    ]
    for command in bad:
        apply_command(engine, command)
    notes = [e["message"] for e in events if e["event"] == "note"]
    assert len(notes) == len(bad)
    assert "no planning problem named 'Nope'" in notes[0] and "no planning problem named 'Nope'" in notes[1]
    assert "'maybe'" in notes[2]
    assert "no such operator's command: 'reboot'" in notes[5]
    assert engine.overrides == {} and engine.decisions == {}
    assert not [e for e in events if e["event"] == "operator"]


def test_a_late_center_gets_the_kept_history_then_the_new_events_once() -> None:
    endpoint = free_endpoints(1)
    with ZenohTransport("a1", listen=endpoint, team="feedtest") as transport:
        feed = CenterFeed(transport, {"event": "trace", "recorder": "a1"}, start=100.0, keep=3)
        try:
            for i in range(5):
                feed({"t": float(i), "agent": "a1", "event": "tick", "i": i})
            assert not feed.listened and feed.published == 0  # nobody subscribes: nothing goes out
            histories: queue.Queue[dict[str, Any]] = queue.Queue()
            events: queue.Queue[tuple[str, dict[str, Any]]] = queue.Queue()
            with CenterLink(endpoint, "feedtest", histories.put, lambda n, e: events.put((n, e))) as link:
                answer = histories.get(timeout=10)
                assert answer["agent"] == "a1" and answer["start"] == 100.0 and answer["header"]["recorder"] == "a1"
                assert [e["i"] for e in answer["events"]] == [2, 3, 4]
                assert answer["count"] == 5 and answer["dropped"] == 2
                deadline = time.monotonic() + 10
                sent, first = 5, None
                while first is None:  # published only once the center's subscription reached the agent
                    assert time.monotonic() < deadline, "no live event within 10 s"
                    feed({"t": float(sent), "agent": "a1", "event": "tick", "i": sent})
                    sent += 1
                    try:
                        first = events.get(timeout=0.05)
                    except queue.Empty:
                        continue
                got = [first[1]["i"]]
                feed({"t": 99.0, "agent": "a1", "event": "tick", "i": 99})
                while got[-1] != 99:
                    got.append(events.get(timeout=10)[1]["i"])
                assert got == sorted(set(got)) and got[0] >= 5  # none twice, none from the history again
                assert link.alive == {"a1"} and link.missed == 0
                commands = [{"what": "goal", "problem": "P", "goal": "g"}]
                link.send(commands[0])
                assert feed.commands(wait=10) == commands
        finally:
            feed.close()
