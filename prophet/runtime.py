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
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace

from alica.engine.child import ChildHost, ChildSlot, ChildStatus, PlanKey, RunningPlan, key_text
from alica.errors import AlicaError, PlannerError
from alica.lang.fact import Fact
from alica.model import Condition, ConditionKind, Plan, PlanningProblem
from alica.prophet.board import PlanBoard, PlanShare, ReplanRequest, ShareStatus
from alica.prophet.budget import LeaderSearch, SearchBudget, advance
from alica.prophet.giving_up import GIVE_UP_AFTER, GIVE_UP_ANYWAY_AFTER, GiveUp
from alica.prophet.leader_search import magic_events, positions
from alica.prophet.leadership import is_leader, next_generation
from alica.prophet.magic.team import TeamMagic
from alica.prophet.monitoring import StepMarks, executing, stalled, task_progress
from alica.prophet.pipeline import ValidPlan, plan_problem
from alica.prophet.planner import Done, PlanStatus, PlanStep
from alica.prophet.planners import planner_class
from alica.prophet.problem import predicate_types
from alica.prophet.review import apply_pins
from alica.prophet.reviewing import Pins, Reviewing
from alica.prophet.runtime_states import LeaderPhase, child_phase, leader_phase
from alica.prophet.tasks import (
    STEP_DONE,
    CreatedTasks,
    Literal,
    conjunction,
    create_tasks,
    holds,
)
from alica.prophet.waiting import TEAM_WAIT, Waiting
from alica.prophet.world import (
    PlanningWorld,
    goal_literals,
    reachable_goal,
    read_world,
    remaining_fits,
)

