"""One vocabulary of flags across run, agent, demo, skill run and protap; what the summary says of messages,
of a misspelt role and of a running skill (issue 35)."""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from alica.app.cli import build_parser, main
from alica.app.cli_run import message_counts
from alica.app.options import FIELD_SIZE, ROCKS, SAMPLES
from tests.conftest import PLANS

LUNAR = str(PLANS / "lunar" / "mission.yaml")
TEAM = ["--stand-ins", "--agents", "scout,stummel,amparo"]

#: Every command of the vocabulary, as its words on the command line.
COMMANDS = [
    ("run",),
    ("agent",),
    ("demo", "lunar"),
    ("demo", "blocksworld"),
    ("skill", "run"),
    ("protap", "run"),
    ("protap", "generate"),
]


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def subparser(words: tuple[str, ...]) -> argparse.ArgumentParser:
    parser = build_parser()
    for word in words:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        parser = sub.choices[word]
    return parser


def options(words: tuple[str, ...]) -> dict[str, argparse.Action]:
    """The options ``alica WORDS --help`` shows, by spelling."""
    return {
        spelling: action
        for action in subparser(words)._actions
        if action.help != argparse.SUPPRESS
        for spelling in action.option_strings
    }


def hidden(words: tuple[str, ...]) -> dict[str, argparse.Action]:
    """The options that are there but not shown: the deprecated spellings."""
    return {
        spelling: action
        for action in subparser(words)._actions
        if action.help == argparse.SUPPRESS
        for spelling in action.option_strings
    }


def deprecation(old: str, new: str) -> str:
    return f"alica: {old} is deprecated here; use {new} (the old spelling goes in the next release)\n"


# -- A. one vocabulary ------------------------------------------------------------------------------


def test_the_same_option_has_the_same_default_in_every_command() -> None:
    found: dict[str, dict[tuple[str, ...], object]] = {}
    for words in COMMANDS:
        for spelling, action in options(words).items():
            found.setdefault(spelling, {})[words] = action.default
    assert found["--samples"] == dict.fromkeys([("run",), ("demo", "lunar"), ("skill", "run")], SAMPLES)
    assert found["--rocks"] == dict.fromkeys([("run",), ("demo", "lunar"), ("skill", "run")], ROCKS)
    assert found["--size"] == dict.fromkeys([("run",), ("demo", "lunar"), ("skill", "run")], FIELD_SIZE)
    assert SAMPLES == 6 and ROCKS == 60 and FIELD_SIZE == 40.0
    assert set(found["--seed"].values()) == {0}
    # one name for the give-up time; the old ones are gone from the help
    assert set(found["--time-limit"]) == {
        ("run",),
        ("agent",),
        ("demo", "lunar"),
        ("demo", "blocksworld"),
        ("skill", "run"),
    }
    assert "--max-time" not in found and "--timeout" not in found
    # --agents is a roster wherever it is shown; --robots a count
    assert set(found["--agents"]) == {("run",), ("agent",), ("demo", "lunar")}
    assert all(options(w)["--agents"].metavar == "NAME[:ROLE],..." for w in found["--agents"])
    assert found["--robots"] == {("demo", "blocksworld"): 2, ("protap", "run"): 2, ("protap", "generate"): 2}
    assert all(options(w)["--robots"].metavar == "N" for w in found["--robots"])
    # protap's rocks between the cells have their own name
    assert ("protap", "run") in found["--grid-rocks"]


def test_every_shown_option_with_a_default_says_it_in_its_help() -> None:
    missing = []
    for words in COMMANDS:
        for spelling, action in options(words).items():
            default = action.default
            if default in (None, False, [], argparse.SUPPRESS) or spelling == "--help":
                continue
            if "default" not in (action.help or ""):
                missing.append(f"alica {' '.join(words)} {spelling}")
    assert missing == []


@pytest.mark.parametrize(
    ("words", "old", "new"),
    [
        (("run",), "--max-time", "--time-limit"),
        (("agent",), "--max-time", "--time-limit"),
        (("skill", "run"), "--timeout", "--time-limit"),
        (("demo", "blocksworld"), "--agents", "--robots"),
        (("demo", "lunar"), "--robots", "--agents"),
        (("protap", "run"), "--rocks", "--grid-rocks"),
    ],
)
def test_each_old_spelling_is_kept_as_a_hidden_alias(words: tuple[str, ...], old: str, new: str) -> None:
    assert old in hidden(words) and old not in options(words)
    assert hidden(words)[old].dest == options(words)[new].dest


