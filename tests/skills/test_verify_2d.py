"""Verify2DObject (IMPERA Fig. 13): DetectCircles, CropCandidate, BlobDetect and ClassifySample on rendered scenes.

The scenes are small lunar fields with samples placed in front of Scout, rocks
and a robot among them, and realistic lidar noise (1 cm). Ground truth only
scores the results here; the skills see lidar ranges and pixels.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from alica.errors import SkillError
from alica.skills.vision2d_data import CANDIDATES, CROP, MEMORY, Candidate, Candidates, Memory
from alica.worldmodel import WorldModel
from alica.worldsim.objects import SAMPLE_KINDS

pytest.importorskip("pybullet")
pytest.importorskip("cv2")

PIPELINE = ("DetectCircles", "CropCandidate", "BlobDetect", "ClassifySample")


def _field(seed: int = 0):
    from alica.worldsim.scenarios import lunar

    world = lunar(seed=seed, rocks=0, samples=0, size=14.0)
    world.noise = replace(world.noise, lidar_sigma=0.01)
    return world


def _ahead(world, distance: float, bearing_deg: float) -> tuple[float, float]:
    x, y, yaw = world.robots["scout"].pose
    a = yaw + math.radians(bearing_deg)
    return x + distance * math.cos(a), y + distance * math.sin(a)


def _pipeline(skill_run, world, scratch, wm, rounds=4):
    """The plan's loop: look at the nearest unverified candidate in view until a sample is found."""
    runs = []
    for _ in range(rounds):
        runs = []
        for name in PIPELINE:
            run = skill_run(name, world, "scout", {}, scratch=scratch, world_model=wm)
            runs.append(run)
            if not run.ok:
                break
        if runs[-1].ok or len(runs) < 3:  # a sample, or nothing (more) to look at
            break
    return runs


# -- DetectCircles ---------------------------------------------------------------------------------


def test_detect_circles_reports_samples_not_rocks_or_robots(skill_run):
    world = _field()
    try:
        samples = [_ahead(world, d, b) for d, b in ((1.5, -20.0), (3.0, 10.0), (4.5, 150.0), (6.0, -100.0))]
        for i, xy in enumerate(samples):
            world.add_sample("abcd"[i], SAMPLE_KINDS[i], xy)
        rocks = [(_ahead(world, 2.5, 40.0), 0.2), (_ahead(world, 4.0, -60.0), 0.5), (_ahead(world, 3.0, 100.0), 0.3)]
        for i, (xy, r) in enumerate(rocks):
            world.add_rock(f"rock{i}", xy, r, seed=i)
        world.robots["stummel"].set_pose(*_ahead(world, 3.5, -35.0), 0.0)
        world.step(0.2)
        scratch: dict[str, object] = {}
        wm = WorldModel("scout", clock=world.clock)
        run = skill_run("DetectCircles", world, "scout", {}, scratch=scratch, world_model=wm)
        assert run.ok, run.reason
        circles = CANDIDATES.require(scratch, "test").items
        found = [(c.x, c.y) for c in circles]
        for xy in samples:
            assert min(math.dist(xy, f) for f in found) < 0.03, (xy, found)
        assert len(circles) == len(samples), circles
        for c in circles:
            assert abs(c.radius - 0.03) < 0.02
            assert run.holds("candidate", c.id)
            assert wm.get("candidate_pos", c.id) is not None
        assert [c.range for c in circles] == sorted(c.range for c in circles)
    finally:
        world.close()


def test_detect_circles_waits_for_an_unverified_candidate(skill_run):
    world = _field()
    try:
        world.robots["stummel"].set_pose(-6.0, -6.0, 0.0)  # the edge of a robot may look like a circle for a scan
        world.robots["amparo"].set_pose(-6.0, 6.0, 0.0)
        xy = _ahead(world, 3.0, 60.0)
        started = world.now()

        def drop_a_sample(w, _behaviour):
            if w.now() - started >= 1.0 and "a" not in w.objects:
                w.add_sample("a", SAMPLE_KINDS[1], xy)

        scratch: dict[str, object] = {}
        run = skill_run("DetectCircles", world, "scout", {"wait": 5.0}, scratch=scratch, on_tick=drop_a_sample)
        assert run.ok, run.reason
        assert world.now() - started >= 1.0  # it kept scanning until the sample was there
        (c,) = CANDIDATES.require(scratch, "test")
        assert math.dist((c.x, c.y), xy) < 0.03
        # verified: the next look waits for another one and gives up after the wait
        MEMORY.setdefault(scratch, Memory).verdicts[c.id] = "green_black_red"
        run = skill_run("DetectCircles", world, "scout", {"wait": 2.0, "period": 0.5}, scratch=scratch)
        assert run.status == "failure", run.reason
        assert "no unverified candidate within 8 m in 2." in run.reason and "1 verified" in run.reason
    finally:
        world.close()


