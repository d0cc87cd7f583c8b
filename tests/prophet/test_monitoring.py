"""Watching a generated plan run (alica.prophet.monitoring), with stand-ins for the plan and the world model."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from alica.lang.fact import Fact
from alica.prophet.monitoring import PlanCheck, StepMarks, executing, task_progress
from alica.prophet.tasks import STEP_DONE, Place, Step, StepKind
from alica.prophet.world import TaskProgress


class World:
    """The world model as the marks see it."""

    def __init__(self, *facts: Fact) -> None:
        self.facts = set(facts)
        self.writes: list[tuple[bool, Fact]] = []

    def holds(self, predicate: str, *args: object) -> bool:
        return Fact(predicate, tuple(str(a) for a in args)) in self.facts

    def assert_fact(self, predicate: str, *args: object) -> None:
        fact = Fact(predicate, tuple(str(a) for a in args))
        self.facts.add(fact)
        self.writes.append((True, fact))

    def retract_fact(self, predicate: str, *args: object) -> None:
        fact = Fact(predicate, tuple(str(a) for a in args))
        self.facts.discard(fact)
        self.writes.append((False, fact))


def _step(index: int, effect: tuple[tuple[bool, Fact], ...]) -> Step:
    return Step(index, SimpleNamespace(name="Pickup"), (), (), effect, robot="r1")  # type: ignore[arg-type]


PICK = _step(0, ((True, Fact("holding", ("r1", "a"))), (False, Fact("at", ("r1", "a")))))
DROP = _step(1, ((True, Fact("on", ("a", "b"))), (False, Fact("holding", ("r1", "a")))))
PLACES = {
    "Pick": Place(0, 0, StepKind.RUN),
    "Drop": Place(0, 1, StepKind.RUN),
    "Wait": Place(0, 1, StepKind.WAIT),
    "End": Place(0, 2, StepKind.DONE),
}


def _created() -> Any:
    return SimpleNamespace(
        plan=SimpleNamespace(name="G1"),
        tasks=((PICK, DROP),),
        task_entry_points=(SimpleNamespace(name="G1_T0"),),
        place=PLACES.get,
    )


def _node(created: Any, state: str, **believed: tuple[str, str]) -> Any:
    return SimpleNamespace(plan=created.plan, ep="G1_T0", state=state, believed=believed, succeeded={})


def test_a_finished_step_is_marked_done_with_its_effect_for_this_agent():
    world, created = World(Fact("at", ("r2", "a"))), _created()
    marks = StepMarks(world, "r2")  # the plan named r1; this agent is r2
    marks.mark_done(_node(created, "Wait"), created)
    assert world.holds(STEP_DONE, "G1_s0") and world.holds("holding", "r2", "a") and not world.holds("at", "r2", "a")
    writes = len(world.writes)
    marks.mark_done(_node(created, "Wait"), created)  # once only
    assert len(world.writes) == writes


def test_a_step_under_way_whose_effect_holds_writes_its_whole_effect_once():
    world, created = World(Fact("on", ("a", "b")), Fact("holding", ("r2", "a"))), _created()
    marks = StepMarks(world, "r2")
    marks.mark_done(_node(created, "Drop"), created)
    assert not world.holds("holding", "r2", "a") and marks.effected == {"G1_s1"}
    # the step it marked done (Pick) wrote its effect too; Drop, once over, is not written again
    before = len(world.writes)
    marks.mark_done(_node(created, "End"), created)
    assert world.writes[before:] == [(True, Fact(STEP_DONE, ("G1_s1",)))]


def test_nothing_is_marked_outside_the_generated_plan():
    world, created = World(), _created()
    marks = StepMarks(world, "r1")
    marks.mark_done(None, created)
    marks.mark_done(SimpleNamespace(plan=object(), ep="x", state="Wait"), created)
    assert not world.writes


def test_executing_and_task_progress_read_the_believed_states():
    created = _created()
    waiting = _node(created, "Wait", r2=("G1_T0", "Wait"))
    running = _node(created, "Pick", r1=("G1_T0", "Pick"), r2=("G1_T0", "Wait"))
    assert not executing(waiting, created)
    assert executing(running, created)
    assert not executing(None, created)
    assert task_progress(running, created) == [TaskProgress("r1", 0, running=True)]
    assert task_progress(_node(created, "Wait"), created) == [TaskProgress(None, 0)]
    done = _node(created, "End")
    done.succeeded["G1_T0"] = True
    assert task_progress(done, created) == [TaskProgress(None, 2, done=True)]


def test_the_plan_is_replanned_only_after_two_failed_checks_in_a_row():
    check = PlanCheck()
    assert check.replan_reason("on(a, b) no longer holds") is None
    assert check.replan_reason(None) is None  # a check that passes forgets the failed one
    assert check.replan_reason("on(a, b) no longer holds") is None
    assert (
        check.replan_reason("on(a, b) no longer holds") == "the world changed under the plan: on(a, b) no longer holds"
    )
    check.reset()
    assert check.replan_reason("task T1 has nobody") is None
    assert check.replan_reason("task T1 has nobody") == "the plan is stuck: task T1 has nobody"
