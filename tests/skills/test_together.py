"""Several robots running their own sequences of skills at once in one world (alica.skills.together)."""

from __future__ import annotations

import math

import pytest

from alica.errors import SkillError
from alica.skills.together import SKIPPED, SkillCall, run_together
from alica.worldsim.objects import SAMPLE_KINDS
from alica.worldsim.world import World


@pytest.fixture
def two_robots():
    """A small field: sample ``a`` at (1.5, 1.5) with stummel ``r1`` beside it, stummel ``r2`` at (4.5, 4.5)."""
    with World(0, bounds=(-1.0, -1.0, 10.0, 10.0)) as world:
        world.add_sample("a", SAMPLE_KINDS[0], (1.5, 1.5))
        world.add_robot("stummel", "r1", (2.4, 1.5, math.pi))
        world.add_robot("stummel", "r2", (4.5, 4.5, 0.0))
        world.step(0.1)
        yield world


def test_two_robots_run_their_sequences_at_the_same_time(two_robots):
    world = two_robots
    runs = run_together(
        world,
        {
            "r1": [
                SkillCall("Pickup", {"object": "a"}, label="do"),
                SkillCall("Putdown", {"object": "a", "target": [1.5, 1.5]}, chained=True, label="do"),
            ],
            "r2": [SkillCall("MoveToPosition", {"goal": [7.5, 4.5]}, label="goto")],
        },
        timeout=90.0,
    )
    r1, r2 = runs["r1"], runs["r2"]
    assert r1.ok and r2.ok, (r1.runs, r2.runs)
    assert [run.skill for run in r1.runs] == ["Pickup", "Putdown"]
    # at once: r2 drove while r1 picked up (both started in the first round); in order: Putdown after Pickup
    pickup_start, putdown_start = r1.starts
    (drive_start,) = r2.starts
    assert pickup_start == drive_start
    assert putdown_start is not None and putdown_start >= pickup_start + r1.runs[0].sim_time_s
    assert drive_start + r2.runs[0].sim_time_s > pickup_start  # the drive overlapped the pickup
    assert math.dist(world.robots["r2"].pose[:2], (7.5, 4.5)) <= 0.3
    assert math.dist(world.objects["a"].position()[:2], (1.5, 1.5)) < 0.1  # set down where it was
    # the world advanced once for both: the run took as long as the longer sequence, not the sum
    longest = max(sum(run.sim_time_s for run in r1.runs), r2.runs[0].sim_time_s)
    assert world.now() < 0.1 + longest + 1.0


def test_a_chained_skill_is_skipped_after_a_failure_and_the_next_unchained_one_runs(two_robots):
    runs = run_together(
        two_robots,
        {
            "r1": [
                SkillCall("DetectCircles", {"max_range": 0.5}),  # nothing that close: it fails
                SkillCall("Pickup", {"object": "a"}, chained=True),
                SkillCall("MoveToPosition", {"goal": [1.5, 4.5]}),
            ],
            "r2": [],
        },
        timeout=60.0,
    )
    detect, pickup, drive = runs["r1"].runs
    assert detect.status == "failure" and "no circle" in detect.reason
    assert pickup.status == SKIPPED and "DetectCircles before it did not succeed" in pickup.reason
    assert drive.ok and runs["r1"].starts[1] is None
    assert runs["r2"].runs == [] and runs["r2"].ok


def test_the_time_bound_stops_running_skills_and_skips_the_rest(two_robots):
    runs = run_together(
        two_robots,
        {
            "r1": [SkillCall("Idle", {"duration": 50.0}), SkillCall("Idle", {"duration": 1.0})],
            "r2": [SkillCall("Idle", {"duration": 1.0})],
        },
        timeout=3.0,
    )
    first, second = runs["r1"].runs
    assert first.status == "timeout" and first.reason == "stopped at the time bound of 3 s (standing still)"
    assert second.status == SKIPPED and "time bound" in second.reason
    assert runs["r2"].ok
    assert two_robots.now() == pytest.approx(0.1 + 3.0, abs=0.11)


def test_a_fault_injected_when_a_skill_starts_fails_it(two_robots):
    def crash_r2_when_it_drives(world, robot, index):
        if robot == "r2" and index == 1 and not world.robots["r2"].crashed:
            world.faults.crash("r2")

    runs = run_together(
        two_robots,
        {"r2": [SkillCall("Idle", {"duration": 0.5}), SkillCall("MoveToPosition", {"goal": [7.5, 4.5]})]},
        timeout=60.0,
        on_tick=crash_r2_when_it_drives,
    )
    idle, drive = runs["r2"].runs
    assert idle.ok and drive.status in ("failure", "timeout")
    assert math.dist(two_robots.robots["r2"].pose[:2], (4.5, 4.5)) < 0.01  # crashed before it moved


def test_every_call_is_checked_before_any_skill_runs(two_robots):
    with pytest.raises(SkillError, match="no robot named 'r9'"):
        run_together(two_robots, {"r9": [SkillCall("Idle")]})
    with pytest.raises(SkillError, match="needs the parameter 'goal'"):
        run_together(two_robots, {"r1": [SkillCall("Idle")], "r2": [SkillCall("MoveToPosition")]})
    assert two_robots.now() == pytest.approx(0.1, abs=0.01)
