"""What an agent does while it leads a planning problem: search, share, review, wait, watch the plan, give up.

The leader is the lowest alive agent in the state (:mod:`alica.prophet.leadership`).
On each tick it acts on its phase (:class:`~alica.prophet.runtime_states.LeaderPhase`,
worked out by :meth:`Leader.phase`):

* **starting**, **settling** (an UpdateTime after a failed step) or **waiting**
  (when the world changed): it reads World and starts an anytime search
  (:meth:`Leader.start_search`), or shares ``done``, or waits;
* **searching**: it spends the tick's budget (:mod:`alica.prophet.budget`), shares the
  first plan at once (a temporal planner's when the search ends or after one UpdateTime)
  and cheaper ones every UpdateTime, and on no plan waits for the world or the team
  (:mod:`alica.prophet.waiting`) or shares ``failed``;
* **reviewing**: it reads the operator's decisions (:mod:`alica.prophet.reviewing`);
* then, every UpdateTime, it repeats the share and, while the plan runs, checks
  that its rest still fits the world (:mod:`alica.prophet.monitoring`); twice in
  a row not, it replans. A failed step replans after the team settles, unless
  the same step failed too often (:mod:`alica.prophet.giving_up`).

The leader reaches the rest of the runtime through :class:`Team` only: the share
the agent follows, its generated plan, publishing a share, reading World.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import replace
from typing import Protocol

from alica.engine.child import ChildHost, ChildSlot, key_text
from alica.errors import AlicaError, PlannerError
from alica.lang.fact import Fact
from alica.model import Condition, ConditionKind, PlanningProblem
from alica.prophet.board import PlanBoard, PlanShare, ShareStatus
from alica.prophet.budget import LeaderSearch, SearchBudget, advance
from alica.prophet.durations import StepTimes
from alica.prophet.giving_up import GiveUp, failure_cause
from alica.prophet.keep_off import KeepOff
from alica.prophet.leader_search import magic_events, positions
from alica.prophet.magic.team import TeamMagic
from alica.prophet.monitoring import PlanCheck, StepMarks, executing, stalled, task_progress
from alica.prophet.pipeline import ProblemEvent, ProblemPlanning, ValidPlan
from alica.prophet.planner import Done, Planner, PlanStatus
from alica.prophet.planners import planner_class
from alica.prophet.problem import predicate_types
from alica.prophet.reviewing import Pins, Reviewing
from alica.prophet.runtime_states import LeaderPhase, leader_phase
from alica.prophet.tasks import STEP_DONE, CreatedTasks, Literal, conjunction, for_robot, holds
from alica.prophet.waiting import TEAM_WAIT, Waiting
from alica.prophet.world import PlanningWorld, goal_literals, reachable_goal, remaining_fits

SEARCHING, PLAN, FAILED, DONE = ShareStatus.SEARCHING, ShareStatus.PLAN, ShareStatus.FAILED, ShareStatus.DONE


class Team(Protocol):
    """The runtime as its leader sees it: what the agent follows, and how it shares."""

    @property
    def share(self) -> PlanShare | None:
        """The share the agent follows (``None``: none yet)."""

    @property
    def created(self) -> CreatedTasks | None:
        """The generated plan of that share."""

    @property
    def failed_generation(self) -> int:
        """The latest generation whose plan failed here (``-1``: none)."""

    @property
    def problem(self) -> PlanningProblem:
        """The planning problem with the operator's goal and world."""

    @property
    def times(self) -> StepTimes:
        """How long the agent's steps took (the durations a temporal planner plans with)."""

    def publish(self, share: PlanShare, now: float) -> None:
        """Send a share to the team and follow it."""

    def read_world(self, problem: PlanningProblem, facts: Iterable[Fact] | None = None) -> PlanningWorld:
        """The planning world from the world model."""

    def next_generation(self) -> int:
        """One more than any generation the agent has seen."""


