"""Task creation (IMPERA 7.3-7.4): Algorithms 2-3, role-task priorities, cardinalities, utility, the emitted plan."""

from __future__ import annotations

import os

import pytest
from hypothesis import given
from hypothesis import strategies as st

from alica.errors import PlannerError
from alica.io import load_library
from alica.prophet.planner import PlanStep
from alica.prophet.tasks import create_tasks, emit_yaml, generic_utility, parallelise, steps_of
from tests.conftest import PLANS

SUSSMAN = [
    ("on", ("c", "a")),
    ("ontable", ("a",)),
    ("ontable", ("b",)),
    ("clear", ("c",)),
    ("clear", ("b",)),
    ("handempty", ("r",)),
]
PLAN = [
    PlanStep("Unstack", ("r", "c", "a")),
    PlanStep("Putdown", ("r", "c")),
    PlanStep("Pickup", ("r", "b")),
    PlanStep("Stack", ("r", "b", "c")),
    PlanStep("Pickup", ("r", "a")),
    PlanStep("Stack", ("r", "a", "b")),
]


@pytest.fixture(scope="module")
def blocks():
    return load_library(PLANS / "blocksworld" / "mission.yaml")


def _created(blocks):
    roleset = (
        blocks.rolesets["BlocksWorld"] if "BlocksWorld" in blocks.rolesets else next(iter(blocks.rolesets.values()))
    )
    return create_tasks("StackBlocksPlan", PLAN, blocks, SUSSMAN, "r", roleset, "Default"), roleset


def test_algorithm_2_3_opens_a_task_when_a_new_robot_could_act(blocks):
    steps = steps_of(PLAN, blocks, "r")
    tasks = parallelise(steps, SUSSMAN, "r")
    assert [[s.label for s in t] for t in tasks] == [
        ["Unstack(c, a)", "Putdown(c)"],  # Putdown needs the block the first robot holds
        ["Pickup(b)", "Stack(b, c)"],  # a fresh robot can pick b up
        ["Pickup(a)", "Stack(a, b)"],  # a is clear once c is off it
    ]


def test_a_single_robot_chain_stays_one_task(blocks):
    plan = [PlanStep("Pickup", ("r", "b")), PlanStep("Stack", ("r", "b", "c"))]
    tasks = parallelise(steps_of(plan, blocks, "r"), SUSSMAN, "r")
    assert len(tasks) == 1


def test_a_robot_that_has_acted_is_no_longer_new(blocks):
    # r5 holds f at the start and stacks it on g; r1 takes f off again and puts it back. r5's initial
    # holding(r5, f) is used up: the second Stack(f, g) is not a new task for r5, it continues r1's task
    init = [("holding", ("r5", "f")), ("ontable", ("g",)), ("clear", ("g",)), ("handempty", ("r1",))]
    plan = [
        PlanStep("Stack", ("r5", "f", "g")),
        PlanStep("Unstack", ("r1", "f", "g")),
        PlanStep("Stack", ("r1", "f", "g")),
    ]
    created = create_tasks("P", plan, blocks, init, ("r1", "r5"), next(iter(blocks.rolesets.values())), "Default")
    assert [[s.label for s in t] for t in created.tasks] == [["Stack(f, g)"], ["Unstack(f, g)", "Stack(f, g)"]]
    # the first is pinned to the robot that holds f; the second to r1, whose initial empty hand can start it
    assert created.allowed == (("r5",), ("r1",))


def test_role_task_priorities_follow_eq_9(blocks):
    created, roleset = _created(blocks)
    n = len(created.tasks)
    for role in created.roleset.roles:
        p = roleset.priority(role.name, "Default")
        prio = role.priority_map
        for i, task in enumerate(created.task_defs):
            vetoed = p < 0 or any(
                roleset.priority(role.name, s.skill.entry_points[0].task) < 0 for s in created.tasks[i]
            )
            assert prio[task.name] == pytest.approx(-1.0 if vetoed else (1 - i / n) * p)


