"""An agent's running plan tree as text: plans, entry points, states, children and their status."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from alica.engine.agent import AgentEngine
    from alica.engine.node import PlanNode


def running_tree(engine: AgentEngine) -> str:
    """The plan tree the agent runs, one line per plan, state and behaviour.

    Example::

        scout [Scout]
        └─ LunarMission  task Explore  state Exploring  running
           └─ Explore  task GetMap  state Mapping  running
              └─ BuildFirstMap  running  says: driving to (4.0, 2.5)

    A running behaviour's own word on its progress (its ``feedback_message``) follows ``says:``.
    """
    lines = [f"{engine.name} [{engine.role}]" + ("  (not started)" if engine.root is None else "")]
    if engine.root is not None:
        _node(engine.root, "", True, lines)
    return "\n".join(lines)


def _node(node: PlanNode, prefix: str, last: bool, lines: list[str]) -> None:
    branch = "└─ " if last else "├─ "
    if node.ep is None:
        where = "idle"
    else:
        where = f"task {node.plan.entry_point(node.ep).task}  state {node.state}"
    team = ", ".join(f"{a}:{e[0] or '-'}" for a, e in sorted(node.believed.items()))
    lines.append(f"{prefix}{branch}{node.plan.name}  {where}  {node.status.value}  [{team}]")
    child_prefix = prefix + ("   " if last else "│  ")
    for i, slot in enumerate(node.slots):
        final = i == len(node.slots) - 1
        if slot.node is not None:
            _node(slot.node, child_prefix, final, lines)
        else:
            reason = f"  ({slot.reason})" if slot.reason else ""
            feedback = f"  says: {slot.feedback}" if slot.feedback else ""
            lines.append(f"{child_prefix}{'└─ ' if final else '├─ '}{slot.name}  {slot.status.value}{reason}{feedback}")
