"""A fast simulator of the ProTaP domain: a grounded model of one :class:`ProblemSpec`.

The state is compact (:class:`State`: each robot's cell index and a bit mask
of the goals done); an action of a robot is an integer code:

* ``0`` (:data:`NOOP`): nothing;
* ``1 .. cells``: ``goto`` the cell with index ``code - 1`` (any cell of the
  grid but the robot's own, as in the domain: ``goto`` takes any cell and
  costs the Euclidean distance);
* ``cells + 1 .. cells + actions``: ``do`` the action ``code - cells - 1``.

A joint action (:data:`JointAction`) has one code per robot, so the domain's
limit of one action per robot holds by construction; :meth:`ProtapModel.violations`
checks an arbitrary set of true action fluents against every limit of the domain.
The transitions and the reward are those of ``domain.rddl``: a goto succeeds
with the robot's ``PROB_GOTO`` (else the robot stays), a ``do`` completes
the open goals of that action at the robot's current cell, and the reward of
a step is the utility of the goals done at its start minus the costs of its
actions.

>>> from alica.prophet.protap.generate import appendix_c_spec
>>> model = ProtapModel(appendix_c_spec())
>>> state = model.initial
>>> model.cell_of(state, 0)
(3, 0)
>>> next_state, reward = model.step(state, (model.goto((3, 1)), NOOP), random.Random(0))
>>> reward
-1.0
"""

from __future__ import annotations

import random
from collections.abc import Iterable
from typing import NamedTuple

from alica.prophet.protap.spec import Cell, ProblemSpec

NOOP = 0
JointAction = tuple[int, ...]


class State(NamedTuple):
    """A state: ``cells[r]`` is robot ``r``'s cell index, bit ``g`` of ``done`` says goal ``g`` is done.

    A named tuple rather than a dataclass: the simulator makes one per step
    and a tuple is several times cheaper to build; it is immutable all the same.
    """

    cells: tuple[int, ...]
    done: int


