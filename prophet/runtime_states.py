"""The states of a planning problem's runtime, and the moves between them, in one place.

A :class:`~alica.prophet.runtime.ProblemRuntime` has two state machines, both
worked out from what it holds (never stored twice, so they cannot disagree):

* the **child phase** (:class:`ChildPhase`), what the whole team runs: it
  follows the latest share the agent adopted (:func:`child_phase`);
* the **leader phase** (:class:`LeaderPhase`), what the leader does on a tick:
  review a proposal, wait before a replan, search, wait for the world, start a
  search, or watch the plan run (:func:`leader_phase`). The order of the tests
  in :func:`leader_phase` is the order in which ``ProblemRuntime._lead`` used to
  test its flags, so the leader does exactly what it did before.

:data:`TRANSITIONS` lists every move between leader phases that the runtime
makes, with the event that makes it; ``docs/planning.md`` draws them.
"""

from __future__ import annotations

from enum import Enum, StrEnum

from alica.prophet.board import ShareStatus


class ChildPhase(StrEnum):
    """What the team runs for the planning problem (the values are the trace's ``phase``)."""

    WAIT = "wait"
    """The WaitPlan: no plan is shared yet, the leader searches or replans, or a step failed."""
    PLAN = "plan"
    """The generated plan of the latest share."""
    ALTERNATIVE = "alternative"
    """The AlternativePlan: planning failed (or the runtime gave up) and the problem declares one."""
    DONE = "done"
    """Nothing: the goal holds (the child succeeds)."""
    FAILED = "failed"
    """Nothing: planning failed and the problem declares no AlternativePlan (the child fails)."""


def child_phase(
    status: ShareStatus | None, generation: int, failed_generation: int, has_alternative: bool
) -> ChildPhase:
    """The child phase from the adopted share's ``status`` and ``generation`` (``None``: no share yet).

    Args:
        status: the adopted share's status, ``None`` before any share.
        generation: the adopted share's generation (ignored without a share).
        failed_generation: the latest generation whose plan failed here (``-1``: none).
        has_alternative: whether the problem declares an AlternativePlan.

    Returns:
        What the team runs.
    """
    if status is None or status is ShareStatus.SEARCHING or generation <= failed_generation:
        return ChildPhase.WAIT
    if status is ShareStatus.PLAN:
        return ChildPhase.PLAN
    if status is ShareStatus.DONE:
        return ChildPhase.DONE
    return ChildPhase.ALTERNATIVE if has_alternative else ChildPhase.FAILED


class LeaderPhase(Enum):
    """What the runtime of one agent does for its problem on a tick."""

    FOLLOWING = "following"
    """Not the leader: adopt the leader's shares, repeat a pending replan request every UpdateTime."""
    STARTING = "starting"
    """The leader has no plan to stand by (no share, a ``searching`` share, or the plan that failed): start a search."""
    SETTLING = "settling"
    """A step failed: the team runs the WaitPlan for an UpdateTime, then the leader searches again."""
    SEARCHING = "searching"
    """An anytime search runs, a budget a tick; its first plan is shared at once, better ones every UpdateTime."""
    REVIEWING = "reviewing"
    """Review on: the generation's first plan waits for the operator's decision (the team waits)."""
    WAITING = "waiting"
    """Nothing to plan for now (robots outside the team hold the rest of the goal, or the team waits for them)."""
    EXECUTING = "executing"
    """A plan is shared and runs: the leader repeats it and checks that its rest still fits the world."""
    DONE = "done"
    """The goal held: the leader repeats the ``done`` share."""
    GAVE_UP = "gave up"
    """Planning failed, timed out, or the same step failed too often: the ``failed`` share (AlternativePlan)."""