def test_detections_are_placed_by_the_pose_estimate(skill_run):
    """The skills know only the estimate: a shifted and turned estimate shifts and turns what they report."""
    world = _field()
    try:
        scout = world.robots["scout"]
        xy = _ahead(world, 2.5, 10.0)
        world.add_sample("a", "red-white-red", xy)
        world.step(0.2)
        x, y, yaw = scout.pose
        turn = math.radians(3.0)
        scout.set_estimate((x + 0.3, y - 0.2, yaw + turn))
        scratch: dict[str, object] = {}
        wm = WorldModel("scout", clock=world.clock)
        runs = _pipeline(skill_run, world, scratch, wm, rounds=1)
        assert [r.status for r in runs] == ["success"] * 4, [r.reason for r in runs]
        # where the robot believes the sample is: the true offset from the robot, turned and moved with the estimate
        dx, dy = xy[0] - x, xy[1] - y
        believed = (
            x + 0.3 + dx * math.cos(turn) - dy * math.sin(turn),
            y - 0.2 + dx * math.sin(turn) + dy * math.cos(turn),
        )
        assert math.dist(wm.get("pos", "red_white_red"), believed) < 0.03
        assert math.dist(wm.get("pos", "red_white_red"), xy) > 0.25
    finally:
        world.close()


def test_detect_circles_of_another_radius_finds_nothing_here(skill_run):
    world = _field()
    try:
        world.add_sample("a", SAMPLE_KINDS[0], _ahead(world, 2.0, 0.0))
        world.step(0.2)
        run = skill_run("DetectCircles", world, "scout", {"radius": 0.12, "tolerance": 0.02})
        assert run.status == "failure" and "no circle" in run.reason
    finally:
        world.close()


# -- the whole pipeline on every kind ---------------------------------------------------------------


@pytest.mark.parametrize("kind", SAMPLE_KINDS)
def test_each_kind_is_found_and_classified(skill_run, kind):
    world = _field(seed=SAMPLE_KINDS.index(kind))
    try:
        xy = _ahead(world, 1.5 + 0.5 * SAMPLE_KINDS.index(kind), -15.0 + 6.0 * SAMPLE_KINDS.index(kind))
        world.add_sample("a", kind, xy)
        world.add_rock("rock1", _ahead(world, 3.0, 25.0), 0.3, seed=3)
        world.step(0.2)
        scratch: dict[str, object] = {}
        wm = WorldModel("scout", clock=world.clock)
        wm.set("sample_kind", "a", value=kind)  # the mission knows which code sample a carries
        runs = _pipeline(skill_run, world, scratch, wm)
        assert [r.status for r in runs] == ["success"] * 4, [r.reason for r in runs]
        assert wm.holds("found", "a")
        assert wm.get("sample_kind", "a") == kind
        assert math.dist(wm.get("pos", "a"), xy) < 0.05
        assert 0.5 <= wm.get("confidence", "a") <= 1.0
        assert not wm.holds("candidate", CROP.require(scratch, "test").candidate.id)
    finally:
        world.close()


def test_crop_candidate_renders_only_the_crops_part_of_the_frame_with_its_pixels(skill_run):
    from alica.worldsim.robot_camera import robot_camera

    world = _field(seed=2)
    try:
        world.noise = replace(world.noise, pixel_sigma=0.0, depth_sigma=0.0)
        world.add_sample("a", "green-white-red", _ahead(world, 2.0, 10.0))
        world.add_sample("b", "red-black-red", _ahead(world, 3.0, -12.0))
        world.step(0.2)
        scratch: dict[str, object] = {}
        assert skill_run("DetectCircles", world, "scout", {}, scratch=scratch).ok
        crop_run = skill_run("CropCandidate", world, "scout", {}, scratch=scratch)
        assert crop_run.ok, crop_run.reason
        crop = CROP.require(scratch, "test")
        whole = robot_camera(world.robots["scout"], width=752, height=480, pan=crop.pan, believed=True)
        u0, v0, u1, v1 = crop.box
        assert np.array_equal(crop.rgb, whole.rgb[v0:v1, u0:u1])
        assert (u1 - u0) * (v1 - v0) < 752 * 480 // 10
    finally:
        world.close()


