"""The steps of the Pickup and Putdown plans (IMPERA Figs. 15 and 16) on a lunar sample, alone, in turn and in the engine.

Ground truth only scores the results here; the skills act through the robot interface.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from alica.errors import SkillError
from alica.lang.fact import Fact
from alica.skills.arm_scratch import ARM_RETREAT
from alica.worldmodel import WorldModel

pytest.importorskip("pybullet")

PICKUP = (
    ("AlignWithObject", {"object": "a"}),
    ("Grasp", {"object": "a"}),
    ("MoveArmToTransport", {}),
    ("ValidateGrip", {}),
)
PUTDOWN = (
    ("MoveArmToPlace", {"target": "pos(g)"}),
    ("OpenGripper", {}),
    ("MoveArmToTransport", {}),
    ("VerifyPlaced", {"object": "a", "target": "pos(g)"}),
)


@pytest.fixture
def field() -> Iterator[Any]:
    """A 12 m lunar field with two rocks and the samples a and b (a about 6 m from Stummel)."""
    from alica.worldsim.scenarios import lunar

    world = lunar(seed=0, rocks=2, samples=2, size=12.0)
    try:
        yield world
    finally:
        world.close()


class Steps:
    """Runs steps on one robot with one world model and one scratch space, as ``alica skill run --after`` does."""

    def __init__(self, skill_run: Any, world: Any, robot: str = "stummel") -> None:
        self.skill_run, self.world, self.robot = skill_run, world, robot
        self.wm = WorldModel(robot, clock=world.clock)
        self.scratch: dict[str, object] = {}

    def __call__(self, name: str, params: dict[str, object] | None = None, **kw: Any) -> Any:
        return self.skill_run(
            name, self.world, self.robot, params or {}, world_model=self.wm, scratch=self.scratch, **kw
        )

    def all_ok(self, steps: tuple[tuple[str, dict[str, object]], ...]) -> None:
        for name, params in steps:
            run = self(name, params)
            assert run.ok, (name, run.reason, run.trace[-5:])


def _xy(obj: Any) -> tuple[float, float]:
    return float(obj.position()[0]), float(obj.position()[1])


# -- each step alone -----------------------------------------------------------------------------------


def test_align_with_object_faces_the_sample_at_the_standoff(skill_run, field):
    robot = field.robots["stummel"]
    run = skill_run("AlignWithObject", field, "stummel", {"object": "a", "standoff": 0.75, "tolerance": 0.02})
    assert run.ok, (run.reason, run.trace[-5:])
    x, y, yaw = robot.pose
    sx, sy = _xy(field.objects["a"])
    assert abs(math.hypot(sx - x, sy - y) - 0.75) <= 0.025
    assert abs(math.remainder(math.atan2(sy - y, sx - x) - yaw, 2 * math.pi)) < 0.05
    assert "facing a" in run.reason and not robot.bumped


def test_align_with_object_by_default_stands_where_the_arm_reaches_best(skill_run, field):
    from alica.skills.handling import REACH

    run = skill_run("AlignWithObject", field, "stummel", {"object": "a"})
    assert run.ok, run.reason
    robot = field.robots["stummel"]
    wanted = REACH + robot.arm.mount_offset[0]
    assert abs(math.dist(robot.pose[:2], _xy(field.objects["a"])) - wanted) <= 0.025


def test_grasp_holds_the_sample_writes_the_facts_and_counts_the_attempt(skill_run, field):
    steps = Steps(skill_run, field)
    assert steps("AlignWithObject", {"object": "a"}).ok
    run = steps("Grasp", {"object": "a", "force": 8.0})
    assert run.ok, (run.reason, run.trace[-5:])
    arm = field.robots["stummel"].arm
    assert arm.held is field.objects["a"] and arm.grip_force() == 8.0
    assert run.holds("holding", "stummel", "a") and not run.holds("handempty", "stummel")
    assert run.values[Fact("attempts", ("stummel",))] == 1
    assert ARM_RETREAT.require(steps.scratch, "the test").paths  # the lift, for MoveArmToTransport


def test_move_arm_to_transport_plans_its_own_way_without_a_stored_one(skill_run, field):
    steps = Steps(skill_run, field)
    steps.all_ok(PICKUP[:2])
    steps.scratch.pop("arm_retreat")
    run = steps("MoveArmToTransport")
    assert run.ok, (run.reason, run.trace[-5:])
    from alica.worldsim.arm_model import PANDA_HOME_Q

    arm = field.robots["stummel"].arm
    assert np.abs(np.asarray(arm.q()) - PANDA_HOME_Q).max() < 1e-3  # where the pick-up plans carry to
    assert arm.held is field.objects["a"] and field.objects["a"].position()[2] > 0.3  # lifted over the base


def test_a_weak_grip_fails_validate_grip(skill_run, field):
    steps = Steps(skill_run, field)
    steps.all_ok((PICKUP[0], ("Grasp", {"object": "a", "force": 1.0}), PICKUP[2]))
    run = steps("ValidateGrip", {"min_force": 2.0})
    assert run.status == "failure"
    assert run.reason == "the finger force on a is 1 N, below 2 N"


# -- the pipelines step by step ------------------------------------------------------------------------


def test_pickup_and_putdown_step_by_step_bring_the_sample_to_g(skill_run, field):
    steps = Steps(skill_run, field)
    steps.all_ok(PICKUP)
    assert steps.wm.holds("holding", "stummel", "a") and not steps.wm.holds("onground", "a")
    assert "grasp" not in steps.scratch  # the count of attempts ended with the pickup
    steps.all_ok(PUTDOWN)
    a, g = _xy(field.objects["a"]), _xy(field.objects["g"])
    assert math.dist(a, g) < field.objects["g"].radius
    assert field.robots["stummel"].arm.held is None
    for fact in (("onground", "a"), ("handempty", "stummel"), ("at", "a", "g")):
        assert steps.wm.holds(*fact), fact
    assert not steps.wm.holds("holding", "stummel", "a")
    assert math.dist(steps.wm.get("pos", "a"), a) < 0.01


def test_a_slip_fails_validate_grip_and_the_retry_succeeds(skill_run, field):
    from alica.worldsim.faults import set_grasp_slip

    steps = Steps(skill_run, field)
    set_grasp_slip(field, 1.0)
    steps.all_ok(PICKUP[:3])
    run = steps("ValidateGrip")
    assert run.status == "failure" and "a slipped out of the gripper" in run.reason
    assert steps.wm.holds("handempty", "stummel") and steps.wm.holds("onground", "a")
    assert not steps.wm.holds("holding", "stummel", "a")
    set_grasp_slip(field, 0.0)
    # the plan's retry: Release, then Align and Grasp again (the second attempt)
    steps.all_ok((("OpenGripper", {}), PICKUP[0]))
    run = steps("Grasp", {"object": "a"})
    assert run.ok, (run.reason, run.trace[-5:])
    assert run.values[Fact("attempts", ("stummel",))] == 2
    steps.all_ok(PICKUP[2:])
    assert field.robots["stummel"].arm.held is field.objects["a"]


def test_a_failed_grasp_counts_on_and_a_new_pickup_starts_at_one(skill_run, field):
    steps = Steps(skill_run, field)
    far = steps("Grasp", {"object": "a"})  # not aligned: out of reach
    assert far.status == "failure" and far.values[Fact("attempts", ("stummel",))] == 1
    assert "beyond its reach" in far.reason and "AlignWithObject" in far.reason
    assert steps("OpenGripper").ok
    again = steps("Grasp", {"object": "a"})
    assert again.values[Fact("attempts", ("stummel",))] == 2
    fresh = steps("Grasp", {"object": "a"})  # no Release in between: a new pickup
    assert fresh.values[Fact("attempts", ("stummel",))] == 1


# -- bad parameters and states -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("skill", "params", "words"),
    [
        ("AlignWithObject", {"object": "a", "tolerance": -0.1}, "parameter 'tolerance' must be > 0"),
        ("AlignWithObject", {"object": "a", "standoff": 0.0}, "parameter 'standoff' must be > 0"),
        ("AlignWithObject", {"object": "nowhere"}, "cannot tell where 'nowhere' is"),
        ("Grasp", {"object": "a", "force": 0.0}, "parameter 'force' must be > 0"),
        ("Grasp", {"object": "zz"}, "the world has no object 'zz'"),
        ("ValidateGrip", {"min_force": -1.0}, "parameter 'min_force' must be >= 0"),
        ("Grasp", {}, "needs the parameter 'object'"),
    ],
)
def test_bad_parameters_give_clear_errors(skill_run, field, skill, params, words):
    with pytest.raises(SkillError, match=words):
        skill_run(skill, field, "stummel", params)


def test_scout_has_no_arm_to_grasp_with(skill_run, field):
    with pytest.raises(SkillError, match="robot 'scout' has no arm"):
        skill_run("Grasp", field, "scout", {"object": "a"})
    with pytest.raises(SkillError, match="robot 'scout' has no arm"):
        skill_run("OpenGripper", field, "scout", {})


def test_steps_out_of_order_fail_and_say_why(skill_run, field):
    steps = Steps(skill_run, field)
    place = steps("MoveArmToPlace", {"target": "pos(g)"})
    assert place.status == "failure" and "the hand is empty" in place.reason
    grip = steps("ValidateGrip")
    assert grip.status == "failure" and "holds nothing" in grip.reason
    placed = steps("VerifyPlaced", {"object": "a", "target": "pos(g)"})
    # it looks with its camera where the sample should lie after a put-down: a lies 6 m away, unseen
    assert placed.status == "failure" and "the camera sees no a where it was put down" in placed.reason
    steps.all_ok(PICKUP)
    held = steps("VerifyPlaced", {"object": "a"})
    assert held.status == "failure" and held.reason == "the gripper still holds a"
    assert steps("OpenGripper").ok and steps("MoveArmToTransport").ok
    assert steps("OpenGripper").reason == "opened (the hand was empty)"


# -- the plans in the engine ---------------------------------------------------------------------------

FETCH = """\
alica: 1
imports: [{roles}, {pickup}, {putdown}]
plans:
  - name: FetchA
    description: pick the sample a up and put it down at the collection point g
    entry_points:
      - {{task: Pickup, state: PickUpA, min: 1, max: 1}}
    states:
      - name: PickUpA
        children:
          - {{ref: Pickup, bind: {{x: a}}}}
        transitions:
          - {{to: PutDownA, condition: "succeeded"}}
          - {{to: Failed, condition: "failed"}}
      - name: PutDownA
        children:
          - {{ref: Putdown, bind: {{x: a, l: g}}}}
        transitions:
          - {{to: Fetched, condition: "succeeded"}}
          - {{to: Failed, condition: "failed"}}
      - name: Fetched
        kind: success
      - name: Failed
        kind: failure