def test_cardinalities_and_utility(blocks):
    created, _ = _created(blocks)
    for ep in created.plan.entry_points:
        # every blocks skill plan takes exactly one robot: min 0 lets fewer robots take the tasks in turn
        assert (ep.min, ep.max, ep.success_required) == (0, 1, True)
        assert ep.success_required
    u = created.plan.utility
    n = 3
    wt, wp, ws = 1 / n, 1 / (n + 1) ** 2, 1 / (n + 1) ** 3
    wd = ws / (n + 1)  # the proximity summand: below one agent's similarity
    total = wt + wp + ws + wd
    assert u.weight_sum == pytest.approx(1.0)
    assert u.priority_weight == pytest.approx(wp / total) and u.similarity_weight == pytest.approx(ws / total)
    assert u.summands[0].weight == pytest.approx(wt / total) and u.threshold == pytest.approx(ws / total)
    assert u.summands[1].name == "Proximity" and u.summands[1].weight == pytest.approx(wd / total)
    assert generic_utility(1).weight_sum == pytest.approx(1.0)
    assert [s.name for s in generic_utility(1).summands] == ["Coverage"]  # no work sites, no proximity


def test_steps_wait_for_their_preconditions(blocks):
    created, _ = _created(blocks)
    waits = {t.source: t.condition.text for t in created.plan.transitions if "_Wait" in t.source}
    # ... and for the earlier steps of other tasks on the same blocks (c put down, c off a, b on c)
    assert waits["T1_Wait1"] == "holding(self, b) and clear(c) and step_done(StackBlocksPlan_s1)"
    assert waits["T2_Wait0"] == "clear(a) and ontable(a) and handempty(self) and step_done(StackBlocksPlan_s0)"
    assert waits["T2_Wait1"] == "holding(self, a) and clear(b) and step_done(StackBlocksPlan_s3)"
    assert waits["T0_Wait0"] == "on(c, a) and clear(c) and handempty(self)"


def test_emitted_plan_is_a_valid_plan_file(blocks, tmp_path):
    created, _ = _created(blocks)
    skills = os.path.relpath(PLANS / "blocksworld" / "skills.yaml", tmp_path)
    tasks = os.path.relpath(PLANS / "tasks.yaml", tmp_path)
    text = emit_yaml(created, imports=[tasks, skills])
    assert text.startswith("# Generated by pRoPhEt MAS: T0: Unstack(c, a), Putdown(c); T1:")
    path = tmp_path / "generated.yaml"
    path.write_text(text, encoding="utf-8")
    library = load_library(path)
    assert library.plans["StackBlocksPlan"] == created.plan


def test_unknown_or_malformed_steps_are_refused(blocks):
    with pytest.raises(PlannerError, match="names no skill plan"):
        steps_of([PlanStep("Fly", ("r",))], blocks, "r")
    with pytest.raises(PlannerError, match="takes 2 parameters"):
        steps_of([PlanStep("Pickup", ("r",))], blocks, "r")
    with pytest.raises(PlannerError, match="empty plan"):
        create_tasks("P", [], blocks, SUSSMAN, "r", next(iter(blocks.rolesets.values())), "Default")


def test_the_execution_check_runs_a_free_task_with_a_robot_that_could_start_it(blocks):
    from alica.prophet.world import TaskProgress, remaining_fits

    # the planner gave Pickup(b) to r1, which held c at the start (it put c down in T0); r2 had an empty hand
    init = [
        ("holding", ("r1", "c")),
        ("handempty", ("r2",)),
        ("ontable", ("b",)),
        ("clear", ("b",)),
        ("ontable", ("a",)),
        ("clear", ("a",)),
    ]
    plan = [PlanStep("Putdown", ("r1", "c")), PlanStep("Pickup", ("r1", "b"))]
    tasks = [[s] for s in steps_of(plan, blocks, ("r1", "r2"))]
    now = [
        ("ontable", ("c",)),
        ("clear", ("c",)),
        ("handempty", ("r1",)),
        ("handempty", ("r2",)),
        ("ontable", ("b",)),
        ("clear", ("b",)),
        ("ontable", ("a",)),
        ("clear", ("a",)),
    ]
    progress = [TaskProgress(None, 1, done=True), TaskProgress(None, 0)]
    goal = [(True, ("holding", ("~T1", "b")))]
    assert remaining_fits(tasks, progress, now, init, goal, ("r1", "r2")) is None
    # without the team's robots no robot as it was at the start could start T1: r1 does, after its put-down
    assert remaining_fits(tasks, progress, now, init, [(True, ("holding", ("r1", "b")))]) is None


