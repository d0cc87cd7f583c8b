"""Shared test set-up: deterministic hypothesis runs, OMPL seeded, paths to the shipped plans and the benchmark sets."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from alica.skills.motion import configure_ompl

settings.register_profile(
    "deterministic",
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("deterministic")

# OMPL has one generator per process, seeded before its first use: seed it here, so a run of the
# suite (the same tests in the same order) plans the same paths every time.
configure_ompl(0)

ROOT = Path(__file__).resolve().parent.parent
PLANS = ROOT / "plans"
BENCHMARKS_VARIABLE = "ALICA_BENCHMARKS"


def benchmarks_folder() -> Path:
    """The folder holding the benchmark sets (``pddl/``, ``ipc/``): ``$ALICA_BENCHMARKS``, else ``../shared/benchmarks``.

    The sets are read in place, never copied into the repository (``bench/benchmark_sets.py`` has the same rule).
    """
    value = os.environ.get(BENCHMARKS_VARIABLE, "")
    return Path(value).expanduser() if value else ROOT / ".." / "shared" / "benchmarks"


BENCHMARKS = benchmarks_folder()


def benchmark_set(name: str) -> Path:
    """``BENCHMARKS / name`` (``"pddl"`` or ``"ipc"``); a failed test naming the folder when it is missing.

    Call it inside a test or fixture, not at import: a module that failed to import would stop the collection.
    """
    folder = BENCHMARKS / name
    if not folder.is_dir():
        pytest.fail(
            f"the benchmark sets are read in place from {BENCHMARKS.resolve()} and {name}/ is not there: "
            f"put ../shared beside the checkout or set {BENCHMARKS_VARIABLE} to the folder holding pddl/ and ipc/",
            pytrace=False,
        )
    return folder


@pytest.fixture
def plans_dir() -> Path:
    """The shipped plans/ folder."""
    return PLANS


def blocks_mission_with_builtin(folder: Path) -> Path:
    """A copy of the shipped plans in ``folder`` whose blocks mission plans StackBlocks with ``planner: builtin``.

    The shipped mission plans for the team's time (``planner: temporal``); MAGiC splits the builtin
    planner's search, so a test of MAGiC in a team of processes runs this copy.
    """
    import shutil

    copy = folder / "plans"
    shutil.copytree(PLANS, copy, ignore=shutil.ignore_patterns("__pycache__"))
    (folder / ".alica-project").touch()  # the mission imports ../tasks.yaml: the copy's folder is its project
    mission = copy / "blocksworld" / "mission.yaml"
    text = mission.read_text(encoding="utf-8")
    assert text.count("    planner: temporal\n") == 1, "the blocks mission no longer names its planner once"
    mission.write_text(text.replace("    planner: temporal\n", "    planner: builtin\n"), encoding="utf-8")
    return mission
