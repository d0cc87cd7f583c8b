"""A team's planning problem read as a ProTaP problem: robots at places, a goto element, do elements.

A plan file's planning problem names ``planner: protap`` and lists skill
plans as its elements, as for the classical planners; the pipeline writes
them as PDDL (:func:`alica.prophet.pipeline.plan_problem`). This module reads
that PDDL as ProTaP's domain (:func:`read_places`):

* **the location predicate** ``P``: the binary predicate ``P(?r, ?s)`` ("robot
  at place") that the do elements require;
* **do elements** (ProTaP's ``do``/``uda`` actions): the elements with the
  parameters ``(?r - robot, ?s - place)`` whose precondition holds
  ``P(?r, ?s)``; one acts at the place where its robot stands;
* **the goto element** (ProTaP's ``goto``): the one element whose effect adds
  ``P(?r, ?to)``, with the parameters ``(?r, ?to)`` or ``(?r, ?from, ?to)``
  (then its precondition holds ``P(?r, ?from)``: the classical move);
* **places**: the objects of the places' type; a place's cell is a column of a
  one-row grid, and ``GOTO_COST`` between two places is their distance in
  metres when both positions are known (the world model's ``pos``), else 1;
* **goals**: each positive goal literal is the effect of a do element at a
  place (``sampled(s1)``: ``TakeSample`` at ``s1``), with utility
  :data:`GOAL_UTILITY`; literals that hold already are done;
* **robots** start at the place they are ``P`` at (the nearest one to their
  position when the facts name several); a robot at no place starts at a
  place of its own at its position (``<robot>_start``), which no goal uses.

:meth:`Places.steps` turns a joint action back into plan steps: per robot its
do (at the place it stands) and then its goto, so that a plan validates in
PDDL's sequential semantics exactly as ProTaP's step acts (a do acts where
the robot stood at the step's start).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from alica.errors import PlannerError
from alica.prophet.pddl.model import Action as PddlAction
from alica.prophet.pddl.model import Atom, Domain, Formula, Not, Problem, top_level_parts
from alica.prophet.planner import PlanStep
from alica.prophet.protap.model import NOOP, JointAction, ProtapModel, State
from alica.prophet.protap.spec import Action, Goal, ProblemSpec, Robot

#: The utility of every goal of a plan file's ProTaP problem (as ``random_spec`` gives).
GOAL_UTILITY = 100.0
#: The probability that a goto succeeds, for every robot of a plan file's ProTaP problem (the paper's 0.9).
PROB_GOTO = 0.9
#: The robot parameter of every element (the pipeline's ``?r``).
ROBOT = "?r"

Position = tuple[float, float]


def _atoms(formula: Formula | object) -> list[tuple[bool, Atom]]:
    """The literals of a conjunction (other parts, such as cost increases, are left out)."""
    out: list[tuple[bool, Atom]] = []
    for part in top_level_parts(formula):  # type: ignore[arg-type]
        if isinstance(part, Atom):
            out.append((True, part))
        elif isinstance(part, Not) and isinstance(part.formula, Atom):
            out.append((False, part.formula))
    return out


@dataclass(frozen=True, slots=True)
class Places:
    """A planning problem read as ProTaP (see the module docstring).

    Attributes:
        spec: the ProTaP problem (one cell per place, a one-row grid).
        robots: the PDDL robot objects, in the spec's order.
        places: the PDDL place objects, in cell order (robots' own start places last).
        goto: the goto element.
        goto_from: whether the goto element names the place it leaves (``(?r, ?from, ?to)``).
        dos: the do elements, in the spec's action order.
        state: the robots' cells now and the goals done already.
    """

    spec: ProblemSpec
    robots: tuple[str, ...]
    places: tuple[str, ...]
    goto: PddlAction
    goto_from: bool
    dos: tuple[PddlAction, ...]
    state: State

    def steps(self, model: ProtapModel, joint: JointAction) -> tuple[PlanStep, ...]:
        """The plan steps of a joint action: per robot its do, then its goto."""
        out: list[PlanStep] = []
        n_cells = model.n_cells
        for r, (goto, do) in enumerate(joint):
            robot, here = self.robots[r], self.places[self.state.cells[r]]
            if do != NOOP:
                out.append(PlanStep(self.dos[do - n_cells - 1].name, (robot, here)))
            if goto != NOOP:
                there = self.places[goto - 1]
                args = (robot, here, there) if self.goto_from else (robot, there)
                out.append(PlanStep(self.goto.name, args))
        return tuple(out)


def read_places(
    domain: Domain,
    problem: Problem,
    positions: Mapping[str, Sequence[float]] | None = None,
    *,
    horizon: int = 10,
) -> Places:
    """Read a pipeline's PDDL domain and problem as a ProTaP problem (see the module docstring).

    Args:
        domain: the PDDL domain of the planning problem's elements.
        problem: the PDDL problem of the world and the goal.
        positions: object name (any letter case) -> ``(x, y, ...)`` in metres, e.g. the world model's ``pos``.
        horizon: ProTaP's look-ahead in steps.

    Raises:
        PlannerError: the elements have no do or goto element of the forms above, a goal
            literal is no do element's effect, or a robot is at no place and has no position.
    """
    do_elements, predicate = _do_elements(domain)
    goto, goto_from = _goto_element(domain, predicate)
    place_type = goto.parameters[-1][1]
    robot_type = goto.parameters[0][1]
    robot_kinds, place_kinds = _below(domain, robot_type), _below(domain, place_type)
    robots = tuple(sorted(name for name, kind in problem.objects if kind in robot_kinds))
    if not robots:
        raise PlannerError(f"protap: the world has no robots (objects of type {robot_type})")
    places = [name for name, kind in problem.objects if kind in place_kinds and name not in robots]
    init = [atom for atom in problem.init if isinstance(atom, Atom)]
    located: dict[str, list[str]] = {}
    for atom in init:
        if atom.predicate == predicate and len(atom.args) == 2 and atom.args[1] in places:
            located.setdefault(atom.args[0], []).append(atom.args[1])
    where = {name.lower(): (float(p[0]), float(p[1])) for name, p in (positions or {}).items() if len(p) >= 2}
    starts: dict[str, str] = {}
    for robot in robots:
        options = sorted(located.get(robot, ()))
        if len(options) > 1 and robot in where:
            options.sort(key=lambda place: _distance(where.get(robot), where.get(place)))
        if options:
            starts[robot] = options[0]
        elif robot in where:
            starts[robot] = f"{robot}_start"
            where[starts[robot]] = where[robot]
            places.append(starts[robot])
        else:
            raise PlannerError(
                f"protap: robot {robot} is at no place ({predicate}({robot}, ...) holds for none) and its position "
                "is unknown: write where it is in the world model"
            )
    goals, done = _goals(problem, do_elements, places, init)
    if not goals:
        raise PlannerError("protap: the goal has no literal a do element achieves at a place")
    index = {place: i for i, place in enumerate(places)}
    order = [d.name for d in do_elements]
    used = sorted({action for action, _ in goals.values()}, key=order.index)
    costs = tuple(tuple(_cost(where.get(a), where.get(b), a == b) for b in places) for a in places)
    spec = ProblemSpec(
        robots=tuple(Robot(f"r{i + 1}", (index[starts[robot]], 0), PROB_GOTO) for i, robot in enumerate(robots)),
        actions=tuple(Action(f"a{i + 1}") for i in range(len(used))),
        goals=tuple(
            Goal(f"g{i + 1}", f"a{used.index(action) + 1}", (index[place], 0), GOAL_UTILITY)
            for i, (action, place) in enumerate(goals.values())
        ),
        width=len(places),
        height=1,
        costs=costs,
        horizon=horizon,
    )
    by_name = {d.name: d for d in do_elements}
    mask = sum(1 << g for g, key in enumerate(goals) if key in done)
    state = State(tuple(index[starts[robot]] for robot in robots), mask)
    return Places(spec, robots, tuple(places), goto, goto_from, tuple(by_name[a] for a in used), state)


def _distance(a: Position | None, b: Position | None) -> float:
    return math.inf if a is None or b is None else math.hypot(a[0] - b[0], a[1] - b[1])


def _cost(a: Position | None, b: Position | None, same: bool) -> float:
    if same:
        return 0.0
    distance = _distance(a, b)
    return round(distance, 2) if math.isfinite(distance) else 1.0


def _below(domain: Domain, kind: str) -> set[str]:
    """``kind`` and every type below it in the domain's type hierarchy."""
    out = {kind}
    changed = True
    while changed:
        changed = False
        for child, parents in domain.types.items():
            if child not in out and any(parent in out for parent in parents):
                out.add(child)
                changed = True
    return out


def _do_elements(domain: Domain) -> tuple[list[PddlAction], str]:
    """The do elements and the location predicate they require."""
    found: list[PddlAction] = []
    predicates: set[str] = set()
    for action in domain.actions:
        params = [name for name, _ in action.parameters]
        if len(params) != 2 or params[0] != ROBOT:
            continue
        place = params[1]
        needs = {
            atom.predicate for positive, atom in _atoms(action.precondition) if positive and atom.args == (ROBOT, place)
        }
        adds_location = any(
            positive and atom.args == (ROBOT, place) and atom.predicate in needs
            for positive, atom in _atoms(action.effect)
        )
        if needs and not adds_location:
            found.append(action)
            predicates |= needs
    if not found:
        raise PlannerError(
            "protap: no do element: a do element has the parameters (?r - robot, ?s - place) and its precondition "
            "holds the robot at the place, e.g. at(?r, ?s)"
        )
    if len(predicates) != 1:
        raise PlannerError(
            f"protap: the do elements require the robot at their place with different predicates "
            f"({', '.join(sorted(predicates))}); use one location predicate"
        )
    return found, predicates.pop()


def _goto_element(domain: Domain, predicate: str) -> tuple[PddlAction, bool]:
    """The one element whose effect puts its robot at a place, and whether it names the place it leaves."""
    found: list[tuple[PddlAction, bool]] = []
    for action in domain.actions:
        params = [name for name, _ in action.parameters]
        if len(params) not in (2, 3) or params[0] != ROBOT:
            continue
        target = params[-1]
        if not any(
            positive and a.predicate == predicate and a.args == (ROBOT, target) for positive, a in _atoms(action.effect)
        ):
            continue
        pre = _atoms(action.precondition)
        if len(params) == 3 and not any(
            p and a.predicate == predicate and a.args == (ROBOT, params[1]) for p, a in pre
        ):
            continue
        if any(p and a.predicate == predicate and a.args == (ROBOT, target) for p, a in pre):
            continue  # it needs the robot there already: not a goto
        found.append((action, len(params) == 3))
    if len(found) != 1:
        names = ", ".join(a.name for a, _ in found) or "none"
        raise PlannerError(
            f"protap: needs exactly one goto element, whose effect adds {predicate}(?r, ?to) with the parameters "
            f"(?r, ?to) or (?r, ?from, ?to); found {names}"
        )
    return found[0]


def _goals(
    problem: Problem, dos: Sequence[PddlAction], places: Sequence[str], init: Sequence[Atom]
) -> tuple[dict[tuple[str, str], tuple[str, str]], set[tuple[str, str]]]:
    """Goal literal key -> (do element, place) for each positive goal literal, and the keys that hold already."""
    holding = {(a.predicate, a.args) for a in init}
    goals: dict[tuple[str, str], tuple[str, str]] = {}
    done: set[tuple[str, str]] = set()
    for positive, atom in _atoms(problem.goal):
        if not positive:
            raise PlannerError(f"protap: the goal literal (not {atom}) is no effect a do element achieves")
        match = _achiever(atom, dos, places)
        if match is None:
            raise PlannerError(
                f"protap: no do element achieves the goal literal {atom} at a place (a do element's effect adds "
                "it with the place as argument)"
            )
        key = (atom.predicate, " ".join(atom.args))
        goals[key] = match
        if (atom.predicate, atom.args) in holding:
            done.add(key)
    return goals, done


def _achiever(atom: Atom, dos: Sequence[PddlAction], places: Sequence[str]) -> tuple[str, str] | None:
    """The first do element (and its place) whose effect adds ``atom``."""
    for action in dos:
        place_param = action.parameters[1][0]
        for positive, added in _atoms(action.effect):
            if not positive or added.predicate != atom.predicate or len(added.args) != len(atom.args):
                continue
            if ROBOT in added.args:
                continue  # a fact about the robot is no goal of the team's places
            binding: dict[str, str] = {}
            if all(
                (binding.setdefault(p, a) == a) if p.startswith("?") else p == a
                for p, a in zip(added.args, atom.args, strict=True)
            ):
                place = binding.get(place_param)
                if place is not None and place in places:
                    return action.name, place
    return None
