"""Temporal plans: durative actions at start times, in PDDL 2.1's plan format.

A line of a plan file is ``START: (action arg ...) [DURATION]``, e.g.
``0.000: (move r p q) [4.000]``; ``;`` starts a comment. Happenings closer than
:data:`EPSILON` count as simultaneous (as VAL's default tolerance does): a plan
keeps two interfering happenings at least that far apart.

>>> plan = parse_temporal_plan("0: (move r p q) [4]\\n4.001: (drill r q) [2]")
>>> plan.makespan
6.001
>>> print(plan)
0.000: (move r p q) [4.000]
4.001: (drill r q) [2.000]
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from alica.errors import PlannerError
from alica.prophet.planner import PlanStep

EPSILON = 0.001
"""The separation of two interfering happenings (seconds of plan time)."""

_LINE = re.compile(
    r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*:\s*\(([^()]*)\)\s*\[\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*\]\s*$"
)


class TemporalPlanError(PlannerError):
    """A temporal plan file that does not parse: ``FILE:LINE: error: ...``."""


@dataclass(frozen=True, slots=True)
class TimedStep:
    """One durative action of a temporal plan: when it starts and how long it takes."""

    start: float
    step: PlanStep
    duration: float

    @property
    def end(self) -> float:
        """When it ends."""
        return self.start + self.duration

    def __str__(self) -> str:
        return f"{self.start:.3f}: {self.step} [{self.duration:.3f}]"


@dataclass(frozen=True, slots=True)
class TemporalPlan:
    """Durative actions at their start times, in the order written (sorted by start by :func:`scheduled`)."""

    steps: tuple[TimedStep, ...]

    @property
    def makespan(self) -> float:
        """The time the last action ends (0 for an empty plan)."""
        return round(max((s.end for s in self.steps), default=0.0), 9)

    def __len__(self) -> int:
        return len(self.steps)

    def __str__(self) -> str:
        return "\n".join(str(s) for s in self.steps)


def parse_temporal_plan(text: str, file: str = "<plan>") -> TemporalPlan:
    """A temporal plan from its text (see the module docstring).

    Raises:
        TemporalPlanError: a line that is no ``START: (action args) [DURATION]``, or a time that is
            negative or not finite; the message names the file and line.
    """
    steps: list[TimedStep] = []
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.split(";", 1)[0].strip()
        if not line:
            continue
        match = _LINE.match(line)
        if match is None:
            raise TemporalPlanError(
                f"{file}:{number}: error: expected 'START: (action arg ...) [DURATION]', found '{line}'"
            )
        start, duration = float(match.group(1)), float(match.group(3))
        if not (math.isfinite(start) and math.isfinite(duration)):
            raise TemporalPlanError(f"{file}:{number}: error: times must be finite numbers")
        words = match.group(2).split()
        if not words:
            raise TemporalPlanError(f"{file}:{number}: error: expected an action name in '()'")
        steps.append(TimedStep(start, PlanStep(words[0].lower(), tuple(w.lower() for w in words[1:])), duration))
    return TemporalPlan(tuple(steps))


__all__ = ["EPSILON", "TemporalPlan", "TemporalPlanError", "TimedStep", "parse_temporal_plan"]
