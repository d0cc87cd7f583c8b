"""The team's periodic joint reassignment of frontiers, with hysteresis (alica.skills.exploration.assign)."""

from __future__ import annotations

import math

import pytest

from alica.skills.exploration import FrontierCandidate
from alica.skills.exploration.assign import (
    KEEP_BONUS,
    Explorer,
    How,
    decide,
    explore_terms,
    proposal_of,
    solve_team,
)


def cand(name: str, x: float, y: float, gain: float) -> FrontierCandidate:
    return FrontierCandidate(name, (x, y), (0, 0), 1, gain, False)


@pytest.fixture(scope="module")
def terms():
    """The shipped Explore plan's constraints (Eq. 7-8) and utilities (GainOverTravel, KeepFrontier)."""
    return explore_terms()


def team(terms, explorers, cands):
    """The plan's joint solution (an exact search: these problems are tiny)."""
    return solve_team(explorers, cands, terms.constraints, terms.utilities, time_limit=5.0)


def run_decisions(explorers, cands, proposal, spacing=4.0):
    """Every robot applies ``decide`` in turn, as each robot does at its reading of the map."""
    by_name = {c.name: c for c in cands}
    targets = {e.name: (by_name[e.target] if e.target in by_name else None) for e in explorers}
    hows = {}
    for e in explorers:
        heading = {n: t.position for n, t in targets.items() if n != e.name and t is not None}
        choice = decide(
            e.name, e.position, targets[e.name], by_name, set(e.frontiers), proposal, heading, spacing=spacing
        )
        targets[e.name] = choice.frontier
        hows[e.name] = choice.how
    return {n: (t.name if t is not None else None) for n, t in targets.items()}, hows


def test_the_plan_carries_the_hysteresis_bonus(terms):
    keep = terms.utility("KeepFrontier")
    assert f"{KEEP_BONUS}" in keep.text and "Targets(a, frontier(a))" in keep.text
    assert {c.name for c in terms.constraints} == {"SpreadFrontiers", "NearbyFrontiers"}


def test_two_robots_swap_frontiers_when_that_is_clearly_better(terms):
    # each robot drives to the frontier next to the other one: crossing the field twice
    cands = [cand("f_a", 1.0, 10.0, 10.0), cand("f_b", 10.0, 1.0, 10.0)]
    explorers = [
        Explorer("scout", (10.0, 0.0), "f_a", ("f_a", "f_b")),
        Explorer("stummel", (0.0, 10.0), "f_b", ("f_a", "f_b")),
    ]
    proposal = team(terms, explorers, cands)
    assert proposal == {"scout": "f_b", "stummel": "f_a"}
    targets, hows = run_decisions(explorers, cands, proposal)
    assert targets == {"scout": "f_b", "stummel": "f_a"}
    assert hows == {"scout": How.SWITCHED, "stummel": How.SWITCHED}


def test_a_robot_keeps_its_frontier_when_the_gain_is_below_the_margin(terms):
    # scout at the origin drives to f_near (gain 10, 5 m: 5); f_other gives 2 more (7), less than the bonus
    explorers = [Explorer("scout", (0.0, 0.0), "f_near", ("f_near", "f_other"))]
    below = [cand("f_near", 5.0, 0.0, 10.0), cand("f_other", 0.0, 5.0, 10.0 + KEEP_BONUS - 1.0)]
    proposal = team(terms, explorers, below)
    assert proposal == {"scout": "f_near"}
    assert run_decisions(explorers, below, proposal) == ({"scout": "f_near"}, {"scout": How.KEPT})
    # without a frontier of its own the better one wins: the bonus is what kept it
    fresh = [Explorer("scout", (0.0, 0.0), None, ("f_near", "f_other"))]
    assert team(terms, fresh, below) == {"scout": "f_other"}
    # above the margin the team moves it
    above = [cand("f_near", 5.0, 0.0, 10.0), cand("f_other", 0.0, 5.0, 10.0 + KEEP_BONUS + 1.0)]
    proposal = team(terms, explorers, above)
    assert proposal == {"scout": "f_other"}
    assert run_decisions(explorers, above, proposal) == ({"scout": "f_other"}, {"scout": How.SWITCHED})


