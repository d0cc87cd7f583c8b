"""Benchmark of coordinated exploration (issue 16's Exploration figure).

Run with ``.venv/bin/python bench/exploration.py`` (``--seeds 10`` by default;
``--seeds 2 --robots 1,3`` for a quick look).

The field: ``alica.worldsim.scenarios.lunar(seed, rocks=60, size=40)`` in the
2-D simulation of ``bench/exploration_sim.py`` (no pybullet stepping): every
robot has the same speed (``--speed``, 0.8 m/s) and a 2-D lidar of
``--range`` metres (180 rays, ray-marched on the true grid every time step of
``--dt`` seconds) that updates one team map (the map the team shares). A robot
drives along a shortest path on a coarse grid (0.2 m) of the known map,
unknown cells counted passable, its centre kept :data:`RADIUS` from known
occupied cells; it plans again as soon as its path runs into a cell newly seen
too close to a rock. Every ``--period`` seconds, and whenever a robot reached
its frontier, the frontier candidates and their information gain are computed
from the team map with the library's own
:func:`alica.skills.exploration.extract_frontiers` (Algorithm 1).

Ways to choose a robot's next frontier, in the same run and on the same seeds:

* **coordinated** (ours): the Explore plan of ``plans/skills/explore.yaml`` as
  shipped: its constraints SpreadFrontiers (Eq. 7), NearbyFrontiers (Eq. 8)
  and its utilities GainOverTravel and KeepFrontier (the hysteresis: a bonus
  for every robot that keeps the frontier it drives to, read from
  ``Targets(robot, frontier)``) are read from the plan file and solved with
  ``alica.solver.solve`` directly, as the engine would, but without running
  the engine: one joint solve for the whole team, every robot's variable
  ranging over the frontiers it may use. Every bench robot is in
  ``agents(ExploreFrontiers)`` (``agents(ExploreAfterMapping)`` is empty: its
  terms are empty sums and empty ``forall``). The team is solved again at
  every reading of the map (every ``--period``, and when a robot reached its
  frontier) and whenever a robot has no frontier; every robot then applies
  the library's rule, the one ExploreFrontier applies with ``reassign: true``
  (:func:`alica.skills.exploration.assign.decide`): a robot with a frontier
  follows the solution when it moves it (``switches``), one without takes
  the solution's; when the constraints have no solution, or the solution lies
  within 4 m of a frontier another robot keeps heading for, a robot keeps its
  frontier or, without one, takes the best usable frontier by gain /
  (1 + distance) that is more than 4 m from the others' frontiers (any usable
  one if none is) -- counted as ``fallbacks``. ``--no-periodic`` runs the
  plan without KeepFrontier and with the others' frontiers fixed (only the
  robot that needs a frontier is assigned): ExploreFrontier with
  ``reassign: false`` (the skill's default; the shipped plan sets it true),
  and this bench before the periodic reassignment.
  ``--spacing`` replaces the plan's 4 m of Eq. 7 (an experiment).
* **nearest frontier** (Yamauchi 1997): every robot drives to the usable
  frontier nearest to it by path length, uncoordinated.
* **gain only** (ablation, ``--ablation``): the coordinated strategy with the
  summed gain alone in place of GainOverTravel (the plan's utility before it
  counted travel).

As in ExploreFrontier, a frontier the robot reached is not chosen by it
again, one it could not plan a path to is left out for 30 s.

For 1, 2 and 3 robots the simulated time to 90 % coverage of the truly free
cells is measured; a run ends at ``--stop`` coverage (95 %), when no frontier
is left, or at ``--max-time`` (a run that never reached 90 % is a *stall*).
``contacts`` counts robot-steps in which a robot overlapped a rock (should
be 0: the simulation has no collisions, so it checks the planner). Prints a
markdown table and the goals, writes ``build/exploration_coverage.png`` (mean
coverage over time; time to 90 % per run).
"""

from __future__ import annotations

import argparse
import math
import re
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from exploration_sim import RADIUS, Field, Planner, make_field, sense

