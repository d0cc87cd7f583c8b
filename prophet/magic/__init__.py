"""MAGiC: IMPERA's parallel planning, one share of the search per agent (IMPERA, Section 8.3).

The leader (:class:`MagicLeader`) splits its planning task into one share
per agent of the team, itself included: the same PDDL task, each share with
another first search of the builtin planner (:func:`share_searches`). Every
agent searches its share (:class:`MagicWorker` on the teammates), the first
valid plan wins, and the leader sends it to the others, which stops their
search: at most ``3 * (n - 1)`` messages a round, counted in
:class:`MessageCounts`.

The protocol knows no transport: it talks to the team through a
:class:`MagicLink` (the application layer adapts a transport to it) and
reads time only from an injected clock, so agents stepped in lock step over
a simulated network give the same round for the same seed.
"""

from __future__ import annotations

from alica.prophet.magic.leader import MagicLeader, RoundOutcome
from alica.prophet.magic.messages import (
    SHARE_SEARCHES,
    Final,
    MagicLink,
    MagicMessage,
    MessageCounts,
    Result,
    Share,
    share_searches,
)
from alica.prophet.magic.search import ShareSearch
from alica.prophet.magic.worker import MagicWorker

__all__ = [
    "SHARE_SEARCHES",
    "Final",
    "MagicLeader",
    "MagicLink",
    "MagicMessage",
    "MagicWorker",
    "MessageCounts",
    "Result",
    "RoundOutcome",
    "Share",
    "ShareSearch",
    "share_searches",
]
