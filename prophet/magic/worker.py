"""MAGiC's worker: search the share the leader sent, answer once, stop on the final plan.

A :class:`MagicWorker` waits for a :class:`Share` addressed to it, searches
it in steps (:meth:`MagicWorker.step`), and sends one :class:`Result`: the
first plan it found, or why there is none. The leader's :class:`Final` for
the round stops the search (no result is sent then) and gives the team's
plan. A share of a newer round, or of another leader (one that took over the
team), replaces the current one.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from alica.prophet.magic.messages import Final, MagicLink, MessageCounts, Result, Share
from alica.prophet.magic.search import PROGRESS_EVERY, ShareSearch
from alica.prophet.planner import PlanStatus


class MagicWorker:
    """A teammate's side of MAGiC (see the module docstring).

    Args:
        link: how the worker reaches the team.
        clock: the worker's clock (its shares' time budgets, the search's duration).
        memory_mb: the memory bound of its searches; ``None``: none.
        progress_every: expansions between two planner events (one search step).
    """

    def __init__(
        self,
        link: MagicLink,
        *,
        clock: Callable[[], float] = time.monotonic,
        memory_mb: float | None = None,
        progress_every: int = PROGRESS_EVERY,
    ) -> None:
        self._link = link
        self._clock = clock
        self._memory_mb = memory_mb
        self._progress_every = progress_every
        self._search: ShareSearch | None = None
        self.share: Share | None = None
        """The current share (the latest round's)."""
        self.result: Result | None = None
        """The result sent for the current share, if any."""
        self.final: Final | None = None
        """The leader's final message of the current round, once it came."""
        self.counts = MessageCounts()
        """The MAGiC messages of the current round."""

    @property
    def name(self) -> str:
        """The worker's agent id."""
        return self._link.name

    @property
    def searching(self) -> bool:
        """Whether a share is being searched."""
        return self._search is not None

    @property
    def expansions(self) -> int:
        """States expanded by the current share's search so far."""
        if self._search is not None:
            return self._search.expansions
        return 0 if self.result is None else self.result.expansions

    def step(self, budget: int = 1) -> None:
        """Handle what arrived, then search at most ``budget`` planner events; answer when the search ends.

        Args:
            budget: planner events to handle, at least 1.
        """
        for payload in self._link.receive():
            self._receive(payload)
        search = self._search
        if search is None or self.share is None or not search.step(budget):
            return
        self._search = None
        share = self.share
        plan = search.plan
        self.result = Result(
            share.round_id,
            share.leader,
            self.name,
            share.index,
            None if plan is None else plan.steps,
            search.status or PlanStatus.ERROR,
            search.expansions,
            search.seconds,
            search.message,
        )
        self._link.send(self.result)
        self.counts.results_sent += 1

    def _receive(self, payload: object) -> None:
        if isinstance(payload, Share) and payload.to == self.name and self._newer(payload):
            self.share = payload
            self.result = None
            self.final = None
            self.counts = MessageCounts(shares_received=1)
            self._search = ShareSearch(
                payload.domain,
                payload.problem,
                payload.search,
                seconds=payload.seconds,
                clock=self._clock,
                memory_mb=self._memory_mb,
                progress_every=self._progress_every,
            )
        elif isinstance(payload, Final) and payload.to == self.name and self._current(payload):
            self.final = payload
            self.counts.finals_received += 1
            if self._search is not None:
                self._search.stop()
                self._search = None
        else:
            self.counts.ignored += 1

    def _newer(self, share: Share) -> bool:
        current = self.share
        return current is None or share.leader != current.leader or share.round_id > current.round_id

    def _current(self, final: Final) -> bool:
        current = self.share
        return current is not None and (final.leader, final.round_id) == (current.leader, current.round_id)

    def __repr__(self) -> str:
        state = "searching" if self.searching else "idle"
        round_id = 0 if self.share is None else self.share.round_id
        return f"<MagicWorker {self.name} round {round_id} {state}>"
