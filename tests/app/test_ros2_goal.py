"""The operator's goal from ``/alica/goal``: checked as the control center checks it, applied between ticks, answered."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rosbags.typesys import Stores, get_typestore

from alica.app.ros2_goal import GOAL_TOPIC, MAX_GOAL, GoalTopic, parse_goal
from alica.comm.ros2 import dds_name, type_hash
from alica.comm.ros2.rmw import Ros2Node, open_session, topic_key
from alica.comm.zenoh_transport import free_endpoints
from alica.errors import AlicaError
from tests.comm.ros2.fake_ros2 import FakeRos2, fake_attachment

TS = get_typestore(Stores.ROS2_JAZZY)
STRING = "std_msgs/msg/String"
PROBLEMS: dict[str, dict[str, Any]] = {
    "Transport": {"goal": "at(s1, g)", "planner": "ff", "predicates": {"at": 2, "holding": 2}},
    "Stack": {"goal": "on(a, b)", "planner": "ff", "predicates": {"on": 2}},
}


def test_a_goal_names_its_problem_and_is_checked_like_the_control_centers() -> None:
    assert parse_goal("Transport=at(s1, g) and at(s2, g)", PROBLEMS) == ("Transport", "at(s1, g) and at(s2, g)")
    assert parse_goal("on(a, b)", {"Stack": PROBLEMS["Stack"]}) == ("Stack", "on(a, b)")  # one problem: no name needed
    with pytest.raises(AlicaError, match="write PROBLEM=FORMULA"):
        parse_goal("at(s1, g)", PROBLEMS)
    with pytest.raises(AlicaError, match="no planning problem named 'Fetch'"):
        parse_goal("Fetch=at(s1, g)", PROBLEMS)
    with pytest.raises(AlicaError, match="'near' is no predicate of Transport's domain"):
        parse_goal("Transport=near(s1, g)", PROBLEMS)
    with pytest.raises(AlicaError, match="takes 2 arguments, not 1"):
        parse_goal("Transport=at(s1)", PROBLEMS)
    with pytest.raises(AlicaError, match="at most"):
        parse_goal("Transport=" + "at(s1, g) and " * MAX_GOAL, PROBLEMS)


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=80))
def test_any_text_is_a_goal_or_a_clear_refusal(text: str) -> None:
    try:
        problem, formula = parse_goal(text, PROBLEMS)
    except AlicaError as exc:
        assert str(exc)
    else:
        assert problem in PROBLEMS and formula


@pytest.fixture
def wire() -> Iterator[tuple[Ros2Node, FakeRos2]]:
    (endpoint,) = free_endpoints(1)
    session = open_session(None, listen=[endpoint])
    node = Ros2Node(session, "alica_operator")
    ros = FakeRos2(endpoint)
    yield node, ros
    ros.close()
    node.close()
    session.close()


def test_goals_from_the_topic_are_applied_at_the_next_poll_and_answered(wire: tuple[Ros2Node, FakeRos2]) -> None:
    node, ros = wire
    applied: list[tuple[str, str]] = []
    topic = GoalTopic(node, PROBLEMS, lambda problem, goal: applied.append((problem, goal)))
    hashed = type_hash(STRING, "jazzy")
    key = topic_key(0, GOAL_TOPIC, dds_name(STRING), hashed)
    ros.subscribe(topic_key(0, "/alica/goal_result", dds_name(STRING), hashed))
    assert ros.wait(lambda: any(e.topic == GOAL_TOPIC and e.kind == "MS" for e in ros.endpoints()))
    texts = ["Transport=at(s1, g)", "Transport=near(s1, g)", "Stack=on(a, b)"]
    for sequence, text in enumerate(texts):
        ros.put(
            key, bytes(TS.serialize_cdr(TS.types[STRING](data=text), STRING)), fake_attachment(sequence, 0, bytes(16))
        )
    ros.put(key, b"\x00\x01\x00\x00\xff\xff\xff\xff", fake_attachment(9, 0, bytes(16)))  # no String: dropped
    assert applied == []  # nothing from the middleware's thread
    assert ros.wait(lambda: topic.dropped == 1 and len(topic._pending) == 3)
    topic.poll(1.0)
    assert applied == [("Transport", "at(s1, g)"), ("Stack", "on(a, b)")]
    assert topic.answers[0] == "applied: Transport=at(s1, g)"
    assert topic.answers[1].startswith("refused: Transport: column 1: 'near' is no predicate")
    assert ros.wait(lambda: len(ros.received) == 3)
    answers = [TS.deserialize_cdr(r.payload, STRING).data for r in ros.received]
    assert answers == topic.answers


def test_a_goal_the_team_refuses_is_answered_and_a_flood_is_bounded(wire: tuple[Ros2Node, FakeRos2]) -> None:
    node, ros = wire

    def refuse(problem: str, goal: str) -> None:
        raise AlicaError(f"no planning problem named '{problem}'")

    topic = GoalTopic(node, PROBLEMS, refuse)
    key = topic_key(0, GOAL_TOPIC, dds_name(STRING), type_hash(STRING, "jazzy"))
    assert ros.wait(lambda: any(e.topic == GOAL_TOPIC for e in ros.endpoints()))
    data = bytes(TS.serialize_cdr(TS.types[STRING](data="Stack=on(a, b)"), STRING))
    for sequence in range(100):
        ros.put(key, data, fake_attachment(sequence, 0, bytes(16)))
    assert ros.wait(lambda: len(topic._pending) + topic.dropped == 100)
    topic.poll()
    assert len(topic.answers) == 64 and topic.dropped == 36
    assert topic.answers[0] == "refused: no planning problem named 'Stack'"