def test_an_unknown_sample_is_named_after_its_kind(skill_run):
    world = _field()
    try:
        world.add_sample("a", "red-white-red", _ahead(world, 2.0, 5.0))
        world.step(0.2)
        wm = WorldModel("scout", clock=world.clock)
        wm.assert_fact("holding", "amparo", "red_white_red")  # amparo crashed holding it; it fell
        runs = _pipeline(skill_run, world, {}, wm)
        assert runs[-1].ok, [r.reason for r in runs]
        assert wm.holds("found", "red_white_red") and wm.get("sample_kind", "red_white_red") == "red-white-red"
        assert wm.holds("onground", "red_white_red") and not wm.holds("holding", "amparo", "red_white_red")
    finally:
        world.close()


# -- a closer look disagrees ------------------------------------------------------------------------


def _false_candidate(world, scratch, xy, cid="scout_c9"):
    x, y, _ = world.robots["scout"].pose
    candidate = Candidate(cid, xy[0], xy[1], radius=0.03, range=math.dist((x, y), xy), bearing=0.0, points=3)
    CANDIDATES.put(scratch, Candidates((candidate,), radius=0.03))


def test_a_rock_candidate_is_retracted_and_recorded_invalid(skill_run):
    world = _field()
    try:
        rock = _ahead(world, 2.5, 0.0)
        world.add_rock("rock1", rock, 0.25, seed=1)
        world.step(0.2)
        scratch: dict[str, object] = {}
        wm = WorldModel("scout", clock=world.clock)
        wm.assert_fact("candidate", "scout_c9")
        _false_candidate(world, scratch, _ahead(world, 2.25, 0.0))  # the rock's near face
        crop = skill_run("CropCandidate", world, "scout", {}, scratch=scratch, world_model=wm)
        assert crop.ok, crop.reason
        blobs = skill_run("BlobDetect", world, "scout", {}, scratch=scratch, world_model=wm)
        assert blobs.status == "failure" and "no green or red blob" in blobs.reason
        assert not wm.holds("candidate", "scout_c9") and wm.holds("invalid", "scout_c9")
    finally:
        world.close()


def test_a_red_robot_is_no_sample(skill_run):
    world = _field()
    try:
        world.robots["amparo"].set_pose(*_ahead(world, 2.5, 0.0), 0.0)
        world.step(0.2)
        scratch: dict[str, object] = {}
        wm = WorldModel("scout", clock=world.clock)
        # the laser does not take the robot for a sample
        assert not skill_run("DetectCircles", world, "scout", {}, scratch=scratch, world_model=wm).ok
        # a candidate on its front (as a broken scan might give) is refused by the closer look
        _false_candidate(world, scratch, _ahead(world, 2.5 - 0.35 + 0.03, 0.0))
        runs = [skill_run(n, world, "scout", {}, scratch=scratch, world_model=wm) for n in PIPELINE[1:3]]
        assert runs[0].ok, runs[0].reason
        if runs[1].ok:
            last = skill_run("ClassifySample", world, "scout", {}, scratch=scratch, world_model=wm)
            assert last.status == "failure" and "no sample" in last.reason
        assert wm.holds("invalid", "scout_c9")
        assert not any(f.predicate == "found" for f in wm.facts())
    finally:
        world.close()


def test_a_found_sample_that_is_gone_is_retracted(skill_run):
    world = _field()
    try:
        xy = _ahead(world, 2.0, 0.0)
        sample = world.add_sample("a", "green-black-red", xy)
        world.step(0.2)
        scratch: dict[str, object] = {}
        wm = WorldModel("scout", clock=world.clock)
        runs = _pipeline(skill_run, world, scratch, wm)
        assert runs[-1].ok and wm.holds("found", "green_black_red") and wm.holds("onground", "green_black_red")
        world.client.resetBasePositionAndOrientation(sample.body_id, (5.5, 5.5, 0.05), (0, 0, 0, 1))
        world.step(0.1)
        skill_run("CropCandidate", world, "scout", {}, scratch=scratch, world_model=wm)
        look = skill_run("BlobDetect", world, "scout", {}, scratch=scratch, world_model=wm)
        assert look.status == "failure"
        assert not wm.holds("found", "green_black_red") and not wm.holds("onground", "green_black_red")
    finally:
        world.close()


