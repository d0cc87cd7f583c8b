"""The team view: what each agent says it is doing, and who is alive.

Every agent broadcasts a :class:`TeamMessage` with one :class:`Claim` per plan
it runs (plan instance, entry point, state). Teammates' claims override what
an agent predicted for them. An agent silent for longer than the team timeout
is taken out of every assignment; when it speaks again it is taken back. Any
message counts as a sign of life, from the time it was sent.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

#: Identifies a running plan in a team: the path of (plan, state, child) names
#: from the root plan down to it. Agents in the same state of the same plan
#: instance that run the same child share the key of that child's instance.
PlanKey = tuple[str, ...]

#: Topics of the engine's messages.
TEAM_TOPIC = "alica/team"
SYNC_TOPIC = "alica/sync"
WORLD_TOPIC = "alica/world"


def key_text(key: PlanKey) -> str:
    """A plan key as one string for traces: ``LunarMission/DriveToA/MoveToPosition``."""
    return "/".join(key)


@dataclass(frozen=True, slots=True)
class Claim:
    """An agent's statement about one plan it runs.

    Args:
        key: the plan instance.
        plan: the plan chosen there (for plan types, the alternative).
        entry: the agent's entry point, ``None`` when it idles in the plan.
        state: the agent's state, ``None`` when it idles.
        success: entry points in which the agent's task succeeded in this instance.
        contested: the agent saw this plan's allocation flip back and forth.
    """

    key: PlanKey
    plan: str
    entry: str | None
    state: str | None
    success: tuple[str, ...] = ()
    contested: bool = False


@dataclass(frozen=True, slots=True)
class AuthorityClaim:
    """An allocation one agent imposes on a plan instance until ``until``."""

    key: PlanKey
    plan: str
    entries: tuple[tuple[str, str | None], ...]
    until: float


@dataclass(frozen=True, slots=True)
class TeamMessage:
    """What an agent broadcasts to its team at the broadcast rate."""

    sender: str
    sent_at: float
    role: str
    claims: tuple[Claim, ...]
    authority: tuple[AuthorityClaim, ...] = ()
    library: str = ""
    """The digest of the plan library the sender runs (hot reload: :mod:`alica.engine.reload`)."""
    proposed: str = ""
    """The digest of the newest library the sender loaded and waits to adopt with its team (``""``: none)."""
    adopt: tuple[str, float] | None = None
    """The leader's announcement: the team adopts library ``adopt[0]`` at its first tick at or after ``adopt[1]``."""


@dataclass(slots=True)
class Teammate:
    """What an agent knows of one teammate."""

    name: str
    role: str
    last_heard: float
    alive: bool = True
    claims: dict[PlanKey, Claim] | None = None
    authority: tuple[AuthorityClaim, ...] = ()
    changed_at: float = float("-inf")
    departed_at: float = float("-inf")
    """When the transport last reported it gone (its liveliness token vanished)."""
    library: object = ""
    proposed: object = ""
    adopt: object = None
    """The plan library it runs and proposes, and its announcement, as its latest message said (unchecked: the
    reader checks them, :mod:`alica.engine.reload`)."""


class TeamView:
    """One agent's view of its team.

    Args:
        me: the agent's own name.
        roster: every team member (including ``me``) and its role.
        now: the start time; every member counts as alive until it has been
            silent for ``timeout`` seconds from then.
        timeout: the team timeout in seconds.
    """

    def __init__(self, me: str, roster: Mapping[str, str], now: float, timeout: float) -> None:
        if me not in roster:
            raise ValueError(f"agent '{me}' is not in its own team roster {sorted(roster)}")
        self.me = me
        self.timeout = timeout
        self.mates: dict[str, Teammate] = {
            name: Teammate(name, role, now) for name, role in sorted(roster.items()) if name != me
        }
        self.roles: dict[str, str] = dict(sorted(roster.items()))
        self._alive_cache: tuple[str, ...] | None = None

    # -- queries -------------------------------------------------------

    def alive(self) -> tuple[str, ...]:
        """Alive agents, ``me`` included, sorted."""
        if self._alive_cache is None:
            self._alive_cache = tuple(sorted([self.me, *(m.name for m in self.mates.values() if m.alive)]))
        return self._alive_cache

    def is_alive(self, agent: str) -> bool:
        """Whether ``agent`` is me or a teammate heard from recently."""
        if agent == self.me:
            return True
        mate = self.mates.get(agent)
        return mate is not None and mate.alive

    def claim(self, agent: str, key: PlanKey) -> Claim | None:
        """What ``agent`` last said about the plan instance ``key``."""
        mate = self.mates.get(agent)
        if mate is None or mate.claims is None:
            return None
        return mate.claims.get(key)

    def changed_at(self, agent: str) -> float:
        """When ``agent``'s claims last changed (minus infinity if never heard)."""
        mate = self.mates.get(agent)
        return mate.changed_at if mate is not None else float("-inf")

    def has_spoken(self, agent: str) -> bool:
        """Whether a message of ``agent`` has been received."""
        mate = self.mates.get(agent)
        return mate is not None and mate.claims is not None

    def authority_claims(self) -> Iterable[tuple[str, AuthorityClaim]]:
        """Authority claims of alive teammates, by sender, sorted by sender."""
        for name, mate in self.mates.items():
            if mate.alive:
                for claim in mate.authority:
                    yield name, claim

    # -- changes -------------------------------------------------------

    def integrate(self, message: TeamMessage, now: float) -> tuple[set[PlanKey], bool]:
        """Take in a teammate's message.

        Returns:
            The plan keys whose claims changed, and whether the sender came back to life.
        """
        mate = self.mates.get(message.sender)
        if mate is None:  # not in our team
            return set(), False
        revived = self.heard(message.sender, message.sent_at, now)
        mate.authority = message.authority
        mate.library, mate.proposed, mate.adopt = message.library, message.proposed, message.adopt
        new = {c.key: c for c in message.claims}
        old = mate.claims or {}
        mate.claims = new
        if old == new:
            return set(), revived
        mate.changed_at = now
        changed = {k for k in new.keys() | old.keys() if new.get(k) != old.get(k)}
        return changed, revived

    def heard(self, sender: str, sent_at: float, now: float) -> bool:
        """Any message of ``sender`` sent at ``sent_at`` shows it was alive then; returns whether it came back.

        A message counts from when it was sent (never later than ``now``): a late
        reliable message of an agent that has since crashed does not bring it back.
        """
        mate = self.mates.get(sender)
        if mate is None:
            return False
        heard = min(sent_at, now)
        if heard <= mate.last_heard or heard <= mate.departed_at:
            return False
        mate.last_heard = heard
        if mate.alive or now - heard > self.timeout:
            return False
        mate.alive = True
        self._alive_cache = None
        return True

    def depart(self, agent: str, now: float) -> bool:
        """The transport says ``agent`` is gone (a crash, a partition): take it out now; returns whether it was in.

        Messages it sent before ``now`` that arrive late do not bring it back;
        a message sent after does (a restart, a healed link).
        """
        mate = self.mates.get(agent)
        if mate is None:
            return False
        mate.departed_at = now
        if not mate.alive:
            return False
        mate.alive = False
        self._alive_cache = None
        return True

    def update(self, now: float) -> list[str]:
        """Mark teammates silent for longer than the timeout as lost; returns them."""
        lost = []
        for mate in self.mates.values():
            if mate.alive and now - mate.last_heard > self.timeout:
                mate.alive = False
                lost.append(mate.name)
        if lost:
            self._alive_cache = None
        return lost
