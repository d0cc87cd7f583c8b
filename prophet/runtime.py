"""The runtime of a planning problem (IMPERA 7.1-7.2), inside each agent's engine.

A state's child may be a planning problem. Each agent that enters the state
gets a :class:`ProblemRuntime` for it, which says which plan the child runs:

* **WaitPlan** until a plan is shared, and again while the leader replans;
* the **generated plan** of the latest :class:`PlanShare`: every agent turns
  the shared single-agent plan into the same multi-agent plan with
  :func:`alica.prophet.tasks.create_tasks`, and the team switches to it through the
  normal allocation;
* the **AlternativePlan** when the planner failed, proved the goal
  unreachable, or found nothing within the problem's ``timeout``.

The **leader** is the lowest alive agent in the state; when it crashes the
next lowest takes over. The leader reads World (:func:`alica.prophet.world.read_world`),
runs the planner as an anytime search (:func:`alica.prophet.pipeline.plan_problem`),
a budget per tick (:class:`alica.prophet.plugin.Planning`), and shares:

* a ``searching`` share when it starts (the team runs the WaitPlan);
* the first plan as soon as it is found and validated;
* every UpdateTime a better plan, while the world is still the one it planned from;
* ``failed`` (AlternativePlan) or ``done`` (the goal holds already).

While robots outside the team hold objects of the goal (an opponent holds a
block), the leader plans for the rest of the goal (:func:`alica.prophet.world.reachable_goal`),
and the execution check leaves out the goal literals on objects held
outside. A plan for part of the goal runs to its end; then the leader plans
for what is left, or, with nothing left to plan for, the team waits in the
WaitPlan until the world changes.

When no plan exists with the robots in the team while the world names
robots outside it (teammates cut off by a partition, say), the leader waits
up to :data:`TEAM_WAIT` seconds for them, and plans again as soon as the
world changes, before the problem fails.

Every UpdateTime it repeats its latest share (for agents that come late) and,
while the team executes, checks that what is left of the plan still reaches
the goal from the current world (:func:`alica.prophet.world.remaining_fits`); twice
in a row not, it replans. A step that fails sends its agent back to the
WaitPlan and asks the leader to replan (:class:`~alica.prophet.board.ReplanRequest`); so does a
change of goal or world by the operator (``AgentEngine.set_problem``, read through the host).

With review on (``EngineConfig.review``, read through the host), the leader
does not share the first plan of a generation: it proposes it to the operator
(a ``proposal`` trace event) and waits for the operator's
:class:`~alica.engine.child.PlanDecision` (``AgentEngine.decide_plan``, read
through the host): accept, decline (plan again) or modify (reorder or drop
steps, pin tasks to robots; validated before it is shared). See
:mod:`alica.prophet.review`.

The runtime sees the engine only through the child-runtime seam
(:mod:`alica.engine.child`): the agent's :class:`~alica.engine.child.ChildHost`,
its :class:`~alica.engine.child.ChildSlot` and the
:class:`~alica.engine.child.RunningPlan` there. Progress in a generated plan
is read from the plan's :attr:`~alica.prophet.tasks.CreatedTasks.places`
(state -> task, step, kind), never from state names.

Where each part lives: this module keeps the child-runtime seam and what the
agent follows (the adopted share, the generated plan, a teammate's replan
request). The phases and their moves are in :mod:`alica.prophet.runtime_states`;
the leader's side in :mod:`alica.prophet.leader`, with its collaborators
:mod:`~alica.prophet.leadership` (who leads, generations),
:mod:`~alica.prophet.budget` (the search and its budget per tick),
:mod:`~alica.prophet.leader_search` (MAGiC as a search, positions),
:mod:`~alica.prophet.reviewing` (the operator's review),
:mod:`~alica.prophet.waiting` (waits for the world and the team),
:mod:`~alica.prophet.giving_up` (when failed steps fail the problem) and
:mod:`~alica.prophet.monitoring` (steps done, the team's progress, stalls).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace

from alica.engine.child import ChildHost, ChildSlot, ChildStatus, PlanKey, RunningPlan, key_text
from alica.errors import AlicaError, PlannerError
from alica.lang.fact import Fact
from alica.model import Condition, ConditionKind, Plan, PlanningProblem
from alica.prophet.board import PlanBoard, PlanShare, ReplanRequest, ShareStatus
from alica.prophet.budget import SearchBudget
from alica.prophet.durations import StepTimes
from alica.prophet.giving_up import GIVE_UP_AFTER, GIVE_UP_ANYWAY_AFTER
from alica.prophet.keep_off import bar
from alica.prophet.leader import Leader, planner_traits
from alica.prophet.leadership import is_leader, next_generation
from alica.prophet.magic.team import TeamMagic
from alica.prophet.monitoring import StepMarks, stalled
from alica.prophet.pipeline import plan_problem
from alica.prophet.planner import PlanStep
from alica.prophet.review import apply_pins
from alica.prophet.reviewing import Reviewing
from alica.prophet.runtime_states import LeaderPhase, child_phase
from alica.prophet.tasks import (
    CreatedTasks,
    create_tasks,
)
from alica.prophet.waiting import TEAM_WAIT
from alica.prophet.world import (
    PlanningWorld,
    goal_literals,
    read_world,
)

PLAN = ShareStatus.PLAN

__all__ = [
    "GIVE_UP_AFTER",
    "GIVE_UP_ANYWAY_AFTER",
    "TEAM_WAIT",
    "ProblemRuntime",
    "SearchBudget",
    "_stalled",
]

_stalled = stalled  # the name the tests of the runtime knew it by


class ProblemRuntime:
    """One agent's runtime of one planning problem child (see the module docstring).

    Args:
        host: what the agent's engine offers.
        slot: the child of the state that holds the planning problem.
        board: the agent's plan board.
        budget: the leader's search budget per tick.

    Raises:
        TypeError: the child is not a planning problem.
    """

    def __init__(
        self, host: ChildHost, slot: ChildSlot, board: PlanBoard, budget: SearchBudget, magic: TeamMagic | None = None
    ) -> None:
        element = slot.element
        if not isinstance(element, PlanningProblem):
            raise TypeError(f"pRoPhEt MAS runs planning problems, not {element!r}")
        self.host = host
        self.slot = slot
        self.board = board
        self.budget = budget
        self.magic = magic
        """The agent's MAGiC (parallel planning on): the leader searches with the teammates in the state."""
        self.model = element
        self.key: PlanKey = slot.key
        self.share: PlanShare | None = None
        self.created: CreatedTasks | None = None
        self.revision = 0
        self.reason = ""
        self.failed_generation = -1
        self.request: ReplanRequest | None = None
        self.marks = StepMarks(host.world, host.name)
        """The steps this agent finished in the generated plan (``step_done``, with their effects)."""
        self.times = StepTimes()
        """How long this agent's steps took, per skill (a temporal planner's durations)."""
        self.stepwise = (traits := planner_traits(element.planner)) is not None and traits.stepwise
        """Whether the problem's planner plans one step at a time (the operator changes goal and world, not planner)."""
        self.overrides = dict(host.override(self.model.name))
        reviewing = Reviewing(
            element.name,
            key_text(self.key),
            host.name,
            host.emit,
            lambda: host.decisions(element.name),
            lambda name, steps, world, robots: self._tasks_for(name, steps, world, robots, self.slot.entry_task),
            lambda: self.problem.goal.text,
        )
        self.leader = Leader(
            self, host, slot, board, budget, magic, reviewing, self.marks, stepwise=self.stepwise, plan=plan_problem
        )
        """What this agent does when it leads: search, share, review, wait, watch the plan, give up."""
        now = host.now()
        # a share received lately is current (the leader repeats it every UpdateTime); an older one is stale
        fresh = board.fresh(self.key, now, 2 * self.model.update_time)
        self.stale = board.shares.get(self.key) if fresh is None else None
        if fresh is not None:
            self._adopt(fresh, now)

    # -- what the slot runs --------------------------------------------------

    @property
    def problem(self) -> PlanningProblem:
        """The planning problem with the operator's goal and world, if set."""
        goal, world = self.overrides.get("goal"), self.overrides.get("world")
        if goal is None and world is None:
            return self.model
        return replace(
            self.model,
            goal=Condition(ConditionKind.POST, goal) if goal is not None else self.model.goal,
            world=Condition(ConditionKind.PRE, world) if world is not None else self.model.world,
        )

    def phase(self) -> str:
        """``wait``, ``plan``, ``alternative``, ``done`` or ``failed``."""
        share = self.share
        status, generation = (share.status, share.generation) if share is not None else (None, 0)
        return child_phase(status, generation, self.failed_generation, bool(self.model.alternative_plan)).value

    def leader_phase(self) -> LeaderPhase:
        """What this agent does for the problem now (:mod:`alica.prophet.runtime_states`)."""
        return self.leader.phase(self._is_leader())

    def wanted(self) -> tuple[Plan, ...]:
        """The plan the child runs now (none when done or failed)."""
        phase = self.phase()
        plans = self.host.library.plans
        if phase == "wait":
            return (plans[self.model.wait_plan],) if self.model.wait_plan else ()
        if phase == "plan":
            assert self.created is not None
            return (self.created.plan,)
        if phase == "alternative":
            return (plans[self.model.alternative_plan],)  # type: ignore[index]
        return ()

    def bindings(self) -> dict[str, object]:
        """While the team waits, the WaitPlan guards the finished part of the goal, when it declares ``guard``.

        ``guard`` is bound to the objects of the goal's positive literals that
        hold now, space-separated; each waiting agent guards the nearest one
        nobody guards yet (IMPERA 8.2: "the opponents often were not able to
        act, because the stack was blocked by an agent"). Nothing to bind in
        the other phases: the generated plan binds its own states' WaitPlans.
        """
        name = self.model.wait_plan
        if self.phase() != "wait" or not name:
            return {}
        wait_plan = self.host.library.plans.get(name)
        if wait_plan is None or all(v.name != "guard" for v in wait_plan.variables):
            return {}
        believed = {Fact(f.predicate, tuple(str(a) for a in f.args)) for f in self.host.world.facts()}
        try:
            goal = goal_literals(self.problem)
        except PlannerError:
            return {}
        finished = sorted({str(a) for positive, fact in goal if positive and fact in believed for a in fact.args})
        return {"guard": " ".join(finished)} if finished else {}

    def outcome(self) -> ChildStatus | None:
        """The child's status when it no longer depends on a running plan."""
        phase = self.phase()
        if phase == "done":
            return ChildStatus.SUCCESS
        if phase == "failed":
            return ChildStatus.FAILURE
        return None

    def is_generated(self, plan: Plan) -> bool:
        """Whether ``plan`` is the generated plan this runtime made."""
        return self.created is not None and plan is self.created.plan

    def may_retry_in(self, plan: Plan) -> bool:
        """A step of the generated plan is not retried: its failure goes up at once, and the problem replans."""
        return not self.is_generated(plan)

    def child_status(self, node: RunningPlan) -> ChildStatus:
        """The child's status from its running plan: the WaitPlan never ends it; the generated plan only with the goal."""
        plan = node.plan
        if self.is_generated(plan):
            if node.status is ChildStatus.SUCCESS and not self.host.holds(self.problem.goal.text, node):
                return ChildStatus.RUNNING  # the leader's check replans
            return node.status
        if plan.name == self.model.wait_plan and self.phase() == "wait":
            return ChildStatus.RUNNING
        return node.status

    # -- the tick --------------------------------------------------------------

    def update(self, now: float) -> None:
        """Take in shares, lead when this agent is the leader, repeat a pending replan request."""
        host = self.host
        if self.magic is not None:
            self.magic.tick(self.slot.members)  # search a share of the leader's, if one came
        latest = self.board.shares.get(self.key)
        if (
            latest is not None
            and latest is not self.share
            and latest is not self.stale
            and latest.generation > self.failed_generation
            and (self.share is None or latest.supersedes(self.share))
        ):
            self._adopt(latest, now)
        if self.key in self.board.behind:
            # a teammate leads with an older plan than the team's (it restarted): tell it the latest
            self.board.behind.discard(self.key)
            known = self.board.shares.get(self.key)
            if known is not None:
                host.publish(known)
        overrides = host.override(self.model.name)
        changed = overrides != self.overrides
        if changed:
            self.overrides = dict(overrides)
        leader = self.leader
        if self._is_leader():
            if changed:
                leader.replan(now, "the operator changed the planning problem")
            leader.lead(now)
        else:
            leader.hand_over()
            if self.request is not None and now >= leader.next_update:
                host.publish(self.request)
                leader.next_update = now + self.model.update_time
        if self.request is not None and self.share is not None and self.share.generation > self.request.generation:
            self.request = None
        self.marks.mark_done(self.slot.node, self.created)
        self.times.observe(self.slot.node, self.created, now)

    def stop(self) -> None:
        """The agent leaves the state: stop planning, forget the generated plan."""
        self.leader.search = None
        if self.created is not None:
            self.host.unregister_plan(self.created.plan.name)

    def _is_leader(self) -> bool:
        return is_leader(self.slot.members(), self.host.name)

    # -- shares ---------------------------------------------------------------

    def _adopt(self, share: PlanShare, now: float) -> None:
        host = self.host
        current = self.share
        if current is not None and current.same_plan(share):
            self.share = share  # the same plan, repeated by another leader
            return
        self.leader.supersede(share)
        created = None
        if share.status == PLAN:
            name = share.plan_name(self.model.name)
            try:
                created = bar(
                    apply_pins(
                        self._tasks_for(name, share.steps, share.world, share.robots, share.entry_task), share.pins
                    ),
                    share.barred,
                    share.robots,
                    host.roles,
                    share.world,
                )
            except (PlannerError, AlicaError) as exc:
                host.emit("warning", key=key_text(self.key), message=f"shared plan cannot be executed: {exc}")
                return
        if self.created is not None:
            host.unregister_plan(self.created.plan.name)
        self.created = created
        if created is not None:
            host.register_plan(created.plan, created.priorities(), created.pins())
            self.board.latest[self.key] = created
            if all(made.plan.name != created.plan.name for _, _, made in self.board.made):
                self.board.made.append((share.generation, share.version, created))
        self.share = share
        self.revision += 1
        self.reason = share.reason
        self.leader.check.reset()
        fields = {"generation": share.generation, "version": share.version, "leader": share.leader}
        if created is not None:
            fields.update(plan=created.plan.name, steps=len(share.steps), tasks=len(created.tasks), cost=share.cost)
        if share.reason:
            fields["reason"] = share.reason
        host.emit("problem", key=key_text(self.key), phase=self.phase(), **fields)

    def _tasks_for(
        self, name: str, steps: Sequence[PlanStep], world: Sequence[Fact], robots: Sequence[str], entry_task: str
    ) -> CreatedTasks:
        """Task creation for a plan of this problem (every agent makes the same tasks from the same share)."""
        return create_tasks(
            name,
            steps,
            self.host.library,
            world,
            robots,
            self.host.roleset,
            entry_task,
            standby=self.model.wait_plan,
            per_robot=self.stepwise,
        )

    def publish(self, share: PlanShare, now: float) -> None:
        self.board.receive(share, now)
        self.host.publish(share)
        if share is not self.share and (self.share is None or share.supersedes(self.share)):
            self._adopt(share, now)

    def next_generation(self) -> int:
        """One more than any generation this agent has seen for the problem."""
        return next_generation(
            self.board.generations.get(self.key, 0), self.failed_generation, self.share.generation if self.share else 0
        )

    def read_world(self, problem: PlanningProblem, facts: Iterable[Fact] | None = None) -> PlanningWorld:
        """The planning world from the world model (``facts``: its facts, when the caller read them already)."""
        world = self.host.world
        if facts is None:
            facts = world.facts()
        typed = {t: world.objects(t) for t in world.types()}
        return read_world(problem, self.host.library, facts, self.slot.members(), typed)

    # -- failures --------------------------------------------------------------

    def _running_step(self, node: RunningPlan) -> str:
        """The label of the step of the generated plan that ``node`` is at (``""``: none)."""
        created = self.created
        place = created.place(node.state) if created is not None and node.plan is created.plan else None
        if created is None or place is None or place.step >= len(created.tasks[place.task]):
            return ""
        return created.tasks[place.task][place.step].label

    def execution_failed(self, node: RunningPlan, now: float) -> None:
        """A step of the generated plan failed here: back to the WaitPlan; the leader replans."""
        share = self.share
        assert share is not None
        reason = f"a step of {node.plan.name} failed: {node.reason}"
        step = self._running_step(node)
        self.failed_generation = share.generation
        self.revision += 1
        self.host.emit("problem", key=key_text(self.key), phase="wait", generation=share.generation, reason=reason)
        if self._is_leader():
            self.leader.replan(now, reason, settle=True, failed=(self.host.name, step))
        else:
            self.request = ReplanRequest(self.key, share.generation, self.host.name, reason, step)
            self.host.publish(self.request)
            self.leader.next_update = now + self.model.update_time
