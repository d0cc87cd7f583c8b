"""Frontier extraction, IMPERA Algorithm 1 and the ExploreFrontier skill (issue 16)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from alica.errors import SkillError
from alica.lang.fact import Fact
from alica.skills.exploration import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    coverage,
    extract_frontiers,
    frontier_mask,
    information_gain,
)

F, W, U = FREE, OCCUPIED, UNKNOWN  # free, wall, unknown


def grid(rows: list[str]) -> np.ndarray:
    """'.' free, '#' occupied, '?' unknown; the first string is the top row (highest y)."""
    table = {".": F, "#": W, "?": U}
    return np.array([[table[ch] for ch in row] for row in reversed(rows)], dtype=np.int8)


# -- frontier cells -------------------------------------------------------------


def test_frontier_cells_are_free_cells_next_to_unknown_ones():
    occ = grid(
        [
            "..??",
            ".#??",
            "....",
        ]
    )
    mask = frontier_mask(occ)
    # rows reversed: row 0 is the bottom line "...."
    expected = np.array(
        [
            [False, True, True, True],  # bottom: touching the unknown above, diagonally too
            [False, False, False, False],  # '#' is not free
            [False, True, False, False],  # top: (2,1) touches (2,2) and (1,2)
        ]
    )
    assert (mask == expected).all()


def test_a_fully_known_map_has_no_frontier():
    occ = grid(["...", ".#.", "..."])
    assert not frontier_mask(occ).any()
    assert extract_frontiers(occ, 0.1, (0.0, 0.0)) == []


# -- Algorithm 1 ----------------------------------------------------------------


def test_one_open_region_is_propagated_once_and_shared_by_all_its_frontier_cells():
    occ = grid(["..???"] * 5)  # 15 unknown cells on the right, touching the map's edge
    result = information_gain(occ, reach=50)
    mask = frontier_mask(occ)
    assert mask[:, 1].all() and mask.sum() == 5
    assert result.propagations == 1  # the other four frontier cells were observed (line 16)
    assert (result.gain[mask] == 15).all()
    assert (result.gain[~mask] == 0).all()
    assert result.boundary[mask].all()


def test_an_enclosed_pocket_has_no_boundary_relation_and_its_own_gain():
    occ = grid(
        [
            ".........",
            ".........",
            "..???....",
            "..???..??",
            "..???..??",
            ".........",
        ]
    )
    result = information_gain(occ, reach=50)
    pocket = (slice(1, 5), 1)  # column 1 borders the 3x3 pocket
    assert result.gain[2, 1] == 9 and not result.boundary[2, 1]
    # the 2x2 region at the right edge: gain 4, next to the boundary
    assert result.gain[1, 6] == 4 and result.boundary[1, 6]
    assert result.propagations == 2
    assert pocket  # (documentation of the place)


def test_the_wave_front_stops_after_reach_cells():
    occ = grid([".?????????"])  # a corridor of 9 unknown cells
    for reach in (1, 3, 9, 20):
        assert information_gain(occ, reach=reach).gain[0, 0] == min(reach, 9)


def test_occupied_cells_stop_the_wave_front():
    occ = grid([".?#???"])
    assert information_gain(occ, reach=10).gain[0, 0] == 1


def test_bad_reach_is_refused():
    with pytest.raises(ValueError, match="reach"):
        information_gain(grid([".?"]), reach=0)


@settings(max_examples=60, deadline=None)
@given(
    arrays(np.int8, st.tuples(st.integers(1, 12), st.integers(1, 12)), elements=st.sampled_from([F, W, U])),
    st.integers(1, 6),
)
def test_gain_properties_on_random_grids(occ, reach):
    result = information_gain(occ, reach=reach)
    mask = frontier_mask(occ)
    # every frontier cell has an unknown neighbour, so a gain of at least 1; other cells none
    assert (result.gain[mask] >= 1).all()
    assert (result.gain[~mask] == 0).all()
    # a wave front travels at most reach steps from its frontier cell, over unknown cells only
    assert (result.gain <= min((2 * reach + 1) ** 2, int((occ == U).sum()))).all()
    assert result.propagations <= int(mask.sum())


def test_remembered_wave_fronts_give_what_fresh_ones_give_after_the_map_changed():
    from alica.skills.exploration import frontiers

    rng = np.random.default_rng(3)
    occ = np.full((60, 70), U, dtype=np.int8)
    occ[20:40, 15:50] = F
    occ[rng.random(occ.shape) < 0.03] = W
    for _ in range(4):
        first = information_gain(occ, reach=8)
        frontiers._PROPAGATIONS.clear()
        fresh = information_gain(occ, reach=8)
        assert np.array_equal(first.gain, fresh.gain) and np.array_equal(first.boundary, fresh.boundary)
        assert first.propagations == fresh.propagations
        occ[rng.integers(0, 60, 40), rng.integers(0, 70, 40)] = F  # the robot saw some more


@settings(max_examples=40, deadline=None)
@given(
    arrays(np.int8, st.tuples(st.integers(1, 14), st.integers(1, 14)), elements=st.sampled_from([F, W, U])),
    st.sampled_from([0.05, 0.1, 0.25]),
    st.floats(0.01, 0.6),
)
def test_clearance_is_the_distance_to_the_nearest_occupied_cell(occ, resolution, clearance):
    from scipy import ndimage

    from alica.skills.exploration.frontiers import _clear

    rows, cols = np.nonzero(frontier_mask(occ))
    kept = _clear(occ == W, rows, cols, resolution, clearance)
    if (occ == W).any():
        far = ndimage.distance_transform_edt(occ != W) * resolution >= clearance
        assert np.array_equal(kept, far[rows, cols])
    else:
        assert kept.all()


# -- candidates -----------------------------------------------------------------


def test_candidates_lie_on_frontier_cells_with_names_from_their_place_best_first():
    occ = np.full((40, 60), U, dtype=np.int8)
    occ[:, :20] = F  # known on the left: a straight frontier at column 19, 4 m long (0.1 m cells)
    occ[10:14, 30:34] = F  # a small known island in the unknown
    cands = extract_frontiers(occ, 0.1, (-3.0, -2.0), reach=1.0, chunk=2.0)
    names = [c.name for c in cands]
    assert len(names) == len(set(names))
    mask = frontier_mask(occ)
    for c in cands:
        row, col = c.cell
        assert mask[row, col]
        assert c.position == pytest.approx((-3.0 + (col + 0.5) * 0.1, -2.0 + (row + 0.5) * 0.1))
        assert c.name == f"f_{col // 20}_{row // 20}"
    gains = [c.gain for c in cands]
    assert gains == sorted(gains, reverse=True)
    assert {c.name for c in cands if c.cell[1] == 19} == {"f_0_0", "f_0_1"}  # the long frontier in two chunks


def test_clearance_drops_frontier_cells_next_to_obstacles():
    occ = grid(["....#???"] * 6)
    assert extract_frontiers(occ, 0.1, (0.0, 0.0), clearance=0.0) == []  # '#' hides the unknown
    occ = grid(["...#?"] + ["...??"] * 6)
    near = extract_frontiers(occ, 0.1, (0.0, 0.0), clearance=0.0, min_size=1)
    far = extract_frontiers(occ, 0.1, (0.0, 0.0), clearance=0.25, min_size=1)
    assert near and all(c.cell[0] < 5 for c in far)


def test_coverage_counts_known_free_cells():
    occ = grid(["..??", "#.??"])
    truth_free = np.ones(occ.shape, dtype=bool)
    truth_free[0, 0] = False
    assert coverage(occ) == pytest.approx(0.5)
    assert coverage(occ, truth_free) == pytest.approx(3 / 7)


# -- the skill ----------------------------------------------------------------


@pytest.fixture
def small_field():
    from alica.worldsim.scenarios import lunar

    world = lunar(seed=0, rocks=8, samples=0, size=14.0)
    try:
        yield world
    finally:
        world.close()


def test_explore_frontier_alone_covers_a_small_field_and_ends_with_explored(small_field, skill_run):
    from alica.skills.mapping import team_map
    from alica.worldmodel import WorldModel
    from alica.worldsim.grid import OccupancyGrid

    wm = WorldModel("scout", clock=small_field.clock)
    run = skill_run("ExploreFrontier", small_field, "scout", {}, timeout=400.0, world_model=wm)
    assert run.ok, (run.reason, run.trace[-5:])
    assert Fact("explored", ()) in run.facts
    # stale frontiers were retracted: no frontier keeps a gain in the world model
    assert not [k for k in run.values if k.predicate == "gain"]
    # coverage scored against the ground truth (the test may read it; the skill does not)
    view = team_map(wm)  # the robot mapped as it explored, into the team map
    assert view is not None
    truth = OccupancyGrid.from_obstacles(small_field.ground_truth_obstacles(), small_field.bounds, view.resolution)
    occ = view.occupancy()
    free = truth.cells == 0
    assert truth.cells.shape == occ.shape
    assert coverage(occ, free) >= 0.9


def _first_frontier(run) -> tuple[float, float]:
    import re

    for entry in run.trace:
        found = re.search(r"to frontier \S+ at \((-?[\d.]+), (-?[\d.]+)\)", str(entry["feedback"]))
        if found:
            return float(found.group(1)), float(found.group(2))
    raise AssertionError(f"the robot never headed for a frontier: {run.trace[:5]}")


def test_its_own_choice_keeps_away_from_where_the_others_head(skill_run):
    """Without a solution (alone, no engine) the robot picks a frontier more than `spacing` from the others' headings."""
    import math

    from alica.skills.exploration.skill import HEADING
    from alica.worldmodel import WorldModel
    from alica.worldsim.scenarios import lunar

    def first(heading: tuple[float, float] | None) -> tuple[float, float]:
        world = lunar(seed=0, rocks=8, samples=0, size=14.0)
        try:
            wm = WorldModel("scout", clock=world.clock)
            if heading is not None:
                wm.set(HEADING, "stummel", value=heading)
            return _first_frontier(skill_run("ExploreFrontier", world, "scout", {}, timeout=1.0, world_model=wm))
        finally:
            world.close()

    best = first(None)
    other = first(best)  # stummel heads for it now
    assert math.dist(other, best) > 4.0


