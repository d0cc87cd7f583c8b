"""Fixtures shared by the skill tests."""

from __future__ import annotations

import pytest


@pytest.fixture
def teams(monkeypatch):
    """The teams ``alica run`` makes, to read their world models afterwards."""
    import alica.engine

    made = []

    class Recording(alica.engine.SimulatedTeam):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            made.append(self)

    monkeypatch.setattr(alica.engine, "SimulatedTeam", Recording)
    return made