from alica.errors import AlicaError
from alica.lang import parse
from alica.skills.exploration import UNKNOWN, FrontierCandidate, extract_frontiers
from alica.skills.exploration.assign import Explorer, How, decide, explore_terms, solve_team
from alica.solver import Term

ROBOTS = ("scout", "stummel", "amparo")
#: The plan's names: its constraints (Eq. 7, Eq. 8), its utility and its hysteresis.
PLAN_CONSTRAINTS = ("SpreadFrontiers", "NearbyFrontiers")
PLAN_UTILITY = "GainOverTravel"
PLAN_KEEP = "KeepFrontier"
#: The ablation's utility: the summed gain alone (the plan's utility before it counted the travel).
GAIN_ONLY = "sum a in agents(ExploreFrontiers): gain(frontier(a))"
#: Metres from the frontiers the others head for (ExploreFrontier's ``spacing``, eps1 of Eq. 7, the plan's 4 m).
SPACING = 4.0
#: Eq. 7's distance in the plan's SpreadFrontiers (``--spacing`` replaces it).
EPS1 = re.compile(r"(MaximalDist\(frontier\(\w+\), frontier\(\w+\), )4\.0\)")
#: Seconds a frontier the robot could not reach is left out (ExploreFrontier's UNREACHABLE_FOR).
UNREACHABLE_FOR = 30.0
LABELS = {
    "coordinated": "Eq. 7-8 + GainOverTravel (explore.yaml)",
    "nearest": "nearest frontier",
    "gain-only": "ablation: Eq. 7-8, gain only",
}
STYLES = {"coordinated": "-", "nearest": "--", "gain-only": ":"}


@dataclass(frozen=True)
class Terms:
    """The Explore plan's constraints, utility and hysteresis."""

    constraints: tuple[Term, ...]
    utility: Term
    keep: Term


def plan_terms(spacing: float = SPACING) -> Terms:
    """The Explore plan's constraints and utilities, read from the shipped ``skills/explore.yaml``.

    ``spacing`` other than the plan's 4 m (``--spacing``) replaces Eq. 7's distance in SpreadFrontiers.
    """
    try:
        terms = explore_terms()
    except AlicaError as exc:
        raise SystemExit(f"the bench solves the shipped Explore plan: {exc}") from None
    by_name = {t.name: t for t in terms.constraints}
    missing = [n for n in PLAN_CONSTRAINTS if n not in by_name]
    try:
        utility, keep = terms.utility(PLAN_UTILITY), terms.utility(PLAN_KEEP)
    except KeyError as exc:
        raise SystemExit(f"skills/explore.yaml: {exc}") from None
    if missing:
        raise SystemExit(f"skills/explore.yaml: the Explore plan has no constraint {', '.join(missing)}")
    constraints = tuple(by_name[n] for n in PLAN_CONSTRAINTS)
    if spacing != SPACING:
        spread = by_name["SpreadFrontiers"]
        text, found = EPS1.subn(lambda m: f"{m.group(1)}{spacing!r})", spread.text)
        if not found:
            raise SystemExit(
                f"--spacing: SpreadFrontiers has no MaximalDist(frontier(a), frontier(b), 4.0): {spread.text}"
            )
        constraints = (Term(spread.name, parse(text), text), *(c for c in constraints if c is not spread))
    return Terms(constraints, utility, keep)


@dataclass
class Bot:
    name: str
    xy: tuple[float, float]
    target: FrontierCandidate | None = None
    path: list[tuple[float, float]] = field(default_factory=list)
    reached: set[str] = field(default_factory=set)
    unreachable: dict[str, float] = field(default_factory=dict)

    def usable(self, cands: list[FrontierCandidate], now: float) -> list[FrontierCandidate]:
        """The candidates this robot may choose (ExploreFrontier's ``usable``)."""
        return [c for c in cands if c.name not in self.reached and self.unreachable.get(c.name, -math.inf) <= now]


