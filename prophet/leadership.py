"""Who leads a planning problem, and the generations the leader numbers its searches with.

The leader is the lowest alive agent in the state (the engine sorts the
members); when it crashes the next lowest takes over. Each search of the
problem is a *generation*: a new one is one more than any the agent has seen,
so a share of a newer generation supersedes the older ones on every agent.
"""

from __future__ import annotations

from collections.abc import Sequence


def is_leader(members: Sequence[str], me: str) -> bool:
    """Whether ``me`` leads: it is the first (lowest) of the sorted ``members`` in the state."""
    return bool(members) and members[0] == me


def next_generation(seen: int, failed: int, adopted: int) -> int:
    """One more than any generation the agent has seen for the problem.

    Args:
        seen: the newest generation on the agent's board (``0``: none).
        failed: the newest generation whose plan failed here (``-1``: none).
        adopted: the generation of the share the agent follows (``0``: none).

    Returns:
        The generation of the agent's next search.
    """
    return max(seen, failed, adopted) + 1
