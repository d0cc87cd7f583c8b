"""The leader's waits: for the world to change, and for robots outside the team to come back.

When there is nothing the team can plan for now (robots outside the team hold
the rest of the goal, or no plan exists with the robots in the team), the
team runs the WaitPlan and the leader watches the world (:class:`Waiting`):

* it plans again as soon as the world's facts differ from those it waited in;
* when no plan exists with the robots in the team while the world names robots
  outside it (teammates cut off by a partition, or crashed), it waits up to
  :data:`TEAM_WAIT` simulated seconds for them, then plans once more, and the
  problem fails if there is still no plan.
"""

from __future__ import annotations

from collections.abc import Iterable

from alica.lang.fact import Fact

#: Simulated seconds the leader waits, when no plan exists with the robots in the team while robots outside
#: it are named in the world (teammates cut off by a partition, or crashed), before the problem fails.
TEAM_WAIT = 30.0


class Waiting:
    """What the leader waits for (see the module docstring)."""

    def __init__(self) -> None:
        self.blocked: set[Fact] | None = None
        """The world's facts while the leader waits for them to change (``None``: it does not wait)."""
        self.team_until: float | None = None
        """While no plan exists without robots outside the team: when the leader stops waiting for them."""

    def block(self, facts: Iterable[Fact]) -> None:
        """Wait for the world to differ from ``facts``."""
        self.blocked = set(facts)

    def unblock(self) -> None:
        """Stop waiting for the world."""
        self.blocked = None

    def changed(self, facts: Iterable[Fact]) -> bool:
        """Whether the world's ``facts`` differ from those the leader waits in."""
        return set(facts) != self.blocked

    def team_wait_over(self, now: float) -> bool:
        """Whether the wait for the robots outside the team is over."""
        return self.team_until is not None and now >= self.team_until

    def end_team_wait(self) -> None:
        """A plan was found: the wait for the robots outside the team ends."""
        self.team_until = None

    def wait_for_team(self, now: float, unsolvable: bool, outsiders: bool) -> bool:
        """Whether to wait for robots outside the team (a partition heals, a crashed robot restarts) before failing.

        The wait starts with the first unsolvable search while the world names robots outside the
        team, lasts :data:`TEAM_WAIT` seconds, and ends early when the world changes (the leader
        plans again); a plan found ends it.

        Args:
            now: the time now.
            unsolvable: whether the search proved that the team alone cannot reach the goal.
            outsiders: whether the world names robots outside the team.

        Returns:
            Whether to wait (else the problem fails).
        """
        if not unsolvable or not outsiders:
            self.team_until = None
            return False
        if self.team_until is None:
            self.team_until = now + TEAM_WAIT
        if now < self.team_until:
            return True
        self.team_until = None  # waited long enough: the problem fails
        return False
