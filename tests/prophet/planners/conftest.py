"""Fixtures of the planner back-end tests: benchmark paths, a tiny unsolvable task, running ``alica``."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

from alica.app.cli import main
from tests.conftest import benchmark_set
from tests.prophet.planners.checks import UNSOLVABLE_DOMAIN, UNSOLVABLE_PROBLEM


@dataclass(frozen=True)
class Run:
    """What one ``alica`` run gave."""

    code: int
    out: str
    err: str


@pytest.fixture
def alica(capsys: pytest.CaptureFixture[str]) -> Callable[..., Run]:
    """Run ``alica`` in-process with string arguments; returns the exit code and output."""

    def run(*args: object) -> Run:
        code = main([str(a) for a in args])
        captured = capsys.readouterr()
        return Run(code, captured.out, captured.err)

    return run


@pytest.fixture
def blocks() -> Callable[[str], tuple[Path, Path]]:
    """The blocks domain and a problem of it, e.g. ``blocks("4-0")``."""
    return lambda name: (
        benchmark_set("pddl") / "blocks" / "domain.pddl",
        benchmark_set("pddl") / "blocks" / f"probBLOCKS-{name}.pddl",
    )


@pytest.fixture
def rovers() -> Callable[[str], tuple[Path, Path]]:
    """The Rovers domain and a problem of it, e.g. ``rovers("p01")``."""
    return lambda name: (
        benchmark_set("pddl") / "rovers" / "domain.pddl",
        benchmark_set("pddl") / "rovers" / f"{name}.pddl",
    )


@pytest.fixture
def unsolvable(tmp_path: Path) -> tuple[Path, Path]:
    """A two-state task whose goal is reachable only in the relaxation: no plan exists."""
    domain, problem = tmp_path / "switch.pddl", tmp_path / "both.pddl"
    domain.write_text(UNSOLVABLE_DOMAIN, encoding="utf-8")
    problem.write_text(UNSOLVABLE_PROBLEM, encoding="utf-8")
    return domain, problem
