"""Engine settings, with the defaults of the reference engine where they apply."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from alica.engine.child import ChildKind


@dataclass(frozen=True, slots=True)
class EngineConfig:
    """How an agent's engine runs and talks to its team.

    Args:
        frequency: engine ticks per second.
        broadcast_interval: seconds between two team messages at most (heartbeat).
        min_broadcast_gap: seconds between two team messages at least, when the
            agent's plan tree keeps changing.
        team_timeout: an agent silent for longer than this is taken out of every
            assignment until it speaks again. Every message of the agent counts
            (team messages are its heartbeat, sent at least every
            ``broadcast_interval``); the timeout must span at least two heartbeats
            and should span many more, so that a few lost messages never take a
            live teammate out (the default, 3 s, is 15 heartbeats: at a loss of 0.5
            a false loss needs 15 lost messages in a row).
        rejoin_wait: a plan that fails for want of agents (no valid assignment
            with the teammates alive now) is restarted as soon as the team allows,
            without using up its repair stages, for this many seconds; after that
            the failure propagates.
        assignment_protection: for this long after a plan starts, teammates that
            were allocated to it are not removed for missing from their messages.
        max_rule_applications: rule rounds per plan and tick (chains of transitions).
        allow_idle: agents may stay unassigned in a plan that has no room for them.
        cycle_window: seconds of allocation history in which flips count as a cycle.
        cycle_count: flips within the window that trigger authority.
        authority_min: the first authority window, in seconds.
        authority_max: the longest authority window.
        authority_growth: the factor by which each new conflict grows the window.
        children: model element type -> the child runtime that decides what a
            child of that type runs (:mod:`alica.engine.child`); e.g.
            ``{PlanningProblem: alica.prophet.PLANNING}``. A plan tree that
            reaches an element of a type not given here cannot run.
        review: the operator reviews every plan a child runtime generates before the
            team runs it (a planning problem's leader proposes it and waits for
            :meth:`AgentEngine.decide_plan <alica.engine.agent.AgentEngine.decide_plan>`;
            the team runs the WaitPlan meanwhile). Off: plans run at once.
        auto_failure_handling: a failed plan that no transition of its parent state
            handles is repaired (retry, replace, propagate: :mod:`alica.engine.slot`),
            as the C++ engine's ``AutoFailureHandling: true``. Off: a failed plan stays
            failed, its parent state's ``failed`` conditions hold until a transition
            leaves the state, nothing is retried and nothing fails upwards; a failed
            root plan ends the agent's mission. A plan restarted for want of
            teammates is not a failure and is restarted either way.
        reload_lead: seconds from the leader's announcement that the whole team has a
            new plan library to the tick at which every agent adopts it (hot reload,
            :mod:`alica.engine.reload`); longer than a team message takes to arrive,
            so that the agents switch at the same tick.
    """

    frequency: float = 30.0
    broadcast_interval: float = 0.2
    min_broadcast_gap: float = 0.0
    team_timeout: float = 3.0
    rejoin_wait: float = 30.0
    assignment_protection: float = 0.5
    max_rule_applications: int = 20
    allow_idle: bool = True
    cycle_window: float = 5.0
    cycle_count: int = 3
    authority_min: float = 1.0
    authority_max: float = 16.0
    authority_growth: float = 2.0
    children: Mapping[type, ChildKind] = field(default_factory=dict, hash=False)
    review: bool = False
    auto_failure_handling: bool = True
    reload_lead: float = 0.5

    def __post_init__(self) -> None:
        positive = {
            "frequency": self.frequency,
            "broadcast_interval": self.broadcast_interval,
            "team_timeout": self.team_timeout,
            "cycle_window": self.cycle_window,
            "authority_min": self.authority_min,
            "reload_lead": self.reload_lead,
        }
        for name, value in positive.items():
            if value <= 0:
                raise ValueError(f"EngineConfig.{name} must be > 0, got {value}")
        if self.team_timeout < 2 * self.broadcast_interval:
            raise ValueError(
                f"EngineConfig.team_timeout ({self.team_timeout} s) must span at least two heartbeats "
                f"(2 x broadcast_interval = {2 * self.broadcast_interval} s): a teammate would be taken out "
                "for one lost message"
            )
        non_negative = {
            "min_broadcast_gap": self.min_broadcast_gap,
            "assignment_protection": self.assignment_protection,
            "rejoin_wait": self.rejoin_wait,
        }
        for name, value in non_negative.items():
            if value < 0:
                raise ValueError(f"EngineConfig.{name} must be >= 0, got {value}")
        if self.max_rule_applications < 1 or self.cycle_count < 1:
            raise ValueError("EngineConfig.max_rule_applications and cycle_count must be at least 1")
        for element_type in self.children:
            if not isinstance(element_type, type):
                raise ValueError(f"EngineConfig.children is keyed by model element type, got {element_type!r}")
        if self.authority_max < self.authority_min or self.authority_growth < 1:
            raise ValueError("EngineConfig needs authority_max >= authority_min and authority_growth >= 1")

    @property
    def period(self) -> float:
        """Seconds between two ticks."""
        return 1.0 / self.frequency
