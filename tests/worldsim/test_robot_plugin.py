"""The robot plug-in (``--robot``): a driver of one's own runs the plans and skills (issue 38).

The shipped example driver is the unicycle (:mod:`alica.worldsim.unicycle`,
entry point ``unicycle`` of the group ``alica.robots``); a user's own module
plugs in by ``MODULE:FACTORY``.
"""

from __future__ import annotations

import json
import textwrap

import pytest

from alica.app.cli import main
from alica.io.loader import plans_dir

PLANS = plans_dir()
FORMATION = str(PLANS / "examples" / "formation.yaml")
EXPLORE = str(PLANS / "skills" / "explore.yaml")


def run_json(argv: list[str], capfd: pytest.CaptureFixture[str]) -> tuple[int, dict]:
    code = main([*argv, "--json"])
    out = capfd.readouterr().out
    return code, json.loads(out[out.index("{") :])


def test_move_to_position_runs_on_the_unicycle_through_the_plug_in(capfd):
    code, summary = run_json(
        [
            "run",
            FORMATION,
            "--agents",
            "r1:Robot,r2:Robot",
            "--robot",
            "unicycle",
            "--robot-option",
            "origin=-6,-6",
            "--robot-option",
            "r2.pose=-5,4,0",  # r2 only; r1 starts at the default, 1 m in from the corner
            "--time-limit",
            "120",
        ],
        capfd,
    )
    assert code == 0 and summary["success"], summary
    assert summary["skills"]["real"] == ["MoveToPosition"] and summary["skills"]["robot"] == "unicycle"


def test_the_explore_plan_runs_on_the_unicycle(capfd):
    code, summary = run_json(
        ["run", EXPLORE, "--agents", "scout:Scout", "--robot", "unicycle", "--time-limit", "300"], capfd
    )
    assert code == 0 and summary["success"], summary
    assert {"BuildMap", "Localize", "ExploreFrontier"} <= set(summary["skills"]["real"])
    assert summary["agents"]["scout"]["path"] == "Explore:MapComplete"


def test_the_explore_plan_runs_as_processes_one_unicycle_each(capfd):
    code, summary = run_json(
        [
            "run",
            EXPLORE,
            "--agents",
            "scout:Scout,stummel:Stummel",
            "--robot",
            "unicycle",
            "--robot-option",
            "stummel.pose=10,10,3",
            "--processes",
            "--time-limit",
            "60",
        ],
        capfd,
    )
    assert code == 0 and summary["success"], summary
    assert summary["processes"] and summary["skills"]["robot"] == "unicycle"


def test_a_skill_runs_alone_on_the_plug_in(capfd):
    code, result = run_json(["skill", "run", "MoveToPosition", "--robot", "unicycle", "--param", "goal=[9, 9]"], capfd)
    assert code == 0 and result["status"] == "success" and result["robot"] == "robot", result


DRIVERS = '''
from alica.worldsim.unicycle import make_robot, OccupancyMap, UnicycleWorld

def build(name, role, options):
    """A user's factory: an empty walled room, the robot where the options say."""
    rows = ["#" * 20] + ["#" + "." * 18 + "#"] * 18 + ["#" * 20]
    world = UnicycleWorld(OccupancyMap.from_rows(rows, 0.5), seed=1)
    world.add_robot("scout", name, [float(v) for v in options.get("at", "2,2,0").split(",")])
    return world

class Hardware:
    """A driver without step(seconds): it runs on the wall clock."""
    def __init__(self, world):
        self._world = world
    def __getattr__(self, name):
        if name in ("step", "clock"):
            raise AttributeError(name)  # moved by its own motors, not by the run
        return getattr(self._world, name)
    @property
    def robots(self):
        return self._world.robots
    @property
    def objects(self):
        return {}
    @property
    def bounds(self):
        return self._world.bounds
    @property
    def seed(self):
        return 0

def hardware(name, role, options):
    return Hardware(build(name, role, options))

def broken(name, role, options):
    raise RuntimeError("no robot on /dev/ttyUSB0")

def nothing(name, role, options):
    return 42

def stranger(name, role, options):
    return build("someone_else", role, options)
'''


@pytest.fixture
def drivers(tmp_path, monkeypatch):
    (tmp_path / "my_driver.py").write_text(textwrap.dedent(DRIVERS), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    return tmp_path


def test_a_users_own_factory_plugs_in_by_module_and_name(drivers, capfd):
    code, result = run_json(
        [
            "skill",
            "run",
            "MoveToPosition",
            "--robot",
            "my_driver:build",
            "--robot-name",
            "rover",
            "--robot-option",
            "at=2,8,0",
            "--param",
            "goal=[8, 2]",
        ],
        capfd,
    )
    assert code == 0 and result["status"] == "success" and result["robot"] == "rover", result


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--robot", "no_such_driver"], "no installed robot plug-in of that name (installed: ros2, unicycle"),
        (["--robot", "my_driver:missing"], "module 'my_driver' has no 'missing'"),
        (["--robot", "my_driver:broken"], "making robot 'r1' failed: RuntimeError: no robot on /dev/ttyUSB0"),
        (["--robot", "my_driver:nothing"], "returned a int, which does not offer the robot interface"),
        (["--robot", "my_driver:stranger"], "has no robot named 'r1' (robots: someone_else)"),
        (["--robot", "my_driver:hardware"], "runs on the wall clock"),
        (["--robot", "unicycle", "--robot-option", "speed=3"], "the unicycle has no option speed"),
        (["--robot", "unicycle", "--robot-option", "pose=1,2"], "option pose: '1,2' is not x,y,yaw"),
        (["--robot", "unicycle", "--robot-option", "kind=tank"], "no robot kind 'tank'"),
        (["--robot", "unicycle", "--robot-option", "pose=0.2,0.2,0"], "does not fit"),
        (["--robot", "unicycle", "--robot-option", "pose"], "is not KEY=VALUE"),
        (["--robot-option", "pose=1,1,0"], "--robot-option goes with --robot"),
        (["--robot", "unicycle", "--world", "lunar"], "choose one"),
    ],
)
def test_bad_plug_ins_and_options_get_a_clear_error(drivers, argv, message, capfd):
    code = main(["run", FORMATION, "--agents", "r1:Robot,r2:Robot", *argv])
    err = capfd.readouterr().err
    assert code != 0 and message in err, err
    assert "Traceback" not in err


def test_a_crash_stops_the_plug_ins_robot(tmp_path, capfd):
    room = tmp_path / "room.txt"  # 12 m x 12 m, walls only: the formation's spots are all free
    room.write_text("\n".join(["#" * 48] + ["#" + "." * 46 + "#"] * 46 + ["#" * 48]), encoding="utf-8")
    code, summary = run_json(
        [
            "run",
            FORMATION,
            "--agents",
            "r1:Robot,r2:Robot,r3:Robot",
            "--robot",
            "unicycle",
            "--robot-option",
            f"map={room}",
            "--robot-option",
            "origin=-6,-6",
            "--robot-option",
            "r2.pose=-5,4,0",
            "--robot-option",
            "r3.pose=4,-5,1.5",
            "--crash",
            "r3@0.5",
            "--time-limit",
            "120",
        ],
        capfd,
    )
    assert summary["agents"]["r3"]["status"] == "crashed", summary["agents"]["r3"]
    assert code == 0 and summary["success"]  # two robots are enough for the formation
