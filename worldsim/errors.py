"""The error the simulated world raises for bad arguments and misuse."""

from __future__ import annotations

from alica.errors import AlicaError

__all__ = ["WorldError"]


class WorldError(AlicaError, ValueError):
    """A bad argument or an impossible request to the simulated world.

    The message says what is wrong and what to do about it (for example which
    robot kinds exist, or which names are taken).
    """
