"""What the ROS 2 bridge reads of a running agent: its robot's pose, its world model, its plans.

:class:`EngineView` satisfies :class:`alica.app.ros2_bridge.AgentView` for an
:class:`~alica.engine.agent.AgentEngine` and the robot it drives (a pybullet
robot, a plug-in's, a world server's). Everything comes from what the agent
knows: the robot's own estimate of its pose, and the team's world model (the
map, the samples found, the places its planning goals name), never the
simulator's ground truth.
"""

from __future__ import annotations

import re
import zlib
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from alica.app.ros2_bridge import Place

if TYPE_CHECKING:
    from alica.engine import AgentEngine

#: ``at(thing, place)`` literals of a goal: the places a planning goal names.
_AT = re.compile(r"\bat\(\s*([A-Za-z_][\w\-]*)\s*,\s*([A-Za-z_][\w\-]*)\s*\)")


def _xy(value: object) -> tuple[float, float] | None:
    if isinstance(value, (tuple, list)) and len(value) >= 2:
        try:
            return float(value[0]), float(value[1])
        except (TypeError, ValueError):
            return None
    return None


class EngineView:
    """One agent as the bridge sees it (see the module docstring).

    Args:
        engine: the agent's engine, or a function giving it (a simulated team makes a new engine when a
            crashed agent restarts).
        robot: its robot (``estimate``: ``(x, y, yaw)``), or ``None`` for an agent without one.
    """

    def __init__(self, engine: AgentEngine | Callable[[], AgentEngine], robot: Any | None) -> None:
        self._engine = engine
        self.robot = robot

    @property
    def engine(self) -> AgentEngine:
        """The agent's engine now."""
        engine = self._engine
        return engine() if callable(engine) else engine

    def pose(self) -> tuple[float, float, float] | None:
        """The robot's own estimate of its pose (``None`` without a robot, or for a crashed one)."""
        robot = self.robot
        if robot is None or getattr(robot, "crashed", False):
            return None
        x, y, yaw = robot.estimate
        return float(x), float(y), float(yaw)

    def team_map(self) -> tuple[int, tuple[float, float], float, np.ndarray] | None:
        """The team map of the agent's world model, with a checksum of its cells as its version."""
        from alica.skills.mapping import team_map

        grid = team_map(self.engine.world_model)
        if grid is None:
            return None
        return zlib.crc32(grid.logodds.tobytes()), grid.origin, grid.resolution, grid.logodds

    def places(self) -> tuple[Place, ...]:
        """The samples the team found (``found(s)``, ``pos(s)``, ``sample_kind(s)``) and the goals' places."""
        wm = self.engine.world_model
        out: list[Place] = []
        for fact in wm.facts():
            if fact.predicate == "found" and len(fact.args) == 1:
                name = str(fact.args[0])
                xy = _xy(wm.get("pos", name))
                if xy is not None:
                    kind = wm.get("sample_kind", name)
                    out.append(Place(name, xy[0], xy[1], str(kind) if kind is not None else ""))
        goals: set[str] = set()
        for problem, override in sorted(self.engine.overrides.items()):
            text = override.get("goal")
            if text is None and problem in self.engine.library.problems:
                text = self.engine.library.problems[problem].goal.text
            goals.update(place for _, place in _AT.findall(text or ""))
        for name in sorted(goals):
            xy = _xy(wm.get("pos", name))
            if xy is not None:
                out.append(Place(name, xy[0], xy[1], goal=True))
        return tuple(out)

    def plans(self) -> tuple[Mapping[str, str], ...]:
        """The agent's running plans, root first (depth first): key, plan, task, state, behaviours, status."""
        out: list[dict[str, str]] = []
        todo = [self.engine.root] if self.engine.root is not None else []
        while todo:
            node = todo.pop()
            task = node.plan.entry_point(node.ep).task if node.ep is not None else ""
            behaviours = [f"{slot.name}: {slot.status.value}" for slot in node.slots if slot.is_behaviour]
            out.append(
                {
                    "key": node.key_text,
                    "plan": node.plan.name,
                    "task": task,
                    "state": node.state or "",
                    "behaviours": ", ".join(behaviours),
                    "status": node.status.value,
                }
            )
            todo.extend(reversed([slot.node for slot in node.slots if slot.node is not None]))
        return tuple(out)
