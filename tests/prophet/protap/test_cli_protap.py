"""``alica protap generate`` and ``alica protap run --world none`` through the command line."""

from __future__ import annotations

import json

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
    assert main(["protap", "run", "--world", "lunar"]) == 1
    assert "not built yet" in capsys.readouterr().err
    assert main(["protap", "generate", "--grid", "5", "--out", "x"]) == 2
    assert "WIDTHxHEIGHT" in capsys.readouterr().err
