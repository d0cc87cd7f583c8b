"""The plan board: names of generated plans, and a leader that shares an older plan than the team's."""

from __future__ import annotations

from alica.lang.fact import Fact
from alica.prophet.board import PlanBoard, PlanShare, ShareStatus
from alica.prophet.planner import PlanStep

KEY = ("Mission", "Stacking", "StackBlocks")
WORLD = (Fact("ontable", ("a",)), Fact("clear", ("a",)))


def _share(leader: str, generation: int, version: int, *steps: PlanStep, origin: str = "") -> PlanShare:
    return PlanShare(
        KEY,
        generation,
        version,
        leader,
        ShareStatus.PLAN,
        steps,
        float(len(steps)),
        WORLD,
        ("r1", "r2"),
        "Stack",
        origin=origin or leader,
    )


def test_plans_of_the_same_generation_and_version_with_different_content_have_different_names() -> None:
    # a restarted leader counts generations from 1 again: its plan must not take the name of the team's
    before = _share("r1", 2, 1, PlanStep("pick-up", ("a",)))
    after = _share("r1", 2, 1, PlanStep("unstack", ("b", "a")))
    other = _share("r2", 2, 1, PlanStep("pick-up", ("a",)))
    names = {s.plan_name("StackBlocks") for s in (before, after, other)}
    assert len(names) == 3
    assert all(n.startswith("StackBlocks_g2v1_") and n.isidentifier() for n in names)
    # a repeat by another leader is the same plan, under the same name
    repeat = _share("r3", 2, 1, PlanStep("pick-up", ("a",)), origin="r1")
    assert repeat.plan_name("StackBlocks") == before.plan_name("StackBlocks") and repeat.same_plan(before)
    assert not after.same_plan(before)


def test_a_board_notes_a_leader_sharing_an_older_plan_than_it_holds() -> None:
    board = PlanBoard()
    board.receive(_share("r2", 2, 1, PlanStep("pick-up", ("a",))), 0.0)
    board.receive(_share("r2", 2, 1, PlanStep("pick-up", ("a",))), 1.0)  # the leader repeats it
    assert not board.behind
    board.receive(_share("r1", 1, 1, PlanStep("unstack", ("b", "a"))), 2.0)  # r1 restarted and leads
    assert board.behind == {KEY}
    assert board.shares[KEY].leader == "r2"  # the older plan does not replace the team's
