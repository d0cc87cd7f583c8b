"""``alica demo lunar``: the operator's choice, the options, and the mission's run (issue 17)."""

from __future__ import annotations

import pytest

from alica.app.cli import main
from alica.app.demos.lunar import Crash, LunarConfig, Operator, goal_samples, kind_name, parse_crash
from alica.errors import AlicaError
from alica.io import validate_paths


class _WM:
    def __init__(self, found: dict[str, tuple[str, tuple[float, float]]], explored: bool = False) -> None:
        self.found = found
        self.explored = explored

    def holds(self, pred: str, *args: object) -> bool:
        return pred == "explored" and self.explored

    def facts(self):
        from alica.lang.fact import Fact

        return [Fact("found", (name,)) for name in self.found]

    def get(self, name: str, arg: str):
        kind, pos = self.found[arg]
        return kind if name == "sample_kind" else pos


class _Engine:
    def __init__(self, wm: _WM) -> None:
        self.world_model = wm


class _Team:
    def __init__(self, *wms: _WM) -> None:
        self.engines = [_Engine(w) for w in wms]

    def running(self):
        return self.engines


GWR = ("green-white-red", (3.0, 4.0))
RBR = ("red-black-red", (-5.0, 1.0))
GBG = ("green-black-green", (8.0, -2.0))


def test_without_a_goal_the_operator_picks_the_first_samples_found():
    op = Operator(LunarConfig(pick=2))
    assert not op.read(_Team(_WM({"green_white_red": GWR})))
    assert op.choose(explored=False) is None  # one found, two wanted: wait
    op.read(_Team(_WM({"green_white_red": GWR}), _WM({"red_black_red": RBR, "green_black_green": GBG})))
    assert op.choose(explored=False) == ["green_white_red", "red_black_red"]
    op.chosen = ["green_white_red", "red_black_red"]
    assert op.goal() == "at(green_white_red, g) and at(red_black_red, g)"
    assert op.places["red_black_red"] == (-5.0, 1.0)


def test_the_operator_collects_kinds_and_takes_what_was_found_when_the_field_is_explored():
    op = Operator(LunarConfig(collect=("red-black-red", "green-black-green")))
    op.read(_Team(_WM({"green_white_red": GWR, "red_black_red": RBR})))
    assert op.choose(explored=False) is None
    explored = op.read(_Team(_WM({"green_white_red": GWR, "red_black_red": RBR}, explored=True)))
    assert explored and op.choose(explored) == ["red_black_red"]


def test_nothing_wanted_found_on_an_explored_field_ends_the_choice_with_a_reason():
    op = Operator(LunarConfig(goal="at(green_black_green, g)"))
    explored = op.read(_Team(_WM({"green_white_red": GWR}, explored=True)))
    assert op.choose(explored) == []
    assert "no sample the operator wants" in op.reason


def test_goal_crash_and_kind_names():
    assert goal_samples("at(a, g) and at(green_white_red, g)") == ["a", "green_white_red"]
    assert kind_name("green-white-red") == "green_white_red"
    assert parse_crash("amparo@grasp") == Crash("amparo", None)
    assert parse_crash("scout@2.5") == Crash("scout", 2.5)
    for bad in ("at(a, b)", "not at(a, g)", "holding(r, a)"):
        with pytest.raises(AlicaError, match="at\\(sample, g\\)"):
            goal_samples(bad)
    with pytest.raises(AlicaError, match="NAME@T or NAME@grasp"):
        parse_crash("amparo")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--agents", "scout,robby"], "name each of scout, stummel, amparo at most once"),
        (["--collect", "green-pink-red"], "unknown kind(s) green-pink-red"),
        (["--goal", "on(a, g)"], "at(sample, g)"),
        (["--crash", "amparo@soon"], "neither seconds nor 'grasp'"),
        (["--agents", "scout,stummel", "--crash", "amparo@3"], "'amparo' is not in the team"),
        (["--partition", "scout|robby@1-5"], "robby not in the team"),
        (["--loss", "1.5"], "--loss must be a probability"),
        (["--time-limit", "0"], "--time-limit must be a positive"),
    ],
)
def test_bad_options_give_a_clear_error(argv, message, capsys):
    assert main(["demo", "lunar", *argv, "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert message in err, err
    assert "Traceback" not in err


def test_the_mission_brings_the_chosen_samples_to_g_on_a_small_field(tmp_path):
    """End to end with the real skills: explore, detect, choose, plan at run time, fetch (16 m field, 2 samples).

    In a fresh process, as a user runs it: OMPL has one generator per process, seeded once (the
    test session seeded it already), and the same seed gives the same run only in a fresh process.
    """
    import json
    import subprocess
    import sys

    argv = ["demo", "lunar", "--size", "16", "--rocks", "6", "--samples", "2", "--seed", "3", "--time-limit", "300"]
    done = subprocess.run(
        [sys.executable, "-m", "alica.app.cli", *argv, "--out", str(tmp_path), "--json", "--no-progress"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    result = json.loads(done.stdout)
    assert done.returncode == 0 and result["success"], (result, done.stderr[-2000:])
    assert sorted(result["delivered"]) == sorted(result["chosen"]) and len(result["chosen"]) == 2
    assert set(result["chosen"]) <= set(result["found"])
    assert result["coverage"] > 0.9 and result["plans"] >= 1
    # Amparo and Stummel carried (Scout has no arm), and everything the demo writes is there
    carried = {name for name, robot in result["robots"].items() if robot["steps"]}
    assert carried <= {"amparo", "stummel"} and carried
    assert {p.name for p in tmp_path.iterdir()} >= {"trace.jsonl", "map.png", "plan.yaml", "plans"}
    assert len(list((tmp_path / "plans").glob("GetObjects_g*.yaml"))) == result["plans"]
    # the generated plans import the mission by name: valid wherever the folder is moved
    for written in [tmp_path / "plan.yaml", *(tmp_path / "plans").glob("*.yaml")]:
        text = written.read_text(encoding="utf-8")
        assert "alica:plans/lunar/" in text and "../" not in text, written
        assert validate_paths([written]) == [], written