def test_a_robot_whose_frontier_vanished_gets_a_new_one(terms):
    cands = [cand("f_1", 6.0, 0.0, 12.0), cand("f_2", 0.0, 6.0, 9.0), cand("f_3", -6.0, 0.0, 8.0)]
    explorers = [
        Explorer("scout", (0.0, 0.0), "f_gone", ("f_1", "f_2", "f_3")),  # its frontier was seen meanwhile
        Explorer("stummel", (5.0, 1.0), "f_1", ("f_1", "f_2", "f_3")),
    ]
    proposal = team(terms, explorers, cands)
    assert proposal["stummel"] == "f_1"  # kept
    targets, hows = run_decisions(explorers, cands, proposal)
    assert hows["scout"] is How.SOLVED and targets["scout"] in {"f_2", "f_3"}
    assert hows["stummel"] is How.KEPT and targets["stummel"] == "f_1"
    # with no solution it chooses itself, away from where stummel heads
    targets, hows = run_decisions(explorers, cands, {})
    assert hows["scout"] is How.FALLBACK and targets["scout"] == "f_2"
    assert hows["stummel"] is How.KEPT


def test_a_proposed_frontier_another_robot_keeps_heading_for_is_not_taken():
    cands = [cand("f_1", 6.0, 0.0, 12.0), cand("f_2", 0.0, 6.0, 9.0)]
    by_name = {c.name: c for c in cands}
    heading = {"stummel": (6.0, 0.5)}  # stummel heads for f_1 and the proposal leaves it there
    choice = decide(
        "scout", (0.0, 0.0), None, by_name, {"f_1", "f_2"}, {"scout": "f_1", "stummel": "f_1"}, heading, spacing=4.0
    )
    assert choice.how is How.FALLBACK and choice.frontier == by_name["f_2"]
    # a robot with a frontier keeps it rather than follow such a proposal
    choice = decide(
        "scout", (0.0, 0.0), by_name["f_2"], by_name, {"f_1", "f_2"}, {"scout": "f_1"}, heading, spacing=4.0
    )
    assert choice.how is How.KEPT and choice.frontier == by_name["f_2"]
    # nothing usable: no frontier
    assert decide("scout", (0.0, 0.0), None, by_name, set(), {}, heading, spacing=4.0).how is How.NONE


def test_three_robots_are_reassigned_jointly_and_deterministically(terms):
    cands = [
        cand("f_0_0", 2.0, 2.0, 6.0),
        cand("f_5_0", 11.0, 1.0, 14.0),
        cand("f_0_5", 1.0, 11.0, 13.0),
        cand("f_5_5", 11.0, 11.0, 20.0),
    ]
    names = tuple(c.name for c in cands)
    explorers = [
        Explorer("scout", (0.0, 0.0), "f_5_5", names),
        Explorer("stummel", (12.0, 12.0), "f_0_0", names),
        Explorer("amparo", (12.0, 0.0), None, names),
    ]
    first = team(terms, explorers, cands)
    for _ in range(3):
        assert team(terms, list(reversed(explorers)), cands) == first
    targets, hows = run_decisions(explorers, cands, first)
    assert run_decisions(explorers, cands, first) == (targets, hows)
    # each robot got a frontier, more than 4 m apart (Eq. 7), and the two that crossed the field were swapped back
    assert len(set(targets.values())) == 3
    by_name = {c.name: c for c in cands}
    chosen = [by_name[t].position for t in targets.values() if t is not None]
    assert all(math.dist(p, q) > 4.0 for i, p in enumerate(chosen) for q in chosen[i + 1 :])
    assert targets["stummel"] == "f_5_5" and hows["stummel"] is How.SWITCHED
    assert hows["scout"] is How.SWITCHED


def test_proposal_of_reads_the_team_values():
    assert proposal_of({"": {"frontier": "x"}, "scout": {"frontier": "f_1"}, "stummel": {"other": 3}}) == {
        "scout": "f_1"
    }