@pytest.mark.parametrize(
    ("params", "name"),
    [
        ({"spacing": -1.0}, "spacing"),
        ({"reach": 0}, "reach"),
        ({"min_gain": "lots"}, "min_gain"),
        ({"period": float("nan")}, "period"),
        ({"frontier": 3}, "frontier"),
        ({"tolerance": True}, "tolerance"),
    ],
)
def test_bad_parameters_give_a_clear_error(small_field, skill_run, params, name):
    with pytest.raises(SkillError, match=f"'{name}'"):
        skill_run("ExploreFrontier", small_field, "scout", params, timeout=1.0)


# -- the Explore plan (Fig. 7) ------------------------------------------------


def test_the_explore_plan_maps_localizes_and_explores_a_field_as_a_team(tmp_path):
    """One robot builds the first map (GetMap), the other localizes in it; both explore with Eq. 7-8 until explored."""
    from alica.engine import SimulatedTeam, TraceRecorder
    from alica.io import load_library
    from alica.io.loader import plans_dir
    from alica.lang.skill_plugins import default_registry
    from alica.skills.mapping import team_map
    from alica.worldsim.grid import OccupancyGrid
    from alica.worldsim.scenarios import lunar

    registry = default_registry()
    library = load_library(plans_dir() / "skills" / "explore.yaml", skills=registry)
    world = lunar(seed=3, rocks=8, samples=0, size=16.0)
    try:
        start = {name: robot.pose[:2] for name, robot in world.robots.items()}
        recorder = TraceRecorder()
        team = SimulatedTeam(
            library,
            "Explore",
            {"scout": "Scout", "stummel": "Stummel"},
            seed=0,
            skill_registry=registry,
            world=world,
            observers=[recorder],
        )
        team.run(until_done=True, max_time=300.0)
        summary = team.summary()
        assert summary["success"], summary
        transitions = {(e["agent"], e["source"], e["target"]) for e in recorder.events if e["event"] == "transition"}
        # Fig. 7: the GetMap robot maps, the other waits for the map and localizes; both explore
        mapper = next(a for a, s, t in transitions if s == "Mapping")
        other = "stummel" if mapper == "scout" else "scout"
        assert (mapper, "Mapping", "ExploreAfterMapping") in transitions
        assert (other, "WaitForMap", "Localize") in transitions
        assert (other, "Localize", "ExploreFrontiers") in transitions
        # the team's constraints chose frontiers (Eq. 7-8), solved and shared through the world model
        solves = [e for e in recorder.events if e["event"] == "solve" and e["status"] == "solved"]
        assert solves and all("frontier" in v for s in solves for a, v in s["values"].items() if a)
        # both robots drove, and the team map covers the field
        for name, robot in world.robots.items():
            if name in ("scout", "stummel"):
                x, y = start[name]
                assert abs(robot.pose[0] - x) + abs(robot.pose[1] - y) > 1.0, name
        wm = team.engines[other].world_model
        assert wm.holds("explored")
        view = team_map(wm)
        assert view is not None
        truth = OccupancyGrid.from_obstacles(world.ground_truth_obstacles(), world.bounds, view.resolution)
        assert coverage(view.occupancy(), truth.cells == 0) >= 0.9
    finally:
        world.close()


