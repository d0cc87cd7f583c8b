"""Skill plug-ins: a user's module named with --skills or listed as an entry point, in validate, list-skills and run."""

from __future__ import annotations

import json
import sys
import textwrap
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from alica import ParamSpec, SkillRegistry
from alica.app.cli import main
from alica.lang.skill_plugins import SkillPluginError, default_registry, load_skill_module

COUNTER = '''
import py_trees
from py_trees.common import Status

from alica import ParamSpec

TICKS = []


class CountTicks(py_trees.behaviour.Behaviour):
    """Counts its ticks; after `times` of them writes counted(agent) and succeeds."""

    def __init__(self, name, params, context):
        super().__init__(name)
        self.times = int(params.get("times", 3))
        self.context = context
        self.ticks = 0

    def update(self):
        self.ticks += 1
        TICKS.append((self.context.agent, self.ticks))
        if self.ticks < self.times:
            return Status.RUNNING
        self.context.world_model.assert_fact("counted", self.context.agent)
        return Status.SUCCESS


def register(registry):
    registry.declare_predicate("counted", 1, "the agent counted its ticks")
    registry.declare(
        "CountTicks",
        ParamSpec("times", "int", required=False, default=3, doc="ticks to count"),
        doc="count ticks, then say so",
        implementation=CountTicks,
    )
    registry.declare(
        "Pause",
        ParamSpec("duration", "float", required=False, default=1.0, doc="seconds to pause"),
        doc="pause (no implementation yet)",
    )
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
        priorities: {{Default: 0.5}}
behaviours:
  - name: Work
    skill: {skill}
    params: {params}
plans:
  - name: Job
    entry_points:
      - {{task: Default, state: Working, min: 1, max: 1, success_required: true}}
    states:
      - name: Working
        children: [{{ref: Work}}]
        transitions:
          - {{to: Done, condition: "{condition}"}}
      - name: Done
        kind: success
"""


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A user's folder holding the module ``count_skill``; the working folder for the test."""
    (tmp_path / "count_skill.py").write_text(COUNTER, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", list(sys.path))
    yield tmp_path
    for name in [m for m in sys.modules if m in ("count_skill", "bad_skill")]:
        del sys.modules[name]


def plan(folder: Path, skill: str, params: str, condition: str = "succeeded") -> str:
    path = folder / "job.yaml"
    path.write_text(PLAN.format(skill=skill, params=params, condition=condition), encoding="utf-8")
    return str(path)


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def test_a_user_skill_runs_for_real_in_alica_run(project: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = plan(project, "CountTicks", "{times: 4}", condition="counted(self)")
    code, out, err = cli(capsys, "run", path, "--agents", "ann:Worker", "--skills", "count_skill", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["success"] and summary["skills"] == {"real": ["CountTicks"], "stand_ins": [], "world": None}
    assert sys.modules["count_skill"].TICKS == [("ann", 1), ("ann", 2), ("ann", 3), ("ann", 4)]
    code, out, _ = cli(capsys, "run", path, "--agents", "ann:Worker", "--skills", "count_skill")
    assert code == 0 and "real skills: CountTicks" in out and "stand-in" not in out


def test_a_user_skill_is_listed_and_validated(project: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = cli(capsys, "list-skills", "--skills", "count_skill")
    assert code == 0
    line = next(x for x in out.splitlines() if x.startswith("CountTicks:"))
    assert "(runs count_skill:CountTicks)" in line and "(from count_skill)" in line
    pause = next(x for x in out.splitlines() if x.startswith("Pause:"))
    assert "no implementation yet" in pause
    assert "(from" not in next(x for x in out.splitlines() if x.startswith("MoveToPosition:"))
    path = plan(project, "CountTicks", "{times: 2}")
    assert cli(capsys, "validate", path, "--skills", "count_skill")[0] == 0
    code, _, err = cli(capsys, "validate", path)
    assert code == 1 and "CountTicks" in err
    code, _, err = cli(capsys, "validate", plan(project, "CountTicks", "{times: many}"), "--skills", "count_skill")
    assert code == 1 and "times" in err


def test_entry_points_of_installed_packages_are_found(project: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    info = project / "site" / "count_skill_pkg-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: count-skill-pkg\nVersion: 1.0\n", encoding="utf-8")
    (info / "entry_points.txt").write_text("[alica.skills]\ncounting = count_skill:register\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(project))
    monkeypatch.syspath_prepend(str(project / "site"))
    registry = default_registry()
    assert "CountTicks" in registry and registry.get("CountTicks").origin == "count_skill"
    assert "MoveToPosition" in registry  # the shipped catalogue is an entry point too


def test_an_entry_point_naming_a_module(project: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    info = project / "site" / "count_skill_pkg-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: count-skill-pkg\nVersion: 1.0\n", encoding="utf-8")
    (info / "entry_points.txt").write_text("[alica.skills]\ncounting = count_skill\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(project))
    monkeypatch.syspath_prepend(str(project / "site"))
    assert "Pause" in default_registry()


@pytest.mark.parametrize(
    ("source", "message"),
    [
        (None, "skill module 'bad_skill' cannot be imported: No module named 'bad_skill'"),
        ("X = 1\n", "skill module 'bad_skill' has no register(registry) function"),
        ("raise RuntimeError('half written')\n", "skill module 'bad_skill' failed while importing: RuntimeError"),
        (
            "def register(registry):\n    registry.declare('Idle', doc='mine')\n",
            "skill module 'bad_skill': skill 'Idle' is already registered by alica.skills.catalog",
        ),
        (
            "def register(registry):\n    raise KeyError('oops')\n",
            "skill module 'bad_skill': register() raised KeyError: 'oops'",
        ),
        (
            "from alica import ParamSpec\ndef register(registry):\n    registry.declare('X', ParamSpec('p', 'vector'))\n",
            "skill module 'bad_skill': parameter 'p': unknown type 'vector'",
        ),
    ],
)
def test_a_bad_skill_module_is_a_one_line_error(
    project: Path, capsys: pytest.CaptureFixture[str], source: str | None, message: str
) -> None:
    if source is not None:
        (project / "bad_skill.py").write_text(source, encoding="utf-8")
    for argv in (
        ["list-skills"],
        ["validate", plan(project, "Idle", "{}")],
        ["run", "job.yaml", "--agents", "a:Worker"],
    ):
        code, out, err = cli(capsys, *argv, "--skills", "bad_skill")
        assert code == 1 and out == ""
        assert err.startswith(f"alica: error: {message}") and err.count("\n") == 1, err
    with pytest.raises(SkillPluginError):
        load_skill_module(default_registry(), "bad_skill")


def test_stand_ins_only_on_request_and_honouring_their_duration(
    project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = plan(project, "Pause", "{duration: 2.5}")
    code, out, err = cli(capsys, "run", path, "--agents", "ann:Worker", "--skills", "count_skill")
    assert code == 1 and out == ""
    assert "Job uses skills that have no implementation: Pause; pass --stand-ins" in err
    code, out, _ = cli(
        capsys, "run", path, "--agents", "ann:Worker", "--skills", "count_skill", "--stand-ins", "--json"
    )
    summary = json.loads(out)
    assert code == 0 and summary["success"] and summary["skills"]["stand_ins"] == ["Pause"]
    assert 2.5 <= summary["sim_time_s"] < 2.7
    path = plan(project, "Pause", "{}")  # the declared default, 1 s
    code, out, _ = cli(
        capsys, "run", path, "--agents", "ann:Worker", "--skills", "count_skill", "--stand-ins", "--json"
    )
    assert code == 0 and 1.0 <= json.loads(out)["sim_time_s"] < 1.2
    code, out, _ = cli(capsys, "run", path, "--agents", "ann:Worker", "--skills", "count_skill", "--stand-ins")
    assert "scripted stand-ins (--stand-ins): Pause" in out


def test_the_idle_stand_in_takes_its_duration() -> None:
    from alica.model import Behaviour
    from alica.testing import default_fallback

    fallback = default_fallback(registry=default_registry())
    idle = Behaviour(name="Wait", skill="Idle")
    assert fallback(idle)("Wait", {"duration": 3.0}, None).duration == 3.0
    assert fallback(idle)("Wait", {}, None).duration is None  # the declared default 0: until the state is left
    other = Behaviour(name="Find", skill="Localize")
    assert 0.5 <= fallback(other)("Find", {}, None).duration <= 2.0


def test_a_skill_that_acts_on_a_robot_needs_a_world(project: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = plan(project, "MoveToPosition", "{goal: [0.6, -1.6]}")
    code, _, err = cli(capsys, "run", path, "--agents", "ann:Worker")
    assert code == 1
    assert "Job uses skills that act on a robot and the run has no world: MoveToPosition; pass --world" in err


def test_alica_run_with_a_blocks_world_runs_a_real_skill(project: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = plan(project, "MoveToPosition", "{goal: [0.6, -1.6]}")
    code, out, err = cli(capsys, "run", path, "--agents", "ann:Worker", "--world", "blocks", "--time-limit", "20")
    assert code == 0, out + err
    assert out.startswith("Job: success after") and "real skills in the blocks world: MoveToPosition" in out
    code, _, err = cli(capsys, "run", path, "--agents", "ann:Worker", "--world", "lunar", "--rocks", "0")
    assert code == 1 and "--world lunar: no robot for agent(s) ann" in err


def test_public_names() -> None:
    registry = SkillRegistry()
    spec = registry.declare("Wave", ParamSpec("times", "int", required=False, default=2), implementation="m:Wave")
    assert spec.implementation_name == "m:Wave" and registry.get("Wave").param("times") is not None


def test_a_project_with_its_own_skills_package_runs_pytest_with_the_fixtures(tmp_path: Path) -> None:
    import importlib.metadata
    import subprocess

    plugins = {e.value for e in importlib.metadata.entry_points(group="pytest11")}
    assert "alica.skills.pytest_plugin" in plugins  # the installed name, which a user's skills/ cannot shadow

    (tmp_path / "skills").mkdir()
    (tmp_path / "skills" / "__init__.py").write_text('"""The user\'s own skills package."""\nMINE = True\n')
    (tmp_path / "test_mine.py").write_text(
        textwrap.dedent(
            """
            import alica.io
            import skills


            def test_fixtures_and_imports(blocks_world, skill_run):
                assert skills.MINE and alica.io.load_library is not None
                run = skill_run("Idle", blocks_world, "r1", {"duration": 0.5})
                assert run.status == "success", run.reason
            """
        )
    )
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_mine.py"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 passed" in done.stdout


def test_run_skill_finds_plug_in_modules(project: Path, monkeypatch: pytest.MonkeyPatch, blocks_world: Any) -> None:
    from alica.errors import SkillError
    from alica.skills.testing import run_skill

    monkeypatch.syspath_prepend(str(project))
    run = run_skill("CountTicks", blocks_world, "r1", {"times": 2}, skills=["count_skill"])
    assert run.ok and run.holds("counted", "r1") and run.ticks == 2
    assert run_skill("CountTicks", blocks_world, "r2", skills="count_skill").ticks == 3
    with pytest.raises(SkillError, match="not both"):
        run_skill("CountTicks", blocks_world, "r1", registry=SkillRegistry(), skills=["count_skill"])
