"""The ProTaP grid in metres and the lunar executor, below the command line (alica.app.protap_world).

Here rather than in an earlier folder: OMPL has one random generator per process, seeded by the first
planner that asks, and the demos' tests (tests/demos) compare simulated times of seeded runs.
"""

from __future__ import annotations

import itertools
import math

import pytest

from alica.app.protap_world import GridLayout, LunarExecutor, build_world, sample_of, uda_skill
from alica.errors import AlicaError
from alica.lang.skill_plugins import default_registry
from alica.prophet.protap import (
    MANIPULATION,
    USER_DEFINED,
    Action,
    ActionCall,
    Goal,
    ProblemSpec,
    Robot,
    RobotCalls,
)
from alica.worldsim.robots import ROBOT_KINDS


@pytest.mark.parametrize(("width", "height", "robots"), [(3, 3, 2), (5, 2, 6), (1, 4, 1)])
def test_every_robot_has_its_own_slot_inside_every_cell(width: int, height: int, robots: int) -> None:
    layout = GridLayout(width, height, robots)
    radius = ROBOT_KINDS["stummel"].radius
    xmin, ymin, xmax, ymax = layout.bounds
    for cell in itertools.product(range(width), range(height)):
        assert layout.cell_at(*layout.centre(cell)) == cell
        slots = [layout.slot(cell, robot) for robot in range(robots)]
        for x, y in slots:
            assert (
                layout.cell_at(x, y) == cell and xmin + radius < x < xmax - radius and ymin + radius < y < ymax - radius
            )
        assert all(math.dist(a, b) >= 2 * radius for a, b in itertools.combinations(slots, 2))
        # a rock keeps clear of the cell's centre (the sample) and of every slot with the robot on it
        cx, cy, clear = next(disc for disc in layout.keep_clear() if disc[:2] == layout.centre(cell))
        assert all(math.dist((cx, cy), slot) + radius < clear for slot in slots)
    assert layout.cell_at(xmax + 5, ymin - 5) == (width - 1, 0)  # off the grid: the nearest cell


def test_a_layout_refuses_what_does_not_fit() -> None:
    with pytest.raises(AlicaError, match="needs a field of 45 m"):
        GridLayout(12, 4, 2, cell=3.5)
    with pytest.raises(AlicaError, match="use at most 6 robots"):
        GridLayout(3, 3, 7)
    with pytest.raises(AlicaError, match="too small"):
        GridLayout(3, 3, 2, cell=2.0)
    spec = ProblemSpec(
        robots=(Robot("r1", (0, 0)),),
        actions=(Action("a1"), Action("a2")),
        goals=(Goal("g1", "a1", (1, 1)), Goal("g2", "a2", (1, 1))),
        width=2,
        height=2,
    )
    with pytest.raises(AlicaError, match="goals g1 and g2 share the cell"):
        sample_of(spec)


def test_a_do_without_a_goal_at_the_robots_cell_fails_without_running_a_skill() -> None:
    spec = ProblemSpec(
        robots=(Robot("r1", (0, 0)), Robot("r2", (1, 0))),
        actions=(Action("a1", MANIPULATION), Action("a2", USER_DEFINED)),
        goals=(Goal("g1", "a1", (1, 0)),),
        width=2,
        height=1,
    )
    layout = GridLayout(2, 1, 2)
    registry = default_registry([])
    with build_world(spec, layout, seed=0, rocks=0) as world:
        executor = LunarExecutor(world, spec, layout, registry, uda_skill(registry, "DetectCircles", layout))
        r1, r2 = executor.execute(
            [
                RobotCalls(0, "r1", (0, 0), ActionCall("a2", USER_DEFINED, (0, 0), ())),
                RobotCalls(1, "r2", (1, 0), ActionCall("a1", MANIPULATION, (1, 0), ("g1",))),
            ]
        )
        assert r1.do_ok is False and r1.activities == () and r1.cell == (0, 0)
        assert r1.reason == "do(r1, a2) at (0, 0): no goal of a2 there, so no sample to act on"
        assert r2.do_ok is True and [a.name for a in r2.activities] == ["Pickup", "Putdown"]
        assert math.dist(world.objects["g1"].position()[:2], layout.centre((1, 0))) < 0.1
