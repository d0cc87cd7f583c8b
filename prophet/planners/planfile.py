"""Plan files as planners write them: one ``(action arg ...)`` per line, ``;`` comments.

Fast Downward ends its plan files with ``; cost = N (unit cost)`` (or
``general cost``); pyperplan writes the actions only. Without a cost comment
the cost is the number of actions (unit cost).
"""

from __future__ import annotations

import re
from pathlib import Path

from alica.errors import PlannerError
from alica.prophet.planner import Plan, PlanStep

_COST = re.compile(r";\s*cost\s*=\s*([0-9.eE+-]+)")

__all__ = ["format_plan", "parse_plan", "read_plan"]


def parse_plan(text: str, source: str = "<plan>") -> Plan:
    """The plan written in ``text``.

    Args:
        text: the plan file's text.
        source: where it comes from, for messages.

    Raises:
        PlannerError: a line is neither an action nor a comment.
    """
    steps: list[PlanStep] = []
    cost: float | None = None
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith(";"):
            match = _COST.match(line)
            if match is not None:
                cost = float(match.group(1))
            continue
        if not (line.startswith("(") and line.endswith(")")):
            raise PlannerError(f"{source}:{number}: not a plan step: {line!r}")
        words = line[1:-1].split()
        if not words:
            raise PlannerError(f"{source}:{number}: empty plan step")
        steps.append(PlanStep(words[0].lower(), tuple(w.lower() for w in words[1:])))
    return Plan(tuple(steps), float(len(steps)) if cost is None else cost)


def read_plan(path: str | Path) -> Plan:
    """The plan in the file at ``path`` (see :func:`parse_plan`)."""
    return parse_plan(Path(path).read_text(encoding="utf-8"), str(path))


def format_plan(plan: Plan) -> str:
    """The plan as a plan file: one step a line and a ``; cost = N`` comment."""
    cost = int(plan.cost) if float(plan.cost).is_integer() else plan.cost
    return "".join(f"{step}\n" for step in plan.steps) + f"; cost = {cost}\n"
