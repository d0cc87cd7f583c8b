"""A robot whose step failed is kept off that step for a while (alica.prophet.keep_off)."""

from __future__ import annotations

import pytest

from alica.io import load_library
from alica.prophet.keep_off import KEEP_OFF_S, KeepOff, bar
from alica.prophet.planner import PlanStep
from alica.prophet.tasks import create_tasks
from tests.conftest import PLANS

ROBOTS = ("r1", "r2", "r3")
WORLD = [
    ("on", ("c", "a")),
    ("ontable", ("a",)),
    ("ontable", ("b",)),
    ("clear", ("c",)),
    ("clear", ("b",)),
    *(("handempty", (r,)) for r in ROBOTS),
]
PLAN = [
    PlanStep("Unstack", ("r1", "c", "a")),
    PlanStep("Putdown", ("r1", "c")),
    PlanStep("Pickup", ("r2", "b")),
    PlanStep("Stack", ("r2", "b", "c")),
    PlanStep("Pickup", ("r3", "a")),
    PlanStep("Stack", ("r3", "a", "b")),
]


@pytest.fixture(scope="module")
def created():
    library = load_library(PLANS / "blocksworld" / "mission.yaml")
    roleset = next(iter(library.rolesets.values()))
    return create_tasks("StackBlocksPlan", PLAN, library, WORLD, ROBOTS, roleset, "Default")


def test_failed_steps_are_kept_off_for_a_while_then_forgotten() -> None:
    keep = KeepOff()
    keep.failed("r2", "Unstack(c, a)", now=10.0)
    keep.failed("r1", "Pickup(b)", now=20.0)
    keep.failed("", "Pickup(b)", now=20.0)  # no robot or no step: nothing to keep off
    assert keep.active(11.0) == (("r1", "Pickup(b)"), ("r2", "Unstack(c, a)"))
    assert keep.active(10.0 + KEEP_OFF_S + 1) == (("r1", "Pickup(b)"),)
    assert keep.active(20.0 + KEEP_OFF_S + 1) == ()


def test_a_barred_robot_is_left_out_of_every_task_holding_its_step(created) -> None:
    labels = [[step.label for step in task] for task in created.tasks]
    index = next(i for i, task in enumerate(labels) if "Pickup(b)" in task)
    barred = bar(created, [("r2", "Pickup(b)")], ROBOTS)
    assert barred.allowed[index] == ("r1", "r3")
    assert barred.pins()[barred.plan.entry_points[index].name] == ("r1", "r3")
    others = [allowed for i, allowed in enumerate(barred.allowed) if i != index]
    assert others == [
        created.allowed[i] if i < len(created.allowed) else None for i in range(len(labels)) if i != index
    ]


def test_a_task_nobody_else_may_take_keeps_its_robots(created) -> None:
    everyone = [(robot, "Pickup(b)") for robot in ROBOTS]
    assert bar(created, everyone, ROBOTS) is created  # a retry beats no robot at all
    assert bar(created, [], ROBOTS) is created


def test_malformed_entries_from_the_network_are_ignored(created) -> None:
    junk = [("r2",), ("r2", 3), "r2:Pickup(b)", None, ("r2", "Pickup(b)", "x")]
    assert bar(created, junk, ROBOTS) is created  # type: ignore[arg-type]


def test_a_task_no_other_role_can_take_keeps_its_robot(created) -> None:
    # r2 and r3 in a role that cannot take the blocks tasks (a scout, say): r1 stays on its failed step
    index = next(i for i, task in enumerate(created.tasks) if "Pickup(b)" in [s.label for s in task])
    role = created.roleset.roles[0].name
    assert bar(created, [("r1", "Pickup(b)")], ROBOTS, {"r1": role, "r2": "Scout", "r3": "Scout"}) is created
    barred = bar(created, [("r1", "Pickup(b)")], ROBOTS, {"r1": role, "r2": role, "r3": "Scout"})
    assert barred.allowed[index] == ("r2", "r3")  # r2 can: the bar holds (r3 is vetoed by the engine anyway)


def test_a_robot_is_kept_off_only_a_step_that_could_still_run(created) -> None:
    # the leader reads the world again after the failure: Pickup(b) still possible for r2 means r2 failed
    # it; b gone from the table (an opponent took it) means the world changed, and r2 is not to blame
    from types import SimpleNamespace

    from alica.lang.fact import Fact
    from alica.prophet.leader import Leader

    leader = SimpleNamespace(team=SimpleNamespace(created=created))
    world = frozenset(Fact(p, a) for p, a in WORLD)
    assert Leader._could_run(leader, ("r2", "Pickup(b)"), world)  # type: ignore[arg-type]
    taken = world - {Fact("ontable", ("b",)), Fact("clear", ("b",))} | {Fact("holding", ("o1", "b"))}
    assert not Leader._could_run(leader, ("r2", "Pickup(b)"), frozenset(taken))  # type: ignore[arg-type]
    assert not Leader._could_run(leader, ("r2", "Stack(z, y)"), world)  # type: ignore[arg-type]  # no such step


def test_a_task_no_other_robot_could_start_now_keeps_its_robot(created) -> None:
    # r2 and r3 hold blocks: none of them could start Pickup(b), so r1 keeps the step it failed
    index = next(i for i, task in enumerate(created.tasks) if "Pickup(b)" in [s.label for s in task])
    busy = [(p, a) for p, a in WORLD if p != "handempty" or a == ("r1",)] + [("holding", ("r2", "x"))]
    assert bar(created, [("r1", "Pickup(b)")], ROBOTS, world=busy) is created  # type: ignore[arg-type]
    free = bar(created, [("r1", "Pickup(b)")], ROBOTS, world=WORLD)  # type: ignore[arg-type]
    assert free.allowed[index] == ("r2", "r3")
