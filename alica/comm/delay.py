"""Link models of the simulated network: how long a message takes, how often it is lost."""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Literal

DelayKind = Literal["uniform", "exponential"]
_KINDS: tuple[str, ...] = ("uniform", "exponential")


def _check_seconds(name: str, value: object) -> None:
    """Raise a ValueError unless ``value`` is a finite number of seconds >= 0."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{name} must be a number of seconds, got {value!r}")
    if not math.isfinite(value) or value < 0:
        raise ValueError(f"{name} must be a finite number of seconds >= 0, got {value!r}; use 0.0 for none")


def check_probability(name: str, value: object) -> float:
    """Validate a loss probability.

    Args:
        name: what the value is, for the message.
        value: the probability.

    Returns:
        The probability as a float.

    Raises:
        ValueError: ``value`` is not a number in [0, 1).
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{name} must be a probability in [0, 1), got {value!r}")
    if not 0.0 <= value < 1.0:
        raise ValueError(
            f"{name} must be a probability in [0, 1), got {value!r}; "
            "to cut a link entirely, use partition() instead of loss 1"
        )
    return float(value)


@dataclass(frozen=True, slots=True)
class Delay:
    """The one-way latency of a link.

    ``uniform`` draws from ``[base, base + jitter]``; ``exponential`` draws
    ``base`` plus an exponential variable of mean ``jitter``. With
    ``jitter == 0`` the delay is always ``base`` and nothing is drawn.

    Args:
        base: the smallest delay in seconds (>= 0).
        jitter: the spread in seconds (>= 0).
        kind: ``"uniform"`` or ``"exponential"``.

    Raises:
        ValueError: a negative or non-finite value, or an unknown kind.
    """

    base: float
    jitter: float = 0.0
    kind: DelayKind = "uniform"

    def __post_init__(self) -> None:
        _check_seconds("Delay base", self.base)
        _check_seconds("Delay jitter", self.jitter)
        if self.kind not in _KINDS:
            raise ValueError(f"Delay kind must be one of {', '.join(_KINDS)}, got {self.kind!r}")

    @property
    def fixed(self) -> bool:
        """True when the delay is always ``base`` (no jitter)."""
        return self.jitter == 0.0

    @property
    def upper(self) -> float:
        """The largest possible delay (infinite for exponential jitter)."""
        if self.fixed:
            return self.base
        return self.base + self.jitter if self.kind == "uniform" else math.inf

    def sample(self, rng: random.Random) -> float:
        """Draw one delay.

        Args:
            rng: the network's random generator; not used when the delay is fixed.

        Returns:
            The delay in seconds.
        """
        if self.jitter == 0.0:
            return self.base
        if self.kind == "uniform":
            return self.base + rng.random() * self.jitter
        return self.base + rng.expovariate(1.0 / self.jitter)


@dataclass(frozen=True, slots=True)
class Link:
    """The behaviour of one directed link: loss probability and delay.

    Args:
        loss: probability that one transmission is lost, in [0, 1).
        delay: the latency of the link.

    Raises:
        ValueError: ``loss`` outside [0, 1) or ``delay`` not a :class:`Delay`.
    """

    loss: float
    delay: Delay

    def __post_init__(self) -> None:
        check_probability("loss", self.loss)
        if not isinstance(self.delay, Delay):
            raise ValueError(f"delay must be a Delay, e.g. Delay(0.01, 0.005), got {self.delay!r}")
