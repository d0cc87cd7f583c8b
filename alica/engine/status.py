"""The status of a running child (behaviour or plan) of a state."""

from __future__ import annotations

from enum import Enum


class ChildStatus(Enum):
    """Where a child of the agent's current state is in its life."""

    WAITING = "waiting"
    """Not started: its pre-condition does not hold (yet)."""
    RUNNING = "running"
    """Started and not finished."""
    SUCCESS = "success"
    """Finished successfully; a plan succeeds when its required tasks did."""
    FAILURE = "failure"
    """Failed, and for plans every repair stage is used up."""

    @property
    def done(self) -> bool:
        """Success or failure."""
        return self is ChildStatus.SUCCESS or self is ChildStatus.FAILURE