def test_a_free_task_no_robot_could_start_at_the_start_is_run_by_its_planned_robot_after_its_earlier_steps(blocks):
    from alica.prophet.world import TaskProgress, remaining_fits

    # r1 puts c down (T0, running now), then picks b up (T1, free); r2 holds e all along (seed 18 of the demo:
    # a stand-in with r1's start facts, hand full, made the check replan eleven times)
    init = [("holding", ("r1", "c")), ("holding", ("r2", "e")), ("ontable", ("b",)), ("clear", ("b",))]
    plan = [PlanStep("Putdown", ("r1", "c")), PlanStep("Pickup", ("r1", "b"))]
    tasks = [[s] for s in steps_of(plan, blocks, ("r1", "r2"))]
    progress = [TaskProgress("r1", 0, running=True), TaskProgress(None, 0)]
    goal = [(True, ("ontable", ("c",))), (True, ("holding", ("r1", "b")))]
    assert remaining_fits(tasks, progress, init, init, goal, ("r1", "r2")) is None
    # b taken meanwhile: the step cannot run, whoever does it
    taken = [f for f in init if f[1] != ("b",)]
    assert "Pickup(b) of r1 cannot run" in remaining_fits(tasks, progress, taken, init, goal, ("r1", "r2"))


def test_the_part_of_the_goal_tied_to_a_held_block_is_left_out():
    from alica.prophet.world import reachable_goal

    # the tower b f d g, and e alone; an opponent holds f
    tower = [
        (True, ("ontable", ("b",))),
        (True, ("on", ("f", "b"))),
        (True, ("on", ("d", "f"))),
        (True, ("on", ("g", "d"))),
    ]
    alone = [(True, ("ontable", ("e",)))]
    assert reachable_goal(tower + alone, ["f"]) == tuple(alone)
    assert reachable_goal(tower + alone, ["e"]) == tuple(tower)
    assert reachable_goal(tower + alone, []) == tuple(tower + alone)
    # the order of the literals does not matter
    assert reachable_goal(list(reversed(tower)) + alone, ["g"]) == tuple(alone)


def test_a_fixed_place_in_the_goal_ties_nothing():
    from alica.prophet.world import reachable_goal

    # a lunar goal: a robot outside the team holds a; b still goes to the collection point g
    goal = [(True, ("at", ("a", "g"))), (True, ("at", ("b", "g")))]
    assert reachable_goal(goal, ["a"], fixed=["g"]) == (goal[1],)
    assert reachable_goal(goal, ["a"]) == ()  # without g declared fixed, g ties b to a


@given(
    st.lists(
        st.tuples(st.sampled_from(["on", "ontable"]), st.lists(st.sampled_from("abcdefg"), min_size=1, max_size=2)),
        max_size=8,
    ),
    st.sets(st.sampled_from("abcdefg"), max_size=3),
)
def test_the_kept_part_of_the_goal_shares_no_object_with_the_left_out_part(raw, outside):
    from alica.prophet.world import reachable_goal

    goal = [(True, (name, tuple(args))) for name, args in raw]
    kept = reachable_goal(goal, outside)
    dropped = [literal for literal in goal if literal not in kept]
    kept_names = {a for _, (_, args) in kept for a in args}
    assert not kept_names & set(outside)
    assert not kept_names & {a for _, (_, args) in dropped for a in args}
    assert [literal for literal in goal if literal in kept] == list(kept)  # in the goal's order


