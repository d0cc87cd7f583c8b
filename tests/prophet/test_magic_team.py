"""MAGiC inside a team: with parallel planning the leader splits its search over the agents in the problem's state.

MAGiC splits the builtin planner's search, so the team plans StackBlocks with ``planner: builtin``
(the mission's temporal planner plans alone)."""

from __future__ import annotations

from tests.prophet.blocks_team import BlockSkills, blocks_team, goal_holds

TOWER = [["a", "b", "c", "d", "e", "f"]]


def events(recorder, kind, **match):
    return [e for e in recorder.events if e["event"] == kind and all(e.get(k) == v for k, v in match.items())]


def test_the_leader_plans_with_every_teammate_and_the_team_reaches_the_goal():
    sim, rec = blocks_team(
        ["r1", "r2", "r3"], BlockSkills(), parallel_planning=True, planner="builtin", planner_expansions=200
    )
    summary = sim.run(until_done=True, max_time=120)
    assert summary["success"] and goal_holds(sim, "r3")
    [start] = events(rec, "planner", what="magic")[:1]
    assert start["agent"] == "r1" and start["agents"] == ["r1", "r2", "r3"]
    done = events(rec, "planner", what="magic done")
    assert done and all(e["messages"] <= 3 * (len(start["agents"]) - 1) for e in done)
    assert done[0]["status"] == "solved"
    assert events(rec, "planner", what="plan")  # the round's plan was shared as any plan is


def test_a_teammate_that_crashes_as_the_round_starts_is_not_waited_for():
    sim, rec = blocks_team(["r1", "r2", "r3"], BlockSkills(), stacks=TOWER, parallel_planning=True, planner="builtin")
    sim.tick()
    assert events(rec, "planner", agent="r1", what="started")
    sim.crash("r3")  # before its share reaches it: it never answers
    summary = sim.run(until_done=True, max_time=120)
    assert summary["agents"]["r1"]["status"] == "success" and summary["agents"]["r2"]["status"] == "success"
    first = events(rec, "planner", what="magic done")[0]
    assert first["status"] == "solved" and first["solver"] in ("r1", "r2")


def test_parallel_planning_is_deterministic():
    def trace():
        sim, rec = blocks_team(["r1", "r2", "r3"], BlockSkills(), seed=3, parallel_planning=True, planner="builtin")
        sim.run(until_done=True, max_time=60)
        return list(rec.events)

    assert trace() == trace()
