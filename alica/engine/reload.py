"""Hot reload, agreed by the team: every agent adopts a new plan library at the same tick, or none does.

1. **Proposed.** An agent is given a new, validated library (its plan files
   changed on disk, or :meth:`AgentEngine.reload <alica.engine.agent.AgentEngine.reload>`).
   It goes on running the old one and says in its team messages which library
   it runs (``library``, a digest: :func:`~alica.model.digest.library_digest`)
   and which it has loaded (``proposed``).
2. **Agreed.** The leader, the alive agent with the lowest name, announces
   ``adopt = (digest, at)`` once every alive teammate says it runs or has loaded
   its proposal, with ``at`` = now + ``EngineConfig.reload_lead``. The
   announcement rides on every later team message of the leader.
3. **Adopted.** Every agent that has loaded the announced library adopts it at
   its first tick at or after ``at`` (at once, if it hears the announcement
   late); its plan tree is carried over (:mod:`alica.engine.carry_over`). In
   a team ticked in lock step that is the same tick for every agent.
4. **Disagreement.** While some alive agent says it has another library (a robot
   whose files were not updated), the leader announces nothing and nobody
   switches. Every agent that waits says which agents differ and what they
   have (a ``reload`` event with status ``waiting``), again whenever that changes.

An agent keeps the last few libraries it loaded, so a second edit that races
an announcement does not make it miss the switch the others make.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from alica.engine.config import EngineConfig
from alica.engine.team import TeamView
from alica.model import PlanLibrary
from alica.model.digest import DIGEST_LENGTH, LibraryChanges, library_changes, library_digest

#: Libraries an agent keeps loaded while it waits for its team (the newest ones).
KEEP_LOADED = 4


@dataclass(frozen=True, slots=True)
class Loaded:
    """A library an agent loaded and has not adopted yet."""

    library: PlanLibrary
    digest: str
    changes: LibraryChanges
    since: float


def _digest_field(value: object) -> str:
    """A digest from a teammate's message, or ``""`` when it is not one (network input)."""
    if isinstance(value, str) and 0 < len(value) <= 2 * DIGEST_LENGTH and value.isalnum():
        return value
    return ""


def _adopt_field(value: object) -> tuple[str, float] | None:
    """An ``adopt`` announcement from a teammate's message, or ``None`` when it is not one."""
    if not (isinstance(value, tuple) and len(value) == 2):
        return None
    digest, at = _digest_field(value[0]), value[1]
    if not digest or isinstance(at, bool) or not isinstance(at, (int, float)) or not math.isfinite(at):
        return None
    return digest, float(at)


class Reloads:
    """One agent's side of the agreement (see the module docstring).

    Args:
        name: the agent's name.
        library: the library it runs at the start.
        config: the engine settings (``reload_lead``, ``broadcast_interval``).
        team: the agent's team view (who is alive, who leads).
        emit: the engine's trace.
    """

    def __init__(
        self, name: str, library: PlanLibrary, config: EngineConfig, team: TeamView, emit: Callable[..., None]
    ) -> None:
        self.name = name
        self.library = library
        self.digest = library_digest(library)
        """The digest of the library the agent runs."""
        self.config = config
        self.team = team
        self.emit = emit
        self.loaded: dict[str, Loaded] = {}
        """Libraries loaded and not adopted yet, oldest first; the newest is proposed."""
        self.adopt: tuple[str, float] | None = None
        """The latest announcement heard or made: adopt this digest at this time."""
        self._differ: dict[str, str] = {}

    @property
    def proposed(self) -> str:
        """The digest of the newest library loaded and not adopted (``""``: none)."""
        return next(reversed(self.loaded), "")

    def propose(self, library: PlanLibrary, now: float) -> str:
        """A new library to adopt with the team; returns its digest (the running one's: nothing to do)."""
        digest = library_digest(library)
        if digest == self.digest and not self.loaded:
            return digest
        self.loaded.pop(digest, None)
        changes = library_changes(self.library, library)
        self.loaded[digest] = Loaded(library, digest, changes, now)
        while len(self.loaded) > KEEP_LOADED:
            del self.loaded[next(iter(self.loaded))]
        self._differ = {}
        self.emit("reload", status="proposed", library=self.digest, proposed=digest, changes=changes.describe())
        return digest

    def mate(self, name: str) -> tuple[str, str]:
        """What teammate ``name``'s latest team message says it runs and proposes (``""``: nothing valid)."""
        mate = self.team.mates.get(name)
        if mate is None:
            return "", ""
        return _digest_field(mate.library), _digest_field(mate.proposed)

    def _hear_announcements(self) -> None:
        """Take a teammate's announcement of a library this agent has loaded (the team messages hold them)."""
        for mate in self.team.mates.values():
            if mate.adopt is None or not mate.alive:
                continue
            announced = _adopt_field(mate.adopt)
            if announced is not None and announced[0] in self.loaded and announced != self.adopt:
                self.adopt = announced

    def leads(self) -> bool:
        """Whether this agent leads the agreement (the alive agent with the lowest name)."""
        return self.team.alive()[0] == self.name

    def due(self, now: float) -> Loaded | None:
        """Called every tick: the library to adopt now, if any (the leader announces here)."""
        if not self.loaded:
            return None  # (every tick but a reload's: the team messages' fields are read only now)
        self._hear_announcements()
        wanted = self.proposed
        if wanted and self.leads() and (self.adopt is None or self.adopt[0] != wanted):
            differ = self._differing(wanted)
            if not differ:
                self.adopt = (wanted, now + self.config.reload_lead)
                self.emit("reload", status="agreed", proposed=wanted, at=round(self.adopt[1], 6))
            else:
                self._report(wanted, differ, now)
        elif wanted and not self.leads():
            differ = self._differing(wanted)
            if differ:
                self._report(wanted, differ, now)
        if self.adopt is None:
            return None
        digest, at = self.adopt
        if now + 1e-9 < at or digest not in self.loaded:
            return None
        return self.loaded[digest]

    def adopted(self, loaded: Loaded) -> None:
        """The agent runs ``loaded`` now; libraries loaded before it are dropped."""
        self.library = loaded.library
        self.digest = loaded.digest
        names = list(self.loaded)
        for name in names[: names.index(loaded.digest) + 1]:
            del self.loaded[name]
        self._differ = {}

    def _differing(self, digest: str) -> dict[str, str]:
        """Alive teammates that neither run nor propose ``digest``, with what they say they have."""
        out = {}
        for mate in self.team.alive():
            if mate == self.name:
                continue
            library, proposed = self.mate(mate)
            if digest not in (library, proposed):
                out[mate] = proposed or library or "unknown"
        return out

    def _report(self, digest: str, differ: dict[str, str], now: float) -> None:
        """Say which agents differ, once they had the time to hear of the proposal, and again when that changes."""
        since = self.loaded[digest].since
        if now - since < 2 * self.config.broadcast_interval + self.config.reload_lead or differ == self._differ:
            return
        self._differ = differ
        self.emit("reload", status="waiting", library=self.digest, proposed=digest, differ=dict(sorted(differ.items())))
