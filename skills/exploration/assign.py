"""Which frontier each exploring robot drives to next: the team's joint assignment, with hysteresis.

The Explore plan (``plans/skills/explore.yaml``) assigns one frontier to every
exploring robot at once (the per-agent variable ``frontier``, Eq. 7-8 and the
utility GainOverTravel). Its utility KeepFrontier adds a bonus of
``KEEP_BONUS`` (3.0, the plan's literal) for every robot whose frontier is the
one it already drives to (``Targets(robot, frontier)`` in the world model,
written by ExploreFrontier, :data:`TARGETS`). So the team's solution moves a
robot to another frontier only when that raises the team's summed gain over
travel by more than 3.0 per robot moved (m² of gain, or metres of travel):
that is the hysteresis. A robot whose frontier is gone (seen, reached,
unreachable) gets no bonus and simply gets the best one for the team.

With ExploreFrontier's ``reassign: true`` every robot reads the team's
solution periodically, not only when it needs a frontier (:func:`decide`), so
a solution that reassigns several robots (two robots swapping frontiers, say)
is followed by all of them; the Explore plan's DriveToFrontier sets it.
Without it (the skill's default) no ``Targets`` fact is written and
KeepFrontier adds nothing. The bench of ``bench/exploration.py``
runs the same rule on the same plan (:func:`solve_team` stands in for the
engine there).
"""

from __future__ import annotations

import math
from collections.abc import Container, Mapping, Sequence
from dataclasses import dataclass
from enum import Enum
from pathlib import Path

from alica.skills.exploration.frontiers import FrontierCandidate
from alica.solver import Term

__all__ = [
    "EXPLORERS",
    "KEEP_BONUS",
    "TARGETS",
    "Choice",
    "ExploreTerms",
    "Explorer",
    "How",
    "decide",
    "explore_terms",
    "proposal_of",
    "solve_team",
]

#: World-model predicate ``Targets(robot, frontier)``: true while the robot drives to that frontier.
TARGETS = "Targets"
#: The bonus of the plan's KeepFrontier utility for a robot that keeps its frontier (m² of gain or metres).
#: The plan file holds the value the solver uses; this is the value it ships with, for the docs and tests.
KEEP_BONUS = 3.0
#: The objects :func:`solve_team` lists as the exploring robots (the Explore plan's state ExploreFrontiers).
EXPLORERS = "agents(ExploreFrontiers)"


class How(Enum):
    """How a robot's frontier was chosen."""

    KEPT = "kept"
    """It keeps the frontier it drives to (the team's solution leaves it there, or has none)."""
    SOLVED = "solved"
    """It had none (or its frontier is gone) and takes the team's solution."""
    SWITCHED = "switched"
    """The team's solution moves it from the frontier it drives to to another one."""
    FALLBACK = "fallback"
    """It had none and chose itself: gain over distance, away from where the others head."""
    NONE = "none"
    """No frontier is usable."""


@dataclass(frozen=True, slots=True)
class Choice:
    """A robot's frontier (``None``: none usable) and how it was chosen."""

    frontier: FrontierCandidate | None
    how: How


@dataclass(frozen=True, slots=True)
class ExploreTerms:
    """The Explore plan's constraints (Eq. 7-8) and utilities (GainOverTravel, KeepFrontier), by name."""

    constraints: tuple[Term, ...]
    utilities: tuple[Term, ...]

    def utility(self, name: str) -> Term:
        """The utility ``name``.

        Raises:
            KeyError: the plan has no such utility.
        """
        for term in self.utilities:
            if term.name == name:
                return term
        raise KeyError(f"the Explore plan has no utility {name!r} (has {[t.name for t in self.utilities]})")


def explore_terms(path: Path | None = None) -> ExploreTerms:
    """The constraints and utilities of the plan ``Explore`` of ``path`` (the shipped ``skills/explore.yaml``).

    Raises:
        AlicaError: the file cannot be read (``PlanFormatError``) or has no plan ``Explore``.
    """
    from alica.errors import AlicaError
    from alica.io import load_document, plans_dir
    from alica.lang import parse

    path = path if path is not None else plans_dir() / "skills" / "explore.yaml"
    plan = next((p for p in load_document(path).plans if p.name == "Explore"), None)
    if plan is None:
        raise AlicaError(f"{path}: no plan 'Explore'")
    constraints, utilities = [], []
    for c in plan.constraints:
        if c.text:
            constraints.append(Term(c.name, parse(c.text), c.text))
        if c.utility:
            utilities.append(Term(c.name, parse(c.utility), c.utility))
    return ExploreTerms(tuple(constraints), tuple(utilities))


@dataclass(frozen=True, slots=True)
class Explorer:
    """One exploring robot as :func:`solve_team` sees it.

    Attributes:
        name: the robot.
        position: where it is.
        target: the frontier it drives to (``Targets(name, target)``), if any.
        frontiers: the frontiers it may be given (its variable's domain).
    """

    name: str
    position: tuple[float, float]
    target: str | None
    frontiers: tuple[str, ...]


