"""``alica protap generate`` and ``alica protap run`` (``--world none`` and ``--world lunar``) through the command line."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

from alica.app.cli import main
from alica.prophet.rddl import read_rddl


def test_generate_writes_a_domain_and_an_instance_the_rddl_reader_accepts(tmp_path, capsys):
    assert main(["protap", "generate", "--robots", "3", "--grid", "4x6", "--goals", "2", "--out", str(tmp_path)]) == 0
    assert "instance.rddl" in capsys.readouterr().out
    domain = read_rddl(tmp_path / "domain.rddl").domain
    parsed = read_rddl(tmp_path / "instance.rddl", domain=domain)
    assert parsed.instance is not None and parsed.instance.max_nondef_actions == 6  # 2 x robots
    assert parsed.non_fluents is not None
    robots = {n.text for decl in parsed.non_fluents.objects if decl.type.text == "robot" for n in decl.names}
    assert robots == {"r1", "r2", "r3"}


def test_run_without_a_world_plans_every_step_within_the_limits(capsys):
    argv = ["protap", "run", "--episodes", "2", "--time-per-step", "0", "--json"]
    assert main(argv) == 0
    first = json.loads(capsys.readouterr().out)
    assert first["constraint_breaks"] == 0 and first["episodes"] == 2 and first["world"] == "none"
    assert first["reward_mean"] > 2000 and first["reward_mean"] >= first["greedy_reward_mean"] - 50
    assert main(argv) == 0  # the same seed gives the same run (no search with 0 s per step)
    assert json.loads(capsys.readouterr().out)["reward_mean"] == first["reward_mean"]


def test_bad_input_gets_a_clear_error(capsys):
    assert main(["protap", "run", "--grid", "2x2", "--goals", "9"]) == 1
    assert "do not fit on a 2x2 grid" in capsys.readouterr().err
    assert main(["protap", "generate", "--grid", "5", "--out", "x"]) == 2
    assert "WIDTHxHEIGHT" in capsys.readouterr().err


def _lunar(capsys, *extra: str) -> dict:
    argv = ["protap", "run", "--world", "lunar", "--robots", "2", "--grid", "3x3", "--goals", "2", "--steps", "4"]
    assert main([*argv, "--time-per-step", "0", "--json", *extra]) == 0
    return json.loads(capsys.readouterr().out)


def _overlap(a: dict, b: dict) -> bool:
    return a["start"] < b["end"] and b["start"] < a["end"]


def test_the_lunar_world_runs_both_robots_actions_of_a_step_at_once(capsys):
    # seed 2: r1 goes to g1 (a2, manipulation) at (2, 0), r2 to g2 (a3, uda) at (1, 1); 0 s: the planner's
    # heuristic joint actions, so the run is the same every time
    summary = _lunar(capsys, "--seed", "2")
    for key in ("reward_mean", "reward_std", "episodes", "constraint_breaks", "time_per_step_s", "world"):
        assert key in summary
    assert summary["world"] == "lunar" and summary["episodes"] == 1 and summary["constraint_breaks"] == 0
    assert summary["success"] is True and summary["goals_done"] == summary["goals"] == 2
    assert summary["action_failures"] == 0 and summary["sim_time_s"] > 0 and summary["wall_time_s"] > 0
    trace = summary["trace"]
    assert [step["step"] for step in trace] == [1, 2, 3, 4]
    assert summary["reward_mean"] == round(sum(step["reward"] for step in trace), 3)
    # step 1: both robots drive at the same time; step 2: r1 picks up and puts down while r2 scans (the uda)
    first, second = trace[0]["robots"], trace[1]["robots"]
    assert [r["action"] for r in first] == ["goto(r1, x3, y1)", "goto(r2, x2, y2)"]
    assert all(r["goto_ok"] and r["skills"][0]["skill"] == "MoveToPosition" for r in first)
    assert _overlap(first[0]["skills"][0], first[1]["skills"][0])
    assert [r["cell_after"] for r in first] == [[2, 0], [1, 1]]
    assert [[s["skill"] for s in r["skills"]] for r in second] == [["Pickup", "Putdown"], ["DetectCircles"]]
    assert all(r["do_ok"] for r in second)
    assert _overlap(second[0]["skills"][0], second[1]["skills"][0])
    # every goal done: nothing left to dispatch, and the utility paid on every later step
    assert all(r["action"] == "noop" and r["skills"] == [] for step in trace[2:] for r in step["robots"])
    assert [step["reward"] for step in trace[2:]] == [200.0, 200.0]


def test_the_same_seed_gives_the_same_lunar_run_from_a_fresh_process():
    """OMPL seeds once per process (see alica.skills.manipulation.arm_paths): compare two fresh processes."""
    argv = [sys.executable, "-m", "alica.app.cli", "protap", "run", "--world", "lunar", "--grid", "3x3", "--goals", "2"]
    argv += ["--steps", "3", "--seed", "2", "--time-per-step", "0", "--json"]
    runs = [json.loads(subprocess.run(argv, capture_output=True, text=True, check=True).stdout) for _ in range(2)]
    for run in runs:
        del run["wall_time_s"]
    assert runs[0] == runs[1] and runs[0]["success"] is True


def test_a_goto_that_fails_in_the_world_is_replanned_from_where_the_robot_really_is(capsys):
    # seed 5: r1 and r2 start in (2, 1); r1 heads for g1 at (2, 2). It crashes as its goto starts (a worldsim
    # fault), so it stays in (2, 1); the next step is planned from there and sends it again.
    summary = _lunar(capsys, "--seed", "5", "--fail-goto", "r1@1")
    step1, step2, step3 = (step["robots"][0] for step in summary["trace"][:3])
    assert step1["action"] == "goto(r1, x3, y3)" and step1["goto_ok"] is False
    assert "MoveToPosition failure" in step1["reason"] and "crashed by the injected fault" in step1["reason"]
    assert step1["cell_after"] == step1["cell_before"] == [2, 1]
    assert step2["cell_before"] == [2, 1] and step2["action"] == "goto(r1, x3, y3)" and step2["goto_ok"] is True
    assert step3["action"] == "do(r1, a2)" and step3["do_ok"] is True
    assert summary["action_failures"] == 1 and summary["success"] is True
    assert main(["protap", "run", "--world", "lunar", "--grid", "3x3", "--goals", "2", "--steps", "4", "--seed", "5",
                 "--time-per-step", "0", "--fail-goto", "r1@1"]) == 0  # fmt: skip
    out = capsys.readouterr().out
    assert "r1 goto(r1, x3, y3): FAILED: goto: MoveToPosition failure" in out
    assert "goals done        2 of 2 (every goal done)" in out and "action failures   1" in out


SCAN_SKILL = """
import py_trees
from py_trees.common import Status

