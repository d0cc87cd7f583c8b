"""The built-in anytime planner for ProTaP: UCT over factored joint actions, initialised from a determinisation.

The search is a THTS-style UCT (Keller and Helmert) whose tree never lists
joint actions. A step of the tree is a chain of decision nodes, one per
*slot*: robot 0's goto, robot 0's do, robot 1's goto, ... Each slot offers
only a few choices (:meth:`ProtapPlanner.choices`): no goto or a goto to the
cell of an open goal (another cell is never better: a goto reaches any cell in
one step at the Euclidean distance), no do or a do that completes an open goal
at the robot's cell (another do changes nothing and costs). Once
``max-nondef-actions`` fluents are chosen, every later slot offers only
``NOOP``. So every joint action of the tree is allowed by construction, and a
step costs ``2 x robots`` small decisions instead of one among
``(cells x actions) ^ robots``.

A trial walks down from the root state: in each slot it picks a choice by
UCB1, then samples the outcome of the joint action with the model's
probabilities, and goes on in the next state (the number of steps to go is
part of a state's key, so the values are finite-horizon) until it meets a
state it has not seen, or the horizon. A new decision node values each of its
choices by completing the joint action with the "do, then go" policy and
adding the value of the most likely next state in the determinisation
(:class:`~alica.prophet.protap.heuristic.Determinisation`), counted as
``virtual_visits`` visits (PROST's IDS initialisation); a new state ends the
trial with the best of these values. The trial's return is backed up
(Monte-Carlo averages) along every slot of every step it took.

:meth:`ProtapPlanner.plan_step` is anytime: it runs trials until its
:class:`Budget` (trials or seconds) is spent and returns the joint action of
the most visited choices (ties: the higher value), completed by the heuristic
where the tree stops; with no trial at all, the heuristic's joint action.

>>> import random
>>> from alica.prophet.protap.generate import appendix_c_spec
>>> from alica.prophet.protap.policies import evaluate
>>> model = ProtapModel(appendix_c_spec())
>>> planner = ProtapPlanner(model)
>>> joint = planner.plan_step(model.initial, Budget(trials=200), random.Random(0))
>>> model.violations(model.initial, model.fluents(joint))
[]
>>> evaluate(model, PlannerPolicy(planner, Budget(trials=100)), episodes=2, seed=0).mean > 2000
True
"""

from __future__ import annotations

import math
import random
import time
from dataclasses import dataclass
from typing import Any

from alica.prophet.protap.heuristic import Determinisation, cache_key
from alica.prophet.protap.model import NOOP, JointAction, ProtapModel, State


@dataclass(frozen=True, slots=True)
class Budget:
    """How long :meth:`ProtapPlanner.plan_step` searches: a number of trials, wall-clock seconds, or both.

    The search stops at whichever limit comes first. A trial budget makes the
    planner deterministic for a seed (tests use it); a time budget suits a
    robot team (the bench uses it).

    Attributes:
        trials: the most trials (``None``: no limit).
        seconds: the most wall-clock seconds (``None``: no limit).
    """

    trials: int | None = None
    seconds: float | None = None

    def __post_init__(self) -> None:
        if self.trials is None and self.seconds is None:
            raise ValueError("a budget needs trials or seconds")
        if (self.trials is not None and self.trials < 0) or (self.seconds is not None and self.seconds < 0):
            raise ValueError("a budget is not negative")


class _OutOfTime(Exception):
    """The search's deadline came while a trial expanded a node (the trial is dropped)."""


#: A decision node: the choices of one slot with their mean returns, visit counts and the nodes after them,
#: as one list ``[total visits, choices, q_0 .. q_k-1, n_0 .. n_k-1, child_0 .. child_k-1]``. One list, not an
#: object holding three lists: the garbage collector then tracks one object per node instead of four, and its
#: collections, which scan every tracked object, stall the search four times less on a large tree.
_Node = list[Any]


