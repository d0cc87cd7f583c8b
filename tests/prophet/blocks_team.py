"""A blocks-world team with scripted skills that change the world model as the IPC blocks domain says."""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

import py_trees
from py_trees.common import Status

from alica.engine import SimulatedTeam, TraceRecorder
from alica.io import load_library
from alica.model import PlanLibrary
from alica.prophet import engine_config
from alica.prophet.planner import Feature, Planner, Progress, SearchEvent
from tests.conftest import PLANS

Literal = tuple[bool, str, tuple[str, ...]]


def effects(skill: str, params: Mapping[str, object], me: str) -> list[Literal]:
    """What the blocks-world skill ``skill`` changes when it succeeds (the signatures' effects)."""
    x = str(params.get("object"))
    if skill == "Pickup":
        return [
            (False, "ontable", (x,)),
            (False, "clear", (x,)),
            (False, "handempty", (me,)),
            (True, "holding", (me, x)),
        ]
    if skill == "Putdown":
        return [(False, "holding", (me, x)), (True, "clear", (x,)), (True, "handempty", (me,)), (True, "ontable", (x,))]
    if skill == "Stack":
        y = str(params.get("target"))
        return [
            (False, "holding", (me, x)),
            (False, "clear", (y,)),
            (True, "clear", (x,)),
            (True, "handempty", (me,)),
            (True, "on", (x, y)),
        ]
    if skill == "Unstack":
        y = str(params.get("from"))
        return [
            (False, "on", (x, y)),
            (False, "clear", (x,)),
            (False, "handempty", (me,)),
            (True, "holding", (me, x)),
            (True, "clear", (y,)),
        ]
    return []


class BlockSkill(py_trees.behaviour.Behaviour):
    """Runs for ``ticks`` ticks, then succeeds and writes its effects (or fails, when told to)."""

    def __init__(
        self, name: str, skill: str, params: Mapping[str, object], context: Any, ticks: int | None, fail: bool
    ) -> None:
        super().__init__(name)
        self.skill, self.params, self.context, self.ticks, self.fail = skill, dict(params), context, ticks, fail
        self.count = 0

    def initialise(self) -> None:
        self.count = 0

    def update(self) -> Status:
        self.count += 1
        if self.ticks is None or self.count < self.ticks:
            return Status.RUNNING
        if self.fail:
            return Status.FAILURE
        world = self.context.world_model
        for positive, name, args in effects(self.skill, self.params, self.context.agent):
            (world.assert_fact if positive else world.retract_fact)(name, *args)
        return Status.SUCCESS


class BlockSkills:
    """Skill factories for the blocks-world plans; ``fail`` lists skill names whose next run fails (once each),
    ``broken`` (agent, skill name) pairs whose every run fails (a robot that cannot do it from where it is)."""

    def __init__(self, fail: Iterable[str] = (), ticks: int = 3, broken: Iterable[tuple[str, str]] = ()) -> None:
        self.fail = list(fail)
        self.broken = set(broken)
        self.ticks = ticks
        self.runs: list[tuple[str, str, dict[str, object]]] = []

    def factory(self, skill: str):  # type: ignore[no-untyped-def]
        def make(name: str, params: Mapping[str, object], context: Any) -> BlockSkill:
            fail = skill in self.fail
            if fail:
                self.fail.remove(skill)
            fail = fail or (context.agent, skill) in self.broken
            self.runs.append((context.agent, skill, dict(params)))
            # waiting never ends by itself (the WaitPlan's WaitAside, Idle); a drive to free space takes a tick
            ticks = None if skill in ("Idle", "WaitAside") else (1 if skill == "DriveToFreeSpace" else self.ticks)
            return BlockSkill(name, skill, params, context, ticks, fail)

        return make

    def mapping(self) -> dict[str, Any]:
        """Skill name -> factory, for :class:`SimulatedTeam`."""
        names = ("MoveToPosition", "DriveToFreeSpace", "WaitAside", "Idle", "Pickup", "Putdown", "Stack", "Unstack")
        return {n: self.factory(n) for n in names}


def blocks_library(planner: str | None = None) -> PlanLibrary:
    """The shipped blocks-world mission; ``planner`` plans StackBlocks instead of the mission's (temporal)."""
    from alica.app.demos.blocksworld import with_planner

    return with_planner(load_library(PLANS / "blocksworld" / "mission.yaml"), "StackBlocks", planner)


def world_facts(stacks: Iterable[Iterable[str]], robots: Iterable[str]) -> list[Literal]:
    """Facts of stacks (bottom first) and empty-handed robots."""
    facts: list[Literal] = []
    for stack in stacks:
        blocks = list(stack)
        facts.append((True, "ontable", (blocks[0],)))
        facts.extend((True, "on", (upper, lower)) for lower, upper in itertools.pairwise(blocks))
        facts.append((True, "clear", (blocks[-1],)))
    facts.extend((True, "handempty", (r,)) for r in robots)
    return facts


SUSSMAN = [["a", "c"], ["b"]]
"""c on a, b alone: the goal a on b on c takes 6 steps."""


def blocks_team(
    agents: Iterable[str],
    skills: BlockSkills,
    stacks=SUSSMAN,
    seed: int = 0,
    planner: str | None = None,
    **config: Any,
) -> tuple[SimulatedTeam, TraceRecorder]:  # type: ignore[no-untyped-def]
    """A Manipulator team on BlocksWorldMission with ``stacks`` in every world model (``config``: engine settings;
    ``planner``: StackBlocks's planner instead of the mission's)."""
    names = list(agents)
    recorder = TraceRecorder()
    settings = {
        "frequency": 10.0,
        "broadcast_interval": 0.1,
        "team_timeout": 0.5,
        "assignment_protection": 0.3,
        **config,
    }
    sim = SimulatedTeam(
        blocks_library(planner),
        "BlocksWorldMission",
        dict.fromkeys(names, "Manipulator"),
        seed=seed,
        config=engine_config(**settings),
        skills=skills.mapping(),
        observers=[recorder],
    )
    sim.set_facts(world_facts(stacks, names))
    return sim, recorder


def goal_holds(sim: SimulatedTeam, agent: str) -> bool:
    """Whether a on b on c holds in ``agent``'s world model."""
    world = sim.engines[agent].world_model
    return world.holds("on", "a", "b") and world.holds("on", "b", "c") and world.holds("ontable", "c")


class StallingPlanner(Planner):
    """A planner that never finds anything (for the planning timeout)."""

    name = "stall"
    features = frozenset(Feature)

    def _search(self, domain: object, problem: object, *, anytime: bool) -> Iterator[SearchEvent]:
        expansions = 0
        while True:
            expansions += 100
            yield Progress(expansions)


def events(recorder: Any, kind: str, **match: object) -> list[dict[str, Any]]:
    """The recorded events of ``kind`` whose fields equal ``match``."""
    return [e for e in recorder.events if e["event"] == kind and all(e.get(k) == v for k, v in match.items())]


def child_plan(sim: SimulatedTeam, agent: str) -> str | None:
    """The plan running in the first child slot of ``agent``'s root state (the planning problem's)."""
    node = sim.engines[agent].root.slots[0].node
    return node.plan.name if node is not None else None


def run_until(sim: SimulatedTeam, condition: Any, max_ticks: int = 600) -> None:
    """Tick ``sim`` until ``condition()`` holds, at most ``max_ticks`` ticks."""
    for _ in range(max_ticks):
        if condition():
            return
        sim.tick()
    raise AssertionError("condition not reached")