class ProtapModel:
    """The grounded ProTaP domain for one spec: actions, transitions, reward and limits.

    Args:
        spec: the problem.

    Attributes:
        spec: the problem.
        n_cells: the number of grid cells.
        initial: the initial state (the robots' start cells, no goal done).
    """

    __slots__ = (
        "_available",
        "_do_cost",
        "_goal_mask",
        "_goto_cost",
        "_prob",
        "_utility",
        "initial",
        "n_cells",
        "spec",
    )

    def __init__(self, spec: ProblemSpec) -> None:
        self.spec = spec
        self.n_cells = spec.width * spec.height
        cells = [self.cell(index) for index in range(self.n_cells)]
        self._goto_cost = [[spec.goto_cost(a, b) for b in cells] for a in cells]
        self._do_cost = [list(row) for row in spec.do_costs]
        self._prob = [robot.prob_goto for robot in spec.robots]
        self._goal_mask = [[0] * len(spec.actions) for _ in cells]
        for g, goal in enumerate(spec.goals):
            self._goal_mask[self.index(goal.cell)][spec.action_index(goal.action)] |= 1 << g
        utilities = [goal.utility for goal in spec.goals]
        self._utility: list[float] | None = None
        if len(utilities) <= 16:
            self._utility = [self._sum_utility(mask) for mask in range(1 << len(utilities))]
        do_codes = tuple(range(self.n_cells + 1, self.n_cells + 1 + len(spec.actions)))
        self._available = [
            (NOOP, *(1 + other for other in range(self.n_cells) if other != here), *do_codes)
            for here in range(self.n_cells)
        ]
        self.initial = State(tuple(self.index(robot.cell) for robot in spec.robots), 0)

    # -- cells and codes -------------------------------------------------
    def index(self, cell: Cell) -> int:
        """The index of ``cell`` (``y * width + x``)."""
        return cell[1] * self.spec.width + cell[0]

    def cell(self, index: int) -> Cell:
        """The cell ``(x, y)`` of a cell index."""
        return (index % self.spec.width, index // self.spec.width)

    def cell_of(self, state: State, robot: int) -> Cell:
        """The cell robot ``robot`` stands in."""
        return self.cell(state.cells[robot])

    def goto(self, cell: Cell) -> int:
        """The action code of ``goto`` to ``cell``."""
        return 1 + self.index(cell)

    def do(self, action: int | str) -> int:
        """The action code of ``do`` with an action given by position or name."""
        position = action if isinstance(action, int) else self.spec.action_index(action)
        return self.n_cells + 1 + position

    def describe(self, robot: int, code: int) -> str:
        """The action fluent of a code in RDDL notation, e.g. ``goto(r1, x4, y2)``; ``noop`` for 0."""
        name = self.spec.robots[robot].name
        if code == NOOP:
            return "noop"
        if code <= self.n_cells:
            x, y = self.cell(code - 1)
            return f"goto({name}, {self.spec.x_names[x]}, {self.spec.y_names[y]})"
        return f"do({name}, {self.spec.actions[code - self.n_cells - 1].name})"

    def is_done(self, state: State, goal: int) -> bool:
        """Whether goal number ``goal`` is done in ``state``."""
        return bool(state.done >> goal & 1)

    def available(self, state: State, robot: int) -> tuple[int, ...]:
        """The codes robot ``robot`` may take in ``state``: no-op, goto any other cell, do any action."""
        return self._available[state.cells[robot]]

    # -- dynamics ----------------------------------------------------------
    def _sum_utility(self, mask: int) -> float:
        return sum(goal.utility for g, goal in enumerate(self.spec.goals) if mask >> g & 1)

    def utility(self, state: State) -> float:
        """The first term of the reward: the utility of the goals done in ``state``."""
        table = self._utility
        return table[state.done] if table is not None else self._sum_utility(state.done)

    def reward(self, state: State, joint: JointAction) -> float:
        """The RDDL reward of taking ``joint`` in ``state``.

        Returns:
            The utility of the goals done in ``state``, minus ``DO_COST`` of
            every ``do``, minus ``GOTO_COST`` from the robot's cell to the
            target of every ``goto``.
        """
        cost = 0.0
        n_cells = self.n_cells
        for robot, code in enumerate(joint):
            if code == NOOP:
                continue
            if code <= n_cells:
                cost += self._goto_cost[state.cells[robot]][code - 1]
            else:
                cost += self._do_cost[robot][code - n_cells - 1]
        return self.utility(state) - cost

    def step(self, state: State, joint: JointAction, rng: random.Random) -> tuple[State, float]:
        """Sample the next state of taking ``joint`` in ``state``, and the step's reward.

        Args:
            state: the current state.
            joint: one action code per robot (within the limits; see :meth:`violations`).
            rng: the source of the gotos' outcomes (one draw per goto).

        Returns:
            The next state and the reward (:meth:`reward`).
        """
        cells = list(state.cells)
        done = state.done
        cost = 0.0
        n_cells = self.n_cells
        for robot, code in enumerate(joint):
            if code == NOOP:
                continue
            here = state.cells[robot]
            if code <= n_cells:
                cost += self._goto_cost[here][code - 1]
                if rng.random() < self._prob[robot]:
                    cells[robot] = code - 1
            else:
                action = code - n_cells - 1
                cost += self._do_cost[robot][action]
                done |= self._goal_mask[here][action]
        table = self._utility
        utility = table[state.done] if table is not None else self._sum_utility(state.done)
        return State(tuple(cells), done), utility - cost

    # -- limits ------------------------------------------------------------
    def violations(self, state: State, actions: Iterable[tuple[int, int]]) -> list[str]:
        """Every limit of the domain that a set of true action fluents breaks in ``state``.

        Args:
            state: the state the actions are taken in.
            actions: ``(robot, code)`` pairs, one per action fluent set true
                (no-ops are ignored, a pair given twice is one fluent).

        Returns:
            One message per broken limit: an unknown robot or code, a robot
            with more than one action (the action precondition), a goto to
            the robot's own cell, more true action fluents than
            ``max-nondef-actions``; empty when the actions are allowed.
        """
        out: list[str] = []
        fluents = sorted({pair for pair in actions if pair[1] != NOOP})
        last = self.n_cells + len(self.spec.actions)
        per_robot: dict[int, int] = {}
        for robot, code in fluents:
            if not 0 <= robot < len(self.spec.robots) or not 0 < code <= last:
                out.append(f"unknown action {code} of robot {robot}")
                continue
            per_robot[robot] = per_robot.get(robot, 0) + 1
            if code <= self.n_cells and code - 1 == state.cells[robot]:
                out.append(f"{self.describe(robot, code)}: goto to the robot's own cell")
        out.extend(
            f"robot {self.spec.robots[robot].name} takes {count} actions (at most 1)"
            for robot, count in sorted(per_robot.items())
            if count > 1
        )
        if len(fluents) > self.spec.max_nondef_actions:
            out.append(f"{len(fluents)} actions exceed max-nondef-actions = {self.spec.max_nondef_actions}")
        return out

    def pairs(self, joint: JointAction) -> list[tuple[int, int]]:
        """The ``(robot, code)`` pairs of the actions a joint action sets true (no-ops left out)."""
        return [(robot, code) for robot, code in enumerate(joint) if code != NOOP]
