"""SemanticPerception (Amparo): the five skills alone, their geometry on synthetic clouds, a sample told from a rock."""

from __future__ import annotations

import json
import math
import random

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.errors import SkillError
from alica.skills.context import SkillEnv
from alica.skills.pointcloud import (
    KNOWLEDGE_BASES,
    CylinderFit,
    FuzzyConcept,
    Plane,
    Trapezoid,
    circle_fit,
    euclidean_clusters,
    fit_cylinder,
    ransac_plane,
)
from alica.skills.semantic_perception import (
    FitModel,
    FuzzyDLClassify,
    PointCloud,
    RansacGroundPlane,
    cloud_from_depth,
    sample_id,
)

PIPELINE = ("StereoPointCloud", "RansacGroundPlane", "EuclideanCluster", "FitModel", "FuzzyDLClassify")


# -- synthetic clouds --------------------------------------------------------------------------


def plane_points(rng, normal, offset, n=3000, noise=0.003, extent=3.0):
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    uv = rng.uniform(-extent, extent, (n, 2))
    return uv[:, :1] * e1 + uv[:, 1:] * e2 - offset * normal + rng.normal(0, noise, (n, 1)) * normal


def cylinder_points(rng, centre, radius, height, viewpoint, n=400, noise=0.002, tilt=0.0):
    """The visible half of a cylinder standing on z = 0 (or tilted about x), seen from ``viewpoint``."""
    to_view = np.asarray(viewpoint[:2], float) - np.asarray(centre[:2], float)
    facing = math.atan2(to_view[1], to_view[0])
    angle = rng.uniform(facing - math.pi / 2, facing + math.pi / 2, n)
    z = rng.uniform(0.0, height, n)
    local = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), z])
    if tilt:
        c, s = math.cos(tilt), math.sin(tilt)
        local = local @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]]).T
        local[:, 2] -= local[:, 2].min()
    return local + np.array([centre[0], centre[1], 0.0]) + rng.normal(0, noise, (n, 3))


@settings(max_examples=25, deadline=None)
@given(
    tilt=st.floats(0.0, math.radians(20)),
    azimuth=st.floats(-math.pi, math.pi),
    offset=st.floats(-1.0, 1.0),
    outliers=st.floats(0.0, 0.4),
    seed=st.integers(0, 2**31),
)
def test_ransac_recovers_a_known_plane_among_outliers(tilt, azimuth, offset, outliers, seed):
    rng = np.random.default_rng(seed)
    normal = np.array([math.sin(tilt) * math.cos(azimuth), math.sin(tilt) * math.sin(azimuth), math.cos(tilt)])
    ground = plane_points(rng, normal, offset)
    clutter = rng.uniform(-3, 3, (int(outliers * len(ground)), 3))
    clutter = clutter[np.abs(clutter @ normal + offset) > 0.05]
    cloud = np.vstack([ground, clutter])
    found = ransac_plane(cloud, np.random.default_rng(seed + 1), threshold=0.02, iterations=300)
    assert found is not None
    plane, mask = found
    assert math.degrees(math.acos(min(1.0, float(plane.normal @ normal)))) < 1.0
    assert abs(plane.offset - offset) < 0.01
    assert mask[: len(ground)].mean() > 0.99 and not mask[len(ground) :].any()


def test_ransac_is_repeatable_with_a_seed_and_refuses_a_wall():
    rng = np.random.default_rng(3)
    ground = plane_points(rng, [0, 0, 1], 0.0)
    a = ransac_plane(ground, np.random.default_rng(7))
    b = ransac_plane(ground, np.random.default_rng(7))
    assert a is not None and b is not None
    assert np.array_equal(a[0].normal, b[0].normal) and np.array_equal(a[1], b[1])
    wall = plane_points(rng, [1, 0, 0], -2.0)  # a vertical face: not a ground plane
    assert ransac_plane(wall, np.random.default_rng(7), max_tilt=math.radians(30)) is None
    assert ransac_plane(np.zeros((2, 3)), np.random.default_rng(7)) is None


