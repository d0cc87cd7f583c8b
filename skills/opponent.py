"""The opponents' skill of the blocks-world demo (IMPERA Section 8.2, Fig. 22): disturb the stacks at random.

:class:`RandomBlockSkill` runs forever. Whenever it is idle it reads the
state (:func:`alica.skills.blocks_rules.blocks_state`, the robot interface's
``blocks_facts``: the simulator's perfect perception), lists the IPC
actions its robot could do now, drops those touching a stack that another
robot stands near, draws one with the agent's seeded generator and runs the
matching skill of :mod:`alica.skills.handling` as an inner behaviour, then pauses.
Opponents write nothing to the world model: what they do shows in the
simulated state only.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.context import SkillContextLike, SkillEnv
from alica.skills.world_skill import WorldSkill
from alica.worldsim.errors import WorldError

if TYPE_CHECKING:
    from alica.skills.handling import ArmSkill
    from alica.skills.navigation import DriveToFreeSpace

__all__ = ["BlockAction", "RandomBlockSkill", "applicable_actions", "stack_of"]

#: Default of ``blocking_radius`` (metres). A robot at work on a stack stands with its base centre
#: at the arm's reach plus the arm's mount offset from the stack, about 0.7 m (up to 0.8 m with the
#: approach tolerances), so a radius below that would never see it. 1.0 m covers a robot working at
#: or arriving at the stack, while team robots on their start lines (1.2 m from the row) and a robot
#: working in front of the neighbouring stack (about 1.05 m away with stacks 0.8 m apart) do not block.
BLOCKING_RADIUS = 1.0
#: Default of ``pause``: simulated seconds between two actions.
PAUSE = 2.0
#: Default of ``action_timeout``: simulated seconds an inner skill may run.
ACTION_TIMEOUT = 120.0
#: Looks in a row with every applicable action blocked after which the opponent drives elsewhere for room.
RELOCATE_AFTER = 3
#: Free space (metres, beyond the robots' radii) around the place it then drives to: its put-down spots
#: (about 0.65 m ahead) are then outside the other robots' blocking radius.
RELOCATE_CLEARANCE = 1.0
#: Default of ``step_aside``: after each action the opponent drives to a free place at least this far
#: (metres) from every block, like the team's WaitPlan, instead of standing at the stack it worked on.
STEP_ASIDE = 1.15

Facts = set[tuple[str, ...]]


@dataclass(frozen=True, slots=True, order=True)
class BlockAction:
    """One IPC blocks-world action of the opponent's own robot.

    Attributes:
        skill: ``Pickup``, ``Unstack``, ``Putdown`` or ``Stack``.
        block: the block picked up, unstacked or placed.
        other: the block it comes from (Unstack) or goes onto (Stack); empty otherwise.
    """

    skill: str
    block: str
    other: str = ""

    @property
    def label(self) -> str:
        """The action as text, e.g. ``Unstack(c, a)``."""
        return f"{self.skill}({self.block}{', ' + self.other if self.other else ''})"

    def params(self) -> dict[str, object]:
        """The parameters of the skill, as the catalog names them."""
        if self.skill == "Unstack":
            return {"object": self.block, "from": self.other}
        if self.skill == "Stack":
            return {"object": self.block, "target": self.other}
        return {"object": self.block}


def applicable_actions(facts: Facts, robot: str) -> list[BlockAction]:
    """The IPC actions ``robot`` could do in a state, sorted.

    With an empty hand: pick up a clear block on the table, unstack a clear
    block from the one below. Holding a block: put it down, stack it on a
    clear block.

    Args:
        facts: IPC facts as :func:`alica.skills.blocks_rules.blocks_state` gives them.
        robot: the robot's name.
    """
    clear = {f[1] for f in facts if f[0] == "clear"}
    actions: list[BlockAction] = []
    if ("handempty", robot) in facts:
        actions += [BlockAction("Pickup", f[1]) for f in facts if f[0] == "ontable" and f[1] in clear]
        actions += [BlockAction("Unstack", f[1], f[2]) for f in facts if f[0] == "on" and f[1] in clear]
    for fact in facts:
        if fact[0] == "holding" and fact[1] == robot:
            held = fact[2]
            actions.append(BlockAction("Putdown", held))
            actions += [BlockAction("Stack", held, target) for target in clear if target != held]
    return sorted(actions)


def stack_of(block: str, facts: Facts) -> set[str]:
    """The blocks of the stack ``block`` is in (itself included), following ``on`` facts down and up."""
    below = {f[1]: f[2] for f in facts if f[0] == "on"}
    above = {lower: upper for upper, lower in below.items()}
    members = {block}
    for links in (below, above):
        current = block
        while current in links and links[current] not in members:
            current = links[current]
            members.add(current)
    return members


def _silent_context(context: SkillContextLike | None) -> SkillContextLike | None:
    """The context for the inner skills: the same agent, clock, generator and world, but no world model."""
    return SkillEnv.without_world_model(context) if context is not None else None


def _skill_class(name: str) -> type[ArmSkill]:
    from alica.skills import handling

    return {
        "Pickup": handling.Pickup,
        "Unstack": handling.Unstack,
        "Putdown": handling.Putdown,
        "Stack": handling.Stack,
    }[name]


@functools.cache
def _catalog_defaults(skill: str) -> tuple[tuple[str, object], ...]:
    """The optional parameters of ``skill`` in the catalog, with their defaults."""
    from alica.lang.skill_plugins import default_registry

    return tuple((p.name, p.default) for p in default_registry().get(skill).params if not p.required)


def _catalog_params(skill: str, given: Mapping[str, object]) -> dict[str, object]:
    """``given`` with the catalog's defaults of ``skill`` filled in."""
    return {**dict(_catalog_defaults(skill)), **given}


