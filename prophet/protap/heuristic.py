"""The planner's value estimate: a greedy policy rolled out in the most-likely-outcome determinisation.

In the spirit of PROST's IDS heuristic, new search nodes are valued on a
deterministic copy of the model: every goto has its most likely outcome (it
succeeds when the robot's ``PROB_GOTO`` is at least 0.5, else it fails), and
the remaining steps are played by a fast "do, then go" policy
(:meth:`Determinisation.complete`): a robot standing at an open goal does it,
and the robots are matched greedily (closest pair first) to the open goals
nobody takes yet and set off to them in the same step. The values are
finite-horizon (the number of steps to go is part of the key) and cached.

:meth:`Determinisation.complete` also completes a partly chosen joint action,
which is how the planner initialises the choices of a decision node.

>>> from alica.prophet.protap.generate import appendix_c_spec
>>> from alica.prophet.protap.model import ProtapModel
>>> model = ProtapModel(appendix_c_spec())
>>> det = Determinisation(model)
>>> det.value(model.initial, 10) > 2200
True
"""

from __future__ import annotations

from array import array

from alica.prophet.protap.model import NOOP, JointAction, ProtapModel, State


def cache_key(state: State, steps: int, joint: JointAction = ()) -> bytes:
    """A state, the steps to go and optionally a joint action as one byte string, for the search's caches.

    Bytes rather than a tuple: a dict whose keys and values hold no references
    is never tracked by the cyclic garbage collector, so the caches (hundreds of
    thousands of entries on a large team) add nothing to its full collections,
    which would otherwise stall the search for a tenth of a second now and then.
    """
    codes = array("i", state.cells)
    codes.append(steps)
    for goto, do in joint:
        codes.append(goto)
        codes.append(do)
    done = state.done
    return codes.tobytes() + done.to_bytes((done.bit_length() + 7) // 8, "little")


class Determinisation:
    """The most-likely-outcome determinisation of a model, its "do, then go" policy and a cached value.

    Args:
        model: the simulator.

    Attributes:
        model: the simulator.
        bound: the spec's ``max-nondef-actions``; :meth:`complete` never sets more fluents true.
        goal_do: per goal, the code of the ``do`` that completes it.
    """

    def __init__(self, model: ProtapModel) -> None:
        self.model = model
        spec = model.spec
        self.bound = spec.max_nondef_actions
        self._robots = len(spec.robots)
        self._success = [robot.prob_goto >= 0.5 for robot in spec.robots]
        self._offset = model.n_cells + 1
        self._goal_cell = [model.index(goal.cell) for goal in spec.goals]
        self.goal_do = [model.do(goal.action) for goal in spec.goals]
        self._all = (1 << len(spec.goals)) - 1
        self._cell_goals = [0] * model.n_cells
        for g, cell in enumerate(self._goal_cell):
            self._cell_goals[cell] |= 1 << g
        self._done_by = model.goal_mask  # the goals a do completes: _done_by[cell][code - offset]
        self._dist = model.goto_cost
        # matching keys: the distance in hundredths, then the robot, then the goal, packed in one int
        self._goal_bits = max(1, len(spec.goals).bit_length())
        self._robot_bits = max(1, self._robots.bit_length())
        shift = self._goal_bits + self._robot_bits
        self._keys = [
            [round(self._dist[cell][goal_cell] * 100) << shift | g for g, goal_cell in enumerate(self._goal_cell)]
            for cell in range(model.n_cells)
        ]
        self._values: dict[bytes, float] = {}  # keyed by cache_key: see there why not by State

    def open_goals(self, state: State) -> int:
        """The bit mask of the goals not done in ``state``."""
        return self._all & ~state.done

    def completes(self, state: State, robot: int, do: int) -> int:
        """The bit mask of the goals that ``do`` (a do code, not ``NOOP``) of ``robot`` completes in ``state``."""
        return self._done_by[state.cells[robot]][do - self._offset] & ~state.done

    def distance(self, start: int, target: int) -> float:
        """``GOTO_COST`` between two cell indices."""
        return self._dist[start][target]

    def goals_at(self, cell: int) -> int:
        """The bit mask of the goals at a cell index."""
        return self._cell_goals[cell]

    def goal_cells(self, goals: int) -> list[int]:
        """The distinct cell indices of the goals in a bit mask, in goal order."""
        out: list[int] = []
        g = 0
        while goals:
            if goals & 1 and self._goal_cell[g] not in out:
                out.append(self._goal_cell[g])
            goals >>= 1
            g += 1
        return out

    def complete(self, state: State, prefix: tuple[int, ...] = ()) -> JointAction:
        """A joint action that starts with the codes of ``prefix`` and is completed by the "do, then go" policy.

        Args:
            state: the state the joint action is taken in.
            prefix: the codes chosen so far, slot by slot: robot 0's goto,
                robot 0's do, robot 1's goto, ... (``NOOP`` for none); they
                must be allowed (distinct robots, no goto to the own cell,
                within ``max-nondef-actions``).

        Returns:
            One ``(goto, do)`` pair per robot. An undecided do is the action
            of an open goal at the robot's cell that no earlier do completes;
            the robots with an undecided goto are matched to the remaining open
            goals (closest pair first, ties by lower robot then goal) that no
            decided goto heads for, and go there (or stay when the goal is at
            their cell). Fluents beyond ``max-nondef-actions`` are left out.
        """
        cells = state.cells
        k = len(prefix)
        joint = [[NOOP, NOOP] for _ in range(self._robots)]
        used = 0
        doing = 0
        claimed = 0
        for slot, code in enumerate(prefix):
            joint[slot >> 1][slot & 1] = code
            if code:
                used += 1
                if slot & 1:
                    doing |= self._done_by[cells[slot >> 1]][code - self._offset]
                else:
                    claimed |= self._cell_goals[code - 1]
        open_ = self._all & ~state.done & ~doing
        bound = self.bound
        for robot in range(self._robots):
            if 2 * robot + 1 < k:
                continue
            here = self._cell_goals[cells[robot]] & open_
            if here and used < bound:
                g = (here & -here).bit_length() - 1
                code = self.goal_do[g]
                joint[robot][1] = code
                used += 1
                open_ &= ~self._done_by[cells[robot]][code - self._offset]
        targets = open_ & ~claimed
        free = [robot for robot in range(self._robots) if 2 * robot >= k]
        if targets and free:
            goal_bits = self._goal_bits
            goal_mask = (1 << goal_bits) - 1
            robot_mask = (1 << self._robot_bits) - 1
            goals = [g for g in range(targets.bit_length()) if targets >> g & 1]
            pairs: list[int] = []
            for robot in free:
                keys = self._keys[cells[robot]]
                tag = robot << goal_bits
                pairs.extend(keys[g] | tag for g in goals)
            pairs.sort()
            assigned = 0
            wanted = min(len(free), len(goals))
            busy = 0
            taken = 0
            for key in pairs:
                g = key & goal_mask
                robot = key >> goal_bits & robot_mask
                if busy >> robot & 1 or taken >> g & 1:
                    continue
                busy |= 1 << robot
                taken |= 1 << g
                goal_cell = self._goal_cell[g]
                if goal_cell != cells[robot] and used < bound:
                    joint[robot][0] = goal_cell + 1
                    used += 1
                assigned += 1
                if assigned == wanted:
                    break
        return tuple((goto, do) for goto, do in joint)

    def step(self, state: State, joint: JointAction) -> State:
        """The next state of ``joint`` in the determinisation (each goto has its most likely outcome)."""
        cells = list(state.cells)
        done = state.done
        old = state.cells
        offset = self._offset
        for robot, (goto, do) in enumerate(joint):
            if goto and self._success[robot]:
                cells[robot] = goto - 1
            if do:
                done |= self._done_by[old[robot]][do - offset]
        return State(tuple(cells), done)

    def value(self, state: State, steps: int) -> float:
        """The total reward of the "do, then go" policy over ``steps`` steps of the determinisation (cached).

        Args:
            state: the state to start from.
            steps: the number of steps to go (0 gives 0).
        """
        values = self._values
        key = cache_key(state, steps)
        known = values.get(key)
        if known is not None:
            return known
        model = self.model
        discount = model.spec.discount
        trail: list[tuple[bytes, float]] = []
        total = 0.0
        while steps > 0:
            known = values.get(key)
            if known is not None:
                total = known
                break
            if state.done == self._all:
                utility = model.utility(state)
                total = utility * steps if discount == 1.0 else utility * (1 - discount**steps) / (1 - discount)
                values[key] = total
                break
            joint = self.complete(state)
            trail.append((key, model.reward(state, joint)))
            state = self.step(state, joint)
            steps -= 1
            key = cache_key(state, steps)
        for known_key, reward in reversed(trail):
            total = reward + discount * total
            values[known_key] = total
        return total

    def action_value(self, state: State, steps: int, joint: JointAction) -> float:
        """The reward of ``joint`` in ``state`` plus the determinised value of its most likely next state."""
        if steps <= 0:
            return 0.0
        next_value = self.value(self.step(state, joint), steps - 1)
        return self.model.reward(state, joint) + self.model.spec.discount * next_value

    def clear(self) -> None:
        """Forget the cached values."""
        self._values.clear()
