"""The runtime's phases and the moves between them (alica.prophet.runtime_states)."""

from __future__ import annotations

import itertools

import pytest

from alica.prophet.board import ShareStatus
from alica.prophet.runtime_states import (
    START_OUTCOMES,
    TRANSITIONS,
    ChildPhase,
    LeaderPhase,
    allowed,
    child_phase,
    leader_phase,
)


@pytest.mark.parametrize(
    ("status", "generation", "failed", "alternative", "phase"),
    [
        (None, 0, -1, True, ChildPhase.WAIT),
        (ShareStatus.SEARCHING, 3, -1, True, ChildPhase.WAIT),
        (ShareStatus.PLAN, 2, -1, True, ChildPhase.PLAN),
        (ShareStatus.PLAN, 2, 2, True, ChildPhase.WAIT),  # the plan of a failed generation: wait for the next
        (ShareStatus.DONE, 1, -1, False, ChildPhase.DONE),
        (ShareStatus.FAILED, 1, -1, True, ChildPhase.ALTERNATIVE),
        (ShareStatus.FAILED, 1, -1, False, ChildPhase.FAILED),
    ],
)
def test_the_child_phase_follows_the_adopted_share(status, generation, failed, alternative, phase):
    assert child_phase(status, generation, failed, alternative) is phase


def _phase(**held: object) -> LeaderPhase:
    flags: dict[str, object] = {
        "leader": True,
        "proposal": False,
        "pending": False,
        "search": False,
        "blocked": False,
        "share": ShareStatus.PLAN,
        "share_failed": False,
    }
    flags.update(held)
    return leader_phase(**flags)  # type: ignore[arg-type]


def test_the_leader_phase_is_tested_in_the_order_the_leader_acts():
    assert _phase(leader=False, proposal=True, search=True) is LeaderPhase.FOLLOWING
    assert _phase(proposal=True, pending=True, search=True, blocked=True) is LeaderPhase.REVIEWING
    assert _phase(pending=True, search=True, blocked=True) is LeaderPhase.SETTLING
    assert _phase(search=True, blocked=True) is LeaderPhase.SEARCHING
    assert _phase(blocked=True, share=None) is LeaderPhase.WAITING
    assert _phase(share=None) is LeaderPhase.STARTING
    assert _phase(share=ShareStatus.SEARCHING) is LeaderPhase.STARTING
    assert _phase(share_failed=True) is LeaderPhase.STARTING
    assert _phase() is LeaderPhase.EXECUTING
    assert _phase(share=ShareStatus.DONE) is LeaderPhase.DONE
    assert _phase(share=ShareStatus.FAILED) is LeaderPhase.GAVE_UP


def test_every_phase_is_reached_and_every_leading_phase_can_be_left():
    targets = {target for _, target in TRANSITIONS}
    sources = {source for source, _ in TRANSITIONS}
    assert targets == set(LeaderPhase)
    assert sources == set(LeaderPhase)
    assert all(TRANSITIONS.values())


def test_the_moves_the_runtime_makes_are_in_the_table():
    assert allowed(LeaderPhase.EXECUTING, LeaderPhase.EXECUTING)
    for target in START_OUTCOMES:
        assert allowed(LeaderPhase.STARTING, target)
        assert allowed(LeaderPhase.WAITING, target)
    assert allowed(LeaderPhase.SEARCHING, LeaderPhase.REVIEWING)
    assert allowed(LeaderPhase.REVIEWING, LeaderPhase.EXECUTING)
    assert allowed(LeaderPhase.EXECUTING, LeaderPhase.SETTLING)
    assert allowed(LeaderPhase.SETTLING, LeaderPhase.SEARCHING)
    # a settle waits for the team: it never shares a plan without searching
    assert not allowed(LeaderPhase.SETTLING, LeaderPhase.REVIEWING)
    assert not allowed(LeaderPhase.STARTING, LeaderPhase.EXECUTING)


def test_a_team_run_only_makes_moves_of_the_table():
    # the phases the leader goes through in a blocks run, tick by tick, are moves of the table
    from alica.prophet.runtime import ProblemRuntime
    from tests.prophet.blocks_team import BlockSkills, blocks_team

    seen: list[LeaderPhase] = []
    update = ProblemRuntime.update

    def recording(self: ProblemRuntime, now: float) -> None:
        update(self, now)
        if self.host.name == "r1":
            seen.append(self.leader_phase())

    mp = pytest.MonkeyPatch()
    mp.setattr(ProblemRuntime, "update", recording)
    try:
        sim, _ = blocks_team(["r1", "r2"], BlockSkills())
        sim.run(ticks=80)
    finally:
        mp.undo()
    assert LeaderPhase.EXECUTING in seen
    assert all(allowed(a, b) for a, b in itertools.pairwise(seen)), seen


_SCENARIOS = [
    ("tests.prophet.test_runtime", "test_a_failed_step_sends_the_team_back_to_the_wait_plan_and_the_leader_replans"),
    ("tests.prophet.test_runtime", "test_the_world_changing_under_the_plan_makes_the_leader_replan"),
    ("tests.prophet.test_runtime", "test_the_leader_crashes_while_planning_and_the_next_lowest_id_takes_over"),
    ("tests.prophet.test_runtime", "test_the_operator_sets_a_new_goal_and_the_leader_replans"),
    ("tests.prophet.test_runtime", "test_a_block_held_by_a_robot_outside_the_team_the_team_does_the_rest_then_waits"),
    ("tests.prophet.test_runtime", "test_a_plan_for_part_of_the_goal_runs_to_its_end_then_the_rest_is_planned"),
    ("tests.prophet.test_review", "test_a_declined_plan_is_planned_again_and_the_new_generation_is_proposed"),
    (
        "tests.prophet.test_review",
        "test_dropping_a_needed_step_is_refused_with_the_validators_reason_then_accept_runs_the_plan",
    ),
    ("tests.prophet.test_review", "test_the_leader_crashing_while_a_proposal_waits_the_next_leader_proposes"),
]


@pytest.mark.parametrize(("module", "name"), _SCENARIOS)
def test_the_runtime_scenarios_move_only_along_the_table(module: str, name: str):
    # every agent's leader phase, tick by tick, in scenarios of the runtime's own tests
    import importlib

    from alica.prophet.runtime import ProblemRuntime

    seen: dict[int, list[LeaderPhase]] = {}
    update = ProblemRuntime.update

    def recording(self: ProblemRuntime, now: float) -> None:
        update(self, now)
        seen.setdefault(id(self), []).append(self.leader_phase())

    mp = pytest.MonkeyPatch()
    mp.setattr(ProblemRuntime, "update", recording)
    try:
        getattr(importlib.import_module(module), name)()
    finally:
        mp.undo()
    moves = {(a, b) for phases in seen.values() for a, b in itertools.pairwise(phases) if a is not b}
    assert moves
    assert {(a, b) for a, b in moves if not allowed(a, b)} == set(), sorted(
        (a.value, b.value) for a, b in moves if not allowed(a, b)
    )
