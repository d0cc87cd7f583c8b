"""A fast simulator of the ProTaP domain: a grounded model of one :class:`ProblemSpec`.

The state is compact (:class:`State`: each robot's cell index and a bit mask
of the goals done). An action fluent is an integer code:

* ``0`` (:data:`NOOP`): none;
* ``1 .. cells``: ``goto`` the cell with index ``code - 1`` (any cell of the
  grid but the robot's own, as in the domain: ``goto`` takes any cell and
  costs the Euclidean distance);
* ``cells + 1 .. cells + actions``: ``do`` the action ``code - cells - 1``.

Per step a robot takes at most one goto and at most one do, so its action
(:data:`RobotAction`) is a pair ``(goto code or NOOP, do code or NOOP)``
(:meth:`ProtapModel.act` builds one, :data:`IDLE` is ``(NOOP, NOOP)``), and a
joint action (:data:`JointAction`) has one pair per robot: the domain's
per-robot limits hold by construction, and so does ``max-nondef-actions``
at its default of 2 x the number of robots. :meth:`ProtapModel.violations` checks an arbitrary set of true
action fluents against every limit of the domain.

The transitions and the reward are those of ``domain.rddl``: a goto succeeds
with the robot's ``PROB_GOTO`` (else the robot stays), a ``do`` completes
the open goals of that action at the cell the robot stands in at the start
of the step (also when the same step's goto moves it away), and the reward
of a step is the utility of the goals done at its start minus the costs of
its actions.

>>> from alica.prophet.protap.generate import appendix_c_spec
>>> model = ProtapModel(appendix_c_spec())
>>> state = model.initial
>>> model.cell_of(state, 0)
(3, 0)
>>> next_state, reward = model.step(state, (model.act(goto=(3, 1)), IDLE), random.Random(0))
>>> reward
-1.0
>>> model.cell_of(next_state, 0)
(3, 1)
>>> done_state, reward = model.step(next_state, (model.act(goto=(2, 3), do="a2"), IDLE), random.Random(0))
>>> model.is_done(done_state, 0), model.cell_of(done_state, 0), reward
(True, (2, 3), -3.24)
"""

from __future__ import annotations

import random
from collections.abc import Iterable
from typing import NamedTuple

from alica.prophet.protap.spec import Cell, ProblemSpec

