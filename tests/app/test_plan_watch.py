"""PlanWatch: a changed plan file is loaded once it stayed the same for one look; errors are located."""

from __future__ import annotations

import os
from pathlib import Path

from alica.app.plan_watch import Invalid, PlanWatch, reload_line
from alica.io import Loader, load_library

ROLES = """alica: 1
tasks: [Default]
rolesets:
  - name: Crew
    roles:
      - {name: Worker, priorities: {Default: 0.5}}
"""
PLAN = """alica: 1
imports: [roles.yaml]
predicates: [go/0]
behaviours:
  - {name: Hold, skill: Idle}
plans:
  - name: Top
    entry_points: [{task: Default, state: Waiting, min: 1, max: "*"}]
    states:
      - name: Waiting
        children: [Hold]
        transitions:
          - {to: Done, condition: "go"}
      - {name: Done, kind: success}
"""


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def _watch(tmp_path: Path) -> tuple[PlanWatch, Clock, Path]:
    (tmp_path / "roles.yaml").write_text(ROLES, encoding="utf-8")
    plan = tmp_path / "plan.yaml"
    plan.write_text(PLAN, encoding="utf-8")
    clock = Clock()
    watch = PlanWatch(plan, load_library(plan), lambda: Loader().load(plan), interval=0.1, clock=clock)
    return watch, clock, plan


def _save(path: Path, text: str, stamp: int) -> None:
    path.write_text(text, encoding="utf-8")
    os.utime(path, ns=(stamp, stamp))  # a distinct modification time, whatever the file system's resolution


def _look(watch: PlanWatch, clock: Clock) -> object:
    clock.now += 0.1
    return watch.poll()


def test_an_edit_is_loaded_once_the_file_stayed_the_same_for_one_look(tmp_path: Path) -> None:
    watch, clock, plan = _watch(tmp_path)
    assert _look(watch, clock) is None  # nothing changed
    _save(plan, PLAN.replace('"go"', '"true"'), 10**18)
    assert _look(watch, clock) is None  # changed: read at the next look if it stays so
    clock.now += 0.05
    assert watch.poll() is None  # (no look before the interval passed)
    library = _look(watch, clock)
    assert not isinstance(library, Invalid) and library is not None
    assert library.plans["Top"].transitions[0].condition.text == "true"
    assert _look(watch, clock) is None and watch.loads == 1


def test_a_file_still_being_written_waits_and_an_imported_file_is_watched_too(tmp_path: Path) -> None:
    watch, clock, plan = _watch(tmp_path)
    _save(plan, PLAN[:40], 10**18)  # half written
    assert _look(watch, clock) is None
    _save(plan, PLAN.replace('"go"', '"true"'), 10**18 + 1)  # the rest arrives: not yet
    assert _look(watch, clock) is None
    assert not isinstance(_look(watch, clock), Invalid)
    roles = tmp_path / "roles.yaml"
    _save(roles, ROLES.replace("0.5", "0.7"), 10**18)
    assert _look(watch, clock) is None
    library = _look(watch, clock)
    assert not isinstance(library, Invalid) and library is not None
    assert library.rolesets["Crew"].roles[0].priorities[0].value == 0.7


def test_an_invalid_edit_is_reported_with_file_line_and_column(tmp_path: Path) -> None:
    watch, clock, plan = _watch(tmp_path)
    _save(plan, PLAN.replace('"go"', '"gox"'), 10**18)
    _look(watch, clock)
    invalid = _look(watch, clock)
    assert isinstance(invalid, Invalid)
    assert invalid.errors[0].startswith(f"{plan}:13:") and "unknown predicate 'gox'" in invalid.errors[0]
    line = reload_line({"event": "reload", "agent": "-", "status": "invalid", "errors": list(invalid.errors)})
    assert line is not None and "goes on with the plans it runs" in line and f"{plan}:13:" in line
    # a deleted file is an error too, and the watch goes on
    plan.unlink()
    _look(watch, clock)
    gone = _look(watch, clock)
    assert isinstance(gone, Invalid) and "plan.yaml" in gone.errors[0]