"""


def _fetch(tmp_path: Path, robot: str, role: str) -> tuple[Any, Any, Any]:
    """A 12 m field with the sample a in view of ``robot``, and a team that runs FetchA on it: (team, world, spot)."""
    from alica.engine import SimulatedTeam
    from alica.io import Loader
    from alica.lang.skill_plugins import default_registry
    from alica.worldsim.scenarios import lunar

    root = Path(__file__).resolve().parents[2] / "plans"
    entry = tmp_path / "fetch.yaml"
    entry.write_text(
        FETCH.format(
            roles=root / "roles.yaml", pickup=root / "skills" / "pickup.yaml", putdown=root / "skills" / "putdown.yaml"
        ),
        encoding="utf-8",
    )
    registry = default_registry()
    library = Loader(skills=registry).load(entry)
    world = lunar(seed=0, rocks=0, samples=0, size=12.0)
    x, y, yaw = world.robots[robot].pose
    spot = (x + 2.5 * math.cos(yaw + 0.1), y + 2.5 * math.sin(yaw + 0.1))  # in view of its lidar and camera
    world.add_sample("a", "green-white-red", spot)
    world.step(0.2)
    team = SimulatedTeam(library, "FetchA", {robot: role}, seed=0, skill_registry=registry, world=world)
    team.engines[robot].world_model.set("sample_kind", "a", value="green-white-red")  # asked for: found, it is a
    return team, world, spot


@pytest.mark.parametrize(("robot", "role"), [("stummel", "Stummel"), ("amparo", "Amparo")])
def test_the_pickup_and_putdown_plans_fetch_a_sample_in_the_engine(tmp_path, robot, role):
    team, world, _ = _fetch(tmp_path, robot, role)
    try:
        wm = team.engines[robot].world_model
        team.run(until_done=True, max_time=90.0)
        summary = team.summary()
        assert summary["success"], summary
        # LocateObject ran the robot's own perception: Verify2DObject names the sample a (its kind is known),
        # SemanticPerception after its position (s_<x>_<y>)
        found = [f.args[0] for f in wm.facts() if f.predicate == "found"]
        assert found == ["a"] if robot == "stummel" else len(found) == 1
        for fact in (("onground", "a"), ("handempty", robot), ("at", "a", "g")):
            assert wm.holds(*fact), fact
        assert not wm.holds("holding", robot, "a")
        assert wm.get("attempts", robot) == 1
        assert math.dist(_xy(world.objects["a"]), _xy(world.objects["g"])) < world.objects["g"].radius
    finally:
        world.close()


def _slips_main(slips: int, tmp_path: Path) -> dict[str, Any]:
    """FetchA with the grasp slipping ``slips`` times, until it succeeds or the Pickup plan fails: what happened."""
    from alica.skills.motion import configure_ompl
    from alica.worldsim.faults import set_grasp_slip

    configure_ompl(0)  # a fresh process: OMPL's one generator gets its seed before any planner exists
    team, world, spot = _fetch(tmp_path, "stummel", "Stummel")
    try:
        arm, wm = world.robots["stummel"].arm, team.engines["stummel"].world_model
        engine = team.engines["stummel"]
        set_grasp_slip(world, 1.0)
        dropped, holding = 0, False
        # until the plan succeeds, or the Pickup plan failed (the engine then repairs: it starts the plan again)
        while not team.done() and engine.stats["repairs"] == 0 and team.now() < 90.0:
            team.tick()
            if arm.held is not None:
                holding = True
            elif holding and dropped < slips:  # it slipped
                holding, dropped = False, dropped + 1
                if dropped == slips:
                    set_grasp_slip(world, 0.0)
        summary = team.summary()
        return {
            "dropped": dropped,
            "attempts": wm.get("attempts", "stummel"),
            "success": bool(summary["success"]),
            "summary": {k: v for k, v in summary["agents"]["stummel"].items() if k in ("status", "path", "reason")},
            "at_g": wm.holds("at", "a", "g"),
            "repairs": engine.stats["repairs"],
            "holding": wm.holds("holding", "stummel", "a"),
            "held": arm.held is not None,
            "from_spot": math.dist(_xy(world.objects["a"]), spot),
        }
    finally:
        world.close()


@pytest.mark.parametrize(("slips", "attempts"), [(1, 2), (3, 3)])
def test_the_pickup_plan_retries_after_a_slip_and_gives_up_after_three_attempts(tmp_path, slips, attempts):
    # in a fresh process: OMPL's generator is per process, so in the test session the run would follow the
    # tests that ran before it
    import json
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, str(Path(__file__)), "slips", str(slips), str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    run = json.loads(done.stdout.strip().splitlines()[-1])
    assert run["dropped"] == slips and run["attempts"] == attempts, run
    if slips < 3:
        assert run["success"], run
        assert run["at_g"] and run["repairs"] == 0, run
    else:
        assert run["repairs"] == 1 and not run["holding"], run
        assert not run["held"] and run["from_spot"] < 0.3, run  # it lies where it fell


if __name__ == "__main__":  # a run of the slip test, in a fresh process
    import json
    import sys

    if len(sys.argv) != 4 or sys.argv[1] != "slips":
        sys.exit("usage: test_sample_steps.py slips N OUT")
    print(json.dumps(_slips_main(int(sys.argv[2]), Path(sys.argv[3]))))