def team_solution(
    bots: list[Bot],
    cands: list[FrontierCandidate],
    now: float,
    constraints: tuple[Term, ...],
    utilities: tuple[Term, ...],
    time_limit: float,
    *,
    fixed: Bot | None = None,
) -> dict[str, str]:
    """The plan's joint assignment, robot -> frontier (empty: no solution), solved as the engine would.

    Every robot with a usable frontier is an explorer (the library's
    :func:`~alica.skills.exploration.assign.solve_team`). With ``fixed``
    (``--no-periodic``) only that robot is assigned: the others' domains are
    their current frontier, a robot without one is left out.
    """
    names = {c.name for c in cands}
    explorers = []
    for b in bots:
        target = b.target.name if b.target is not None else None
        if fixed is not None and b is not fixed:
            domain: tuple[str, ...] = (target,) if target is not None and target in names else ()
        else:
            domain = tuple(c.name for c in b.usable(cands, now))
        explorers.append(Explorer(b.name, b.xy, target, domain))
    return solve_team(explorers, cands, constraints, utilities, time_limit=time_limit)


class Run:
    """One exploration run of ``n`` robots with one method on one field."""

    def __init__(self, fld: Field, n: int, method: str, args: argparse.Namespace, terms: Terms) -> None:
        self.fld, self.method, self.args = fld, method, args
        self.constraints = terms.constraints
        utility = terms.utility if method == "coordinated" else Term("GainOnly", parse(GAIN_ONLY), GAIN_ONLY)
        self.periodic = not args.no_periodic
        self.utilities = (utility, terms.keep) if self.periodic else (utility,)
        self.occ = np.full(fld.truth.shape, UNKNOWN, dtype=np.int8)
        self.bots = [Bot(name, fld.starts[name]) for name in ROBOTS[:n]]
        self.planner = Planner(fld)
        self.stats = {"solves": 0, "fallbacks": 0, "switches": 0, "plans": 0, "contacts": 0, "idle": 0}
        self.cands: list[FrontierCandidate] = []

    def go(self) -> tuple[float, list[tuple[float, float]]]:
        """Simulate; the time to 90 % (nan: never) and the coverage curve."""
        fld, args = self.fld, self.args
        total_free = int(fld.free.sum())
        t, next_frontiers, reached = 0.0, 0.0, math.nan
        curve: list[tuple[float, float]] = []
        step = args.speed * args.dt
        while t <= args.max_time:
            for b in self.bots:
                sense(fld, self.occ, b.xy, args.range)
            cov = float(((self.occ != UNKNOWN) & fld.free).sum() / total_free)
            curve.append((t, cov))
            if cov >= 0.9 and math.isnan(reached):
                reached = t
            if cov >= args.stop:
                break
            self.planner.update(self.occ)
            if t >= next_frontiers:
                next_frontiers = t + args.period
                if not self._frontiers():
                    break  # explored: no frontier with gain left
                if self.method != "nearest" and self.periodic:
                    self._reassign(t)  # every robot, jointly, with the plan's hysteresis
            for b in self.bots:
                if b.path and self._runs_into(b.path):
                    b.path = self._plan(b, b.target.position) if b.target is not None else None
                    if b.path is None:
                        b.unreachable[b.target.name] = t + UNREACHABLE_FOR  # type: ignore[union-attr]
                        b.target, b.path = None, []
                if b.target is None:
                    self._assign(b, t)
                if b.target is None:
                    self.stats["idle"] += 1
            arrived = False
            for b in self.bots:
                arrived |= self._move(b, step)
                self.stats["contacts"] += int(fld.contact(b.xy))
            if arrived:  # read the map from where the robot stands now (as ExploreFrontier does)
                next_frontiers = t + args.dt
            t += args.dt
        return reached, curve

    def _frontiers(self) -> bool:
        self.cands = extract_frontiers(
            self.occ, self.fld.resolution, self.fld.origin, reach=3.0, min_gain=1.0, clearance=RADIUS + 0.1
        )
        names = {c.name for c in self.cands}
        for b in self.bots:
            if b.target is not None and b.target.name not in names:
                b.target, b.path = None, []
        return bool(self.cands)

    def _runs_into(self, path: list[tuple[float, float]]) -> bool:
        if len(path) < 2:
            return False
        pts = np.asarray(path[:-1])  # the last point is the frontier itself
        p = self.planner
        cols = np.clip(((pts[:, 0] - self.fld.origin[0]) / p.step).astype(int), 0, p.shape[1] - 1)
        rows = np.clip(((pts[:, 1] - self.fld.origin[1]) / p.step).astype(int), 0, p.shape[0] - 1)
        return bool(p.blocked[rows, cols].any())

    def _move(self, b: Bot, step: float) -> bool:
        """Drive ``step`` metres along the path; True when the robot reached its frontier."""
        left = step
        while left > 0 and b.path:
            nxt = b.path[0]
            d = math.dist(b.xy, nxt)
            if d <= left:
                b.xy, left = nxt, left - d
                b.path.pop(0)
            else:
                f = left / d
                b.xy = (b.xy[0] + f * (nxt[0] - b.xy[0]), b.xy[1] + f * (nxt[1] - b.xy[1]))
                left = 0.0
        if b.target is not None and not b.path:
            b.reached.add(b.target.name)
            b.target = None
            return True
        return False

    def _plan(self, b: Bot, goal: tuple[float, float]) -> list[tuple[float, float]] | None:
        self.stats["plans"] += 1
        dist, pred = self.planner.tree(b.xy)
        k = self.planner.nearest_open(goal, dist)
        if k is None:
            return None
        return self.planner.path(pred, k)[1:] + [goal]

    def _solve(self, now: float, fixed: Bot | None = None) -> dict[str, str]:
        self.stats["solves"] += 1
        return team_solution(
            self.bots,
            self.cands,
            now,
            self.constraints,
            self.utilities,
            self.args.time_limit,
            fixed=None if self.periodic else fixed,
        )

    def _decide(self, b: Bot, now: float, proposal: dict[str, str]) -> tuple[FrontierCandidate | None, How]:
        by_name = {c.name: c for c in self.cands}
        usable = {c.name for c in b.usable(self.cands, now)}
        heading = {o.name: o.target.position for o in self.bots if o is not b and o.target is not None}
        choice = decide(
            b.name,
            b.xy,
            b.target,
            by_name,
            usable,
            proposal,
            heading,
            spacing=self.args.spacing,
            others_follow=self.periodic,
        )
        self.stats["fallbacks"] += int(choice.how is How.FALLBACK)
        return choice.frontier, choice.how

    def _reassign(self, now: float) -> None:
        """The periodic joint reassignment: every robot applies ``decide`` to one team solution."""
        proposal = self._solve(now)
        for b in self.bots:
            if b.target is None:
                self._assign(b, now, proposal)
                continue
            frontier, how = self._decide(b, now, proposal)
            if how is not How.SWITCHED or frontier is None:
                continue
            path = self._plan(b, frontier.position)
            if path is None:  # it keeps its frontier
                b.unreachable[frontier.name] = now + UNREACHABLE_FOR
                continue
            self.stats["switches"] += 1
            b.target, b.path = frontier, path

    def _assign(self, b: Bot, now: float, proposal: dict[str, str] | None = None) -> None:
        for _ in range(5):
            if not b.usable(self.cands, now):
                return
            if self.method == "nearest":
                self._assign_nearest(b, b.usable(self.cands, now))
                return
            if proposal is None:
                proposal = self._solve(now, fixed=b)
            choice, _how = self._decide(b, now, proposal)
            if choice is None:
                return
            path = self._plan(b, choice.position)
            if path is not None:
                b.target, b.path = choice, path
                return
            b.unreachable[choice.name] = now + UNREACHABLE_FOR
            proposal = None

    def _assign_nearest(self, b: Bot, usable: list[FrontierCandidate]) -> None:
        self.stats["plans"] += 1
        dist, pred = self.planner.tree(b.xy)
        best: tuple[float, FrontierCandidate, int] | None = None
        for c in usable:
            k = self.planner.nearest_open(c.position, dist)
            if k is not None and (best is None or dist[k] < best[0]):
                best = (float(dist[k]), c, k)
        if best is not None:
            b.target, b.path = best[1], self.planner.path(pred, best[2])[1:] + [best[1].position]


