"""Engine settings, with the defaults of the reference engine where they apply."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class EngineConfig:
    """How an agent's engine runs and talks to its team.

    Args:
        frequency: engine ticks per second.
        broadcast_interval: seconds between two team messages at most (heartbeat).
        min_broadcast_gap: seconds between two team messages at least, when the
            agent's plan tree keeps changing.
        team_timeout: an agent silent for longer than this is taken out of every
            assignment until it speaks again.
        assignment_protection: for this long after a plan starts, teammates that
            were allocated to it are not removed for missing from their messages.
        max_rule_applications: rule rounds per plan and tick (chains of transitions).
        allow_idle: agents may stay unassigned in a plan that has no room for them.
        cycle_window: seconds of allocation history in which flips count as a cycle.
        cycle_count: flips within the window that trigger authority.
        authority_min: the first authority window, in seconds.
        authority_max: the longest authority window.
        authority_growth: the factor by which each new conflict grows the window.
        planner_expansions: the planning leader's search budget per tick, in
            expansions (deterministic: the same run plans the same way).
        planner_seconds: a wall-time budget per tick instead (for real robots);
            ``None`` uses ``planner_expansions``.
    """

    frequency: float = 30.0
    broadcast_interval: float = 0.2
    min_broadcast_gap: float = 0.0
    team_timeout: float = 1.0
    assignment_protection: float = 0.5
    max_rule_applications: int = 20
    allow_idle: bool = True
    cycle_window: float = 5.0
    cycle_count: int = 3
    authority_min: float = 1.0
    authority_max: float = 16.0
    authority_growth: float = 2.0
    planner_expansions: int = 1000
    planner_seconds: float | None = None

    def __post_init__(self) -> None:
        positive = ("frequency", "broadcast_interval", "team_timeout", "cycle_window", "authority_min")
        for name in positive:
            if getattr(self, name) <= 0:
                raise ValueError(f"EngineConfig.{name} must be > 0, got {getattr(self, name)}")
        for name in ("min_broadcast_gap", "assignment_protection"):
            if getattr(self, name) < 0:
                raise ValueError(f"EngineConfig.{name} must be >= 0, got {getattr(self, name)}")
        if self.planner_expansions < 1 or (self.planner_seconds is not None and self.planner_seconds <= 0):
            raise ValueError("EngineConfig.planner_expansions must be at least 1 and planner_seconds > 0 (or None)")
        if self.max_rule_applications < 1 or self.cycle_count < 1:
            raise ValueError("EngineConfig.max_rule_applications and cycle_count must be at least 1")
        if self.authority_max < self.authority_min or self.authority_growth < 1:
            raise ValueError("EngineConfig needs authority_max >= authority_min and authority_growth >= 1")

    @property
    def period(self) -> float:
        """Seconds between two ticks."""
        return 1.0 / self.frequency