@pytest.mark.parametrize(
    ("old", "new", "value"),
    [(["--max-time"], ["--time-limit"], "7.5"), (["--timeout"], ["--time-limit"], "7.5")],
)
def test_an_old_spelling_sets_what_the_new_one_sets(
    old: list[str], new: list[str], value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    words = ["run", LUNAR, "--agents", "scout"] if old == ["--max-time"] else ["skill", "run", "BuildMap"]
    with_old = build_parser().parse_args([*words, *old, value])
    assert capsys.readouterr().err == deprecation(old[0], new[0])
    with_new = build_parser().parse_args([*words, *new, value])
    assert capsys.readouterr().err == ""
    assert with_old.time_limit == with_new.time_limit == float(value)
    assert build_parser().parse_args(words).time_limit == (300.0 if old == ["--max-time"] else 120.0)


def test_run_with_max_time_warns_once_and_stops_there(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = cli(capsys, "run", LUNAR, *TEAM, "--max-time", "2", "--json")
    assert code == 1  # not finished after 2 simulated seconds
    assert err == deprecation("--max-time", "--time-limit")
    assert 2.0 <= json.loads(out)["sim_time_s"] < 2.1
    code, out, err = cli(capsys, "run", LUNAR, *TEAM, "--time-limit", "2", "--json")
    assert code == 1 and err == "" and 2.0 <= json.loads(out)["sim_time_s"] < 2.1


@pytest.mark.parametrize(
    ("argv", "old", "new", "message"),
    [
        (["demo", "blocksworld", "--agents", "1", "--crash", "r2@1"], "--agents", "--robots", "the team is r1\n"),
        (
            ["demo", "lunar", "--robots", "scout,stummel", "--crash", "amparo@3", "--no-progress"],
            "--robots",
            "--agents",
            "'amparo' is not in the team (scout, stummel)",
        ),
        (["protap", "run", "--rocks", "2"], "--rocks", "--grid-rocks", "--grid-rocks: only with --world lunar"),
        (["skill", "run", "BuildMap", "--timeout", "0"], "--timeout", "--time-limit", "--time-limit must be"),
        (["run", LUNAR, *TEAM, "--max-time", "-1"], "--max-time", "--time-limit", "--time-limit must be"),
        (["agent", LUNAR, "--name", "scout", "--max-time", "0"], "--max-time", "--time-limit", "--time-limit must"),
    ],
)
def test_an_old_spelling_works_and_warns(
    argv: list[str], old: str, new: str, message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """The old spelling reaches the same check as the new one (here each run stops at a check of its value)."""
    code, _, err = cli(capsys, *argv)
    assert code == 1
    assert err.startswith(deprecation(old, new)) and err.count("deprecated") == 1
    assert message in err, err
    code, _, err = cli(capsys, *[new if word == old else word for word in argv])
    assert code == 1 and "deprecated" not in err and message in err, err


def test_the_blocks_demos_old_agents_takes_a_count_only(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = cli(capsys, "demo", "blocksworld", "--agents", "r1,r2")
    assert code == 2
    assert "the blocks demo names its robots r1..rN itself; give their number with --robots N" in err


def test_the_lunar_demo_takes_a_roster_with_the_robots_own_roles(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = cli(capsys, "demo", "lunar", "--agents", "scout:Scout,stummel:Amparo", "--no-progress")
    assert code == 1
    assert "--agents: 'stummel:Amparo': in the lunar demo stummel has the role Stummel; write stummel" in err


# -- B. message counts --------------------------------------------------------------------------------

LOSSY = ["run", LUNAR, *TEAM, "--time-limit", "8", "--loss", "0.3", "--crash", "scout@2", "--seed", "1"]


def test_the_summary_says_what_the_message_counts_count(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = cli(capsys, *LOSSY, "--json")
    assert code == 1
    messages = json.loads(out)["messages"]
    assert set(messages) == {
        "sent",
        "delivered",
        "dropped_loss",
        "dropped_partition",
        "dropped_crash",
        "dropped_closed",
        "superseded",
    }
    assert messages["dropped_loss"] > 0 and messages["dropped_crash"] > 0 and messages["dropped_partition"] == 0
    code, out, _ = cli(capsys, *LOSSY)
    line = next(x for x in out.splitlines() if x.startswith("messages:"))
    match = re.fullmatch(
        r"messages: (\d+) sent; copies to receivers: (\d+) delivered, (\d+) dropped by loss, "
        r"(\d+) dropped at crashed receivers(, (\d+) replaced by a newer one before delivery)?",
        line,
    )
    assert match is not None, line
    shown = [int(match.group(i)) for i in (1, 2, 3, 4)]
    assert shown == [messages[k] for k in ("sent", "delivered", "dropped_loss", "dropped_crash")]


def test_message_counts_name_each_fate_and_say_when_none_was_dropped() -> None:
    assert (
        message_counts({"sent": 4, "delivered": 12})
        == "messages: 4 sent; copies to receivers: 12 delivered, none dropped"
    )
    text = message_counts({"sent": 9, "delivered": 20, "dropped_partition": 3, "dropped_lost": 1, "dropped_crash": 0})
    assert text == (
        "messages: 9 sent; copies to receivers: 20 delivered, 3 dropped by partitions, "
        "1 lost for good (no longer in the sender's history)"
    )


# -- C. did you mean, for roles ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["run", LUNAR, "--agents", "scout:Scot,stummel"],
            "--agents: agent 'scout' has role 'Scot', which no role set has (did you mean 'Scout'?)",
        ),
        (
            ["run", LUNAR, "--agents", "scot"],
            "--agents: agent 'scot' has no role and no role is called like it (did you mean 'Scout'?)",
        ),
        (
            ["run", LUNAR, "--agents", "a:Stumel", "--roleset", "Impera"],
            "which role set 'Impera' does not have (did you mean 'Stummel'?)",
        ),
        (
            ["agent", LUNAR, "--name", "scout", "--role", "Amparro"],
            "--role: agent 'scout' has role 'Amparro', which no role set has (did you mean 'Amparo'?)",
        ),
        (
            ["demo", "lunar", "--agents", "scout:Scoot", "--no-progress"],
            "in the lunar demo scout has the role Scout (did you mean 'Scout'?)",
        ),
    ],
)
def test_a_misspelt_role_gets_did_you_mean(argv: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = cli(capsys, *argv)
    assert code == 1
    assert message in err, err


# -- D. a running skill's own word in the why line and the tree -------------------------------------

SKILL = '''
import py_trees
from py_trees.common import Status


class Approach(py_trees.behaviour.Behaviour):
    """Never arrives: says how far it still has to go."""

    def __init__(self, name, params, context):
        super().__init__(name)

    def update(self):
        self.feedback_message = "0.40 m to go"
        return Status.RUNNING


def register(registry):
    registry.declare("Approach", doc="approach, never arriving", implementation=Approach)
'''

PLAN = """
alica: 1
tasks:
  - name: Default
rolesets:
  - name: Crew
    default_priority: 0
    roles:
      - name: Worker
        priorities: {Default: 0.5}
behaviours:
  - name: GetThere
    skill: Approach
plans:
  - name: Job
    entry_points:
      - {task: Default, state: Going, min: 1, max: 1, success_required: true}
    states:
      - name: Going
        children: [{ref: GetThere}]
        transitions:
          - {to: Done, condition: succeeded}
      - name: Done
        kind: success
"""


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    """A user's folder with the skill module ``approach_skill`` and the plan ``job.yaml``; the working folder."""
    (tmp_path / "approach_skill.py").write_text(SKILL, encoding="utf-8")
    (tmp_path / "job.yaml").write_text(PLAN, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", list(sys.path))
    yield str(tmp_path / "job.yaml")
    sys.modules.pop("approach_skill", None)


def test_the_why_line_gives_the_running_skills_feedback(project: str, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["run", project, "--agents", "ann:Worker", "--skills", "approach_skill", "--time-limit", "1"]
    code, out, _ = cli(capsys, *argv)
    assert code == 1
    why = next(x for x in out.splitlines() if x.startswith("why ann:"))
    assert why == "why ann: in Job:Going (GetThere running), waiting for one of: succeeded; GetThere says: 0.40 m to go"
    code, out, _ = cli(capsys, *argv, "--json")
    assert "GetThere says: 0.40 m to go" in json.loads(out)["agents"]["ann"]["reason"]


def test_show_tree_gives_the_running_skills_feedback(project: str, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["run", project, "--agents", "ann:Worker", "--skills", "approach_skill", "--ticks", "3", "--show-tree"]
    code, out, _ = cli(capsys, *argv)
    assert code == 1
    assert re.search(r"└─ GetThere  running  says: 0\.40 m to go$", out, re.MULTILINE), out