def describe(times: list[float], max_time: float) -> tuple[str, str, float]:
    """Median and mean (a stalled run counts as ``max_time``, shown as a lower bound) and the median."""
    stalls = sum(math.isnan(x) for x in times)
    filled = [max_time if math.isnan(x) else x for x in times]
    med = statistics.median(filled)
    mark = ">= " if stalls else ""
    med_s = f"{mark}{med:.0f}" if stalls * 2 >= len(times) or med >= max_time else f"{med:.0f}"
    return med_s, f"{mark}{statistics.fmean(filled):.0f}", med


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--robots", default="1,2,3")
    parser.add_argument("--speed", type=float, default=0.8)
    parser.add_argument("--range", type=float, default=6.0)
    parser.add_argument("--dt", type=float, default=0.5)
    parser.add_argument("--period", type=float, default=2.0)
    parser.add_argument("--resolution", type=float, default=0.1)
    parser.add_argument("--max-time", type=float, default=1500.0)
    parser.add_argument("--stop", type=float, default=0.95, help="coverage at which a run ends (>= 0.9)")
    parser.add_argument("--time-limit", type=float, default=0.2, help="seconds per solve")
    parser.add_argument("--ablation", action="store_true", help="also run the gain-only utility")
    parser.add_argument(
        "--spacing",
        type=float,
        default=SPACING,
        help="eps1 of Eq. 7 in metres (the plan's 4 m; another value replaces it in SpreadFrontiers and the fallback)",
    )
    parser.add_argument(
        "--no-periodic",
        action="store_true",
        help="assign only the robot that needs a frontier, the others' fixed, without KeepFrontier (as before)",
    )
    parser.add_argument("--out", default="build/exploration_coverage.png")
    args = parser.parse_args()
    try:
        counts = [int(k) for k in args.robots.split(",")]
    except ValueError:
        raise SystemExit(f"--robots takes robot counts separated by commas (1,2,3), got {args.robots!r}") from None
    if not counts or any(not 1 <= k <= len(ROBOTS) for k in counts) or args.seeds < 1 or not 0.9 <= args.stop <= 1.0:
        raise SystemExit("--robots counts must lie in 1..3, --seeds must be >= 1 and --stop within [0.9, 1]")
    terms = plan_terms(args.spacing)
    methods = ("coordinated", "nearest") + (("gain-only",) if args.ablation else ())
    results: dict[tuple[str, int], list[float]] = {}
    curves: dict[tuple[str, int], list[list[tuple[float, float]]]] = {}
    wall: dict[tuple[str, int], list[float]] = {}
    extra: dict[tuple[str, int], dict[str, int]] = {}
    for seed in range(args.seeds):
        fld = make_field(seed, args.resolution)
        for n in counts:
            for method in methods:
                start = time.perf_counter()
                run = Run(fld, n, method, args, terms)
                reached, curve = run.go()
                key = (method, n)
                wall.setdefault(key, []).append(time.perf_counter() - start)
                results.setdefault(key, []).append(reached)
                curves.setdefault(key, []).append(curve)
                acc = extra.setdefault(key, {})
                for k, v in run.stats.items():
                    acc[k] = acc.get(k, 0) + v
                print(
                    f"seed {seed} {method:11s} {n} robots: 90 % at {reached:.0f} s, "
                    f"{run.stats['solves']} solves ({run.stats['fallbacks']} fallbacks, {run.stats['switches']} switches) "
                    f"({wall[key][-1]:.1f} s wall)",
                    flush=True,
                )
    table(results, wall, extra, counts, methods, args)
    plot(curves, results, counts, methods, args)


