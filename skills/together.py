"""Run skills on several robots of one world at once, in simulated time.

Each robot runs its own sequence of skills in order, and all robots run at
the same time: every round ticks each robot's current skill once, then the
world steps one period, as :func:`alica.skills.testing.run_skill` does for a
single skill (the two share :class:`~alica.skills.testing.SkillSession`). A
robot whose skill ends starts its next one on the next round. It is what a
dispatcher needs to run one step of a concurrent plan: robot ``r1`` picks a
sample up and puts it down while ``r2`` drives to another cell.

A :class:`SkillCall` marked ``chained`` runs only if the skill before it in
the robot's sequence succeeded (Putdown after Pickup); one that is not
chained runs whatever happened before (a robot's goto after its do). The
run ends when every robot's sequence has ended, or at the time bound: a
skill still running then is stopped (``timeout``) and the skills after it do
not run (``skipped``).

Example::

    from alica.skills.together import SkillCall, run_together

    runs = run_together(world, {
        "r1": [SkillCall("Pickup", {"object": "a"}), SkillCall("Putdown", {"object": "a"}, chained=True)],
        "r2": [SkillCall("MoveToPosition", {"goal": [4.0, 2.0]})],
    }, timeout=60.0)
    assert runs["r2"].ok, runs["r2"].runs[0].reason
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from alica.errors import SkillError
from alica.lang.skills import SkillRegistry
from alica.skills.testing import SkillRun, SkillSession, checked_params, resolve_registry
from alica.worldmodel.protocol import WorldModelLike

if TYPE_CHECKING:
    from alica.worldsim.world import World

#: The status of a skill that did not run: a chained skill after a failure, or any skill after the time bound.
SKIPPED = "skipped"


@dataclass(frozen=True, slots=True)
class SkillCall:
    """One skill of a robot's sequence.

    Attributes:
        skill: the skill's name, as registered.
        params: its parameters.
        chained: run only if the skill before it in the sequence succeeded.
        label: what the caller calls it (e.g. ``do`` or ``goto``), kept in the result.
    """

    skill: str
    params: Mapping[str, object] = field(default_factory=dict)
    chained: bool = False
    label: str = ""


@dataclass(slots=True)
class RobotRuns:
    """What one robot's sequence did.

    Attributes:
        robot: the robot.
        calls: its sequence.
        runs: one :class:`~alica.skills.testing.SkillRun` per call, in order;
            a skill that did not run has the status ``skipped`` and says why.
        starts: the simulated time each skill started (``None`` for a skipped one).
    """

    robot: str
    calls: tuple[SkillCall, ...]
    runs: list[SkillRun] = field(default_factory=list)
    starts: list[float | None] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """Whether every skill of the sequence succeeded."""
        return all(run.ok for run in self.runs)


class _Robot:
    """One robot's sequence while it runs: its current session and what the finished ones did."""

    def __init__(self, robot: str, calls: tuple[SkillCall, ...], world_model: WorldModelLike | None) -> None:
        self.out = RobotRuns(robot, calls)
        self.world_model = world_model
        self.scratch: dict[str, object] = {}
        self.session: SkillSession | None = None

    @property
    def index(self) -> int:
        """The position of the current (or next) skill in the sequence."""
        return len(self.out.runs)

    @property
    def finished(self) -> bool:
        return self.index >= len(self.out.calls)

    def skip(self, reason: str) -> None:
        call = self.out.calls[self.index]
        self.out.runs.append(SkillRun(call.skill, self.out.robot, SKIPPED, reason, 0.0, 0))
        self.out.starts.append(None)


def run_together(
    world: World,
    sequences: Mapping[str, Sequence[SkillCall]],
    *,
    timeout: float = 120.0,
    rate: float = 10.0,
    seed: int = 0,
    registry: SkillRegistry | None = None,
    skills: Iterable[str] | str = (),
    world_models: Mapping[str, WorldModelLike] | None = None,
    on_tick: Callable[[World, str, int], None] | None = None,
) -> dict[str, RobotRuns]:
    """Run each robot's sequence of skills, all robots at once, until all end or ``timeout`` simulated seconds pass.

    Args:
        world: the world; the robots are its robots, named as in ``sequences``.
        sequences: robot name -> its skills, in order (an empty sequence: the robot stands by).
        timeout: the most simulated seconds; a skill still running then is stopped.
        rate: ticks per simulated second, the same for every robot.
        seed: seeds each skill's ``random.Random`` (with the robot's name).
        registry: where the skills are declared (default: the installed plug-ins and ``skills``).
        skills: plug-in modules to load when no registry is given (as ``--skills``).
        world_models: each robot's world model, kept across calls (a new one
            per robot on the world's clock when omitted). A robot's skills share
            its world model and its scratch space.
        on_tick: ``on_tick(world, robot, index)`` runs before every tick of
            the robot's skill at ``index`` in its sequence (to inject a fault
            when a given skill starts, say).

    Returns:
        Robot name -> what its sequence did (:class:`RobotRuns`).

    Raises:
        SkillError: an unknown robot, bad parameters or no implementation
            (every call is checked before any skill runs).
        UnknownSkillError: no skill of that name.
        SkillPluginError: a module of ``skills`` cannot be loaded.
    """
    registry = resolve_registry(registry, skills, "run_together")
    for robot, calls in sequences.items():
        if robot not in world.robots:
            raise SkillError(f"the world has no robot named '{robot}' (robots: {', '.join(sorted(world.robots))})")
        for call in calls:
            checked_params(registry.get(call.skill), call.params)
    models = world_models or {}
    robots = [_Robot(robot, tuple(calls), models.get(robot)) for robot, calls in sequences.items()]
    start = world.now()
    period = 1.0 / rate
    while True:
        for state in robots:
            _advance(state, world, registry, seed)
            session = state.session
            if session is None:
                continue
            if on_tick is not None:
                on_tick(world, state.out.robot, state.index)
            if session.tick():
                state.out.runs.append(session.result())
                state.session = None
        if all(state.finished and state.session is None for state in robots):
            break
        if world.now() - start >= timeout:
            for state in robots:
                if state.session is not None:
                    state.session.stop()
                    run = state.session.result()
                    said = f" ({run.reason})" if run.reason else ""
                    run.reason = f"stopped at the time bound of {timeout:g} s{said}"
                    state.out.runs.append(run)
                    state.session = None
                while not state.finished:
                    state.skip(f"not started: the time bound of {timeout:g} s was reached")
            break
        world.step(period)
    return {state.out.robot: state.out for state in robots}


def _advance(state: _Robot, world: World, registry: SkillRegistry, seed: int) -> None:
    """Start the robot's next skill if it has none running; skip chained ones after a failure."""
    if state.session is not None:
        return
    while not state.finished:
        call = state.out.calls[state.index]
        before = state.out.runs[-1] if state.out.runs else None
        if call.chained and before is not None and not before.ok:
            state.skip(f"not started: {before.skill} before it did not succeed")
            continue
        session = SkillSession(
            call.skill,
            world,
            state.out.robot,
            call.params,
            registry,
            world_model=state.world_model,
            seed=seed,
            scratch=state.scratch,
        )
        state.world_model = session.world_model  # the robot's skills share one world model
        state.session = session
        state.out.starts.append(session.started)
        return
