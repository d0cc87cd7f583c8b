"""The value objects of a ProTaP problem: robots, actions, goals and the :class:`ProblemSpec`.

A spec holds everything Algorithm 2 of the ProTaP paper writes into an RDDL
instance of the domain ``multi_ros_robot_mdp``. Cells are 0-based ``(x, y)``
pairs; in RDDL the column ``x`` is the object ``x{x+1}`` and the row ``y`` the
object ``y{y+1}``, as in the paper.

>>> spec = ProblemSpec(
...     robots=(Robot("r1", (0, 0)),), actions=(Action("a1"),),
...     goals=(Goal("g1", "a1", (1, 1)),), width=2, height=2)
>>> spec.goto_cost((0, 0), (1, 1))
1.41
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

Cell = tuple[int, int]

DOMAIN_NAME = "multi_ros_robot_mdp"
MANIPULATION = "manipulation"
USER_DEFINED = "uda"

# The words an RDDL reader takes as keywords (pyRDDLGym's lexer and the RDDL
# 2.0 language), aggregations and built-in functions, and the names the domain
# itself uses; a name clashing with any of them (in any letter case) is refused.
_RESERVED = frozenset(
    word.lower()
    for word in """
    domain instance horizon discount objects init-state requirements state-action-constraints
    action-preconditions termination state-invariants types object bool int real neg-inf pos-inf
    pvariables non-fluent non-fluents state-fluent interm-fluent derived-fluent observ-fluent
    action-fluent param-fluent level default max-nondef-actions terminate-when terminal cpfs cdfs
    policy reward forall exists argmax argmin sum prod avg minimum maximum true false if then else
    switch case otherwise KronDelta DiracDelta Uniform Bernoulli Discrete UnnormDiscrete Normal
    Poisson Exponential Weibull Gamma Binomial NegativeBinomial Beta Geometric Pareto Student Gumbel
    Laplace Cauchy Gompertz ChiSquare Kumaraswamy MultivariateNormal MultivariateStudent Dirichlet
    Multinomial det inverse pinverse cholesky row col abs sgn round floor ceil cos sin tan acos asin
    atan cosh sinh tanh exp ln sqrt pow log div mod min max fmod hypot gamma lngamma
    robot action xPos yPos goal PROB_GOTO GOTO_COST DO_COST GOAL_UTILITY GOAL gotoOk robotAt done
    goto do
    """.split()
)
# Letters and digits, single inner underscores: pyRDDLGym grounds names with
# "__" and "___" as separators, so object names never contain them.
_OBJECT_NAME = re.compile(r"[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)*")
_INSTANCE_NAME = re.compile(r"[A-Za-z](?:[A-Za-z0-9_]*[A-Za-z0-9])?")


def is_object_name(name: str) -> bool:
    """Whether ``name`` is a valid RDDL object name that is no keyword.

    Args:
        name: the candidate name.

    Returns:
        True for a letter followed by letters, digits and single inner
        underscores, clashing with no RDDL keyword nor a name of the domain.
    """
    return _OBJECT_NAME.fullmatch(name) is not None and name.lower() not in _RESERVED


def is_instance_name(name: str) -> bool:
    """Whether ``name`` is a valid RDDL identifier for an instance or non-fluents block."""
    return _INSTANCE_NAME.fullmatch(name) is not None and name.lower() not in _RESERVED


def rddl_name(text: str, prefix: str = "o") -> str:
    """A valid object name made from free text (a world model's name, say).

    Args:
        text: any text, e.g. ``"Rock 3"`` or ``"scout-1"``.
        prefix: put before a name that would not start with a letter or
            would be a keyword.

    Returns:
        ``text`` with every run of other characters turned into one ``_``,
        e.g. ``"Rock_3"``, ``"scout_1"``; ``prefix`` + ``_`` + that when needed.
    """
    name = "_".join(part for part in re.split(r"[^A-Za-z0-9]+", text) if part)
    if not name or not name[0].isalpha() or name.lower() in _RESERVED:
        name = f"{prefix}_{name}" if name else prefix
    return name


@dataclass(frozen=True, slots=True)
class Robot:
    """A robot, its start cell and the probability that one of its gotos succeeds."""

    name: str
    cell: Cell
    prob_goto: float = 0.9


@dataclass(frozen=True, slots=True)
class Action:
    """An action object for ``do``: a manipulation action or a user-defined action (``uda``).

    The domain treats both alike; ``kind`` tells an executor where to send it
    (Algorithm 1: MoveIt! for manipulation, a user service for ``uda``).
    """

    name: str
    kind: str = MANIPULATION


@dataclass(frozen=True, slots=True)
class Goal:
    """A goal: do ``action`` at ``cell``; ``utility`` is paid on every step after it is done."""

    name: str
    action: str
    cell: Cell
    utility: float = 100.0


@dataclass(frozen=True, slots=True)
class ProblemSpec:
    """One ProTaP problem: the objects, the non-fluents and the instance's settings.

    Attributes:
        robots: the robots with their start cells and goto success probabilities.
        actions: the action objects (``do`` targets).
        goals: the goals.
        width: the number of columns (``xPos`` objects).
        height: the number of rows (``yPos`` objects).
        do_costs: ``DO_COST``, one row per robot, one column per action.
        goto_unit: ``GOTO_COST`` is this times the Euclidean distance, rounded
            to hundredths as in the paper.
        costs: ``GOTO_COST`` given outright instead, ``costs[a][b]`` from the
            cell of index ``a`` to that of ``b`` (index ``y * width + x``): the
            distances between a team's places in metres, say, when the cells
            are places rather than a grid (``()``: from ``goto_unit``).
        max_nondef_actions: the concurrency bound, by default 2 x the number
            of robots (each robot takes at most one goto and one do per step).
        horizon: the number of steps.
        discount: the discount factor.
        name: the instance name; the non-fluents block is ``nf_`` + name.
    """

    robots: tuple[Robot, ...]
    actions: tuple[Action, ...]
    goals: tuple[Goal, ...]
    width: int
    height: int
    do_costs: tuple[tuple[float, ...], ...] = ()
    goto_unit: float = 1.0
    costs: tuple[tuple[float, ...], ...] = ()
    max_nondef_actions: int = 0
    horizon: int = 10
    discount: float = 1.0
    name: str = "multi_ros_robot_inst_mdp__1"

    def __post_init__(self) -> None:
        if not self.do_costs:
            object.__setattr__(self, "do_costs", tuple(tuple(1.0 for _ in self.actions) for _ in self.robots))
        if self.max_nondef_actions == 0:
            object.__setattr__(self, "max_nondef_actions", 2 * len(self.robots))
        problems = self.problems()
        if problems:
            raise ValueError("invalid ProTaP problem: " + "; ".join(problems))

    def problems(self) -> list[str]:
        """Every reason this spec is invalid (none for a constructed spec)."""
        out: list[str] = []
        if self.width < 1 or self.height < 1:
            out.append(f"grid {self.width}x{self.height} is empty")
        if not self.robots:
            out.append("no robots")
        if not self.actions:
            out.append("no actions")
        if not self.goals:
            out.append("no goals (RDDL wants an object of every type)")
        names = self.object_names()
        out.extend(f"{name!r} is no valid RDDL object name" for name in names if not is_object_name(name))
        seen: set[str] = set()
        for name in names:
            if name in seen:
                out.append(f"object name {name!r} used twice")
            seen.add(name)
        if not is_instance_name(self.name) or not is_instance_name("nf_" + self.name):
            out.append(f"{self.name!r} is no valid RDDL instance name")
        action_names = {action.name for action in self.actions}
        out.extend(
            f"{action.name}: unknown kind {action.kind!r}"
            for action in self.actions
            if action.kind not in (MANIPULATION, USER_DEFINED)
        )
        for robot in self.robots:
            if not self.inside(robot.cell):
                out.append(f"robot {robot.name} at {robot.cell} is outside the grid")
            if not 0.0 <= robot.prob_goto <= 1.0:
                out.append(f"robot {robot.name}: goto probability {robot.prob_goto} is not in [0, 1]")
        for goal in self.goals:
            if not self.inside(goal.cell):
                out.append(f"goal {goal.name} at {goal.cell} is outside the grid")
            if goal.action not in action_names:
                out.append(f"goal {goal.name}: unknown action {goal.action!r}")
            if not math.isfinite(goal.utility):
                out.append(f"goal {goal.name}: utility {goal.utility} is not finite")
        if len(self.do_costs) != len(self.robots) or any(len(row) != len(self.actions) for row in self.do_costs):
            out.append("do_costs is not one row per robot and one column per action")
        elif not all(math.isfinite(cost) for row in self.do_costs for cost in row):
            out.append("do_costs holds a value that is not finite")
        if not (math.isfinite(self.goto_unit) and self.goto_unit >= 0):
            out.append(f"goto_unit {self.goto_unit} is not a finite number >= 0")
        cells = self.width * self.height
        if self.costs and (len(self.costs) != cells or any(len(row) != cells for row in self.costs)):
            out.append(f"costs is not one row and one column per cell ({cells})")
        elif not all(math.isfinite(cost) and cost >= 0 for row in self.costs for cost in row):
            out.append("costs holds a value that is negative or not finite")
        if self.max_nondef_actions < 1:
            out.append(f"max_nondef_actions {self.max_nondef_actions} < 1")
        if self.horizon < 1:
            out.append(f"horizon {self.horizon} < 1")
        if not 0.0 < self.discount <= 1.0:
            out.append(f"discount {self.discount} is not in (0, 1]")
        return out

    def inside(self, cell: Cell) -> bool:
        """Whether ``cell`` lies on the grid."""
        return 0 <= cell[0] < self.width and 0 <= cell[1] < self.height

    @property
    def x_names(self) -> tuple[str, ...]:
        """The ``xPos`` objects, ``x1`` to ``x{width}``."""
        return tuple(f"x{i + 1}" for i in range(self.width))

    @property
    def y_names(self) -> tuple[str, ...]:
        """The ``yPos`` objects, ``y1`` to ``y{height}``."""
        return tuple(f"y{i + 1}" for i in range(self.height))

    def object_names(self) -> list[str]:
        """Every object name of the instance, in the order of the objects block."""
        return [
            *(robot.name for robot in self.robots),
            *(action.name for action in self.actions),
            *self.x_names,
            *self.y_names,
            *(goal.name for goal in self.goals),
        ]

    def goto_cost(self, start: Cell, target: Cell) -> float:
        """``GOTO_COST``: from :attr:`costs` when given, else ``goto_unit`` times the Euclidean distance, rounded to hundredths."""
        if self.costs:
            return self.costs[start[1] * self.width + start[0]][target[1] * self.width + target[0]]
        return round(self.goto_unit * math.hypot(start[0] - target[0], start[1] - target[1]), 2)

    def action_index(self, name: str) -> int:
        """The position of the action called ``name``."""
        for index, action in enumerate(self.actions):
            if action.name == name:
                return index
        raise KeyError(name)
