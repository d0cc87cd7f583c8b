"""MAGiC: one share per agent, the first valid plan wins, at most 3(n-1) messages a round.

The protocol is driven two ways: over a hand-made link whose reachability the
test sets (the protocol's rules one by one), and in lock step over the
simulated network (:func:`alica.app.magic.run_lockstep`) on Rovers problems.
"""

from __future__ import annotations

import io
import pickle
from functools import cache

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.magic import TOPIC, MagicRun, TransportLink, run_lockstep
from alica.clock import ManualClock
from alica.comm import SimNetwork
from alica.prophet.magic import (
    Final,
    MagicLeader,
    MagicLink,
    MagicWorker,
    Result,
    Share,
    share_searches,
)
from alica.prophet.pddl import PddlError, parse_domain, parse_problem
from alica.prophet.planner import PlanStatus, PlanStep
from alica.prophet.search import BuiltinPlanner, FirstSearch
from alica.prophet.validate import validate_plan
from tests.conftest import benchmark_set
from tests.prophet.planners.checks import UNSOLVABLE_DOMAIN, UNSOLVABLE_PROBLEM


@cache
def rovers(name: str) -> tuple[str, str]:
    """The Rovers domain and problem ``name`` as text."""
    rovers = benchmark_set("pddl") / "rovers"
    return (rovers / "domain.pddl").read_text(), (rovers / f"{name}.pddl").read_text()


def assert_valid(run: MagicRun, texts: tuple[str, str]) -> None:
    """The run solved the task with a valid plan of the cost it reports, within the message bound."""
    assert run.status is PlanStatus.SOLVED, run
    assert run.plan is not None
    domain = parse_domain(texts[0])
    check = validate_plan((domain, parse_problem(texts[1], "<p>", domain)), run.plan)
    assert check.valid, check.reason
    assert check.cost == run.cost
    assert run.messages <= run.bound
    assert run.received <= run.messages


class Team:
    """An in-memory team for the protocol tests: every message reaches every other member at once."""

    def __init__(self) -> None:
        self.inbox: dict[str, list[object]] = {}
        self.up: set[str] = set()
        self.log: list[object] = []

    def link(self, name: str) -> Link:
        self.inbox[name] = []
        self.up.add(name)
        return Link(self, name)


class Link:
    """One member's :class:`MagicLink` on a :class:`Team`."""

    def __init__(self, team: Team, name: str) -> None:
        self.team = team
        self._name = name

    @property
    def name(self) -> str:
        return self._name

    def send(self, payload: object) -> None:
        self.team.log.append(payload)
        for other, box in self.team.inbox.items():
            if other != self._name:
                box.append(payload)

    def receive(self) -> list[object]:
        box = self.team.inbox[self._name]
        out = list(box)
        box.clear()
        return out

    def reachable(self) -> frozenset[str]:
        return frozenset(self.team.up - {self._name})


def sent(team: Team, kind: type) -> list[object]:
    return [m for m in team.log if isinstance(m, kind)]


# ------------------------------------------------------------------ shares


def test_shares_differ_and_share_zero_is_the_default_search() -> None:
    searches = share_searches(8, seed=5)
    assert searches[0] == FirstSearch()
    assert len(set(searches)) == 8
    assert share_searches(8, seed=5) == searches
    assert share_searches(8, seed=6) != searches
    with pytest.raises(ValueError, match="at least one agent"):
        share_searches(0)


class AlicaOnly(pickle.Unpickler):
    """An unpickler that finds classes of ``alica.`` modules only, as a transport's would."""

    def find_class(self, module: str, name: str) -> object:
        if not module.startswith("alica."):
            raise pickle.UnpicklingError(f"{module}.{name} is not allowed")
        return super().find_class(module, name)


def test_messages_are_plain_data_that_pickle() -> None:
    share = Share(1, "a", "b", 1, "(d)", "(p)", FirstSearch("ff", 3.0, 7), 2.5)
    result = Result(1, "a", "b", 1, (PlanStep("go", ("x",)),), PlanStatus.SOLVED, 12, 0.5)
    final = Final(1, "a", "b", (PlanStep("go", ("x",)),), PlanStatus.SOLVED, 1.0, "b")
    for message in (share, result, final):
        data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
        assert AlicaOnly(io.BytesIO(data)).load() == message
    assert (share.to, result.to, final.to) == ("b", "a", "b")