def _node(choices: tuple[int, ...], values: list[float], visits: float) -> _Node:
    k = len(choices)
    return [visits * k, choices, *values, *([visits] * k), *([None] * k)]


def _child(node: _Node, index: int) -> _Node | None:
    """The node after choice ``index`` of ``node``, if any."""
    child: _Node | None = node[2 + 2 * len(node[1]) + index]
    return child


class ProtapPlanner:
    """An anytime UCT planner for one ProTaP model, over factored joint actions.

    Args:
        model: the simulator (its spec's horizon and ``max-nondef-actions`` are used).
        exploration: the UCB1 constant, relative to the size of the node's best value.
        virtual_visits: how many visits the heuristic value of a new choice counts for.
        max_nodes: the tree is cleared when it holds more state nodes than this.
        max_targets: a goto slot offers the gotos to at most this many open
            goal cells, the nearest (and the heuristic's choice besides);
            ``None``: all. It keeps large teams' nodes small.

    Attributes:
        model: the simulator.
        heuristic: the determinisation that values new nodes.
        last_trials: the number of trials of the last :meth:`plan_step`.
    """

    def __init__(
        self,
        model: ProtapModel,
        *,
        exploration: float = 0.1,
        virtual_visits: float = 5.0,
        max_nodes: int = 200_000,
        max_targets: int | None = 8,
    ) -> None:
        self.model = model
        self.heuristic = Determinisation(model)
        self.exploration = exploration
        self.virtual_visits = virtual_visits
        self.max_nodes = max_nodes
        self.max_targets = max_targets
        self.last_trials = 0
        self._slots = 2 * len(model.spec.robots)
        # keyed by cache_key (bytes), never by State: see there why
        self._tree: dict[bytes, _Node] = {}
        self._joint_values: dict[bytes, float] = {}
        self._deadline: float | None = None

    def reset(self) -> None:
        """Forget the search tree and the cached values (a new episode, say)."""
        self._tree.clear()
        self._joint_values.clear()
        self.heuristic.clear()

    # -- the factored decisions ----------------------------------------------
    def choices(self, state: State, slot: int, used: int, doing: int, prefix: tuple[int, ...] = ()) -> tuple[int, ...]:
        """The codes slot ``slot`` may take in ``state``, ``NOOP`` first.

        Args:
            state: the state of the step.
            slot: ``2 * robot`` for the robot's goto, ``2 * robot + 1`` for its do.
            used: how many fluents the earlier slots of the step set true.
            doing: the bit mask of the goals the earlier slots' dos complete.
            prefix: the codes of the earlier slots (only read with ``max_targets``).

        Returns:
            Only ``NOOP`` once ``max-nondef-actions`` fluents are used; else
            ``NOOP`` and a goto to each cell of an open goal but the robot's
            own (with ``max_targets``: the nearest ones, and the heuristic's
            target), or ``NOOP`` and each do that completes an open goal at the
            robot's cell that no earlier do completes.
        """
        if used >= self.heuristic.bound:
            return (NOOP,)
        det = self.heuristic
        robot = slot >> 1
        here = state.cells[robot]
        open_ = det.open_goals(state) & ~doing
        if slot & 1 == 0:
            targets = [cell for cell in det.goal_cells(open_) if cell != here]
            limit = self.max_targets
            if limit is not None and len(targets) > limit:
                targets.sort(key=lambda cell: (det.distance(here, cell), cell))
                kept = targets[:limit]
                default = det.complete(state, prefix)[robot][0] - 1
                if default >= 0 and default not in kept:
                    kept.append(default)
                targets = kept
            return (NOOP, *(cell + 1 for cell in targets))
        return self._do_codes(open_ & det.goals_at(here))

    def _do_codes(self, goals: int) -> tuple[int, ...]:
        codes = [NOOP]
        goal_do = self.heuristic.goal_do
        g = 0
        while goals:
            if goals & 1:
                code = goal_do[g]
                if code not in codes:
                    codes.append(code)
            goals >>= 1
            g += 1
        return tuple(codes)

    def _expand(self, state: State, steps: int, prefix: tuple[int, ...], choices: tuple[int, ...]) -> _Node:
        values = []
        cache = self._joint_values
        deadline = self._deadline
        for code in choices:
            if deadline is not None and time.perf_counter() >= deadline:
                raise _OutOfTime
            joint = self.heuristic.complete(state, (*prefix, code))
            key = cache_key(state, steps, joint)
            value = cache.get(key)
            if value is None:
                value = self.heuristic.action_value(state, steps, joint)
                cache[key] = value
            values.append(value)
        return _node(choices, values, self.virtual_visits)

    def _select(self, node: _Node) -> int:
        k = len(node[1])
        if k == 1:
            return 0
        scale = self.exploration * max(1.0, abs(max(node[2 : 2 + k])))
        log_total = math.log(node[0])
        best, best_score = 0, -math.inf
        for i in range(k):
            score = node[2 + i] + scale * math.sqrt(log_total / node[2 + k + i])
            if score > best_score:
                best, best_score = i, score
        return best

    # -- trials ----------------------------------------------------------------
    def _trial(self, state: State, steps: int, rng: random.Random) -> None:
        tree = self._tree
        det = self.heuristic
        model = self.model
        slots = self._slots
        path: list[tuple[list[tuple[_Node, int]], float]] = []
        leaf = 0.0
        while steps > 0:
            key = cache_key(state, steps)
            node: _Node | None = tree.get(key)
            if node is None:
                root = self._expand(state, steps, (), self.choices(state, 0, 0, 0))
                tree[key] = root
                leaf = max(root[2 : 2 + len(root[1])])
                break
            chain: list[tuple[_Node, int]] = []
            prefix: list[int] = []
            used = 0
            doing = 0
            parent: _Node = node
            for slot in range(slots):
                if node is None:
                    choices = self.choices(state, slot, used, doing, tuple(prefix))
                    node = self._expand(state, steps, tuple(prefix), choices)
                    parent[2 + 2 * len(parent[1]) + chain[-1][1]] = node
                index = self._select(node)
                chain.append((node, index))
                code = node[1][index]
                prefix.append(code)
                if code:
                    used += 1
                    if slot & 1:
                        doing |= det.completes(state, slot >> 1, code)
                parent = node
                node = _child(node, index)
            joint = tuple(zip(prefix[0::2], prefix[1::2], strict=True))
            next_state, reward = model.step(state, joint, rng)
            path.append((chain, reward))
            state = next_state
            steps -= 1
        discount = model.spec.discount
        value = leaf
        for chain, reward in reversed(path):
            value = reward + discount * value
            for node_, index in chain:
                node_[0] += 1
                q_at = 2 + index
                n_at = q_at + len(node_[1])
                count = node_[n_at] + 1
                node_[n_at] = count
                node_[q_at] += (value - node_[q_at]) / count

    def _best(self, state: State, steps: int) -> JointAction:
        node = self._tree.get(cache_key(state, steps))
        prefix: list[int] = []
        for _ in range(self._slots):
            if node is None:
                break
            here: _Node = node
            choices = here[1]
            k = len(choices)
            index = max(range(k), key=lambda i: (here[2 + k + i], here[2 + i], -i))
            prefix.append(choices[index])
            node = _child(here, index)
        return self.heuristic.complete(state, tuple(prefix))

    def plan_step(
        self, state: State, budget: Budget, rng: random.Random, steps_to_go: int | None = None
    ) -> JointAction:
        """Search from ``state`` until ``budget`` is spent and return the best joint action found.

        The tree of earlier calls is kept (a state met again keeps its
        statistics) and cleared at the start of an episode (``steps_to_go``
        equal to the horizon) or when it outgrows ``max_nodes``.

        Args:
            state: the observed state.
            budget: trials and/or seconds (the deadline is checked before every
                node a trial expands, and a trial it cuts short is dropped, so
                the call overruns its seconds by one heuristic value at most); a zero budget returns the heuristic's joint
                action, and so does a state with every goal done (no search needed).
            rng: the source of the sampled outcomes (the only randomness).
            steps_to_go: the steps left in the episode, this one included (default: the horizon).

        Returns:
            One ``(goto, do)`` pair per robot, within every limit of the domain.
        """
        horizon = self.model.spec.horizon
        steps = horizon if steps_to_go is None else steps_to_go
        if steps <= 0 or not self.heuristic.open_goals(state):
            self.last_trials = 0
            return self.heuristic.complete(state)  # nothing left to decide: every slot is NOOP
        start = time.perf_counter()
        if steps == horizon or len(self._tree) > self.max_nodes:
            self.reset()  # freeing a large tree takes a while: it counts against the step's seconds
            if budget.seconds is not None:
                budget = Budget(budget.trials, max(0.0, budget.seconds - (time.perf_counter() - start)))
        self.last_trials = self.search(state, budget, rng, steps)
        return self.best(state, steps)

    def search(self, state: State, budget: Budget, rng: random.Random, steps_to_go: int | None = None) -> int:
        """Run trials from ``state`` until ``budget`` is spent, keeping the tree; the number of trials run.

        :meth:`plan_step` is this and :meth:`best`; a caller that searches in
        slices (a team's planner, a budget per engine tick) calls it again and
        again on the same state and asks :meth:`best` at the end.
        """
        steps = self.model.spec.horizon if steps_to_go is None else steps_to_go
        if steps <= 0 or not self.heuristic.open_goals(state):
            return 0
        if len(self._tree) > self.max_nodes:
            self.reset()
        clock = time.perf_counter
        deadline = None if budget.seconds is None else clock() + budget.seconds
        limit = budget.trials
        trials = 0
        self._deadline = deadline
        try:
            while limit is None or trials < limit:
                if deadline is not None and clock() >= deadline:
                    break
                self._trial(state, steps, rng)
                trials += 1
        except _OutOfTime:
            pass  # the deadline came in the middle of a trial's expansion: that trial is dropped, the tree stays valid
        finally:
            self._deadline = None
        return trials

    def best(self, state: State, steps_to_go: int | None = None) -> JointAction:
        """The joint action of the most visited choices from ``state`` (the heuristic's where the tree stops)."""
        steps = self.model.spec.horizon if steps_to_go is None else steps_to_go
        if steps <= 0 or not self.heuristic.open_goals(state):
            return self.heuristic.complete(state)
        return self._best(state, steps)


