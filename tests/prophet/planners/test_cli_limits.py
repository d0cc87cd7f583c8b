"""``alica plan --time-limit/--memory-limit``: a limit reached in any stage exits 4 with one line naming the stage."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from tests.prophet.planners.conftest import Run
from tests.prophet.test_limits import BLOCKS, _blocks_problem


@pytest.fixture
def files(tmp_path: Path) -> Iterator[tuple[Path, Path]]:
    domain, problem = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    domain.write_text(BLOCKS, encoding="utf-8")
    problem.write_text(_blocks_problem(200), encoding="utf-8")
    yield domain, problem


def test_alica_plan_memory_limit_in_reading_exits_4_with_json(alica: Callable[..., Run], files) -> None:
    run = alica("plan", *files, "--memory-limit", "0.01", "--json")
    assert run.code == 4
    assert run.err.startswith("alica: reading the domain needs more than 0.01 MB")
    assert '"solved": false' in run.out


@pytest.mark.parametrize("bad", ["0", "-5", "lots", "inf"])
def test_alica_plan_memory_limit_must_be_positive(alica: Callable[..., Run], files, bad: str) -> None:
    run = alica("plan", *files, "--memory-limit", bad)
    assert run.code == 2 and ("memory limit" in run.err or "MB" in run.err)