def table(results, wall, extra, counts, methods, args) -> None:
    """The markdown table and the goals."""
    print()
    print(
        f"Time to 90 % coverage (simulated s), {args.seeds} seeds, 40 x 40 m, 60 rocks, lidar {args.range:g} m, "
        f"{args.speed:g} m/s, runs end at {args.max_time:g} s, Eq. 7 spacing {args.spacing:g} m"
        + ("" if not args.no_periodic else ", --no-periodic")
    )
    print()
    head = "| robots | coordinated median | mean | x of 1 robot | nearest median | mean | x of 1 robot | coordinated faster by |"
    rule = "|---|---|---|---|---|---|---|---|"
    if "gain-only" in methods:
        head += " gain-only median | x of 1 robot |"
        rule += "---|---|"
    print(head + " solves (fallbacks, switches) | stalls (coord. / nearest) | contacts | wall s/run |")
    print(rule + "---|---|---|---|")
    med = {k: describe(v, args.max_time)[2] for k, v in results.items()}
    base = {m: med[(m, 1)] if 1 in counts else math.nan for m in methods}
    for n in counts:
        cells = [str(n)]
        for m in ("coordinated", "nearest"):
            ms, mean, _ = describe(results[(m, n)], args.max_time)
            cells += [ms, mean, f"{med[(m, n)] / base[m]:.2f}"]
        cells.append(f"{100 * (1 - med[('coordinated', n)] / med[('nearest', n)]):.0f} %")
        if "gain-only" in methods:
            cells += [
                describe(results[("gain-only", n)], args.max_time)[0],
                f"{med[('gain-only', n)] / base['gain-only']:.2f}",
            ]
        co = extra[("coordinated", n)]
        stalls = [sum(math.isnan(x) for x in results[(m, n)]) for m in ("coordinated", "nearest")]
        cells += [
            f"{co['solves']} ({co['fallbacks']}, {co['switches']})",
            f"{stalls[0]} / {stalls[1]}",
            str(sum(extra[(m, n)]["contacts"] for m in methods)),
            f"{statistics.fmean([w for m in methods for w in wall[(m, n)]]):.1f}",
        ]
        print("| " + " | ".join(cells) + " |")
    print()
    if 1 in counts and 3 in counts:
        ratio = med[("coordinated", 3)] / med[("coordinated", 1)]
        faster = 1 - med[("coordinated", 3)] / med[("nearest", 3)]
        print(
            f"Goal: 3 robots <= 0.45 x the time of 1 (coordinated, medians): {ratio:.2f} -> {'met' if ratio <= 0.45 else 'MISSED'}"
        )
        print(
            f"Goal: coordinated >= 20 % faster than nearest frontier with 3 robots (medians): {100 * faster:.0f} % -> {'met' if faster >= 0.2 else 'MISSED'}"
        )