class PlannerPolicy:
    """A :data:`~alica.prophet.protap.policies.Policy` that replans every step with a :class:`ProtapPlanner`.

    It counts its calls to know the steps to go: episodes are taken to last
    ``horizon`` steps each, one call per step, as in
    :func:`~alica.prophet.protap.policies.evaluate` (call :meth:`reset` to
    start an episode early).

    Args:
        planner: the planner.
        budget: the search budget of every step.
        horizon: the steps per episode (default: the spec's horizon).
        rng: the source of the search's sampled outcomes; by default the
            ``rng`` of each call (the episode's). A separate seeded one leaves
            the episode's draws to the outcomes, so episodes of different
            budgets and policies meet the same goto failures.
    """

    def __init__(
        self,
        planner: ProtapPlanner,
        budget: Budget,
        horizon: int | None = None,
        rng: random.Random | None = None,
    ) -> None:
        self.planner = planner
        self.budget = budget
        self.horizon = planner.model.spec.horizon if horizon is None else horizon
        self.rng = rng
        self._step = 0

    def reset(self) -> None:
        """Start a new episode at the next call."""
        self._step = 0

    def __call__(self, model: ProtapModel, state: State, rng: random.Random) -> JointAction:
        """The planner's joint action for ``state`` (``model`` must be the planner's)."""
        steps = self.horizon - self._step % self.horizon
        self._step += 1
        return self.planner.plan_step(state, self.budget, rng if self.rng is None else self.rng, steps)