def test_the_generated_plan_says_where_each_state_is_in_the_tasks(blocks):
    from alica.prophet.tasks import STANDBY, Place, StepKind

    roleset = next(iter(blocks.rolesets.values()))
    created = create_tasks("Gen", PLAN, blocks, SUSSMAN, "r", roleset, "Default", standby="DriveToFreePosition")
    plan = created.plan
    assert created.place(STANDBY) is None and created.place(None) is None
    assert set(created.places) == {s.name for s in plan.states} - {STANDBY}
    # follow each task's chain by its transitions: the places come from the plan's making, not from the names
    for i, (ep, task) in enumerate(zip(created.task_entry_points, created.tasks, strict=True)):
        state = ep.state
        for k in range(len(task)):
            assert created.place(state) == Place(i, k, StepKind.WAIT)
            (start,) = plan.out_transitions(state)
            assert created.place(start.target) == Place(i, k, StepKind.RUN)
            ends = {t.condition.text: t.target for t in plan.out_transitions(start.target)}
            assert created.place(ends["failed"]) == Place(i, 0, StepKind.FAILED)
            state = ends["succeeded"]
        assert created.place(state) == Place(i, len(task), StepKind.DONE)
    # the priorities the engine's allocation gets: each role's priorities of the generated tasks only
    tasks = {ep.task for ep in plan.entry_points}
    for role, priorities in created.priorities().items():
        assert {p.task for p in priorities} == tasks, role


def test_waiting_agents_run_the_wait_plan_near_their_next_step_and_guard_what_they_finished(blocks):
    from alica.prophet.tasks import STANDBY, StepKind

    roleset = next(iter(blocks.rolesets.values()))
    created = create_tasks("Gen", PLAN, blocks, SUSSMAN, "r", roleset, "Default", standby="DriveToFreePosition")
    plan = created.plan
    bound = {}
    for state in plan.states:
        place = created.place(state.name)
        if place is None or place.kind in (StepKind.RUN, StepKind.FAILED):
            continue
        ((ref,),) = (state.children,)
        assert ref.name == "DriveToFreePosition"
        bound[state.name] = {b.variable: b.value for b in ref.bindings}
    waits = {
        s.name: created.tasks[created.place(s.name).task][created.place(s.name).step].label
        for s in plan.states
        if (p := created.place(s.name)) is not None and p.kind is StepKind.WAIT
    }
    # the work site of each step: the block it takes, or the block it stacks on; none for Putdown
    sites = {"Unstack(c, a)": "c", "Putdown(c)": None, "Pickup(b)": "b", "Stack(b, c)": "c", "Pickup(a)": "a"}
    sites["Stack(a, b)"] = "b"
    for state, label in waits.items():
        assert bound[state] == ({"near": sites[label]} if sites[label] else {}), (state, label)
    # the last task ends with Stack(a, b): nothing touches a or b after it, the robot guards a
    done = {s.name: bound[s.name] for s in plan.states if (p := created.place(s.name)) and p.kind is StepKind.DONE}
    last = created.place(plan.entry_points[len(created.tasks) - 1].state).task
    assert done[f"T{last}_Done"] == {"guard": "a"}
    # Putdown(c) is followed by Stack(b, c): its robot guards c, so that opponents leave it for that step
    first = [s.label for s in created.tasks[0]]
    assert first == ["Unstack(c, a)", "Putdown(c)"] and done["T0_Done"] == {"guard": "c"}
    # every block is touched by the plan: the agents standing by have nothing to guard
    (standby,) = plan.state(STANDBY).children
    assert standby.bindings == ()


def test_without_the_variables_the_wait_plan_runs_only_for_standing_by(blocks):
    from alica.prophet.tasks import STANDBY, build_plan

    tasks = parallelise(steps_of(PLAN, blocks, "r"), SUSSMAN, "r")
    plan, _, places = build_plan("Gen", tasks, standby="DriveToFreePosition", standby_variables=())
    with_children = {s.name for s in plan.states if s.children}
    assert with_children == {STANDBY} | {name for name, p in places.items() if p.kind.value == "run"}