def test_the_explore_plan_runs_from_the_command_line(capsys):
    import json

    from alica.app.cli import main
    from alica.io.loader import plans_dir

    argv = ["run", str(plans_dir() / "skills" / "explore.yaml"), "--agents", "scout:Scout,stummel:Stummel"]
    argv += ["--world", "lunar", "--size", "12", "--rocks", "4", "--samples", "0", "--seed", "1", "--json"]
    code = main([*argv, "--time-limit", "120"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["success"], summary
    assert {"BuildMap", "Localize", "ExploreFrontier"} <= set(summary["skills"]["real"])
    assert not summary["skills"]["stand_ins"]


def test_when_the_mapper_crashes_the_other_robot_finishes_the_exploration(capsys):
    import json

    from alica.app.cli import main
    from alica.io.loader import plans_dir

    argv = ["run", str(plans_dir() / "skills" / "explore.yaml"), "--agents", "scout:Scout,stummel:Stummel"]
    argv += ["--world", "lunar", "--size", "12", "--rocks", "4", "--samples", "0", "--seed", "1", "--json"]
    code = main([*argv, "--crash", "scout@3", "--loss", "0.1", "--time-limit", "200"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["success"], summary
    agents = summary["agents"]
    assert agents["scout"]["status"] == "crashed" and agents["stummel"]["status"] == "success"
    assert agents["stummel"]["tasks"][-1] == "GetMap"  # it took over the crashed mapper's task
