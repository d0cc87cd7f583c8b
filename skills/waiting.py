"""WaitAside: where a robot waits while the team works (IMPERA 8.2: "every agent drives to a free position").

A robot waits in three situations, and the skill serves all three:

* **Standing by** (no task needs it, or the team waits for a plan): it stays
  where it is, unless it stands within ``keep_away`` of a block a teammate
  works at (a stand-off point reserved near it); then it drives to a place
  ``keep_away`` from every block or sample lying in the world, as
  :class:`~alica.skills.navigation.DriveToFreeSpace`. A robot that stays
  where it worked keeps opponents off that stack while the team replans.
  It also leaves :data:`HOLDER_ROOM` to any other robot that holds
  something: an opponent with nowhere free to put a block down would hold
  it for good, and the team would wait for it for good.
* **Waiting for its next step** (``near`` names the step's work site, say the
  block it will stack on): it waits within :data:`NEAR_SPAN` of the site,
  beside it as a worker stands, on a side no teammate reserved; when it is
  not there, it drives to the free point of the rings :data:`NEAR_RING`
  around the site nearest to it. It is ready when its turn comes, and
  opponents leave that stack alone meanwhile.
* **Guarding** (``guard`` names the top of a finished part of the goal, or
  several objects, space-separated, of which it takes the nearest one no
  other robot guards): it stays within ``guard_radius`` of it. Opponents leave a stack alone while
  a robot stands that close (``blocking_radius`` of
  :class:`~alica.skills.opponent.RandomBlockSkill`), so they cannot undo it
  (IMPERA 8.2: "the opponents often were not able to act, because the stack
  was blocked by an agent"). With ``threat_radius`` > 0 it guards only while a
  robot outside the team is within that many metres of the guarded object
  (or was, within :data:`THREAT_HOLD` seconds), and otherwise stands by: a guard that no opponent needs stands beside the
  towers the team still builds, in the way of the robots that build them.
  Every :data:`CHECK_PERIOD` it looks again, so it comes back to guard as
  soon as an opponent approaches.

Every waiting place is clear of the other robots and of the stand-off points
teammates reserved (:mod:`alica.skills.reservations`). Once there the robot
stands still, and every :data:`CHECK_PERIOD` seconds it looks again: when a
teammate reserved the point it stands on, or a robot came too close, it
moves to another place. The skill never ends by itself; it runs until its
state is left.
"""

from __future__ import annotations

import math

from py_trees.common import Status

from alica.skills import reservations
from alica.skills.handling import inside_field
from alica.skills.navigation import DriveToFreeSpace, lying_sites
from alica.skills.team_poses import holders
from alica.skills.world_skill import distance

#: Radii (m) of the rings around a step's work site where a robot waits for its turn.
NEAR_RING = (0.8, 0.88)
#: A robot this far (m) from its next work site already waits near it.
NEAR_SPAN = (0.0, 0.95)
#: Default of ``guard_radius``: metres from a guarded block within which the robot stays.
GUARD_RADIUS = 0.9
#: Radii (m) of the ring around a guarded block where a guard that has to move looks for a place.
GUARD_RING = (0.78, 0.82)
#: Directions tried on each ring.
RING_POINTS = 24
#: Seconds a guard keeps guarding after the last opponent left ``threat_radius`` (opponents come back).
THREAT_HOLD = 30.0
#: Room (m) a robot standing by leaves around another robot that holds something, to put it down.
HOLDER_ROOM = 1.8
#: A block this close (m) to a reserved stand-off point is being worked at.
WORKED = 1.2
#: Goal tolerance (m) of the drive to a waiting place: a guard must end up within ``guard_radius``.
TOLERANCE = 0.06
#: Simulated seconds between two looks at the reservations and the robots around a waiting robot.
CHECK_PERIOD = 1.0
#: Room (m) kept between a waiting robot's body and another robot's body or reserved stand-off point.
ROOM = 0.1