def plot(curves, results, counts, methods, args) -> None:
    """Mean coverage over time per method and robot count; time to 90 % per run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.8), gridspec_kw={"width_ratios": [3, 2]})
    colours = {1: "tab:blue", 2: "tab:orange", 3: "tab:green"}
    for (method, n), runs in sorted(curves.items()):
        end = max(c[-1][0] for c in runs)
        grid = np.arange(0.0, end + args.dt, 5.0)
        ys = [np.interp(grid, [c[0] for c in curve], [c[1] for c in curve]) for curve in runs]
        ax.plot(
            grid,
            np.mean(ys, axis=0),
            color=colours.get(n, "k"),
            ls=STYLES[method],
            label=f"{n} robot{'s' if n > 1 else ''}, {LABELS[method]}",
        )
    ax.axhline(0.9, color="grey", lw=0.8)
    ax.set_xlabel("simulated time (s)")
    ax.set_ylabel("coverage of the free field")
    ax.set_title(f"mean coverage, {args.seeds} seeds (a run ends at {100 * args.stop:.0f} %)", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    keys = [(m, n) for n in counts for m in methods]
    data = [[args.max_time if math.isnan(x) else x for x in results[k]] for k in keys]
    box = bx.boxplot(data, patch_artist=True)
    for patch, (m, n) in zip(box["boxes"], keys):
        patch.set_facecolor(colours.get(n, "grey"))
        patch.set_alpha(0.6 if m == "coordinated" else 0.25)
    bx.set_xticks(range(1, len(keys) + 1), [f"{n}\n{m}" for m, n in keys], fontsize=7)
    bx.set_ylabel("time to 90 % (s; a stall counts as --max-time)")
    bx.set_title("time to 90 % coverage per run", fontsize=10)
    bx.grid(alpha=0.3, axis="y")
    fig.suptitle("Exploration, 40 x 40 m, 60 rocks")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"\nplot: {out}")


if __name__ == "__main__":
    main()