from alica import ParamSpec


class Sniff(py_trees.behaviour.Behaviour):
    def __init__(self, name, params, context):
        super().__init__(name)
        self.object = params["object"]

    def update(self):
        self.feedback_message = f"sniffed {self.object}"
        return Status.SUCCESS


def register(registry):
    registry.declare(
        "Sniff",
        ParamSpec("object", "object", required=True, default=None, doc="what to sniff"),
        doc="sniff a sample",
        implementation=Sniff,
    )
"""


def test_a_user_defined_action_runs_a_plug_in_skill_given_the_goals_sample(capsys, tmp_path, monkeypatch):
    (tmp_path / "sniff_skill.py").write_text(textwrap.dedent(SCAN_SKILL), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    monkeypatch.delitem(sys.modules, "sniff_skill", raising=False)
    summary = _lunar(capsys, "--seed", "2", "--skills", "sniff_skill", "--uda-skill", "Sniff")
    r2 = summary["trace"][1]["robots"][1]
    assert r2["action"] == "do(r2, a3)" and r2["skills"][0]["skill"] == "Sniff"
    assert r2["skills"][0]["reason"] == "sniffed g2" and summary["success"] is True


def test_bad_world_input_gets_a_clear_error(capsys):
    lunar = [
        "protap",
        "run",
        "--world",
        "lunar",
        "--grid",
        "3x3",
        "--goals",
        "2",
        "--steps",
        "2",
        "--time-per-step",
        "0",
    ]
    cases = [
        (["--uda-skill", "Sniffle"], "--uda-skill Sniffle: no skill of that name is registered"),
        (["--uda-skill", "StereoPointCloud"], "needs stereo_camera, which a stummel lacks"),
        (["--uda-skill", "MoveToPosition"], "cannot give the required parameter(s) goal"),
        (["--grid", "20x20"], "needs a field of 63 m"),
        (["--robots", "7"], "7 robots do not fit around a cell of 3 m"),
        (["--cell-size", "1"], "a cell of 1 m is too small"),
        (["--fail-goto", "r9@1"], "--fail-goto r9@1: no robot named r9"),
        (["--grid-rocks", "300"], "could only place"),
    ]
    for extra, message in cases:
        assert main([*lunar, *extra]) == 1, extra
        assert message in capsys.readouterr().err, extra
    assert main([*lunar, "--fail-goto", "r1"]) == 2
    assert "ROBOT@STEP" in capsys.readouterr().err
    assert main(["protap", "run", "--uda-skill", "DetectCircles", "--grid-rocks", "2"]) == 1
    assert "--uda-skill, --grid-rocks: only with --world lunar" in capsys.readouterr().err
