"""Shared test set-up: deterministic hypothesis runs, OMPL seeded, paths to the shipped plans."""

from __future__ import annotations

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


@pytest.fixture
def plans_dir() -> Path:
    """The shipped plans/ folder."""
    return PLANS