NOOP = 0
RobotAction = tuple[int, int]
JointAction = tuple[RobotAction, ...]
IDLE: RobotAction = (NOOP, NOOP)


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
        goto_cost: ``goto_cost[a][b]``, the ``GOTO_COST`` from cell index ``a`` to ``b`` (read only).
        goal_mask: ``goal_mask[cell][action]``, the bit mask of the goals a ``do`` of that
            action (by position) completes at that cell index (read only).
    """

    __slots__ = (
        "_available",
        "_do_choices",
        "_do_cost",
        "_goto_choices",
        "_prob",
        "_utility",
        "goal_mask",
        "goto_cost",
        "initial",
        "n_cells",
        "spec",
    )

    def __init__(self, spec: ProblemSpec) -> None:
        self.spec = spec
        self.n_cells = spec.width * spec.height
        cells = [self.cell(index) for index in range(self.n_cells)]
        self.goto_cost = [[spec.goto_cost(a, b) for b in cells] for a in cells]
        self._do_cost = [list(row) for row in spec.do_costs]
        self._prob = [robot.prob_goto for robot in spec.robots]
        self.goal_mask = [[0] * len(spec.actions) for _ in cells]
        for g, goal in enumerate(spec.goals):
            self.goal_mask[self.index(goal.cell)][spec.action_index(goal.action)] |= 1 << g
        utilities = [goal.utility for goal in spec.goals]
        self._utility: list[float] | None = None
        if len(utilities) <= 16:
            self._utility = [self._sum_utility(mask) for mask in range(1 << len(utilities))]
        self._do_choices = (NOOP, *range(self.n_cells + 1, self.n_cells + 1 + len(spec.actions)))
        self._goto_choices = [
            (NOOP, *(1 + other for other in range(self.n_cells) if other != here)) for here in range(self.n_cells)
        ]
        self._available: dict[int, tuple[RobotAction, ...]] = {}
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
        """The code of the fluent ``goto`` to ``cell``."""
        return 1 + self.index(cell)

    def do(self, action: int | str) -> int:
        """The code of the fluent ``do`` with an action given by position or name."""
        position = action if isinstance(action, int) else self.spec.action_index(action)
        return self.n_cells + 1 + position

    def act(self, goto: Cell | None = None, do: int | str | None = None) -> RobotAction:
        """A robot's action: ``goto`` to a cell, ``do`` an action (by position or name), both, or neither.

        >>> from alica.prophet.protap.generate import appendix_c_spec
        >>> model = ProtapModel(appendix_c_spec())
        >>> model.act(goto=(3, 1), do="a2"), model.act(do="a1"), model.act()
        ((9, 27), (0, 26), (0, 0))
        """
        return (NOOP if goto is None else self.goto(goto), NOOP if do is None else self.do(do))

    def is_goto(self, code: int) -> bool:
        """Whether ``code`` is the code of a ``goto`` fluent."""
        return 0 < code <= self.n_cells

    def is_do(self, code: int) -> bool:
        """Whether ``code`` is the code of a ``do`` fluent."""
        return self.n_cells < code <= self.n_cells + len(self.spec.actions)

    def describe(self, robot: int, code: int) -> str:
        """The action fluent of a code in RDDL notation, e.g. ``goto(r1, x4, y2)``; ``noop`` for 0."""
        name = self.spec.robots[robot].name
        if code == NOOP:
            return "noop"
        if code <= self.n_cells:
            x, y = self.cell(code - 1)
            return f"goto({name}, {self.spec.x_names[x]}, {self.spec.y_names[y]})"
        return f"do({name}, {self.spec.actions[code - self.n_cells - 1].name})"

    def describe_action(self, robot: int, action: RobotAction) -> str:
        """A robot's action in RDDL notation, e.g. ``goto(r1, x3, y4) + do(r1, a2)``; ``noop`` for :data:`IDLE`."""
        parts = [self.describe(robot, code) for code in action if code != NOOP]
        return " + ".join(parts) if parts else "noop"

    def is_done(self, state: State, goal: int) -> bool:
        """Whether goal number ``goal`` is done in ``state``."""
        return bool(state.done >> goal & 1)

    def goto_choices(self, state: State, robot: int) -> tuple[int, ...]:
        """The goto codes robot ``robot`` may take in ``state``: ``NOOP`` first, then goto any other cell."""
        return self._goto_choices[state.cells[robot]]

    def do_choices(self) -> tuple[int, ...]:
        """The do codes every robot may take: ``NOOP`` first, then do any action."""
        return self._do_choices

    def available(self, state: State, robot: int) -> tuple[RobotAction, ...]:
        """The actions robot ``robot`` may take in ``state``: every pair of a goto choice and a do choice.

        :data:`IDLE` comes first; ``cells * (actions + 1)`` pairs in all (no
        goto or one of the ``cells - 1`` other cells, times no do or one of the
        actions), made once per cell and then shared.
        """
        here = state.cells[robot]
        pairs = self._available.get(here)
        if pairs is None:
            pairs = tuple((goto, do) for goto in self._goto_choices[here] for do in self._do_choices)
            self._available[here] = pairs
        return pairs

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
        offset = self.n_cells + 1
        for robot, (goto, do) in enumerate(joint):
            if goto:
                cost += self.goto_cost[state.cells[robot]][goto - 1]
            if do:
                cost += self._do_cost[robot][do - offset]
        return self.utility(state) - cost

    def step(self, state: State, joint: JointAction, rng: random.Random) -> tuple[State, float]:
        """Sample the next state of taking ``joint`` in ``state``, and the step's reward.

        A robot's ``do`` acts at the cell it stands in in ``state``, also when
        its ``goto`` of the same step moves it (as ``done'`` reads ``robotAt``).

        Args:
            state: the current state.
            joint: one ``(goto code or NOOP, do code or NOOP)`` pair per robot
                (within the limits; see :meth:`violations` and :meth:`fluents`).
            rng: the source of the gotos' outcomes (one draw per goto, in robot order).

        Returns:
            The next state and the reward (:meth:`reward`).
        """
        old = state.cells
        cells = list(old)
        done = state.done
        cost = 0.0
        offset = self.n_cells + 1
        goto_cost, do_cost, goal_mask, prob = self.goto_cost, self._do_cost, self.goal_mask, self._prob
        for robot, (goto, do) in enumerate(joint):
            if goto:
                cost += goto_cost[old[robot]][goto - 1]
                if rng.random() < prob[robot]:
                    cells[robot] = goto - 1
            if do:
                action = do - offset
                cost += do_cost[robot][action]
                done |= goal_mask[old[robot]][action]
        return State(tuple(cells), done), self.utility(state) - cost

    # -- limits ------------------------------------------------------------
    def violations(self, state: State, actions: Iterable[tuple[int, int]]) -> list[str]:
        """Every limit of the domain that a set of true action fluents breaks in ``state``.

        Args:
            state: the state the actions are taken in.
            actions: ``(robot, code)`` pairs, one per action fluent set true
                (no-ops are ignored, a pair given twice is one fluent); a joint
                action's are :meth:`fluents`.

        Returns:
            One message per broken limit: an unknown robot or code, a robot
            with more than one goto or more than one do (the action
            preconditions), a goto to the robot's own cell, more true action
            fluents than ``max-nondef-actions``; empty when the actions are allowed.
        """
        out: list[str] = []
        fluents = sorted({pair for pair in actions if pair[1] != NOOP})
        last = self.n_cells + len(self.spec.actions)
        gotos: dict[int, int] = {}
        dos: dict[int, int] = {}
        for robot, code in fluents:
            if not 0 <= robot < len(self.spec.robots) or not 0 < code <= last:
                out.append(f"unknown action {code} of robot {robot}")
                continue
            if code <= self.n_cells:
                gotos[robot] = gotos.get(robot, 0) + 1
                if code - 1 == state.cells[robot]:
                    out.append(f"{self.describe(robot, code)}: goto to the robot's own cell")
            else:
                dos[robot] = dos.get(robot, 0) + 1
        for kind, counts in (("gotos", gotos), ("dos", dos)):
            out.extend(
                f"robot {self.spec.robots[robot].name} takes {count} {kind} (at most 1)"
                for robot, count in sorted(counts.items())
                if count > 1
            )
        if len(fluents) > self.spec.max_nondef_actions:
            out.append(f"{len(fluents)} actions exceed max-nondef-actions = {self.spec.max_nondef_actions}")
        return out

    def fluents(self, joint: JointAction) -> list[tuple[int, int]]:
        """The ``(robot, code)`` pairs of the action fluents a joint action sets true (no-ops left out).

        Raises:
            ValueError: for a robot action whose first code is no goto or whose
                second is no do (:meth:`step` would misread it).
        """
        out: list[tuple[int, int]] = []
        for robot, (goto, do) in enumerate(joint):
            if (goto != NOOP and not self.is_goto(goto)) or (do != NOOP and not self.is_do(do)):
                raise ValueError(f"robot {robot}: ({goto}, {do}) is not (goto code or NOOP, do code or NOOP)")
            out.extend((robot, code) for code in (goto, do) if code != NOOP)
        return out