def leader_phase(
    *,
    leader: bool,
    proposal: bool,
    pending: bool,
    search: bool,
    blocked: bool,
    share: ShareStatus | None,
    share_failed: bool,
) -> LeaderPhase:
    """The leader phase from what the runtime holds, tested in the order the leader acts on it.

    Args:
        leader: whether the agent is the leader (the lowest agent in the state).
        proposal: whether a plan waits for the operator's decision.
        pending: whether a replan waits for the team to settle in the WaitPlan.
        search: whether a search runs.
        blocked: whether the leader waits for the world to change.
        share: the adopted share's status (``None``: no share).
        share_failed: whether the adopted share's generation is one whose plan failed here.

    Returns:
        The phase.
    """
    if not leader:
        return LeaderPhase.FOLLOWING
    if proposal:
        return LeaderPhase.REVIEWING
    if pending:
        return LeaderPhase.SETTLING
    if search:
        return LeaderPhase.SEARCHING
    if blocked:
        return LeaderPhase.WAITING
    if share is None or share is ShareStatus.SEARCHING or (share is ShareStatus.PLAN and share_failed):
        return LeaderPhase.STARTING
    if share is ShareStatus.PLAN:
        return LeaderPhase.EXECUTING
    if share is ShareStatus.DONE:
        return LeaderPhase.DONE
    return LeaderPhase.GAVE_UP


_P = LeaderPhase

#: Where starting a search leads: the search runs, or the goal holds already, or there is nothing to plan
#: for (robots outside the team hold the rest), or the planner cannot start.
START_OUTCOMES: dict[LeaderPhase, str] = {
    _P.SEARCHING: "a search starts (a 'searching' share)",
    _P.DONE: "the goal holds (a 'done' share)",
    _P.WAITING: "nothing can be planned for now (robots outside the team hold the rest of the goal)",
    _P.GAVE_UP: "the planner cannot start (a 'failed' share)",
}


def _table() -> dict[tuple[LeaderPhase, LeaderPhase], str]:
    moves: dict[tuple[LeaderPhase, LeaderPhase], str] = {}

    def starts(source: LeaderPhase, why: str) -> None:
        for target, outcome in START_OUTCOMES.items():
            moves.setdefault((source, target), f"{why}: {outcome}")

    leading = [p for p in LeaderPhase if p is not _P.FOLLOWING]
    for phase in leading:
        moves[(_P.FOLLOWING, phase)] = "the agents below this one left the state: it leads (from what it holds)"
        moves[(phase, _P.FOLLOWING)] = "a lower agent is in the state: it leads (a search or proposal is handed over)"
    starts(_P.STARTING, "no plan stands")
    starts(_P.SETTLING, "an UpdateTime after the step failed")
    for target, why in {
        _P.REVIEWING: "the generation's first plan, review on (proposed to the operator)",
        _P.EXECUTING: "the search ended (done, execution began, or the world changed) after sharing a plan",
        _P.WAITING: "no plan with the robots in the team while robots outside it may change the world, or come back",
        _P.GAVE_UP: "no plan: the planner failed, proved the goal unreachable, or the timeout passed",
    }.items():
        moves[(_P.SEARCHING, target)] = why
    starts(_P.SEARCHING, "the world changed while planning (a new generation)")
    moves[(_P.REVIEWING, _P.EXECUTING)] = "the operator accepts (or modifies validly): the plan is shared"
    moves[(_P.REVIEWING, _P.REVIEWING)] = "the operator's change is invalid: proposed again with the error"
    starts(_P.REVIEWING, "the operator declines")
    starts(_P.WAITING, "the world changed, or the wait for the robots outside the team is over")
    starts(_P.EXECUTING, "the plan no longer fits the world, is stuck, or is over (stepwise: the next step)")
    moves[(_P.EXECUTING, _P.WAITING)] = "the plan is over and the rest of the goal is held by robots outside the team"
    for source in (_P.EXECUTING, _P.SEARCHING):
        moves[(source, _P.SETTLING)] = "a step failed (here or in a teammate's replan request)"
        moves[(source, _P.GAVE_UP)] = "the same step failed too often (GIVE_UP_AFTER, GIVE_UP_ANYWAY_AFTER)"
    for source in leading:
        starts(source, "the operator changed the goal or the world")
    for source in (_P.SEARCHING, _P.REVIEWING, _P.SETTLING, _P.WAITING):
        for target in (_P.STARTING, _P.EXECUTING, _P.DONE, _P.GAVE_UP):
            moves.setdefault((source, target), "another leader's newer share is adopted (a partition healed)")
    return moves


#: Every move between leader phases the runtime makes: (from, to) -> the event that makes it.
TRANSITIONS: dict[tuple[LeaderPhase, LeaderPhase], str] = _table()


def allowed(source: LeaderPhase, target: LeaderPhase) -> bool:
    """Whether the runtime moves from ``source`` to ``target`` (staying in a phase is always allowed)."""
    return source is target or (source, target) in TRANSITIONS