SEARCHING, PLAN, FAILED, DONE = ShareStatus.SEARCHING, ShareStatus.PLAN, ShareStatus.FAILED, ShareStatus.DONE

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
        self.search: LeaderSearch | None = None
        self.next_update = -1.0
        self.invalid_once = False
        self.request: ReplanRequest | None = None
        self.marks = StepMarks(host.world, host.name)
        """The steps this agent finished in the generated plan (``step_done``, with their effects)."""
        self.pending: tuple[float, str] | None = None
        self.waiting = Waiting()
        """What the leader waits for: the world to change, the robots outside the team to come back."""
        self.predicates: dict[str, tuple[str, ...]] | None = None
        self.give_up = GiveUp()
        """The leader's count of failed steps: when to stop replanning."""
        self.stepwise = _planner_trait(element.planner, "stepwise")
        """Whether the problem's planner plans one step at a time (the operator changes goal and world, not planner)."""
        self.step_over: float | None = None
        """When a stepwise plan's step was seen over while its effects had not all arrived yet."""
        self.overrides = dict(host.override(self.model.name))
        self.reviewing = Reviewing(
            element.name,
            key_text(self.key),
            host.name,
            host.emit,
            lambda: host.decisions(element.name),
            lambda name, steps, world, robots: self._tasks_for(name, steps, world, robots, self.slot.entry_task),
            lambda: self.problem.goal.text,
        )
        """The operator's review (review on): the plan proposed, and the decisions read."""
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
        return self._leader_phase(self._is_leader())

    def _leader_phase(self, leader: bool) -> LeaderPhase:
        share = self.share
        return leader_phase(
            leader=leader,
            proposal=self.reviewing.proposal is not None,
            pending=self.pending is not None,
            search=self.search is not None,
            blocked=self.waiting.blocked is not None,
            share=share.status if share is not None else None,
            share_failed=share is not None and share.generation <= self.failed_generation,
        )

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
        if self._is_leader():
            if changed:
                self._replan(now, "the operator changed the planning problem")
            self._lead(now)
        else:
            if self.search is not None or self.reviewing.proposal is not None:
                self.search = None
                self.reviewing.drop()
                host.emit("planner", key=key_text(self.key), what="handed over")
            self.reviewing.catch_up()  # whoever leads decides on its own proposals
            if self.request is not None and now >= self.next_update:
                host.publish(self.request)
                self.next_update = now + self.model.update_time
        if self.request is not None and self.share is not None and self.share.generation > self.request.generation:
            self.request = None
        self.marks.mark_done(self.slot.node, self.created)

    def stop(self) -> None:
        """The agent leaves the state: stop planning, forget the generated plan."""
        self.search = None
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
        search = self.search
        if search is not None and share.leader != host.name and share.generation >= search.generation:
            # another leader is ahead (this agent restarted, or a partition healed): its plan wins
            self.search = None
            self.pending = None
            host.emit("planner", key=key_text(self.key), what="superseded", generation=search.generation)
        proposal = self.reviewing.proposal
        if proposal is not None and share.leader != host.name and share.generation >= proposal.search.generation:
            self.reviewing.drop()  # another leader is ahead: its plan wins over the one waiting for the operator
            host.emit("planner", key=key_text(self.key), what="superseded", generation=proposal.search.generation)
        created = None
        if share.status == PLAN:
            name = share.plan_name(self.model.name)
            try:
                created = apply_pins(
                    self._tasks_for(name, share.steps, share.world, share.robots, share.entry_task), share.pins
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
        self.invalid_once = False
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

    def _publish_failure(self, now: float, generation: int, reason: str) -> None:
        """Tell the team that planning ``generation`` failed: it runs the AlternativePlan."""
        share = PlanShare(
            self.key, generation, 1, self.host.name, FAILED, entry_task=self.slot.entry_task, reason=reason
        )
        self._publish(share, now)

    def _publish(self, share: PlanShare, now: float) -> None:
        self.board.receive(share, now)
        self.host.publish(share)
        if share is not self.share and (self.share is None or share.supersedes(self.share)):
            self._adopt(share, now)

    # -- failures --------------------------------------------------------------

    def execution_failed(self, node: RunningPlan, now: float) -> None:
        """A step of the generated plan failed here: back to the WaitPlan; the leader replans."""
        share = self.share
        assert share is not None
        reason = f"a step of {node.plan.name} failed: {node.reason}"
        self.failed_generation = share.generation
        self.revision += 1
        self.host.emit("problem", key=key_text(self.key), phase="wait", generation=share.generation, reason=reason)
        if self._is_leader():
            self._replan(now, reason, settle=True)
        else:
            self.request = ReplanRequest(self.key, share.generation, self.host.name, reason)
            self.host.publish(self.request)
            self.next_update = now + self.model.update_time

    # -- the leader ----------------------------------------------------------

    def _lead(self, now: float) -> None:
        share = self.share
        requests = [r for r in self.board.take_requests(self.key) if share is None or r.generation >= share.generation]
        if requests and share is not None and share.status == PLAN:
            self._replan(now, f"{requests[0].sender}: {requests[0].reason}", settle=True)
            return
        phase = self._leader_phase(True)
        if phase is LeaderPhase.REVIEWING:
            self.reviewing.read(now, self._share_plan, self._replan)
        elif phase is LeaderPhase.SETTLING:
            assert self.pending is not None
            if now + 1e-9 < self.pending[0]:
                return
            reason = self.pending[1]
            self.pending = None
            self._start_search(now, reason, self.share.generation if self.share is not None else None)
        elif phase is LeaderPhase.SEARCHING:
            self._step_search(now)
        elif phase is LeaderPhase.WAITING:
            if now >= self.next_update and self.waiting.changed(self._read_world(self.problem).facts):
                self.waiting.unblock()
                self._start_search(now, "the world changed while planning was blocked")
            elif self.waiting.team_wait_over(now):
                self.waiting.unblock()
                self._start_search(now, f"waited {TEAM_WAIT:g} s for the robots outside the team")
        elif phase is LeaderPhase.STARTING:
            self._start_search(now, "start" if share is None else f"taking over from {share.leader}")
        if now < self.next_update:
            return
        self.next_update = now + self.model.update_time
        share = self.share
        if share is None:
            return
        if self.search is None and share.status == PLAN:
            self._check_execution(now, share)
        if self.share is share:
            me = self.host.name
            self._publish(share if share.leader == me else replace(share, leader=me), now)

    def _replan(self, now: float, reason: str, settle: bool = False) -> None:
        """Plan again; with ``settle`` the team first runs the WaitPlan for an UpdateTime (after a failed step).

        A failed step (``settle``) that failed :data:`GIVE_UP_AFTER` times for the same reason in the
        same world, or :data:`GIVE_UP_ANYWAY_AFTER` times with no step carried out in between, fails
        the problem instead: the team runs the AlternativePlan.
        """
        self.host.counters["replans"] += 1
        self.host.emit("replan", key=key_text(self.key), reason=reason)
        self.search = None
        if not settle:
            self._start_search(now, reason)
            return
        generation = self._next_generation()
        world = frozenset(self._read_world(self.problem).facts)
        done = sum(1 for fact in self.host.world.facts() if fact.predicate == STEP_DONE)
        message = self.give_up.step_failed(reason.split(": ", 1)[-1], world, done)
        if message is not None:
            self.host.emit("planner", key=key_text(self.key), what="failed", reason=message)
            self._publish_failure(now, generation, message)
            return
        self.pending = (now + self.model.update_time, reason)
        self._publish(
            PlanShare(
                self.key, generation, 0, self.host.name, SEARCHING, entry_task=self.slot.entry_task, reason=reason
            ),
            now,
        )

    def _next_generation(self) -> int:
        """One more than any generation this agent has seen for the problem."""
        return next_generation(
            self.board.generations.get(self.key, 0), self.failed_generation, self.share.generation if self.share else 0
        )

    def _start_search(self, now: float, reason: str, generation: int | None = None) -> None:
        host = self.host
        self.reviewing.drop()
        if generation is None:
            generation = self._next_generation()
        me = host.name
        task = self.slot.entry_task
        problem = self.problem
        try:
            world = self._read_world(problem)
            goal = goal_literals(problem)
            if holds(goal, set(world.facts)):
                self._publish(
                    PlanShare(
                        self.key,
                        generation,
                        0,
                        me,
                        DONE,
                        world=world.facts,
                        robots=world.robots,
                        entry_task=task,
                        reason="the goal holds",
                    ),
                    now,
                )
                return
            partial = reachable_goal(goal, world.outside, world.fixed)
            if partial != goal:
                if not partial or holds(partial, set(world.facts)):
                    self._wait_for_world(now, world, generation, _rest_holds(world))
                    self.next_update = now + self.model.update_time
                    return
                problem = replace(problem, goal=Condition(ConditionKind.POST, conjunction(partial)))
            options: dict[str, object] = {"progress_every": 100} if problem.planner == "builtin" else {}
            if _planner_trait(problem.planner, "reads_positions"):
                options.update(positions=positions(host.world.values()), seed=generation)
            planning = plan_problem(problem, host.library, world, options=options)
            team = [a for a in self.slot.members() if a != me]
            if self.magic is not None and problem.planner == "builtin" and team:
                events = magic_events(
                    planning,
                    generation,
                    self.magic,
                    me=me,
                    members=self.slot.members,
                    emit=host.emit,
                    key=key_text(self.key),
                    seconds=self.model.timeout,
                    clock=host.now,
                )
            else:
                events = planning.search(anytime=True)
        except (PlannerError, AlicaError) as exc:
            host.emit("planner", key=key_text(self.key), what="failed", reason=str(exc))
            self._publish(PlanShare(self.key, generation, 0, me, FAILED, entry_task=task, reason=str(exc)), now)
            return
        self.search = LeaderSearch(
            generation, world, events, now, goal=partial if partial != goal else (), planning=planning
        )
        extra = {"goal": conjunction(partial), "outside": list(world.outside)} if partial != goal else {}
        host.emit(
            "planner",
            key=key_text(self.key),
            what="started",
            generation=generation,
            reason=reason,
            planner=problem.planner,
            facts=len(world.facts),
            **extra,
        )
        self._publish(
            PlanShare(
                self.key,
                generation,
                0,
                me,
                SEARCHING,
                world=world.facts,
                robots=world.robots,
                entry_task=task,
                reason=reason,
            ),
            now,
        )
        self.next_update = now + self.model.update_time

    def _wait_for_world(self, now: float, world: PlanningWorld, generation: int, reason: str) -> None:
        """Nothing the team can plan for now: it waits in the WaitPlan, and the leader plans again when the world changes."""
        self.host.emit("planner", key=key_text(self.key), what="waiting", reason=reason)
        self.waiting.block(world.facts)
        if self.share is None or self.share.status != SEARCHING:
            self._publish(
                PlanShare(
                    self.key,
                    generation,
                    0,
                    self.host.name,
                    SEARCHING,
                    world=world.facts,
                    robots=world.robots,
                    entry_task=self.slot.entry_task,
                    reason=reason,
                ),
                now,
            )

    def _read_world(self, problem: PlanningProblem, facts: Iterable[Fact] | None = None) -> PlanningWorld:
        """The planning world from the world model (``facts``: its facts, when the caller read them already)."""
        world = self.host.world
        if facts is None:
            facts = world.facts()
        typed = {t: world.objects(t) for t in world.types()}
        return read_world(problem, self.host.library, facts, self.slot.members(), typed)

    def _step_search(self, now: float) -> None:
        search = self.search
        assert search is not None
        try:
            finished = advance(
                search,
                self.budget,
                lambda message: self.host.emit("warning", key=key_text(self.key), message=message),
            )
        except (PlannerError, AlicaError) as exc:  # grounding runs inside the search: a domain it cannot read
            self.search = None
            self.host.emit("planner", key=key_text(self.key), what="failed", reason=str(exc))
            failed = PlanShare(
                self.key, search.generation, 0, self.host.name, FAILED, entry_task=self.slot.entry_task, reason=str(exc)
            )
            self._publish(failed, now)
            return
        self._after_search(now, search, finished)

    def _after_search(self, now: float, search: LeaderSearch, finished: Done | None) -> None:
        """Share what the search found; end it when it is done."""
        best = search.best
        if best is not None and search.shared_cost is None:
            if self.host.review:
                self.search = None
                self.waiting.end_team_wait()
                self.reviewing.propose(search, best)
                return
            self._share_plan(now, search, best)
        elif search.shared_cost is not None and executing(self.slot.node, self.created):
            finished = finished or Done(PlanStatus.SOLVED, search.expansions, "execution has begun")
        elif search.shared_cost is not None and now >= self.next_update:
            if set(self._read_world(self.problem).facts) != set(search.world.facts):
                finished = finished or Done(
                    PlanStatus.SOLVED, search.expansions, "the world changed: execution has begun"
                )
            elif best is not None and best.plan.cost < search.shared_cost:
                self._share_plan(now, search, best)
        if self.search is not search:
            return
        if finished is not None:
            self.search = None
            self.host.emit(
                "planner",
                key=key_text(self.key),
                what="done",
                status=finished.status.value,
                expansions=search.expansions,
            )
            if search.shared_cost is None:
                message = f"planner '{self.problem.planner}' ended with '{finished.status.value}' and no plan" + (
                    f": {finished.message}" if finished.message else ""
                )
                outsiders = search.world.left_out or (search.world.others and not self.model.alternative_plan)
                if outsiders and finished.status is PlanStatus.UNSOLVABLE:
                    # robots outside the team hold objects, or may change the world and there is no AlternativePlan
                    reason = (
                        f"{message}; robots outside the team ({', '.join(search.world.others)}) may change the world"
                    )
                    self._wait_for_world(now, search.world, search.generation, reason)
                    return
                unsolvable = finished.status is PlanStatus.UNSOLVABLE
                if self.waiting.wait_for_team(now, unsolvable, bool(search.world.others)):
                    reason = (
                        f"{message} with the robots in the team ({', '.join(search.world.robots)}); waiting up to "
                        f"{TEAM_WAIT:g} s for those outside it ({', '.join(search.world.others)}): they may be back"
                    )
                    self._wait_for_world(now, search.world, search.generation, reason)
                    return
                self._publish_failure(now, search.generation, message)
            return
        if search.shared_cost is None:
            if now - search.started > self.model.timeout:
                self.search = None
                reason = f"no plan within the timeout of {self.model.timeout:g} s"
                self.host.emit("planner", key=key_text(self.key), what="timeout", expansions=search.expansions)
                self._publish_failure(now, search.generation, reason)
            elif now >= self.next_update and set(self._read_world(self.problem).facts) != set(search.world.facts):
                self._replan(now, "the world changed while planning")

    def _next_step(self, now: float, created: CreatedTasks, goal: Sequence[Literal]) -> None:
        """A stepwise plan's step is over: plan the next one from the world as it is now (nothing when the goal holds).

        The step's effects are awaited first (a teammate's finished step may be known before the facts its
        runtime wrote arrive), for at most two UpdateTimes: planning from a world that lags behind would
        repeat a step that is done.
        """
        self.marks.mark_done(self.slot.node, self.created)  # this agent's own last step first
        believed = {Fact(f.predicate, tuple(str(a) for a in f.args)) for f in self.host.world.facts()}
        if holds(goal, believed):
            return  # the child succeeds with the generated plan (child_status)
        effects = [literal for task in created.tasks for step in task for literal in step.effect]
        if not holds(effects, believed):
            if self.step_over is None:
                self.step_over = now
            if now - self.step_over < 2 * self.model.update_time:
                return
        self.step_over = None
        self.search = None
        self._start_search(now, "the step is done: planning the next one")

    def _share_plan(self, now: float, search: LeaderSearch, plan: ValidPlan, pins: Pins = ()) -> None:
        steps = plan.steps
        self.waiting.end_team_wait()
        search.version += 1
        search.shared_cost = plan.plan.cost  # the cost as the planner gave it (the trace shows it)
        self.host.emit(
            "planner",
            key=key_text(self.key),
            what="plan",
            generation=search.generation,
            version=search.version,
            cost=plan.plan.cost,
            steps=len(steps),
            expansions=search.expansions,
            after_s=round(now - search.started, 6),
        )
        share = PlanShare(
            self.key,
            search.generation,
            search.version,
            self.host.name,
            PLAN,
            steps,
            plan.plan.cost,
            search.world.facts,
            search.world.robots,
            self.slot.entry_task,
            goal=search.goal,
            origin=self.host.name,
            pins=pins,
        )
        self._publish(share, now)

    # -- execution monitoring --------------------------------------------------

    def _check_execution(self, now: float, share: PlanShare) -> None:
        node = self.slot.node
        created = self.created
        if node is None or created is None or node.plan is not created.plan:
            return
        progress = task_progress(node, created)
        if self.predicates is None:  # the domain's predicates depend on the problem's elements only
            self.predicates = predicate_types(self.model, self.host.library)
        predicates = self.predicates
        believed = self.host.world.facts()
        facts = [
            Fact(f.predicate, tuple(str(a) for a in f.args)) for f in believed if f.predicate.lower() in predicates
        ]
        goal = goal_literals(self.problem)
        world = self._read_world(self.problem, believed)
        reachable = reachable_goal(goal, world.outside, world.fixed)
        # what the plan was made for, less what robots outside the team hold now (they may put it back)
        target = tuple(literal for literal in share.goal or goal if literal in reachable)
        order = [[step.index for step in steps] for steps in created.tasks]
        members = self.slot.members()
        stepwise = self.stepwise
        if stepwise:
            target = ()  # a step of a policy is not meant to reach the goal: only its actions must still fit
        reason = remaining_fits(created.tasks, progress, facts, share.world, target, share.robots) or stalled(
            progress, order, created.allowed, members
        )
        if reason is None and stepwise and all(p.done for p in progress):
            self._next_step(now, created, reachable)
            return
        if reason is None and all(p.done for p in progress):
            if reachable != goal and holds(reachable, set(world.facts)):  # the rest of the goal is reached
                self._wait_for_world(now, world, self._next_generation(), _rest_holds(world))
                return
            reason = "the plan is done, but the goal does not hold: the part that robots outside the team held can be planned now"
        if reason is None:
            self.invalid_once = False
        elif not self.invalid_once:
            self.invalid_once = True
        elif reason.startswith("task T"):
            self._replan(now, f"the plan is stuck: {reason}")
        else:
            self._replan(now, f"the world changed under the plan: {reason}")


def _planner_trait(name: str, trait: str) -> bool:
    """A class attribute of the planner called ``name`` (``False`` for an unknown planner: planning fails later)."""
    try:
        return bool(getattr(planner_class(name), trait, False))
    except PlannerError:
        return False


def _rest_holds(world: PlanningWorld) -> str:
    return f"robots outside the team hold, or nobody sees, {', '.join(world.outside)}; the rest of the goal holds"
