"""pytest fixtures for testing skills alone (registered as a pytest plugin by the package).

* ``lunar_world``: a small lunar field (seed 0, 20 rocks) with scout, stummel and amparo;
* ``blocks_world``: a blocks world with the stacks ``[["a", "b"], ["c"]]`` and two manipulators;
* ``skill_run``: :func:`alica.skills.testing.run_skill`.

Worlds are closed after each test.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest


@pytest.fixture
def lunar_world() -> Iterator[Any]:
    """A small lunar world (needs pybullet)."""
    from alica.worldsim.scenarios import lunar

    world = lunar(seed=0, rocks=20)
    try:
        yield world
    finally:
        world.close()


@pytest.fixture
def blocks_world() -> Iterator[Any]:
    """A blocks world: b on a, c alone, robots r1 and r2 (needs pybullet)."""
    from alica.worldsim.scenarios import blocksworld

    world = blocksworld([["a", "b"], ["c"]], agents=2, seed=0)
    try:
        yield world
    finally:
        world.close()


@pytest.fixture
def skill_run() -> Callable[..., Any]:
    """:func:`alica.skills.testing.run_skill`."""
    from alica.skills.testing import run_skill

    return run_skill
