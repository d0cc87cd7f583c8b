"""What the leader's search starts from: MAGiC over the team as a search, and the objects' positions.

* :func:`magic_events`: with parallel planning on (MAGiC), a round over the
  agents in the state, seen by the leader as the events of an anytime search
  (its first valid plan wins), so the search budget and the sharing work alike.
* :func:`positions`: the objects' positions from the world model's ``pos``
  values, for planners that read positions.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator

from alica.errors import PlannerError
from alica.prophet.magic.leader import MagicLeader
from alica.prophet.magic.team import STEP_EXPANSIONS, TeamMagic
from alica.prophet.pddl.writer import write_domain, write_problem
from alica.prophet.pipeline import Found, ProblemEvent, ProblemPlanning, Rejected
from alica.prophet.planner import Done, PlanStatus, Progress
from alica.prophet.reviewing import Emit


def magic_events(
    planning: ProblemPlanning,
    generation: int,
    magic: TeamMagic,
    *,
    me: str,
    members: Callable[[], tuple[str, ...]],
    emit: Emit,
    key: str,
    seconds: float,
    clock: Callable[[], float],
) -> Iterator[ProblemEvent]:
    """A MAGiC round over the agents in the state as the leader's search events; its first valid plan wins.

    Args:
        planning: what the leader plans (its PDDL is sent to the workers).
        generation: the search's generation (the round's number and seed).
        magic: the agent's MAGiC.
        me: the leader's name.
        members: the agents in the state now.
        emit: sends a trace event.
        key: the problem's key as text (for the trace).
        seconds: the problem's timeout.
        clock: the time now.

    Yields:
        Progress while the round runs, then Found (or Rejected) and Done.
    """
    leader = MagicLeader(
        magic.leader_link(members),
        write_domain(planning.domain),
        write_problem(planning.pddl),
        seed=generation,
        seconds=seconds,
        clock=clock,
        progress_every=STEP_EXPANSIONS,
        first_round=generation,
    )
    agents = (me, *sorted(a for a in members() if a != me))
    leader.start(agents)
    emit("planner", key=key, what="magic", round=generation, agents=list(agents))
    expansions = 0
    while True:
        outcome = leader.step(1)
        if outcome is None:
            expansions += STEP_EXPANSIONS
            yield Progress(expansions)
            continue
        emit(
            "planner",
            key=key,
            what="magic done",
            round=generation,
            status=outcome.status.value,
            solver=outcome.solver,
            messages=outcome.messages,
            lost=list(outcome.lost),
            seconds=round(outcome.seconds, 6),
        )
        if outcome.plan is None:
            yield Done(outcome.status, outcome.expansions, outcome.message)
            return
        try:
            yield Found(planning.validated(outcome.plan), outcome.expansions)
        except PlannerError as exc:
            yield Rejected(str(exc), outcome.expansions)
        yield Done(PlanStatus.SOLVED, outcome.expansions, "MAGiC: the first valid plan wins")
        return


def positions(values: Iterable[tuple[str, tuple[object, ...], object]]) -> dict[str, tuple[float, ...]]:
    """Object -> its position from the world model's ``pos`` values (for planners that read positions)."""
    out: dict[str, tuple[float, ...]] = {}
    for name, args, value in values:
        if name == "pos" and len(args) == 1 and isinstance(value, (tuple, list)) and len(value) >= 2:
            try:
                out[str(args[0])] = tuple(float(v) for v in value)
            except (TypeError, ValueError):
                continue
    return out