def solve_team(
    explorers: Sequence[Explorer],
    candidates: Sequence[FrontierCandidate],
    constraints: Sequence[Term],
    utilities: Sequence[Term],
    *,
    time_limit: float,
) -> dict[str, str]:
    """The team's joint assignment, robot -> frontier name (empty: no solution), without an engine.

    What the engine solves for the Explore plan, for a caller without one
    (the bench, the tests): the facts ``Pos`` and ``gain`` of every candidate,
    ``Pos`` and ``Targets`` of every explorer, the explorers listed as
    :data:`EXPLORERS`, one variable ``frontier`` per explorer over its
    ``frontiers``. An explorer with no frontier to choose from is left out.
    The solver's time limit is wall-clock seconds; a search that finishes
    within it (a few robots, tens of frontiers) gives the same answer every time.
    """
    from alica.lang import FactBase
    from alica.solver import Finite, Problem, Var, solve

    world = FactBase()
    for c in candidates:
        world.set("Pos", c.name, value=c.position)
        world.set("gain", c.name, value=c.gain)
    variables = []
    for e in explorers:
        if not e.frontiers:
            continue
        world.set("Pos", e.name, value=e.position)
        if e.target is not None:
            world.set(TARGETS, e.name, e.target, value=True)
        world.add_object(e.name, EXPLORERS)
        variables.append(Var("frontier", e.name, Finite(tuple(e.frontiers))))
    if not variables:
        return {}
    problem = Problem(
        variables=tuple(variables), constraints=tuple(constraints), utilities=tuple(utilities), belief=world
    )
    solution = solve(problem, time_limit=time_limit)
    if solution.status != "solved":
        return {}
    return {
        var.agent: value for var, value in solution.values.items() if var.agent is not None and isinstance(value, str)
    }


def proposal_of(team: Mapping[str, Mapping[str, object]], variable: str = "frontier") -> dict[str, str]:
    """Robot -> frontier name of a team solution given as robot -> {variable: value} (``SolveResult.team``)."""
    out: dict[str, str] = {}
    for robot, values in team.items():
        value = values.get(variable)
        if robot and isinstance(value, str):
            out[robot] = value
    return out


def decide(
    robot: str,
    here: tuple[float, float],
    current: FrontierCandidate | None,
    candidates: Mapping[str, FrontierCandidate],
    usable: Container[str],
    proposal: Mapping[str, str],
    heading: Mapping[str, tuple[float, float]],
    *,
    spacing: float,
    others_follow: bool = True,
) -> Choice:
    """The frontier ``robot`` drives to now.

    Args:
        robot: the robot's name.
        here: where it is (its pose estimate).
        current: the frontier it drives to, if any.
        candidates: the frontiers known now, by name.
        usable: the names among them this robot may drive to (not reached, not unreachable).
        proposal: the team's solution, robot -> frontier name (empty: none).
        heading: where the other robots drive to, robot -> position (``heading(robot)``).
        spacing: metres a robot's frontier keeps from the others' (eps1 of Eq. 7).
        others_follow: whether the other robots follow the proposal too (they reassign
            periodically); when not, a frontier within ``spacing`` of another robot's heading is
            never taken.

    A robot whose frontier is still a usable candidate keeps it unless the
    proposal moves it (the plan's KeepFrontier bonus is the hysteresis); one
    without a usable frontier takes the proposal's. Either way the proposed
    frontier must lie more than ``spacing`` from where another robot heads,
    unless the proposal sends that robot away from there too (a swap). With no
    usable proposal a robot without a frontier takes the best by gain over
    (1 + distance) more than ``spacing`` from the others' headings (any usable
    one if none is), as ExploreFrontier always did. Deterministic: ties go to the
    larger name.
    """
    others = {name: pos for name, pos in heading.items() if name != robot}
    mine = proposal.get(robot)
    offered = candidates.get(mine) if mine is not None and mine in usable else None

    def clear(cand: FrontierCandidate) -> bool:
        for other, pos in others.items():
            if math.dist(cand.position, pos) > spacing:
                continue
            theirs = candidates.get(proposal.get(other, "")) if others_follow else None
            if theirs is None or math.dist(theirs.position, cand.position) <= spacing:
                return False  # it stays there
        return True

    if current is not None and current.name in candidates and current.name in usable:
        if offered is not None and offered.name != current.name and clear(offered):
            return Choice(offered, How.SWITCHED)
        return Choice(current, How.KEPT)
    if offered is not None and clear(offered):
        return Choice(offered, How.SOLVED)
    pool = [candidates[name] for name in sorted(candidates) if name in usable]
    if not pool:
        return Choice(None, How.NONE)
    apart = [c for c in pool if all(math.dist(c.position, pos) > spacing for pos in others.values())]
    best = max(apart or pool, key=lambda c: (c.gain / (1.0 + math.dist(here, c.position)), c.name))
    return Choice(best, How.FALLBACK)
