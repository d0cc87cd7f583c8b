"""``alica skill run``: a skill alone from the command line."""

from __future__ import annotations

import json

import pytest

from alica.app.cli import main


def test_unstack_in_the_blocks_world(capfd):
    code = main(["skill", "run", "Unstack", "--world", "blocks", "--param", "object=b", "--param", "from=a", "--json"])
    out = json.loads(capfd.readouterr().out)
    assert code == 0, out
    assert out["status"] == "success" and out["robot"] == "r1"
    assert ["holding", "r1", "b"] in out["facts"] and ["clear", "a"] in out["facts"]


def test_move_to_a_goal_inside_a_rock_fails_with_the_reason(capfd):
    code = main(
        [
            "skill",
            "run",
            "MoveToPosition",
            "--world",
            "lunar",
            "--robot-name",
            "scout",
            "--rocks",
            "0",
            "--param",
            "goal=[100, 0]",
        ]
    )
    out = capfd.readouterr().out
    assert code == 1
    assert "MoveToPosition on scout: failure" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["Fly"], "no skill named 'Fly'"),
        (["Pickup", "--world", "blocks"], "needs the parameter 'object'"),
        (["Pickup", "--world", "blocks", "--param", "object"], "is not KEY=VALUE"),
        (["Pickup", "--world", "blocks", "--param", "object=c", "--param", "grip=hard"], "has no parameter 'grip'"),
        (["Pickup", "--world", "lunar", "--robot-name", "scout", "--param", "object=a"], "has no arm"),
        (["Pickup", "--world", "lunar", "--robot", "scout"], "use --robot-name scout"),
        (["MoveToPosition", "--robot", "unicycle", "--world", "lunar"], "choose one"),
        (["MoveToPosition", "--world", "lunar", "--param", "goal=[1, 2", "--rocks", "5"], "not a YAML value"),
        (["BuildMap", "--size", "5"], "--size 5"),
        (["BuildMap", "--samples", "-1"], "--samples must be >= 0"),
        (["BuildMap", "--size", "12", "--rocks", "500"], "--rocks 500"),
    ],
)
def test_bad_input(argv, message, capfd):
    assert main(["skill", "run", *argv]) == 1
    err = capfd.readouterr().err
    assert message in err, err
    assert "Traceback" not in err and "internal error" not in err


def test_a_small_lunar_field_from_the_command_line(capfd):
    """--size, --rocks and --samples shape the field: BuildMap on a 12 m field with no rocks maps it at once."""
    code = main(["skill", "run", "BuildMap", "--size", "12", "--rocks", "0", "--samples", "1", "--param", "radius=3"])
    out = capfd.readouterr().out
    assert code == 0, out
    assert "mapped" in out


@pytest.mark.parametrize(
    ("argv", "robot", "words"),
    [
        (
            ["ClassifySample", "--after", "DetectCircles", "--after", "CropCandidate", "--after", "BlobDetect"],
            "scout",
            "found",
        ),
        (
            ["FuzzyDLClassify", "--after", "StereoPointCloud", "--after", "RansacGroundPlane"]
            + ["--after", "EuclideanCluster", "--after", "FitModel", "--seed", "4"],
            "amparo",
            "found",
        ),
    ],
)
def test_a_pipeline_runs_step_by_step_from_the_command_line(argv, robot, words, capfd):
    """--after runs the steps before on the same robot, world model and scratch space (Verify2DObject, SemanticPerception)."""
    field = ["--size", "12", "--rocks", "3", "--samples", "3"]
    code = main(["skill", "run", *argv, *field, *([] if "--seed" in argv else ["--seed", "1"])])
    out = capfd.readouterr().out
    assert code == 0, out
    assert out.startswith(f"{argv[0]} on {robot}: success") and words in out


def test_a_pipeline_step_that_fails_is_named(capfd):
    code = main(["skill", "run", "BlobDetect", "--after", "DetectCircles", "--after", "CropCandidate", "--seed", "0"])
    out = capfd.readouterr().out
    assert code == 1
    assert "step DetectCircles before BlobDetect did not succeed: no circle of the sample radius" in out