def test_the_camera_pans_to_a_candidate_behind_the_robot(skill_run):
    world = _field()
    try:
        xy = _ahead(world, 2.0, 175.0)
        world.add_sample("a", "green-black-red", xy)
        world.step(0.2)
        scratch: dict[str, object] = {}
        wm = WorldModel("scout", clock=world.clock)
        runs = _pipeline(skill_run, world, scratch, wm, rounds=1)
        assert [r.status for r in runs] == ["success"] * 4, [r.reason for r in runs]
        assert abs(CROP.require(scratch, "test").pan) > math.radians(150)  # turned round (pan limit 160 deg)
        assert wm.holds("found", "green_black_red")
        assert math.dist(wm.get("pos", "green_black_red"), xy) < 0.05
    finally:
        world.close()


def test_crop_fails_clearly_when_no_candidate_is_in_reach(skill_run):
    world = _field()
    try:
        world.add_sample("a", SAMPLE_KINDS[0], _ahead(world, 5.6, 90.0))
        world.step(0.2)
        scratch: dict[str, object] = {}
        assert skill_run("DetectCircles", world, "scout", {}, scratch=scratch).ok
        run = skill_run("CropCandidate", world, "scout", {}, scratch=scratch)
        assert run.status == "failure" and "beyond the 5 m" in run.reason
        none = skill_run("CropCandidate", world, "scout", {}, scratch={})
        assert none.status == "failure" and "DetectCircles first" in none.reason
        # Amparo's stereo camera has no pan unit: a candidate behind it is out of reach
        x, y, yaw = world.robots["amparo"].pose
        behind = Candidate("c1", x - 2.0 * math.cos(yaw), y - 2.0 * math.sin(yaw), 0.03, 2.0, math.pi, 3)
        scratch = {}
        CANDIDATES.put(scratch, Candidates((behind,), radius=0.03))
        run = skill_run("CropCandidate", world, "amparo", {}, scratch=scratch)
        assert run.status == "failure" and "out of the camera's reach (pan +-0 deg)" in run.reason
    finally:
        world.close()


def test_a_candidate_the_camera_cannot_see_goes_last(skill_run):
    """A candidate the lidar sees below a rock's overhang is hidden from the camera: the next crop takes another."""
    world = _field()
    try:
        world.add_sample("a", "green-white-red", _ahead(world, 3.0, -10.0))
        world.step(0.2)
        scratch: dict[str, object] = {}
        assert skill_run("DetectCircles", world, "scout", {}, scratch=scratch).ok
        (seen,) = CANDIDATES.require(scratch, "test")
        ghost = replace(seen, id="ghost", x=seen.x + 0.5, y=seen.y + 0.3)  # no sample there: a hole in the view
        ghost = replace(ghost, range=math.dist(world.robots["scout"].estimate[:2], (ghost.x, ghost.y)))
        CANDIDATES.put(scratch, Candidates(tuple(sorted([seen, ghost], key=lambda c: c.range)), radius=0.03))
        MEMORY.setdefault(scratch, Memory).unseen["ghost"] = world.now()
        run = skill_run("CropCandidate", world, "scout", {}, scratch=scratch)
        assert run.ok and CROP.require(scratch, "test").candidate.id == seen.id, run.reason
    finally:
        world.close()


# -- parameters and the command line --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("skill", "params", "words"),
    [
        ("DetectCircles", {"radius": -0.1}, "'radius'"),
        ("DetectCircles", {"radius": 0.03, "tolerance": 0.05}, "'tolerance'"),
        ("DetectCircles", {"n_rays": 4}, "'n_rays'"),
        ("DetectCircles", {"max_range": 0.0}, "'max_range'"),
        ("DetectCircles", {"wait": -1.0}, "'wait'"),
        ("DetectCircles", {"wait": "soon"}, "'wait'"),
        ("DetectCircles", {"period": 0.0}, "'period'"),
        ("CropCandidate", {"retry": -1.0}, "'retry'"),
        ("CropCandidate", {"margin": -1.0}, "'margin'"),
        ("CropCandidate", {"width": 2}, "'width'"),
        ("BlobDetect", {"colours": ["purple"]}, "'colours'"),
        ("BlobDetect", {"min_area": 0}, "'min_area'"),
        ("ClassifySample", {"min_confidence": 2.0}, "'min_confidence'"),
    ],
)
def test_bad_parameters_give_clear_errors(skill_run, lunar_world, skill, params, words):
    with pytest.raises(SkillError, match=words):
        skill_run(skill, lunar_world, "scout", params)