class Leader:
    """The leader's side of a planning problem's runtime (see the module docstring).

    Args:
        team: the runtime, as the leader reaches it.
        host: what the agent's engine offers.
        slot: the child of the state that holds the planning problem.
        board: the agent's plan board (replan requests, generations seen).
        budget: the search budget per tick.
        magic: the agent's MAGiC (parallel planning on), or ``None``.
        reviewing: the operator's review.
        marks: the steps this agent finished in the generated plan.
        stepwise: whether the problem's planner plans one step at a time.
        plan: starts the planning of a problem.
    """

    def __init__(
        self,
        team: Team,
        host: ChildHost,
        slot: ChildSlot,
        board: PlanBoard,
        budget: SearchBudget,
        magic: TeamMagic | None,
        reviewing: Reviewing,
        marks: StepMarks,
        *,
        stepwise: bool,
        plan: Callable[..., ProblemPlanning],
    ) -> None:
        element = slot.element
        assert isinstance(element, PlanningProblem)
        self.team = team
        self.host = host
        self.slot = slot
        self.board = board
        self.budget = budget
        self.magic = magic
        self.reviewing = reviewing
        self.marks = marks
        self.stepwise = stepwise
        self.plan = plan
        self.model = element
        self.key = slot.key
        self.search: LeaderSearch | None = None
        """The running search."""
        self.pending: tuple[float, str] | None = None
        """A replan waiting for the team to settle in the WaitPlan: (when, why)."""
        self.next_update = -1.0
        """When the agent next repeats its share (or its replan request) and checks the plan."""
        self.check = PlanCheck()
        """The check of the rest of the plan (twice in a row not fitting: replan)."""
        self.waiting = Waiting()
        """What the leader waits for: the world to change, the robots outside the team to come back."""
        self.give_up = GiveUp()
        """The leader's count of failed steps: when to stop replanning."""
        self.keep_off = KeepOff()
        """The failed steps and their robots, kept off them for a while."""
        self.step_over: float | None = None
        """When a stepwise plan's step was seen over while its effects had not all arrived yet."""
        self.predicates: dict[str, tuple[str, ...]] | None = None
        """The domain's predicates (they depend on the problem's elements only), worked out once."""

    def phase(self, leader: bool) -> LeaderPhase:
        """What the agent does now, whether it leads (``leader``) or not."""
        share = self.team.share
        return leader_phase(
            leader=leader,
            proposal=self.reviewing.proposal is not None,
            pending=self.pending is not None,
            search=self.search is not None,
            blocked=self.waiting.blocked is not None,
            share=share.status if share is not None else None,
            share_failed=share is not None and share.generation <= self.team.failed_generation,
        )

    def hand_over(self) -> None:
        """The agent no longer leads: drop the search and the proposal; the decisions so far are not its own."""
        if self.search is not None or self.reviewing.proposal is not None:
            self.search = None
            self.reviewing.drop()
            self.host.emit("planner", key=key_text(self.key), what="handed over")
        self.reviewing.catch_up()  # whoever leads decides on its own proposals

    def supersede(self, share: PlanShare) -> None:
        """Another leader's share is ahead of this agent's search or proposal (it restarted, a partition healed)."""
        host = self.host
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

    def lead(self, now: float) -> None:
        """The leader's tick: act on its phase (:mod:`alica.prophet.runtime_states`), then every UpdateTime repeat the share and check the plan."""
        share = self.team.share
        requests = [r for r in self.board.take_requests(self.key) if share is None or r.generation >= share.generation]
        if requests and share is not None and share.status == PLAN:
            first = requests[0]
            self.replan(now, f"{first.sender}: {first.reason}", settle=True, failed=(first.sender, first.step))
            return
        phase = self.phase(True)
        if phase is LeaderPhase.REVIEWING:
            self.reviewing.read(now, self._share_plan, self.replan)
        elif phase is LeaderPhase.SETTLING:
            assert self.pending is not None
            if now + 1e-9 < self.pending[0]:
                return
            reason = self.pending[1]
            self.pending = None
            self.start_search(now, reason, self.team.share.generation if self.team.share is not None else None)
        elif phase is LeaderPhase.SEARCHING:
            self._step_search(now)
        elif phase is LeaderPhase.WAITING:
            if now >= self.next_update and self.waiting.changed(self.team.read_world(self.team.problem).facts):
                self.waiting.unblock()
                self.start_search(now, "the world changed while planning was blocked")
            elif self.waiting.team_wait_over(now):
                self.waiting.unblock()
                self.start_search(now, f"waited {TEAM_WAIT:g} s for the robots outside the team")
        elif phase is LeaderPhase.STARTING:
            self.start_search(now, "start" if share is None else f"taking over from {share.leader}")
        if now < self.next_update:
            return
        self.next_update = now + self.model.update_time
        share = self.team.share
        if share is None:
            return
        if self.search is None and share.status == PLAN:
            self._check_execution(now, share)
        if self.team.share is share:
            me = self.host.name
            self.team.publish(share if share.leader == me else replace(share, leader=me), now)

    def replan(self, now: float, reason: str, settle: bool = False, failed: tuple[str, str] = ("", "")) -> None:
        """Plan again; with ``settle`` the team first runs the WaitPlan for an UpdateTime (after a failed step).

        ``failed`` is the robot and the label of the step that failed: the robot is kept off that step for
        a while (:mod:`alica.prophet.keep_off`) when the step could still run now (its precondition holds
        for the robot in the world read again): then the robot failed it, not a world that changed under it
        (an opponent took the block).

        A failed step (``settle``) that failed :data:`~alica.prophet.giving_up.GIVE_UP_AFTER` times for the
        same reason in the same world, or :data:`~alica.prophet.giving_up.GIVE_UP_ANYWAY_AFTER` times with no
        step carried out in between, fails the problem instead (:class:`~alica.prophet.giving_up.GiveUp`):
        the team runs the AlternativePlan.
        """
        self.host.counters["replans"] += 1
        self.host.emit("replan", key=key_text(self.key), reason=reason)
        self.search = None
        if not settle:
            self.start_search(now, reason)
            return
        generation = self.team.next_generation()
        world = frozenset(self.team.read_world(self.team.problem).facts)
        if self._could_run(failed, world):
            self.keep_off.failed(*failed, now)
        done = sum(1 for fact in self.host.world.facts() if fact.predicate == STEP_DONE)
        # the failed step's label where it is known (whichever robot failed it), else what made it fail
        cause = f"{failed[1]} failed" if failed[1] else failure_cause(reason)
        message = self.give_up.step_failed(cause, world, done)
        if message is not None:
            self.host.emit("planner", key=key_text(self.key), what="failed", reason=message)
            self._publish_failure(now, generation, message)
            return
        self.pending = (now + self.model.update_time, reason)
        self.team.publish(
            PlanShare(
                self.key, generation, 0, self.host.name, SEARCHING, entry_task=self.slot.entry_task, reason=reason
            ),
            now,
        )

    def _could_run(self, failed: tuple[str, str], world: frozenset[Fact]) -> bool:
        """Whether the failed step (robot, label) of the plan followed could run now, for that robot."""
        robot, label = failed
        created = self.team.created
        if not robot or not label or created is None:
            return False
        step = next((s for task in created.tasks for s in task if s.label == label), None)
        return step is not None and holds(for_robot(step.pre, step.robot, robot), world)

    def start_search(self, now: float, reason: str, generation: int | None = None) -> None:
        """Read World and start a search of ``generation`` (default: a new one), sharing ``searching``.

        The goal holding already shares ``done``; with robots outside the team holding part of the
        goal the search plans for the rest, or, with nothing left to plan for, the team waits; a
        planner that cannot start shares ``failed``.
        """
        host = self.host
        self.reviewing.drop()
        if generation is None:
            generation = self.team.next_generation()
        me = host.name
        task = self.slot.entry_task
        problem = self.team.problem
        try:
            world = self.team.read_world(problem)
            goal = goal_literals(problem)
            if holds(goal, set(world.facts)):
                self.team.publish(
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
            planning, events = self._plan(problem, world, generation)
        except (PlannerError, AlicaError) as exc:
            host.emit("planner", key=key_text(self.key), what="failed", reason=str(exc))
            self.team.publish(PlanShare(self.key, generation, 0, me, FAILED, entry_task=task, reason=str(exc)), now)
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
        self.team.publish(
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

    def _plan(
        self, problem: PlanningProblem, world: PlanningWorld, generation: int
    ) -> tuple[ProblemPlanning, Iterator[ProblemEvent]]:
        """What the search plans, and its events: the planner's anytime search, or a MAGiC round over the team.

        Raises:
            PlannerError: the problem cannot be planned (an unknown planner, a domain it cannot read).
            AlicaError: the problem's elements cannot be read.
        """
        host, me = self.host, self.host.name
        options: dict[str, object] = {"progress_every": 100} if problem.planner in ("builtin", "temporal") else {}
        if (traits := planner_traits(problem.planner)) is not None and traits.reads_positions:
            options.update(positions=positions(host.world.values()), seed=generation)
        durations = self.team.times.estimates(host.library, problem.elements) if problem.planner == "temporal" else None
        planning = self.plan(problem, host.library, world, options=options, durations=durations)
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
        return planning, events

    def _wait_for_world(self, now: float, world: PlanningWorld, generation: int, reason: str) -> None:
        """Nothing the team can plan for now: it waits in the WaitPlan, and the leader plans again when the world changes."""
        self.host.emit("planner", key=key_text(self.key), what="waiting", reason=reason)
        self.waiting.block(world.facts)
        if self.team.share is None or self.team.share.status != SEARCHING:
            self.team.publish(
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
            self.team.publish(failed, now)
            return
        self._after_search(now, search, finished)

    def _after_search(self, now: float, search: LeaderSearch, finished: Done | None) -> None:
        """Share what the search found; end it when it is done.

        The first plan goes out at once, except a planner's whose first plan waits
        (:attr:`~alica.prophet.planner.Planner.first_plan_waits`, the temporal planner's): it is
        shared when the search ends or one UpdateTime after it began, whichever comes first, since
        execution ends the search.
        """
        best = search.best
        if (
            best is not None
            and search.shared_cost is None
            and finished is None
            and search.planning is not None
            and search.planning.planner.first_plan_waits
            and now - search.started < self.model.update_time
        ):
            return  # the search goes on for its first UpdateTime
        if best is not None and search.shared_cost is None:
            if self.host.review:
                self.search = None
                self.waiting.end_team_wait()
                self.reviewing.propose(search, best)
                return
            self._share_plan(now, search, best)
        elif search.shared_cost is not None and executing(self.slot.node, self.team.created):
            finished = finished or Done(PlanStatus.SOLVED, search.expansions, "execution has begun")
        elif search.shared_cost is not None and now >= self.next_update:
            if set(self.team.read_world(self.team.problem).facts) != set(search.world.facts):
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
                message = f"planner '{self.team.problem.planner}' ended with '{finished.status.value}' and no plan" + (
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
            elif now >= self.next_update and set(self.team.read_world(self.team.problem).facts) != set(
                search.world.facts
            ):
                self.replan(now, "the world changed while planning")

    def _next_step(self, now: float, created: CreatedTasks, goal: Sequence[Literal]) -> None:
        """A stepwise plan's step is over: plan the next one from the world as it is now (nothing when the goal holds).

        The step's effects are awaited first (a teammate's finished step may be known before the facts its
        runtime wrote arrive), for at most two UpdateTimes: planning from a world that lags behind would
        repeat a step that is done.
        """
        self.marks.mark_done(self.slot.node, self.team.created)  # this agent's own last step first
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
        self.start_search(now, "the step is done: planning the next one")

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
            barred=self.keep_off.active(now),
        )
        self.team.publish(share, now)

    # -- execution monitoring --------------------------------------------------

    def _check_execution(self, now: float, share: PlanShare) -> None:
        node = self.slot.node
        created = self.team.created
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
        goal = goal_literals(self.team.problem)
        world = self.team.read_world(self.team.problem, believed)
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
                self._wait_for_world(now, world, self.team.next_generation(), _rest_holds(world))
                return
            reason = "the plan is done, but the goal does not hold: the part that robots outside the team held can be planned now"
        replan = self.check.replan_reason(reason)
        if replan is not None:
            self.replan(now, replan)

    def _publish_failure(self, now: float, generation: int, reason: str) -> None:
        """Tell the team that planning ``generation`` failed: it runs the AlternativePlan."""
        share = PlanShare(
            self.key, generation, 1, self.host.name, FAILED, entry_task=self.slot.entry_task, reason=reason
        )
        self.team.publish(share, now)


def planner_traits(name: str) -> type[Planner] | None:
    """The class of the planner called ``name``, whose declared traits (``stepwise``, ``reads_positions``)
    a runtime reads; ``None`` for an unknown planner (planning fails later, with the reason)."""
    try:
        return planner_class(name)
    except PlannerError:
        return None


def _rest_holds(world: PlanningWorld) -> str:
    return f"robots outside the team hold, or nobody sees, {', '.join(world.outside)}; the rest of the goal holds"
