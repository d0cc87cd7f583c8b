"""Looking for a sample a crashed teammate dropped: the facts, the stale verdicts and DriveToDroppedSample alone."""

from __future__ import annotations

import math

from alica.lang.fact import Fact
from alica.skills.sample_facts import dropped_samples, stale_verdicts
from alica.worldmodel import WorldModel


class _Belief:
    """A team view: ``role`` for the roster, ``alive`` for the living."""

    def __init__(self, roster: dict[str, str], alive: set[str]) -> None:
        self.roster, self.alive = roster, alive

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        who = str(args[0])
        if name == "role":
            return self.roster.get(who)
        if name == "alive":
            return who in self.alive
        return None


def _world_model() -> WorldModel:
    wm = WorldModel("scout")
    wm.assert_fact("holding", "amparo", "s1")
    wm.set("pos", "s1", value=(2.0, 3.0))
    wm.assert_fact("holding", "stummel", "s2")
    wm.set("pos", "s2", value=(5.0, 1.0))
    wm.assert_fact("holding", "opponent", "s3")  # not a teammate: nobody knows what it does
    wm.set("pos", "s3", value=(0.0, 0.0))
    return wm


ROSTER = {"scout": "Scout", "stummel": "Stummel", "amparo": "Amparo"}


def test_a_sample_counts_as_dropped_only_when_the_teammate_holding_it_is_lost():
    wm = _world_model()
    assert dropped_samples(wm, _Belief(ROSTER, {"scout", "stummel", "amparo"})) == []
    assert dropped_samples(wm, _Belief(ROSTER, {"scout", "stummel"})) == [("s1", "amparo", (2.0, 3.0))]
    assert [d[0] for d in dropped_samples(wm, _Belief(ROSTER, {"scout"}))] == ["s1", "s2"]
    assert dropped_samples(wm, None) == [] and dropped_samples(None, _Belief(ROSTER, set())) == []


def test_a_verdict_on_a_dropped_sample_is_stale_so_its_candidate_is_looked_at_again():
    wm = _world_model()
    verdicts = {"scout_c1": "s1", "scout_c2": "s2", "scout_c3": "invalid"}
    assert stale_verdicts(verdicts, wm, _Belief(ROSTER, {"scout", "stummel"})) == {"scout_c1"}
    assert stale_verdicts(verdicts, wm, _Belief(ROSTER, set(ROSTER))) == set()


def _lost_amparo_held(wm: WorldModel, sample: str, where: tuple[float, float]) -> None:
    # alone, the world model is the skill's whole belief base: role(amparo) set, alive(amparo) not
    wm.set("role", "amparo", value="Amparo")
    wm.assert_fact("holding", "amparo", sample)
    wm.set("pos", sample, value=where)


def test_drive_to_dropped_sample_looks_from_the_far_side_of_the_crashed_holder(lunar_world, skill_run):
    wm = WorldModel("scout", clock=lunar_world.clock)
    sx, sy = (float(v) for v in lunar_world.objects["a"].position()[:2])
    _lost_amparo_held(wm, "a", (sx, sy))
    wm.set("pos", "amparo", value=(sx, sy - 0.8))  # the crashed robot stood south of the sample: it may hide it
    run = skill_run("DriveToDroppedSample", lunar_world, "scout", {"distance": 1.5}, world_model=wm, timeout=150.0)
    assert run.ok, (run.reason, run.trace[-4:])
    assert "looking at where a was last seen" in run.reason and "amparo" in run.reason
    x, y, _ = lunar_world.robots["scout"].pose
    assert 1.0 <= math.hypot(x - sx, y - sy) <= 2.0 and y > sy + 0.9  # north of it
    assert Fact("at", ("scout", "a")) not in run.facts  # it stands off; it is not at the sample


def test_drive_to_dropped_sample_stands_still_while_nothing_is_dropped(lunar_world, skill_run):
    wm = WorldModel("scout", clock=lunar_world.clock)
    wm.set("role", "amparo", value="Amparo")
    start = lunar_world.robots["scout"].pose
    run = skill_run("DriveToDroppedSample", lunar_world, "scout", {}, world_model=wm, timeout=5.0)
    assert run.status == "timeout" and "no teammate that held a sample is lost" in run.trace[-1]["feedback"]
    assert math.dist(lunar_world.robots["scout"].pose[:2], start[:2]) < 0.01
