"""What the team tells itself about its planning problems: plan shares, replan requests, and each agent's board.

The leader of a planning problem shares its plans as :class:`PlanShare`
messages; a teammate whose step failed asks it to replan with a
:class:`ReplanRequest`. Both travel on :data:`PLAN_TOPIC`, a topic
pRoPhEt MAS owns: the engine hands what arrives there to the agent's
:class:`PlanBoard` (through :class:`alica.prophet.plugin.PlanningAgent`),
also while the agent is not in the problem's state, so that an agent entering
it late still finds the latest plan.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from enum import Enum

from alica.engine.child import PlanKey
from alica.lang.fact import Fact
from alica.prophet.planner import PlanStep
from alica.prophet.tasks import CreatedTasks, Literal

#: Topic of plan shares and replan requests (reliable).
PLAN_TOPIC = "prophet/plan"


class ShareStatus(Enum):
    """What a :class:`PlanShare` says about the planning problem."""

    SEARCHING = "searching"
    """The leader plans (again): the team runs the WaitPlan."""
    PLAN = "plan"
    """Here is a plan: the team runs the plan generated from it."""
    FAILED = "failed"
    """Planning failed or timed out: the team runs the AlternativePlan (or the child fails)."""
    DONE = "done"
    """The goal holds already: the child succeeds."""


@dataclass(frozen=True, slots=True)
class PlanShare:
    """What the leader tells the team about a planning problem.

    Attributes:
        key: the planning problem's instance (its plan key).
        generation: counts the plannings of this instance (each replan starts a new one).
        version: counts the plans shared within a generation (anytime improvements).
        leader: who shares it.
        status: searching, a plan, failed or done.
        steps: the single-agent plan (status ``PLAN``).
        cost: its cost.
        world: the facts it was planned from.
        robots: the robots it was planned with (the alive members in the state).
        entry_task: the task through which the team runs the problem (for Eq. 9).
        reason: why it failed, or why the leader replans.
        goal: the goal literals the plan reaches when robots outside the team hold
            objects of the goal (the rest of the goal); empty: the whole goal.
        origin: the agent that made the plan (a leader repeating it keeps it).
        pins: ``(task index, robot)``: tasks the operator pinned to a robot when reviewing the plan.
        barred: ``(robot, step label)``: robots kept off the tasks holding a step that failed with them
            (:mod:`alica.prophet.keep_off`).
    """

    key: PlanKey
    generation: int
    version: int
    leader: str
    status: ShareStatus
    steps: tuple[PlanStep, ...] = ()
    cost: float = 0.0
    world: tuple[Fact, ...] = ()
    robots: tuple[str, ...] = ()
    entry_task: str = ""
    reason: str = ""
    goal: tuple[Literal, ...] = ()
    origin: str = ""
    pins: tuple[tuple[int, str], ...] = ()
    barred: tuple[tuple[str, str], ...] = ()

    def plan_name(self, problem: str) -> str:
        """The name of the plan generated from this share: unique to its content.

        Two leaders may share plans of the same generation and version (a
        restarted agent leads before it learns the team's generation; a
        partition heals), so the name also holds who made the plan and a
        digest of what it holds: agents that know a plan by a name know the
        same plan.
        """
        content = repr((self.steps, self.world, self.robots, self.entry_task, self.goal, self.key))
        if self.pins:
            content += repr(self.pins)
        if self.barred:
            content += repr(self.barred)
        digest = hashlib.blake2b(content.encode("utf-8"), digest_size=3).hexdigest()
        who = self.origin or self.leader
        return f"{problem}_g{self.generation}v{self.version}_{who}_{digest}"

    def same_plan(self, other: PlanShare) -> bool:
        """Whether ``other`` shares the same plan (a repeat, maybe by another leader)."""
        return (
            (self.generation, self.version, self.status) == (other.generation, other.version, other.status)
            and self.steps == other.steps
            and self.world == other.world
            and self.robots == other.robots
            and self.goal == other.goal
            and self.pins == other.pins
            and self.barred == other.barred
        )

    def supersedes(self, other: PlanShare) -> bool:
        """Newer generation, then newer version; the lower leader wins a tie (a partition healed)."""
        mine, theirs = (self.generation, self.version), (other.generation, other.version)
        return mine > theirs or (mine == theirs and self.leader < other.leader)


@dataclass(frozen=True, slots=True)
class ReplanRequest:
    """A teammate asks the leader to replan: a step of generation ``generation`` failed (``step``: its
    label, ``Unstack(c, a)``; the sender is kept off it for a while)."""

    key: PlanKey
    generation: int
    sender: str
    reason: str
    step: str = ""


class PlanBoard:
    """One agent's board: the latest share per planning problem, the pending replan requests, the plans made."""

    def __init__(self) -> None:
        self.shares: dict[PlanKey, PlanShare] = {}
        self.received_at: dict[PlanKey, float] = {}
        self.generations: dict[PlanKey, int] = {}
        self.requests: dict[PlanKey, list[ReplanRequest]] = {}
        self.latest: dict[PlanKey, CreatedTasks] = {}
        """The latest generated plan per planning problem, kept after the problem's state is left."""
        self.made: list[tuple[int, int, CreatedTasks]] = []
        """Every generated plan this agent took up (each once), in order, with its generation and version."""
        self.behind: set[PlanKey] = set()
        """Problems whose leader shared an older plan than this board holds (a restarted leader): tell it."""

    def receive(self, payload: object, now: float) -> None:
        """Take in a share (kept if it supersedes the one known) or a replan request; ignore anything else."""
        if isinstance(payload, ReplanRequest):
            self._generation(payload.key, payload.generation)
            self.requests.setdefault(payload.key, []).append(payload)
        elif isinstance(payload, PlanShare):
            key = payload.key
            self._generation(key, payload.generation)
            current = self.shares.get(key)
            if current is None or payload.supersedes(current):
                self.shares[key] = payload
                self.received_at[key] = now
            elif payload.same_plan(current):
                self.received_at[key] = now  # the leader repeats it: still current
            elif payload.leader != current.leader and (payload.generation, payload.version) < (
                current.generation,
                current.version,
            ):
                self.behind.add(key)  # its leader has not seen the latest plan: it restarted, or was cut off

    def _generation(self, key: PlanKey, generation: int) -> None:
        self.generations[key] = max(self.generations.get(key, 0), generation)

    def take_requests(self, key: PlanKey) -> list[ReplanRequest]:
        """The replan requests for ``key`` received since the last call."""
        return self.requests.pop(key, [])

    def fresh(self, key: PlanKey, now: float, within: float) -> PlanShare | None:
        """The share known for ``key`` if it was received (or repeated) within the last ``within`` seconds."""
        share = self.shares.get(key)
        return share if share is not None and now - self.received_at[key] <= within else None