def test_amparo_has_no_2d_lidar(skill_run, lunar_world):
    with pytest.raises(SkillError, match="no 2D lidar"):
        skill_run("DetectCircles", lunar_world, "amparo", {})


def test_cli_runs_detect_circles_in_the_lunar_world():
    out = subprocess.run(
        [sys.executable, "-m", "alica.app.cli", "skill", "run", "DetectCircles", "--world", "lunar"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    text = out.stdout + out.stderr
    assert "DetectCircles on scout" in text and "Traceback" not in text
    assert out.returncode in (0, 1)


# -- the plan --------------------------------------------------------------------------------------


def test_the_verify_plan_finds_a_sample_in_the_engine(tmp_path):
    from pathlib import Path

    from alica.engine import SimulatedTeam
    from alica.io import Loader
    from alica.lang.skill_plugins import default_registry

    root = Path(__file__).resolve().parents[2] / "plans"
    entry = tmp_path / "verify.yaml"
    entry.write_text(
        f"alica: 1\nimports: [{root / 'roles.yaml'}, {root / 'skills' / 'verify_2d_object.yaml'}]\n", encoding="utf-8"
    )
    registry = default_registry()
    library = Loader(skills=registry).load(entry)
    world = _field()
    try:
        xy = _ahead(world, 2.5, 8.0)
        world.add_sample("a", "green-white-red", xy)
        world.add_rock("rock1", _ahead(world, 3.5, -15.0), 0.4, seed=2)
        world.step(0.2)
        team = SimulatedTeam(
            library, "Verify2DObject", {"scout": "Scout"}, seed=0, skill_registry=registry, world=world
        )
        team.run(until_done=True, max_time=20.0)
        summary = team.summary()
        assert summary["success"], summary
        wm = team.engines["scout"].world_model
        assert wm.holds("found", "green_white_red")
        assert math.dist(wm.get("pos", "green_white_red"), xy) < 0.05
    finally:
        world.close()


# -- the plan from the command line --------------------------------------------------------------------

PLAN = str(Path(__file__).resolve().parents[2] / "plans" / "skills" / "verify_2d_object.yaml")


def _sample_near(seed: int, robot: str) -> tuple[str, tuple[float, float]]:
    """The kind and place of the sample ``alica run --world lunar --size 10 --rocks 2 --samples 1`` puts near ``robot``."""
    from alica.worldsim.scenarios import lunar

    with lunar(seed=seed, rocks=2, samples=1, size=10.0) as world:
        sample = world.objects["a"]
        xy = (float(sample.position()[0]), float(sample.position()[1]))
        assert math.dist(world.robots[robot].pose[:2], xy) < 4.0  # within the 5 m of a closer look
        return str(sample.sample_kind), xy


@pytest.mark.parametrize(("agents", "seed"), [("scout:Scout", 27), ("stummel:Stummel", 2)])
def test_the_verify_plan_runs_from_the_command_line(capfd, teams, agents, seed):
    from alica.app.cli import main

    robot = agents.split(":")[0]
    kind, xy = _sample_near(seed, robot)
    args = ["run", PLAN, "--agents", agents, "--world", "lunar", "--size", "10", "--rocks", "2", "--samples", "1"]
    code = main([*args, "--seed", str(seed), "--time-limit", "30", "--json"])
    summary = json.loads(capfd.readouterr().out)
    assert code == 0, summary
    assert summary["agents"][robot]["path"] == "Verify2DObject:ValidCandidate"
    assert summary["agents"][robot]["repairs"] == 0
    wm = teams[0].engines[robot].world_model
    name = kind.replace("-", "_")
    assert wm.holds("found", name) and wm.get("sample_kind", name) == kind
    assert math.dist(wm.get("pos", name), xy) < 0.05


def test_the_verify_plan_waits_without_churn_when_nothing_is_in_reach(tmp_path, capfd):
    from alica.app.cli import main

    trace = tmp_path / "trace.jsonl"
    args = ["run", PLAN, "--agents", "scout:Scout", "--world", "lunar", "--size", "16", "--rocks", "8"]
    code = main([*args, "--samples", "2", "--ticks", "240", "--trace", str(trace)])  # 8 s: less than the wait
    capfd.readouterr()
    assert code == 1  # not finished: still waiting for a candidate
    events = [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()]
    assert not [e for e in events if e["event"] in ("transition", "repair")], events
    (running,) = [e for e in events if e["event"] == "behaviour"]
    assert running["behaviour"] == "DetectSampleCircles" and running["status"] == "running"