def test_the_link_protocol_is_met_by_the_transport_adapter() -> None:
    clock = ManualClock()
    network = SimNetwork(clock)
    a, b = TransportLink(network.attach("a")), TransportLink(network.attach("b"))
    assert isinstance(a, MagicLink)
    final = Final(1, "a", "b", None, PlanStatus.TIMEOUT)
    a.heartbeat()
    a.send(final)
    network.attach("c").publish("other/topic", "noise")
    assert b.receive() == [final]
    assert b.reachable() == {"a"}
    assert a.receive() == []
    assert TOPIC == "alica/magic"


# ------------------------------------------------------------------ lock step over the simulated network


@pytest.mark.parametrize("problem", ["p01", "p02", "p03", "p04", "p05"])
@pytest.mark.parametrize("agents", [1, 2, 3, 4])
def test_rovers_plans_are_valid_within_three_messages_per_teammate(problem: str, agents: int) -> None:
    texts = rovers(problem)
    run = run_lockstep(*texts, agents)
    assert_valid(run, texts)
    assert run.agents == agents
    if agents == 1:
        assert run.messages == 0
    else:
        assert run.messages >= 2 * (agents - 1)  # every teammate got a share and a final


def test_one_agent_finds_the_builtin_planners_first_plan() -> None:
    texts = rovers("p05")
    domain = parse_domain(texts[0])
    alone = BuiltinPlanner().solve(domain, parse_problem(texts[1], "<p>", domain), anytime=False)
    run = run_lockstep(*texts, 1)
    assert run.plan == alone.plan
    assert run.solver == "agent1"


def test_a_teammates_plan_can_win() -> None:
    texts = rovers("p05")  # the ff_add_unit share finds its plan in fewer expansions than the default
    run = run_lockstep(*texts, 2, progress_every=1)
    assert_valid(run, texts)
    assert run.solver == "agent2"
    assert run.messages == 3


def test_a_worker_crashed_during_the_search_is_not_waited_for() -> None:
    texts = rovers("p05")
    run = run_lockstep(*texts, 3, crash={"agent2": 2}, lease=0.25, progress_every=1)
    assert_valid(run, texts)
    assert run.lost == ("agent2",)
    assert run.outcome is not None
    assert "agent2" not in run.outcome.informed  # no final to a teammate known lost
    assert run.solver in {"agent1", "agent3"}


def test_the_same_seed_gives_the_same_round() -> None:
    texts = rovers("p04")

    def summary(seed: int) -> tuple[object, ...]:
        run = run_lockstep(*texts, 4, seed=seed, loss=0.3, delay=0.05, crash={"agent3": 4}, progress_every=2)
        return run.status, run.plan, run.messages, run.received, run.solver, run.lost, run.ticks, run.expansions

    assert summary(3) == summary(3)


def test_an_unsolvable_task_ends_the_round_for_every_agent() -> None:
    run = run_lockstep(UNSOLVABLE_DOMAIN, UNSOLVABLE_PROBLEM, 3)
    assert run.status is PlanStatus.UNSOLVABLE
    assert run.plan is None
    assert run.messages <= run.bound
    assert run.outcome is not None and run.outcome.informed == ("agent2", "agent3")


def test_when_every_share_runs_out_of_time_the_round_times_out() -> None:
    texts = rovers("p10")
    run = run_lockstep(*texts, 3, seconds=0.1, progress_every=1)
    assert run.status is PlanStatus.TIMEOUT
    assert run.plan is None
    assert run.messages == 6  # two shares, two results, two finals
    assert run.outcome is not None and "time limit" in run.outcome.message


def test_the_driver_checks_its_arguments() -> None:
    texts = rovers("p01")
    with pytest.raises(ValueError, match="cannot crash agent1"):
        run_lockstep(*texts, 2, crash={"agent1": 3})
    with pytest.raises(ValueError, match="at least one agent"):
        run_lockstep(*texts, 0)
    with pytest.raises(PddlError):
        run_lockstep("(define", texts[1], 2)


@settings(max_examples=30)
@given(
    agents=st.integers(1, 4),
    victim=st.integers(0, 3),
    crash_tick=st.one_of(st.none(), st.integers(1, 30)),
    loss=st.sampled_from([0.0, 0.3]),
    problem=st.sampled_from(["p01", "p03", "p05"]),
    seed=st.integers(0, 3),
)
def test_every_round_stays_within_the_message_bound(
    agents: int, victim: int, crash_tick: int | None, loss: float, problem: str, seed: int
) -> None:
    texts = rovers(problem)
    crash = {f"agent{2 + victim % (agents - 1)}": crash_tick} if agents > 1 and crash_tick is not None else {}
    run = run_lockstep(*texts, agents, seed=seed, loss=loss, crash=crash, lease=0.25, progress_every=2)
    assert_valid(run, texts)


# ------------------------------------------------------------------ the protocol's rules, one by one