def _another_frontier(world, behaviour, asked):
    """A team solver that moves scout to a frontier other than the one it drives to; logs (time, current frontier)."""
    from alica.engine.parts import SolveResult

    def solver(names):
        current = behaviour.target.name if behaviour.target is not None else None
        others = sorted(c.name for c in behaviour.candidates if c.name != current)
        asked.append((world.now(), current))
        if not others:
            return SolveResult("infeasible", {}, {}, math.nan, "no frontier")
        return SolveResult("solved", {"frontier": others[0]}, {"scout": {"frontier": others[0]}}, 0.0)

    return solver


def test_explore_frontier_follows_the_team_when_it_moves_the_robot_while_it_drives(skill_run):
    """The skill reads the team's solution at every reading of the map, not only when it needs a frontier."""
    from alica.skills.exploration.assign import TARGETS
    from alica.worldmodel import WorldModel
    from alica.worldsim.scenarios import lunar

    asked = []
    held = []

    def install(world, behaviour):
        if behaviour.context.world_model is not None:
            held.append(
                (
                    behaviour.target.name if getattr(behaviour, "target", None) is not None else None,
                    [f.args for f in behaviour.context.world_model.facts() if f.predicate == TARGETS],
                )
            )

        if behaviour.context.solver is None:
            behaviour.context.solver = _another_frontier(world, behaviour, asked)

    world = lunar(seed=0, rocks=8, samples=0, size=14.0)
    try:
        wm = WorldModel("scout", clock=world.clock)
        run = skill_run(
            "ExploreFrontier", world, "scout", {"reassign": True}, timeout=4.5, world_model=wm, on_tick=install
        )
        assert any(current is not None for _, current in asked), asked  # asked while driving
        moved = [entry for entry in run.trace if "to frontier" in str(entry["feedback"])]
        frontiers = {str(e["feedback"]).split()[2] for e in moved}
        assert len(frontiers) >= 2, run.trace  # it followed the team to another frontier
        # Targets(scout, f) names the frontier it drives to, the one before retracted; none once it stopped
        driving = [(target, facts) for target, facts in held if target is not None]
        assert driving and all(facts == [("scout", target)] for target, facts in driving[1:]), driving
        assert not [f for f in wm.facts() if f.predicate == TARGETS]
    finally:
        world.close()


def test_without_reassign_the_skill_keeps_its_frontier_and_writes_no_targets(skill_run):
    """Without reassign (the skill's default) a robot reads the team's solution only when it needs a frontier."""
    from alica.skills.exploration.assign import TARGETS
    from alica.worldmodel import WorldModel
    from alica.worldsim.scenarios import lunar

    asked = []
    targets = []

    def install(world, behaviour):
        wm = behaviour.context.world_model
        targets.extend(f for f in wm.facts() if f.predicate == TARGETS)

        if behaviour.context.solver is None:
            behaviour.context.solver = _another_frontier(world, behaviour, asked)

    world = lunar(seed=0, rocks=8, samples=0, size=14.0)
    try:
        wm = WorldModel("scout", clock=world.clock)
        skill_run("ExploreFrontier", world, "scout", {}, timeout=4.5, world_model=wm, on_tick=install)
        assert asked and all(current is None for _, current in asked)  # only when it needed a frontier
        assert not targets
    finally:
        world.close()


def test_when_the_others_do_not_follow_a_proposal_their_heading_blocks_it():
    cands = [cand("f_1", 6.0, 0.0, 12.0), cand("f_2", 0.0, 6.0, 9.0)]
    by_name = {c.name: c for c in cands}
    heading = {"stummel": (6.0, 0.5)}  # stummel heads for f_1; the proposal would move it to f_2
    proposal = {"scout": "f_1", "stummel": "f_2"}
    follow = decide("scout", (0.0, 0.0), None, by_name, {"f_1", "f_2"}, proposal, heading, spacing=4.0)
    assert follow.how is How.SOLVED and follow.frontier == by_name["f_1"]
    alone = decide(
        "scout", (0.0, 0.0), None, by_name, {"f_1", "f_2"}, proposal, heading, spacing=4.0, others_follow=False
    )
    assert alone.how is How.FALLBACK and alone.frontier == by_name["f_2"]
