"""The operator's goal from a ROS 2 topic: ``/alica/goal`` (``std_msgs/msg/String``), checked as the control center checks it.

A message's text is ``PROBLEM=FORMULA`` (``Transport=at(s1, g) and at(s2, g)``),
or just the formula when the plans hold one planning problem. The goal is
checked with the control center's checks (:func:`alica.app.center.operator.check_goal`:
a known problem, the formula parses, its predicates are the domain's with the
right number of arguments). A goal that passes is applied between two ticks of
the run, never from the middleware's thread; every message, applied or refused,
gets an answer on ``/alica/goal_result`` (``std_msgs/msg/String``): ``applied:
PROBLEM=FORMULA`` or ``refused: <why>``. A payload that is not a ``String`` is
counted and dropped, never fatal.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping
from typing import Any

from alica.comm.ros2 import dds_name, decode, encode, type_hash
from alica.comm.ros2.rmw import Ros2Node
from alica.errors import AlicaError

#: Where goals arrive and where their answers go.
GOAL_TOPIC = "/alica/goal"
RESULT_TOPIC = "/alica/goal_result"
STRING = "std_msgs/msg/String"
#: The longest goal text read; a longer one is refused.
MAX_GOAL = 4096
#: Goals waiting for the next tick at most; more are refused (a flood cannot grow memory).
MAX_PENDING = 64


def parse_goal(text: str, problems: Mapping[str, dict[str, Any]]) -> tuple[str, str]:
    """``PROBLEM=FORMULA`` (or ``FORMULA`` with one problem) as ``(problem, formula)``, checked.

    Raises:
        AlicaError: no problem named, an unknown one, or a formula the control center would refuse.
    """
    from alica.app.center.operator import check_goal

    if len(text) > MAX_GOAL:
        raise AlicaError(f"the goal is {len(text)} characters long; at most {MAX_GOAL}")
    head, sep, tail = text.partition("=")
    if sep and head.strip().isidentifier():
        problem, formula = head.strip(), tail.strip()
    elif len(problems) == 1:
        problem, formula = next(iter(problems)), text.strip()
    else:
        names = ", ".join(sorted(problems)) or "none"
        raise AlicaError(f"write PROBLEM=FORMULA: the plans have the planning problems {names}")
    checked = check_goal(problems, problem, formula)
    if not checked["ok"]:
        hint = f" ({checked['hint']})" if checked.get("hint") else ""
        raise AlicaError(f"{problem}: column {checked['column']}: {checked['error']}{hint}")
    return problem, formula


class GoalTopic:
    """Subscribes ``/alica/goal`` on ``node`` and applies checked goals when :meth:`poll` is called.

    Args:
        node: the ROS 2 node that listens and answers.
        problems: the planning problems a goal may name (:func:`alica.app.center.operator.problems`).
        apply: sets goal ``formula`` of ``problem`` on the team or the agent (may raise AlicaError: refused).
        distro: ``humble`` or ``jazzy``.
    """

    def __init__(
        self,
        node: Ros2Node,
        problems: Mapping[str, dict[str, Any]],
        apply: Callable[[str, str], None],
        distro: str = "jazzy",
    ) -> None:
        self.problems = problems
        self.apply = apply
        self.distro = distro
        self.dropped = 0
        """Payloads that were no ``String``, or arrived with too many goals waiting."""
        self.answers: list[str] = []
        """Every answer given, in order (``applied: ...`` / ``refused: ...``)."""
        self._lock = threading.Lock()
        self._pending: list[str] = []
        hashed = type_hash(STRING, distro)
        self._result = node.publisher(RESULT_TOPIC, dds_name(STRING), hashed)
        node.subscribe(GOAL_TOPIC, dds_name(STRING), hashed, self._arrived)

    def _arrived(self, payload: bytes, _attachment: object) -> None:
        try:
            text = decode(STRING, payload, self.distro)["data"]
        except AlicaError:
            text = None
        with self._lock:
            if not isinstance(text, str) or len(self._pending) >= MAX_PENDING:
                self.dropped += 1
                return
            self._pending.append(text)

    def poll(self, _now: float = 0.0) -> None:
        """Apply the goals that arrived since the last call, in order (a hook for after each tick)."""
        with self._lock:
            pending, self._pending = self._pending, []
        for text in pending:
            try:
                problem, formula = parse_goal(text, self.problems)
                self.apply(problem, formula)
            except AlicaError as exc:
                self._answer(f"refused: {exc}")
            else:
                self._answer(f"applied: {problem}={formula}")

    def _answer(self, text: str) -> None:
        self.answers.append(text)
        self._result.put(encode(STRING, {"data": text}, self.distro))


__all__ = ["GOAL_TOPIC", "RESULT_TOPIC", "GoalTopic", "parse_goal"]
