"""The runtime's small collaborators: giving up, waiting, leadership (alica.prophet.{giving_up,waiting,leadership})."""

from __future__ import annotations

from alica.lang.fact import Fact
from alica.prophet.giving_up import GIVE_UP_AFTER, GIVE_UP_ANYWAY_AFTER, GiveUp
from alica.prophet.leadership import is_leader, next_generation
from alica.prophet.waiting import TEAM_WAIT, Waiting

A = frozenset({Fact("on", ("a", "b"))})
B = frozenset({Fact("on", ("a", "c"))})


def test_the_same_step_failing_in_the_same_world_gives_up_after_GIVE_UP_AFTER_times():
    give_up = GiveUp()
    for _ in range(GIVE_UP_AFTER - 1):
        assert give_up.step_failed("no grasp", A, 0) is None
    message = give_up.step_failed("no grasp", A, 0)
    assert message == f"gave up: the same step failed {GIVE_UP_AFTER} times while the world stayed the same: no grasp"
    assert give_up.step_failed("no grasp", A, 0) is None  # the counts start afresh


def test_other_reasons_and_worlds_count_apart():
    give_up = GiveUp()
    for _ in range(GIVE_UP_AFTER - 1):
        assert give_up.step_failed("no grasp", A, 0) is None
        assert give_up.step_failed("blocked", A, 0) is None
    assert give_up.step_failed("no grasp", B, 0) is None


def test_a_changing_world_gives_up_anyway_while_no_step_is_carried_out():
    give_up = GiveUp()
    worlds = [frozenset({Fact("at", ("r1", str(i)))}) for i in range(GIVE_UP_ANYWAY_AFTER)]
    for world in worlds[:-1]:
        assert give_up.step_failed("no grasp", world, 0) is None
    assert give_up.step_failed("no grasp", worlds[-1], 0) == (
        f"gave up: the same step failed {GIVE_UP_ANYWAY_AFTER} times: no grasp"
    )


def test_a_step_carried_out_counts_the_changing_world_afresh():
    give_up = GiveUp()
    worlds = [frozenset({Fact("at", ("r1", str(i)))}) for i in range(GIVE_UP_ANYWAY_AFTER)]
    for world in worlds[:-1]:
        assert give_up.step_failed("no grasp", world, 0) is None
    assert give_up.step_failed("no grasp", worlds[-1], 1) is None  # a step was done meanwhile


def test_the_leader_waits_for_the_world_to_change():
    waiting = Waiting()
    waiting.block(A)
    assert waiting.blocked == set(A)
    assert not waiting.changed(A)
    assert waiting.changed(B)
    waiting.unblock()
    assert waiting.blocked is None


def test_the_team_wait_lasts_TEAM_WAIT_seconds_and_only_for_an_unsolvable_search_with_robots_outside():
    waiting = Waiting()
    assert not waiting.wait_for_team(0.0, unsolvable=False, outsiders=True)
    assert not waiting.wait_for_team(0.0, unsolvable=True, outsiders=False)
    assert waiting.wait_for_team(1.0, unsolvable=True, outsiders=True)
    assert not waiting.team_wait_over(1.0 + TEAM_WAIT - 0.1)
    assert waiting.wait_for_team(1.0 + TEAM_WAIT - 0.1, unsolvable=True, outsiders=True)
    assert waiting.team_wait_over(1.0 + TEAM_WAIT)
    assert not waiting.wait_for_team(1.0 + TEAM_WAIT, unsolvable=True, outsiders=True)  # waited long enough
    assert waiting.team_until is None


def test_a_plan_found_ends_the_team_wait():
    waiting = Waiting()
    assert waiting.wait_for_team(0.0, unsolvable=True, outsiders=True)
    waiting.end_team_wait()
    assert not waiting.team_wait_over(TEAM_WAIT + 1)


def test_the_lowest_member_leads():
    assert is_leader(("r1", "r2"), "r1")
    assert not is_leader(("r1", "r2"), "r2")
    assert not is_leader((), "r1")


def test_a_new_generation_is_newer_than_any_seen():
    assert next_generation(0, -1, 0) == 1
    assert next_generation(4, 2, 3) == 5
    assert next_generation(1, 6, 3) == 7


def test_a_failure_counts_by_its_cause_whichever_robot_reports_it_in_whichever_generation():
    from alica.prophet.giving_up import failure_cause

    cause = "reached failure state 'T0_Failed'"
    assert failure_cause(f"a step of StackBlocks_g2v0_r1_ab12cd failed: {cause}") == cause  # the leader's own
    assert failure_cause(f"r2: a step of StackBlocks_g3v1_r1_0f0f0f failed: {cause}") == cause  # a teammate's
    assert failure_cause("r2: the world changed under the plan") == "the world changed under the plan"