class WaitAside(DriveToFreeSpace):
    """Wait out of the way: near the next work site, guarding a finished stack, or away from every stack.

    See the module docstring. Parameters: those of ``DriveToFreeSpace``, and
    ``near`` / ``guard`` (an object's name; anything that names no object of
    the world counts as not given) and ``guard_radius``.
    """

    def initialise(self) -> None:
        """Choose the waiting place and drive there (or stay, when the robot already waits well)."""
        self.threat_seen: dict[str, float] = {}
        """Guarded object -> when a robot outside the team was last seen within ``threat_radius`` of it."""
        self.waiting = False
        self.next_check = 0.0
        self.placing = False
        self.params.setdefault("tolerance", TOLERANCE)
        super().initialise()

    # -- where to wait -----------------------------------------------------------

    def _site(self, name: str) -> tuple[float, float] | None:
        """Where the object the parameter ``name`` names lies (``None``: no such object, or it is held).

        ``guard`` may name several objects, space-separated: the nearest one
        that no other robot guards yet (stands within ``guard_radius`` of) is
        taken, or none when every one is guarded.
        """
        value = self.param(name)
        if not isinstance(value, str):
            return None
        here = self._here()
        radius = float(self.param("guard_radius", GUARD_RADIUS))  # type: ignore[arg-type]
        found: list[tuple[float, tuple[float, float]]] = []
        held = holders(self.team_model, self.team_belief)
        mates = [p for p in self.teammates() if p.robot != self.robot.name] if name == "guard" else []
        guards = [(p.x, p.y) for p in mates]
        team = {p.robot for p in mates} | {self.robot.name}
        for label in value.split():
            obj = self.world.objects.get(label)
            if obj is None or label in held or (self.robot.arm is not None and self.robot.arm.held is obj):
                continue  # no such object, or held (the team's holding facts): its work site is elsewhere
            position = obj.position()
            xy = (float(position[0]), float(position[1]))
            if name == "guard" and any(distance(xy, (x, y)) <= radius for x, y in guards):
                continue  # a teammate guards it already (an opponent beside it is what a guard is for)
            if name == "guard" and not self._threatened(label, xy, team):
                continue  # no opponent near it: nothing to guard it from
            found.append((distance(xy, here), xy))
        return min(found)[1] if found else None

    def _threatened(self, label: str, xy: tuple[float, float], team: set[str]) -> bool:
        """Whether a robot outside the team is within ``threat_radius`` of object ``label`` at ``xy``, or was
        within the last :data:`THREAT_HOLD` seconds (always, with no radius); ``team``: the team's robots."""
        radius = float(self.param("threat_radius", 0.0))  # type: ignore[arg-type]
        if radius <= 0:
            return True
        now = self.now()
        if any(
            distance(xy, (float(robot.pose[0]), float(robot.pose[1]))) <= radius
            for name, robot in self.world.robots.items()
            if name not in team and not robot.crashed
        ):
            self.threat_seen[label] = now
        return now - self.threat_seen.get(label, -math.inf) < THREAT_HOLD

    def _crowding(self) -> list[tuple[float, float, float]]:
        """Discs a waiting robot's centre must stay out of: other robots and reserved stand-off points."""
        mine = self.robot.spec.radius + ROOM
        discs = super()._others() + reservations.reserved(self)
        return [(x, y, r + mine) for x, y, r in discs]

    def _free(self, xy: tuple[float, float], discs: list[tuple[float, float, float]]) -> bool:
        return all(math.hypot(xy[0] - x, xy[1] - y) >= r for x, y, r in discs)

    def _away_from_sites(
        self, xy: tuple[float, float], sites: list[tuple[float, float]], away: float, own: tuple[float, float] | None
    ) -> bool:
        """Whether ``xy`` keeps ``away`` from every one of ``sites`` but those of the site ``own``."""
        return all(
            math.hypot(xy[0] - x, xy[1] - y) >= away
            for x, y in sites
            if own is None or math.hypot(x - own[0], y - own[1]) >= 0.3
        )

    def _worked_sites(self) -> list[tuple[float, float]]:
        """The blocks a teammate works at: a stand-off point reserved within :data:`WORKED` of them."""
        points = reservations.reserved(self)
        return [
            (x, y)
            for x, y in lying_sites(self.world)
            if any(math.hypot(x - px, y - py) < WORKED for px, py, _ in points)
        ]

    def _acceptable(
        self, xy: tuple[float, float], guard: tuple[float, float] | None, near: tuple[float, float] | None
    ) -> bool:
        """Whether the robot may wait at ``xy``: clear of robots and reservations, and where its duty wants it.

        Guarding (``guard``, where the guarded object lies): within ``guard_radius`` of it. Waiting for
        a step (``near``, its work site): within :data:`NEAR_SPAN` of it. Standing by: ``keep_away``
        from every block a teammate works at (a new place, when it has to move, keeps ``keep_away``
        from every block).
        """
        if not self._free(xy, self._crowding()):
            return False
        if guard is not None:
            return distance(xy, guard) <= float(self.param("guard_radius", GUARD_RADIUS))  # type: ignore[arg-type]
        if near is not None:
            return NEAR_SPAN[0] <= distance(xy, near) <= NEAR_SPAN[1]
        # standing by, a robot stays where it is unless a teammate comes to work at a block near it, or a
        # robot holding something stands close (an opponent that cannot put its block down holds it for good)
        if any(distance(xy, holder) < HOLDER_ROOM for holder in self._holders()):
            return False
        away = float(self.param("keep_away", 0.0))  # type: ignore[arg-type]
        return away <= 0 or self._away_from_sites(xy, self._worked_sites(), away, None)

    def _here(self) -> tuple[float, float]:
        return float(self.robot.estimate[0]), float(self.robot.estimate[1])

    def _ring_place(self, centre: tuple[float, float], radii: tuple[float, ...]) -> tuple[float, float] | None:
        """The free point on rings around ``centre`` nearest to the robot."""
        here = self._here()
        discs = self._crowding()
        checker = self._checker()
        sites = lying_sites(self.world)
        margin = self.robot.spec.radius + ROOM
        away = float(self.param("keep_away", 0.0))  # type: ignore[arg-type]
        angles = [2.0 * math.pi * k / RING_POINTS for k in range(RING_POINTS)]
        points = [(centre[0] + r * math.cos(a), centre[1] + r * math.sin(a)) for r in radii for a in angles]
        candidates = [
            p for p in points if checker.valid_xy(*p) and self._free(p, discs) and inside_field(self.world, p, margin)
        ]
        for keep in (away, 0.5 * away, 0.0):  # a crowded field: crowd the other stacks a little rather than not wait
            kept = [p for p in candidates if self._away_from_sites(p, sites, keep, centre)]
            if kept:
                return min(kept, key=lambda p: distance(p, here))
        return None

    def _free_place(self) -> tuple[float, float] | None:
        guard, near = self._site("guard"), self._site("near")
        if self._acceptable(self._here(), guard, near):
            return self._here()
        for centre, ring in ((guard, GUARD_RING), (near, NEAR_RING)):
            place = self._ring_place(centre, ring) if centre is not None else None
            if place is not None:
                return place
        self.placing = True  # every reserved point counts when choosing the place (see _others)
        try:
            return super()._free_place()
        finally:
            self.placing = False

    def _keep_away_sites(self) -> list[tuple[float, float, float]]:
        """The work sites, ``keep_away`` each, and the robots that hold something, :data:`HOLDER_ROOM` each."""
        return super()._keep_away_sites() + [(x, y, HOLDER_ROOM) for x, y in self._holders()]

    def _holders(self) -> list[tuple[float, float]]:
        """Where the other robots that hold something stand: they need room to put it down."""
        holding = set(holders(self.team_model, self.team_belief).values())
        return [(p.x, p.y) for p in self.teammates() if p.robot in holding]

    def _others(self) -> list[tuple[float, float, float]]:
        """The other robots, with the points teammates reserved as robots standing there (for the path too).

        For the path, a reserved point the robot stands on is left out: it is driving away from it.
        """
        x, y = self._here()
        mine = self.robot.spec.radius
        return super()._others() + [
            (rx, ry, rr)
            for rx, ry, rr in reservations.reserved(self)
            if self.placing or math.hypot(rx - x, ry - y) >= rr + mine
        ]

    # -- waiting -------------------------------------------------------------------

    def update(self) -> Status:
        """Drive to the place, then stand there and look around now and then; never ends by itself."""
        now = self.now()
        if self.waiting:
            if now < self.next_check:
                return self.running("waiting aside")
            self.next_check = now + CHECK_PERIOD
            if self._acceptable(self._here(), self._site("guard"), self._site("near")):
                return self.running("waiting aside")
            self._move_on("a teammate needs this place")
            return self.running("making way for a teammate")
        if self.spot is None:
            self.robot.stop()
            if now >= self.next_check:
                self.next_check = now + CHECK_PERIOD
                self._move_on("looking for a free place again")
            return self.running("no free place to wait in now: waiting here")
        status = super().update()
        if status == Status.RUNNING:
            return status
        self.robot.stop()
        self.waiting = True
        self.next_check = now + CHECK_PERIOD
        if status == Status.FAILURE:
            return self.running(f"waiting here ({self.feedback_message})")
        return self.running("waiting aside")

    def _move_on(self, why: str) -> None:
        """Choose a new place and drive there."""
        spot = self._free_place()
        self.spot = spot
        self.waiting = False
        if spot is None:
            return
        self.started = self.now()
        self.replans = 0
        self.moved_goal = 0
        self.escaping = False
        self.reason = why
        self._drive_to(spot)