class RandomBlockSkill(WorldSkill):
    """An opponent: forever picks a random applicable blocks-world action no other robot blocks, and runs it.

    Parameters (see :mod:`alica.skills.catalog`): ``blocking_radius`` (default
    :data:`BLOCKING_RADIUS`, 1.0 m: a robot working at a stack stands about
    0.7 m from it, so the catalog's earlier 0.5 m never blocked anything),
    ``pause`` (:data:`PAUSE`), ``action_timeout`` (:data:`ACTION_TIMEOUT`) and
    ``step_aside`` (:data:`STEP_ASIDE`: after each action the opponent drives to
    a free place that far from every block, then pauses; 0 keeps it where it is).

    An action touches the stack of its block (Pickup, Unstack), the stack it
    puts the block on (Stack) or the spot where Putdown would place it; it
    is dropped when any other robot's base centre (team or opponent,
    crashed or not) is within ``blocking_radius`` of one of those blocks or
    of that spot, horizontally. The choice is uniform, with
    ``context.rng``. A failed inner skill is fine: the opponent pauses and
    chooses again. After :data:`RELOCATE_AFTER` looks in a row with every
    applicable action blocked, it drives to a place with
    :data:`RELOCATE_CLEARANCE` of room (two opponents waiting side by side
    would otherwise block each other for good, one of them holding a block).
    The skill never ends by itself (always RUNNING).

    Attributes:
        chosen: the actions chosen so far, in order.
        outcomes: ``(label, status, reason)`` of every action that ended.
    """

    def __init__(self, name: str, params: Mapping[str, object], context: SkillContextLike | None = None) -> None:
        super().__init__(name, params, context)
        self.chosen: list[BlockAction] = []
        self.outcomes: list[tuple[str, str, str]] = []
        self.inner: ArmSkill | None = None
        self.aside: DriveToFreeSpace | None = None
        self.action: BlockAction | None = None
        self._prepared: dict[BlockAction, ArmSkill] = {}

    def setup(self, **kwargs: Any) -> None:
        """Find the robot; it needs an arm.

        Raises:
            SkillError: no world, no robot named like the agent, a robot without an arm,
                or a parameter that is not a number >= 0.
        """
        super().setup(**kwargs)
        if self.robot.arm is None:
            raise SkillError(
                f"skill '{self.name}': robot '{self.robot.name}' has no arm; opponents must be manipulators"
            )
        self.radius = self._positive("blocking_radius", BLOCKING_RADIUS)
        self.pause = self._positive("pause", PAUSE)
        self.action_timeout = self._positive("action_timeout", ACTION_TIMEOUT)
        self.step_aside = self._positive("step_aside", STEP_ASIDE)

    def initialise(self) -> None:
        """Start idle: look at the world on this first tick."""
        self.inner = None
        self.action = None
        self.aside = None
        self.blocked_looks = 0
        self._prepared = {}
        self.next_look = self.now()
        self.idle_message = "looking for an action"

    def _positive(self, name: str, default: float) -> float:
        value = self.param(name, default)
        if (
            not isinstance(value, (int, float))
            or isinstance(value, bool)
            or not value >= 0.0
            or not math.isfinite(value)
        ):
            raise SkillError(f"skill '{self.name}': parameter '{name}' must be a number >= 0, got {value!r}")
        return float(value)

    # -- one tick ---------------------------------------------------------------

    def update(self) -> Status:
        """Tick the running action, or pause, or choose the next one."""
        if self.inner is not None:
            return self._tick_inner()
        if self.aside is not None:
            self.aside.tick_once()
            if self.aside.status == Status.RUNNING:
                return self.running(f"stepping aside: {self.aside.feedback_message}")
            self.aside = None
            self.robot.stop()
            self.next_look = self.now() + self.pause
        now = self.now()
        if now < self.next_look:
            return self.running(self.idle_message)
        facts = self._facts()
        possible = applicable_actions(facts, self.robot.name)
        free = self.free_actions(facts, possible)
        if not free:
            self.next_look = now + self.pause
            self.blocked_looks = self.blocked_looks + 1 if possible else 0
            if self.blocked_looks >= RELOCATE_AFTER and self.step_aside > 0:
                # other robots crowd every stack and put-down spot within reach (another opponent waiting
                # next to this one, say, each blocking the other for good): look for room elsewhere
                self.blocked_looks = 0
                self.aside = self._drive_aside(RELOCATE_CLEARANCE)
                return self.running(
                    f"all {len(possible)} applicable actions are blocked by other robots: looking for room"
                )
            why = (
                f"all {len(possible)} applicable actions are blocked by other robots"
                if possible
                else "no action is applicable"
            )
            self.idle_message = f"waiting: {why}; looking again at t = {self.next_look:.1f} s"
            return self.running(self.idle_message)
        self.blocked_looks = 0
        assert self.context is not None  # set up with one
        self.action = self.context.rng.choice(free)
        self.chosen.append(self.action)
        self._start(self.action)
        return self._tick_inner()

    def free_actions(
        self, facts: Facts | None = None, actions: Iterable[BlockAction] | None = None
    ) -> list[BlockAction]:
        """The applicable actions no other robot blocks, sorted: what the next choice is drawn from.

        Args:
            facts: the state (the simulated one by default).
            actions: the candidates (by default :func:`applicable_actions` of the state).
        """
        self._prepared = {}
        facts = self._facts() if facts is None else facts
        candidates = applicable_actions(facts, self.robot.name) if actions is None else actions
        return sorted(a for a in candidates if not self._blocked(a, facts))

    def _facts(self) -> Facts:
        from alica.skills.blocks_rules import blocks_state

        return blocks_state(self.world)

    def _start(self, action: BlockAction) -> None:
        """Run ``action``: the inner skill built while checking it (Putdown), or a new one."""
        prepared, self._prepared = self._prepared, {}
        self.inner = prepared.get(action) or self._build(action)
        self.action_started = self.now()

    def _build(self, action: BlockAction, **extra: object) -> ArmSkill:
        context = _silent_context(self.context)
        params = _catalog_params(action.skill, {**action.params(), **extra})
        inner = _skill_class(action.skill)(f"{self.name}/{action.label}", params, context)
        inner.setup(context=context)
        inner.team_source = self.world_model  # it writes no facts, but hears the opponent's own team
        return inner

    def _tick_inner(self) -> Status:
        assert self.action is not None and self.inner is not None
        inner = self.inner
        label = self.action.label
        if self.now() - self.action_started > self.action_timeout:
            inner.stop(Status.INVALID)
            return self._finished(label, "timeout", f"still running after {self.action_timeout:.0f} s")
        try:
            inner.tick_once()
        except (SkillError, WorldError) as exc:  # the world changed under the action (a block taken, say)
            inner.stop(Status.INVALID)
            return self._finished(label, "failure", str(exc))
        status = inner.status
        if status == Status.RUNNING:
            return self.running(f"{label}: {inner.feedback_message}")
        outcome = "success" if status == Status.SUCCESS else "failure"
        return self._finished(label, outcome, inner.feedback_message)

    def _finished(self, label: str, outcome: str, reason: str) -> Status:
        self.outcomes.append((label, outcome, reason))
        self.inner = None
        self.action = None
        self.robot.stop()
        self.next_look = self.now() + self.pause
        if self.step_aside > 0:
            self.aside = self._drive_aside(0.4)
        why = f" ({reason})" if reason and outcome != "success" else ""
        self.idle_message = f"pausing after {label}: {outcome}{why}; next look at t = {self.next_look:.1f} s"
        return self.running(self.idle_message)

    def _drive_aside(self, clearance: float) -> DriveToFreeSpace:
        """A drive to a free place ``clearance`` metres from obstacles and robots, ``step_aside`` from every block."""
        from alica.skills.navigation import DriveToFreeSpace

        context = _silent_context(self.context)
        aside = DriveToFreeSpace(
            f"{self.name}/step aside",
            {"clearance": clearance, "max_distance": 3.0, "keep_away": self.step_aside},
            context,
        )
        aside.setup(context=context)
        aside.team_source = self.world_model
        return aside

    # -- blocking ---------------------------------------------------------------

    def _blocked(self, action: BlockAction, facts: Facts) -> bool:
        """Whether another robot stands within the blocking radius of what ``action`` touches."""
        return any(self._crowded(xy) for xy in self._touched(action, facts))

    def _crowded(self, xy: tuple[float, float]) -> bool:
        """Whether another robot's centre is within the blocking radius of ``xy``."""
        x, y = xy
        return any(
            math.hypot(x - r.pose[0], y - r.pose[1]) < self.radius
            for r in self.world.robots.values()
            if r is not self.robot
        )

    def _touched(self, action: BlockAction, facts: Facts) -> Iterable[tuple[float, float]]:
        """Where ``action`` works: the blocks of the stack it takes from or puts on, or the put-down spot."""
        if action.skill == "Putdown":
            return [self._putdown_spot(action)]
        block = action.other if action.skill == "Stack" else action.block
        return [self._xy(b) for b in sorted(stack_of(block, facts))]

    def _putdown_spot(self, action: BlockAction) -> tuple[float, float]:
        """Where Putdown will put the block; the inner skill is built now and kept, so the spot checked is the spot used."""
        inner = self._prepared.get(action)
        if inner is None:
            spot = self._free_spot()
            inner = self._build(action, **({"target": list(spot)} if spot is not None else {}))
            self._prepared[action] = inner
        spot = inner.site()
        return float(spot[0]), float(spot[1])

    def _free_spot(self) -> tuple[float, float] | None:
        """The first spot Putdown could use (:func:`alica.skills.blocks_rules.putdown_spots`) that no other robot blocks.

        ``None`` when there is none: Putdown then picks its own spot (and the action is blocked there).
        """
        from alica.skills.blocks_rules import putdown_spots

        return next((spot for spot in putdown_spots(self.world, self.robot) if not self._crowded(spot)), None)

    def _xy(self, block: str) -> tuple[float, float]:
        position = self.world.objects[block].position()
        return float(position[0]), float(position[1])

    # -- stopping ---------------------------------------------------------------

    def terminate(self, new_status: Status) -> None:
        """Stop the running action (the inner skill stops its base and approach) and the base."""
        if self.inner is not None and self.inner.status == Status.RUNNING:
            self.inner.stop(Status.INVALID)
        if self.aside is not None and self.aside.status == Status.RUNNING:
            self.aside.stop(Status.INVALID)
        self.inner = None
        self.aside = None
        self.action = None
        if self.has_robot:
            self.robot.stop()