def test_the_share_of_a_teammate_lost_before_it_answered_is_taken_over() -> None:
    team, clock = Team(), ManualClock()
    texts = rovers("p03")
    leader = MagicLeader(team.link("a"), *texts, seconds=1.0, clock=clock.now, progress_every=1)
    team.link("b")  # never steps: it takes no part but is reachable at the start
    leader.start(["a", "b"])
    assert [s.worker for s in sent(team, Share)] == ["b"]
    team.up.discard("b")
    leader.step()  # b is lost; the leader reads its own share's task
    clock.advance(2.0)
    assert leader.step() is None  # its own share runs out of time ...
    outcome = None
    while outcome is None:
        outcome = leader.step()  # ... then it searches b's share
    assert outcome.status is PlanStatus.SOLVED
    assert (outcome.solver, outcome.index, outcome.taken_over, outcome.lost) == ("a", 1, (1,), ("b",))
    assert outcome.search == share_searches(2)[1]
    assert sent(team, Final) == []  # b is lost: no final
    assert outcome.messages == 1


def test_a_teammate_unreachable_at_the_start_gets_no_share() -> None:
    team = Team()
    texts = rovers("p01")
    leader = MagicLeader(team.link("a"), *texts, clock=ManualClock().now)
    leader.start(["a", "b"])
    assert sent(team, Share) == []
    outcome = None
    while outcome is None:
        outcome = leader.step(100)
    assert outcome.status is PlanStatus.SOLVED
    assert outcome.lost == ("b",) and outcome.shared == () and outcome.messages == 0


def test_an_invalid_plan_from_a_teammate_is_not_taken() -> None:
    team = Team()
    texts = rovers("p01")
    leader = MagicLeader(team.link("a"), *texts, clock=ManualClock().now)
    b = team.link("b")
    leader.start(["a", "b"])
    b.send(
        Result(1, "a", "b", 1, (PlanStep("navigate", ("rover0", "waypoint0", "waypoint0")),), PlanStatus.SOLVED, 1, 0)
    )
    b.send(Result(0, "a", "b", 1, None, PlanStatus.UNSOLVABLE, 1, 0))  # an older round's: ignored
    outcome = None
    while outcome is None:
        outcome = leader.step(100)
    assert (outcome.status, outcome.solver) == (PlanStatus.SOLVED, "a")
    assert leader.counts.results_received == 1 and leader.counts.ignored == 1
    b.send(Result(1, "a", "b", 5, None, PlanStatus.UNSOLVABLE, 1, 0))  # no such share: ignored
    b.send(Result(1, "a", "c", 1, None, PlanStatus.UNSOLVABLE, 1, 0))  # share 1 is b's, not c's: ignored
    leader.step()
    assert leader.counts.ignored == 3 and outcome.status is PlanStatus.SOLVED
    assert [f.steps == outcome.plan.steps for f in sent(team, Final)] == [True]


def test_a_worker_answers_once_and_stops_on_the_final_or_a_newer_round() -> None:
    team, clock = Team(), ManualClock()
    texts = rovers("p05")
    a = team.link("a")
    worker = MagicWorker(team.link("b"), clock=clock.now, progress_every=1)
    search = FirstSearch()
    a.send(Share(1, "a", "b", 1, *texts, search))
    a.send(Share(1, "a", "c", 2, *texts, search))  # another teammate's share
    worker.step()
    assert worker.searching and worker.counts.shares_received == 1 and worker.counts.ignored == 1
    a.send(Share(2, "a", "b", 1, *texts, search))  # a newer round replaces the share
    worker.step()
    assert worker.share is not None and worker.share.round_id == 2
    a.send(Final(1, "a", "b", None, PlanStatus.TIMEOUT))  # the old round's final: ignored
    worker.step()
    assert worker.searching and worker.final is None
    a.send(Final(2, "a", "b", None, PlanStatus.SOLVED))
    worker.step()
    assert not worker.searching and worker.final is not None
    for _ in range(200):
        worker.step()
    assert sent(team, Result) == []  # stopped by the final: no answer
    a.send(Share(3, "a", "b", 1, *texts, search))
    while worker.result is None:
        worker.step(100)
    assert worker.result.status is PlanStatus.SOLVED and worker.counts.results_sent == 1
    assert sent(team, Result) == [worker.result]


def test_the_leader_checks_its_team() -> None:
    team = Team()
    leader = MagicLeader(team.link("a"), *rovers("p01"))
    with pytest.raises(ValueError, match="must be one of the agents"):
        leader.start(["b", "c"])
    with pytest.raises(ValueError, match="distinct"):
        leader.start(["a", "b", "b"])
    assert leader.round_id == 0 and not leader.running