def test_agents_standing_by_guard_what_no_step_touches(blocks):
    from alica.prophet.tasks import STANDBY

    roleset = next(iter(blocks.rolesets.values()))
    plan = [PlanStep("Unstack", ("r", "c", "a")), PlanStep("Putdown", ("r", "c"))]  # b stays where it is
    created = create_tasks("Gen", plan, blocks, SUSSMAN, "r", roleset, "Default", standby="DriveToFreePosition")
    (standby,) = created.plan.state(STANDBY).children
    assert {b.variable: b.value for b in standby.bindings} == {"guard": "b"}
    # the robot never counts as an object to guard
    assert "r" not in {b.value for b in standby.bindings}


def _nearest_first(blocks, places, robots=("r1", "r2", "r3")):
    """The generated Sussman plan allocated to three robots placed at ``places`` (blocks and robots)."""
    from alica.allocation import AllocationProblem, allocate
    from alica.lang import FactBase, evaluate

    created, roleset = _created(blocks)
    role = next(r.name for r in created.roleset.roles if roleset.priority(r.name, "Default") > 0)
    belief = FactBase(values={("pos", name): xy for name, xy in places.items()})

    def summand(plan, term, agent, ep):
        return evaluate(term.expression, belief, {"self": agent, "task": ep.task, "entry": ep.name})

    problem = AllocationProblem(robots, dict.fromkeys(robots, role), created.roleset, (created.plan,), summand=summand)
    result = allocate(problem)
    assert result.assignment is not None
    return {agent: ep.rsplit("_", 1)[1] for agent, ep in result.assignment.entries}


def test_a_task_goes_to_the_robot_nearest_where_it_starts(blocks):
    # T0 starts at c (Unstack(c, a)), T1 at b (Pickup(b)), T2 at a (Pickup(a))
    blocks_at = {"c": (0.0, 0.0), "a": (0.0, 0.0), "b": (6.0, 0.0)}
    near = _nearest_first(blocks, {**blocks_at, "r1": (6.5, 0.0), "r2": (0.5, 0.0), "r3": (-0.5, 0.2)})
    assert near["r1"] == "T1"  # the robot beside b picks b up
    swapped = _nearest_first(blocks, {**blocks_at, "r1": (0.5, 0.0), "r2": (6.5, 0.0), "r3": (-0.5, 0.2)})
    assert swapped["r2"] == "T1"
    # positions unknown: every closeness is 0, and the tie rule gives the tasks in agent order
    assert _nearest_first(blocks, {}) == {"r1": "T0", "r2": "T1", "r3": "T2"}
    # proximity never puts a later task first: a lone robot beside b still takes T0, which T1 and T2 wait for
    assert _nearest_first(blocks, {**blocks_at, "r1": (6.5, 0.0)}, robots=("r1",)) == {"r1": "T0"}


_XY = st.tuples(st.floats(-3, 3), st.floats(-3, 3))


@given(
    places=st.fixed_dictionaries(dict.fromkeys(("a", "b", "c", "r1", "r2", "r3"), _XY)),
    team=st.integers(1, 3),
)
def test_proximity_only_decides_who_takes_which_task_never_which_tasks(blocks, places, team):
    import itertools
    import math

    robots = ("r1", "r2", "r3")[:team]
    chosen = _nearest_first(blocks, places, robots)
    # the same tasks as without positions: the earlier tasks first, one robot each
    assert sorted(chosen.values()) == sorted(_nearest_first(blocks, {}, robots).values())
    # and among the robots, the way of giving them out with the most closeness to where they start
    sites = {"T0": "c", "T1": "b", "T2": "a"}

    def closeness(assignment):
        return sum(1 / (1 + math.dist(places[r], places[sites[t]])) for r, t in assignment.items())

    best = max(closeness(dict(zip(robots, p, strict=True))) for p in itertools.permutations(chosen.values()))
    assert closeness(chosen) >= best - 1e-6