@settings(max_examples=25, deadline=None)
@given(k=st.integers(1, 6), seed=st.integers(0, 2**31))
def test_clusters_of_separate_blobs_are_found(k, seed):
    rng = np.random.default_rng(seed)
    centres = [np.array([2.0 * i, rng.uniform(-1, 1), rng.uniform(0, 1)]) for i in range(k)]
    sizes = [int(rng.integers(60, 300)) for _ in range(k)]
    lattice = np.stack(np.meshgrid(*[np.arange(8) * 0.015] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    blobs = [c + lattice[:n] + rng.uniform(-0.002, 0.002, (n, 3)) for c, n in zip(centres, sizes, strict=True)]
    noise = rng.uniform(-5, 15, (20, 3)) + np.array([0, 0, 10.0])  # far, sparse points: no cluster
    cloud = np.vstack([*blobs, noise])
    clusters = euclidean_clusters(cloud, tolerance=0.03, min_points=50)
    assert sorted(len(c) for c in clusters) == sorted(sizes)
    starts = np.cumsum([0, *sizes])
    for c in clusters:
        i = int(np.searchsorted(starts, c[0], side="right")) - 1
        assert set(c.tolist()) == set(range(starts[i], starts[i + 1]))


def test_clusters_below_min_points_are_dropped_and_largest_come_first():
    rng = np.random.default_rng(0)
    big = rng.uniform(0, 0.1, (200, 3))
    small = rng.uniform(0, 0.05, (20, 3)) + 5.0
    clusters = euclidean_clusters(np.vstack([small, big]), 0.03, 50)
    assert [len(c) for c in clusters] == [200]
    assert [len(c) for c in euclidean_clusters(np.vstack([small, big]), 0.03, 1)] == [200, 20]
    assert euclidean_clusters(np.zeros((0, 3)), 0.03) == []


@settings(max_examples=40, deadline=None)
@given(
    cx=st.floats(-5, 5),
    cy=st.floats(-5, 5),
    r=st.floats(0.01, 2.0),
    start=st.floats(-math.pi, math.pi),
    arc=st.floats(math.pi / 2, 2 * math.pi),
)
def test_circle_fit_recovers_a_known_circle_from_an_arc(cx, cy, r, start, arc):
    a = np.linspace(start, start + arc, 50)
    x, y, radius, rms = circle_fit(np.column_stack([cx + r * np.cos(a), cy + r * np.sin(a)]))
    assert math.hypot(x - cx, y - cy) < 1e-6 * max(1.0, r) + 1e-9
    assert abs(radius - r) < 1e-6 * max(1.0, r)
    assert rms < 1e-6
    assert math.isnan(circle_fit(np.zeros((2, 2)))[2])


@pytest.mark.parametrize("radius,height", [(0.03, 0.1), (0.05, 0.3), (0.2, 0.15)])
def test_cylinder_fit_on_the_ground_gives_its_features(radius, height):
    rng = np.random.default_rng(1)
    viewpoint = np.array([0.0, 0.0, 0.45])
    pts = cylinder_points(rng, (1.5, 0.4), radius, height, viewpoint)
    fit = fit_cylinder(pts, Plane(np.array([0.0, 0.0, 1.0]), 0.0), viewpoint)
    assert fit is not None
    assert fit.radius == pytest.approx(radius, rel=0.1)
    assert fit.height == pytest.approx(height, rel=0.05)
    assert fit.width == pytest.approx(2 * radius, rel=0.15)
    assert np.hypot(*(fit.centre[:2] - np.array([1.5, 0.4]))) < 0.2 * radius + 0.003
    assert fit.base_gap < 0.01
    # the tilt is the silhouette's main axis: upright for a slender cylinder, across for a squat one
    assert fit.tilt < 10.0 if height > 2 * radius else fit.tilt > 80.0
    assert fit.points == len(pts) and not fit.truncated


def test_a_lying_cylinder_is_not_upright():
    rng = np.random.default_rng(2)
    viewpoint = np.array([0.0, 0.0, 0.45])
    pts = cylinder_points(rng, (2.0, 0.0), 0.03, 0.1, viewpoint, tilt=math.pi / 2)
    fit = fit_cylinder(pts, Plane(np.array([0.0, 0.0, 1.0]), 0.0), viewpoint, axis_from="pca")
    assert fit is not None and fit.tilt > 60.0
    assert fit_cylinder(pts[:4], Plane(np.array([0.0, 0.0, 1.0]), 0.0), viewpoint) is None


# -- fuzzy rating ---------------------------------------------------------------------------------


@given(a=st.floats(-10, 10), w=st.lists(st.floats(0, 5), min_size=3, max_size=3), x=st.floats(-30, 30))
def test_trapezoid_memberships_are_degrees(a, w, x):
    t = Trapezoid(a, a + w[0], a + w[0] + w[1], a + w[0] + w[1] + w[2])
    assert 0.0 <= t(x) <= 1.0
    if t.b <= x <= t.c:
        assert t(x) == 1.0
    if x < t.a or x > t.d:
        assert t(x) == 0.0


def test_trapezoid_and_concept():
    t = Trapezoid(0.0, 1.0, 2.0, 4.0)
    assert (t(0.5), t(1.5), t(3.0), t(5.0), t(math.nan)) == (0.5, 1.0, 0.5, 0.0, 0.0)
    assert Trapezoid(-1.0, -1.0, 0.0, 1.0)(1.0) == 0.0
    assert Trapezoid(0.0, 0.0, 1.0, 1.0)(1.0) == 1.0
    with pytest.raises(ValueError, match="a <= b <= c <= d"):
        Trapezoid(1.0, 0.0, 2.0, 3.0)
    concept = FuzzyConcept("c", {"x": t, "y": Trapezoid(0, 0, 1, 2)})
    assert concept.degree({"x": 0.5, "y": 1.5}, "min") == 0.5
    assert concept.degree({"x": 0.5, "y": 1.5}, "product") == 0.25
    assert concept.degree({"x": 0.5, "y": 1.5}, "lukasiewicz") == 0.0
    assert concept.degree({"x": 0.5}) == 0.0  # a missing feature


def test_the_drill_sample_description_takes_a_sample_and_refuses_rocks_and_robots():
    kb = KNOWLEDGE_BASES["drill_sample"]
    sample = {"radius": 0.029, "height": 0.1, "tilt": 3.0, "base_gap": 0.022, "width": 0.057, "truncated": 0.0}
    assert kb.degree(sample) == 1.0
    rock = {"radius": 0.19, "height": 0.29, "tilt": 89.0, "base_gap": 0.026, "width": 0.43, "truncated": 0.0}
    robot = {"radius": 0.25, "height": 0.3, "tilt": 85.0, "base_gap": 0.05, "width": 0.5, "truncated": 0.0}
    lying = dict(sample, tilt=88.0, height=0.06, width=0.1)
    cut = dict(sample, truncated=1.0)
    floating = dict(sample, base_gap=0.2)
    for other in (rock, robot, lying, cut, floating):
        assert kb.degree(other) < 0.6


def test_new_sample_ids_come_from_the_position():
    assert sample_id(3.24, -1.46) == "s_32_m15"
    assert sample_id(-0.04, 0.0) == "s_0_0"
    assert sample_id(-12.0, 7.05) == "s_m120_70"


# -- the skills in a rendered lunar scene -------------------------------------------------------


@pytest.fixture
def scene():
    """Amparo with a sample 1.8 m ahead and a rock 2.2 m ahead, 0.6 m to the side."""
    from alica.worldsim.scenarios import lunar

    world = lunar(seed=0, rocks=0, samples=0, size=20.0)
    x, y, yaw = world.robots["amparo"].pose

    def ahead(d, side):
        return (
            x + d * math.cos(yaw) - side * math.sin(yaw),
            y + d * math.sin(yaw) + side * math.cos(yaw),
        )

    world.add_sample("probe", "green-white-red", ahead(1.8, -0.3))
    world.add_rock("stone", ahead(2.2, 0.5), 0.25, seed=5)
    world.step(0.2)
    try:
        yield world
    finally:
        world.close()


def run_pipeline(skill_run, world, scratch, world_model=None, **params):
    runs = []
    for name in PIPELINE:
        run = skill_run(name, world, "amparo", params.get(name, {}), scratch=scratch, world_model=world_model)
        runs.append(run)
        if not run.ok:
            break
    return runs


def test_each_skill_alone_hands_its_data_on_through_the_scratch_space(scene, skill_run):
    scratch: dict = {}
    run = skill_run("StereoPointCloud", scene, "amparo", {"max_depth": 3.0}, scratch=scratch)
    assert run.ok, run.reason
    cloud = scratch["cloud"]
    assert isinstance(cloud, PointCloud) and len(cloud) > 10_000
    camera_xy = cloud.position[:2]
    assert np.linalg.norm(cloud.points - cloud.position, axis=1).max() < 3.0 / math.cos(math.radians(45)) * 1.3
    assert np.hypot(*(camera_xy - np.array(scene.robots["amparo"].pose[:2]))) < 0.4
    assert cloud.rotation.shape == (3, 3) and cloud.pixels.shape == (len(cloud), 2)

    run = skill_run("RansacGroundPlane", scene, "amparo", {}, scratch=scratch)
    assert run.ok, run.reason
    plane = scratch["plane"]
    assert plane.tilt() < math.radians(1.0) and abs(plane.offset) < 0.01  # the ground z = 0
    above = scratch["above_ground"]
    assert 0 < len(above) < len(cloud) and (plane.distance(above.points) >= 0.02).all()

    run = skill_run("EuclideanCluster", scene, "amparo", {"tolerance": 0.03, "min_points": 50}, scratch=scratch)
    assert run.ok, run.reason
    clusters = scratch["clusters"]
    assert len(clusters) >= 2 and all(len(c) >= 50 for c in clusters)

    run = skill_run("FitModel", scene, "amparo", {"model": "cylinder"}, scratch=scratch)
    assert run.ok, run.reason
    models = scratch["models"]
    assert all(isinstance(m, CylinderFit) for m in models)
    truth = scene.objects["probe"].position()[:2]
    best = min(models, key=lambda m: np.hypot(*(m.centre[:2] - truth)))
    assert np.hypot(*(best.centre[:2] - truth)) < 0.05
    assert best.radius == pytest.approx(0.03, abs=0.012) and best.height == pytest.approx(0.1, abs=0.015)
    assert best.tilt < 15.0

    run = skill_run("FuzzyDLClassify", scene, "amparo", {"threshold": 0.6}, scratch=scratch)
    assert run.ok, run.reason
    (detection,) = scratch["detections"]
    assert np.hypot(*(np.array(detection.position) - truth)) < 0.05


def test_semantic_perception_tells_the_sample_from_the_rock(scene, skill_run):
    runs = run_pipeline(skill_run, scene, {})
    assert [r.status for r in runs] == ["success"] * 5, runs[-1].reason
    last = runs[-1]
    truth = scene.objects["probe"].position()[:2]
    found = [f.args[0] for f in last.facts if f.predicate == "found"]
    assert len(found) == 1  # the rock is not reported
    (name,) = found
    assert name == sample_id(*truth) or name.startswith("s_")
    from alica.lang.fact import Fact

    pos = last.values[Fact("pos", (name,))]
    assert np.hypot(pos[0] - truth[0], pos[1] - truth[1]) < 0.05
    assert 0.6 <= last.values[Fact("confidence", (name,))] <= 1.0


def test_the_cloud_and_the_samples_are_placed_by_the_pose_estimate(scene, skill_run):
    """Amparo believes it stands 0.4 m further along x and turned by 2 degrees: so do the samples it reports."""
    amparo = scene.robots["amparo"]
    x, y, yaw = amparo.pose
    turn = math.radians(2.0)
    amparo.set_estimate((x + 0.4, y, yaw + turn))
    scratch: dict = {}
    runs = run_pipeline(skill_run, scene, scratch)
    assert [r.status for r in runs] == ["success"] * 5, runs[-1].reason
    (detection,) = scratch["detections"]
    sx, sy = scene.objects["probe"].position()[:2]
    dx, dy = sx - x, sy - y
    believed = (x + 0.4 + dx * math.cos(turn) - dy * math.sin(turn), y + dx * math.sin(turn) + dy * math.cos(turn))
    assert math.dist(detection.position, believed) < 0.05
    assert math.dist(detection.position, (sx, sy)) > 0.3


def test_a_detection_near_a_known_sample_is_that_sample_and_a_clear_view_retracts_a_false_one(scene, skill_run):
    from alica.worldmodel import WorldModel

    wm = WorldModel("amparo", clock=scene.clock)
    truth = scene.objects["probe"].position()[:2]
    wm.add_object("a", "Sample")
    wm.set("pos", "a", value=(float(truth[0]) + 0.1, float(truth[1])))
    # a false detection, 1.5 m ahead in plain view where nothing stands
    x, y, yaw = scene.robots["amparo"].pose
    ghost = (round(x + 1.5 * math.cos(yaw + 0.3), 3), round(y + 1.5 * math.sin(yaw + 0.3), 3))
    wm.add_object("ghost", "Sample")
    wm.set("pos", "ghost", value=ghost)
    wm.assert_fact("found", "ghost")
    wm.assert_fact("onground", "ghost")
    runs = run_pipeline(skill_run, scene, {}, world_model=wm)
    assert runs[-1].ok, runs[-1].reason
    assert wm.holds("found", "a") and not wm.holds("found", "ghost")
    assert wm.holds("onground", "a") and not wm.holds("onground", "ghost")
    assert "retracted ghost" in runs[-1].reason
    assert wm.get("confidence", "a") >= 0.6


def test_only_rocks_in_view_is_no_sample(skill_run):
    from alica.worldsim.scenarios import lunar

    with lunar(seed=2, rocks=0, samples=0, size=20.0) as world:
        x, y, yaw = world.robots["amparo"].pose
        for i, (d, side, r) in enumerate([(1.5, 0.0, 0.2), (2.5, -0.8, 0.4), (2.0, 0.9, 0.3)]):
            world.add_rock(
                f"r{i}",
                (x + d * math.cos(yaw) - side * math.sin(yaw), y + d * math.sin(yaw) + side * math.cos(yaw)),
                r,
                seed=i,
            )
        world.step(0.1)
        runs = run_pipeline(skill_run, world, {})
    assert runs[-1].skill == "FuzzyDLClassify" and runs[-1].status == "failure"
    assert "no drill_sample" in runs[-1].reason
    assert not [f for f in runs[-1].facts if f.predicate == "found"]


def test_the_pipeline_steps_fail_clearly_without_their_input(scene, skill_run):
    run = skill_run("RansacGroundPlane", scene, "amparo", {}, scratch={})
    assert run.status == "failure" and "run StereoPointCloud first" in run.reason
    run = skill_run("FitModel", scene, "amparo", {}, scratch={"clusters": []})
    assert run.status == "failure" and "run RansacGroundPlane first" in run.reason


def test_no_ground_plane_in_a_cloud_of_a_wall_fails_clearly():
    rng = np.random.default_rng(0)
    wall = plane_points(rng, [1, 0, 0], -2.0, n=2000)
    cloud = PointCloud(
        wall,
        np.zeros((len(wall), 2), np.int32),
        np.ones((4, 4)),
        (1.0, 1.0, 2.0, 2.0),
        np.zeros(3),
        np.eye(3),
        3.0,
        0.0,
    )
    env = SkillEnv("amparo", lambda: 0.0, random.Random(1), scratch={"cloud": cloud})
    skill = RansacGroundPlane("ground", {}, env)
    skill.setup(context=env)
    skill.tick_once()
    skill.tick_once()
    assert skill.status.value == "FAILURE"
    assert "no ground plane" in skill.feedback_message
    assert "plane" not in env.scratch


def test_cloud_from_depth_matches_the_camera_model():
    depth = np.full((4, 6), np.inf)
    depth[1, 2] = 2.0
    depth[3, 5] = 5.0  # beyond max_depth
    cloud = cloud_from_depth(depth, (10.0, 10.0, 2.5, 1.5), np.array([1.0, 2.0, 3.0]), np.eye(3), 3.0)
    assert len(cloud) == 1 and cloud.pixels.tolist() == [[1, 2]]
    assert np.allclose(cloud.points[0], [1.0 + (2 - 2.5) * 0.2, 2.0 + (1 - 1.5) * 0.2, 5.0])
    assert not cloud.touches_border() and cloud.subset(np.array([True])).touches_border(margin=2)


@pytest.mark.parametrize(
    ("skill", "params", "message"),
    [
        ("StereoPointCloud", {"max_depth": -1.0}, "parameter 'max_depth' must be a number in"),
        ("StereoPointCloud", {"width": 3}, "parameter 'width' must be a whole number in"),
        ("StereoPointCloud", {"median": 0}, "parameter 'median'"),
        ("RansacGroundPlane", {"distance_threshold": 0.0}, "parameter 'distance_threshold'"),
        ("RansacGroundPlane", {"iterations": 0}, "parameter 'iterations'"),
        ("RansacGroundPlane", {"max_tilt": 120.0}, "parameter 'max_tilt'"),
        ("EuclideanCluster", {"tolerance": -0.1}, "parameter 'tolerance'"),
        ("EuclideanCluster", {"min_points": 0}, "parameter 'min_points'"),
        ("FitModel", {"model": "sphere"}, "parameter 'model' must be one of cylinder"),
        ("FitModel", {"axis": "up"}, "parameter 'axis' must be one of"),
        ("FuzzyDLClassify", {"knowledge_base": "teapot"}, "parameter 'knowledge_base' must be one of drill_sample"),
        ("FuzzyDLClassify", {"threshold": 1.5}, "parameter 'threshold' must be a number in \\[0, 1\\]"),
        ("FuzzyDLClassify", {"tnorm": "max"}, "parameter 'tnorm'"),
        ("FuzzyDLClassify", {"threshold": "high"}, "parameter 'threshold'"),
    ],
)
def test_bad_parameters_give_clear_errors(lunar_world, skill_run, skill, params, message):
    with pytest.raises(SkillError, match=message):
        skill_run(skill, lunar_world, "amparo", params)


def test_a_robot_without_a_stereo_camera_or_a_world_is_refused(blocks_world, skill_run):
    with pytest.raises(SkillError, match="has no stereo camera"):
        skill_run("StereoPointCloud", blocks_world, "r1", {})
    skill = FitModel("fit", {}, None)
    with pytest.raises(SkillError, match="needs a skill context"):
        skill.setup()
    env = SkillEnv("amparo", lambda: 0.0, random.Random(1))
    classify = FuzzyDLClassify("c", {"threshold": 0.5}, env)
    classify.setup(context=env)
    assert classify.threshold == 0.5


def test_stereo_point_cloud_runs_from_the_command_line(capfd):
    from alica.app.cli import main

    code = main(["skill", "run", "StereoPointCloud", "--world", "lunar", "--rocks", "10", "--json"])
    out = json.loads(capfd.readouterr().out)
    assert code == 0, out
    assert out["robot"] == "amparo" and out["status"] == "success"


@pytest.mark.parametrize("with_sample", [True, False])
def test_the_semantic_perception_plan_runs_with_the_skills(tmp_path, with_sample):
    from pathlib import Path

    from alica.engine import SimulatedTeam
    from alica.io import load_library
    from alica.lang.skill_plugins import default_registry
    from alica.worldsim.scenarios import lunar

    plans = Path(__file__).resolve().parents[2] / "plans"
    team_file = tmp_path / "team.yaml"
    team_file.write_text(
        f"alica: 1\nimports: [{plans / 'roles.yaml'}, {plans / 'skills' / 'semantic_perception.yaml'}]\n",
        encoding="utf-8",
    )
    registry = default_registry()
    library = load_library(team_file, skills=registry)
    with lunar(seed=0, rocks=0, samples=0, size=20.0) as world:
        x, y, yaw = world.robots["amparo"].pose
        if with_sample:
            world.add_sample("probe", "red-black-red", (x + 2 * math.cos(yaw), y + 2 * math.sin(yaw)))
        world.add_rock("stone", (x + 2.5 * math.cos(yaw + 0.4), y + 2.5 * math.sin(yaw + 0.4)), 0.3, seed=1)
        world.step(0.2)
        team = SimulatedTeam(
            library, "SemanticPerception", {"amparo": "Amparo"}, skill_registry=registry, world=world, roleset="Impera"
        )
        team.run(until_done=True, max_time=30)
        summary = team.summary()["agents"]["amparo"]
        wm = team.engines["amparo"].world_model
        found = [f.args[0] for f in wm.facts() if f.predicate == "found"]
        if with_sample:
            assert summary["path"] == "SemanticPerception:SampleRecognised"
            (name,) = found
            assert name in wm.objects("Sample")
            pos = wm.get("pos", name)
            truth = world.objects["probe"].position()
            assert math.hypot(pos[0] - truth[0], pos[1] - truth[1]) < 0.05
        else:
            assert summary["path"] == "SemanticPerception:NoSample" and not found


@pytest.mark.parametrize("seed", [3, 10])
def test_the_semantic_perception_plan_runs_from_the_command_line(capfd, teams, seed):
    from pathlib import Path

    from alica.app.cli import main
    from alica.worldsim.scenarios import lunar

    with lunar(seed=seed, rocks=2, samples=1, size=10.0) as world:  # the field alica run builds
        xy = world.objects["a"].position()[:2]
        assert math.dist(world.robots["amparo"].pose[:2], xy) < 2.8  # within the 3 m of the cloud
    plan = Path(__file__).resolve().parents[2] / "plans" / "skills" / "semantic_perception.yaml"
    args = ["run", str(plan), "--agents", "amparo:Amparo", "--world", "lunar", "--size", "10", "--rocks", "2"]
    code = main([*args, "--samples", "1", "--seed", str(seed), "--time-limit", "30", "--json"])
    summary = json.loads(capfd.readouterr().out)
    assert code == 0, summary
    agent = summary["agents"]["amparo"]
    assert agent["path"] == "SemanticPerception:SampleRecognised" and agent["repairs"] == 0
    wm = teams[0].engines["amparo"].world_model
    (name,) = [f.args[0] for f in wm.facts() if f.predicate == "found"]
    assert math.dist(wm.get("pos", name), xy) < 0.05
