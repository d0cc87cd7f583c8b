"""Benchmark of coordinated exploration (issue 16's Exploration figure).

Run with ``.venv/bin/python bench/exploration.py`` (``--seeds 10`` by default).

The field: ``alica.worldsim.scenarios.lunar(seed, rocks=60, size=40)``; its rocks
(ground truth, used only to simulate the sensor and score) are rasterised at the
map's resolution. The robots start where the scenario puts scout, stummel and
amparo, and move in a fast 2-D kinematic simulation (no pybullet stepping):

* every robot has the same speed (``--speed``, 0.8 m/s) and a 2-D lidar of
  ``--range`` metres (180 rays, ray-marched on the true grid every time step
  of ``--dt`` seconds) that updates one team map (the map the team shares);
* a robot drives along a shortest path on a coarse grid (0.25 m) of the known
  map, unknown cells counted passable, obstacles inflated by its radius, and
  plans again when its path runs into a cell newly seen occupied;
* every ``--period`` seconds the frontier candidates and their information gain
  are computed from the team map with the library's own
  :func:`alica.skills.exploration.extract_frontiers` (Algorithm 1).

Two ways to choose a robot's frontier, in the same run and on the same seeds:

* **coordinated** (ours): the constraints of ``plans/skills/explore.yaml`` (Eq. 7:
  chosen frontiers more than 4 m apart; Eq. 8: each within 15 m of its robot;
  utility: the summed gain) solved with ``alica.solver.solve`` directly, as the
  engine would, but without running the engine. A robot that needs a frontier
  (it reached its own, or its own vanished) triggers a solve in which the other
  robots' frontiers are kept (their domains are their current frontier), so
  robots are not re-routed while they drive; when the constraints cannot be
  satisfied (no frontier within 15 m, say) the robot takes its nearest
  frontier at least 4 m from the others' (counted as ``fallbacks``).
* **nearest frontier** (Yamauchi 1997): every robot drives to the frontier
  nearest to it by path length, uncoordinated.

For 1, 2 and 3 robots the simulated time to 90 % coverage of the truly free
cells is measured (runs end at ``--max-time`` seconds). Prints a markdown table
and writes ``build/exploration_coverage.png`` (mean coverage over time).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from alica.lang import FactBase, parse
from alica.skills.exploration import FREE, OCCUPIED, UNKNOWN, FrontierCandidate, extract_frontiers
from alica.solver import Finite, Problem, Term, Var, solve

ROBOTS = ("scout", "stummel", "amparo")
SPREAD = "forall a, b in agents(ExploreFrontiers): a == b or MaximalDist(frontier(a), frontier(b), 4.0)"
NEAR = "forall a in agents(ExploreFrontiers): MinimalDist(frontier(a), a, 15.0)"
GAIN = "sum a in agents(ExploreFrontiers): gain(frontier(a))"
#: A variant utility (not in explore.yaml): the paper's "minimal distance to travel" as a cost, 1 m² of gain per metre
GAIN_DIST = "sum a in agents(ExploreFrontiers): gain(frontier(a)) - dist(frontier(a), a)"
RADIUS = 0.3
METHODS = ("coordinated", "nearest", "gain-dist")
PLAN_RES = 0.25


@dataclass
class Field:
    truth: np.ndarray  # occupied [row, col] at the map resolution
    free: np.ndarray
    origin: tuple[float, float]
    resolution: float
    starts: dict[str, tuple[float, float]]


def make_field(seed: int, resolution: float) -> Field:
    from alica.worldsim.grid import OccupancyGrid
    from alica.worldsim.scenarios import lunar

    world = lunar(seed, rocks=60, samples=0, size=40.0)
    try:
        grid = OccupancyGrid.from_obstacles(world.ground_truth_obstacles(), world.bounds, resolution)
        starts = {n: (float(r.pose[0]), float(r.pose[1])) for n, r in world.robots.items()}
    finally:
        world.close()
    truth = grid.cells == OCCUPIED
    return Field(truth, ~truth, (float(grid.origin[0]), float(grid.origin[1])), resolution, starts)


def sense(fld: Field, occ: np.ndarray, xy: tuple[float, float], reach: float) -> None:
    """One 180-ray scan at ``xy``: cells up to the first hit free, the hit occupied."""
    res = fld.resolution
    angles = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    steps = np.arange(0.0, reach, 0.5 * res)
    px = xy[0] + np.cos(angles)[:, None] * steps[None, :]
    py = xy[1] + np.sin(angles)[:, None] * steps[None, :]
    cols = np.floor((px - fld.origin[0]) / res).astype(int)
    rows = np.floor((py - fld.origin[1]) / res).astype(int)
    h, w = occ.shape
    inside = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
    rc, cc = np.clip(rows, 0, h - 1), np.clip(cols, 0, w - 1)
    blocked = fld.truth[rc, cc] | ~inside
    first = np.where(blocked.any(axis=1), blocked.argmax(axis=1), len(steps))
    before = np.arange(len(steps))[None, :] < first[:, None]
    occ[rc[before], cc[before]] = FREE
    hit = first < len(steps)
    hr, hc = rc[hit, first[hit]], cc[hit, first[hit]]
    ok = inside[hit, first[hit]]
    occ[hr[ok], hc[ok]] = OCCUPIED


class Planner:
    """Shortest paths on a coarse grid of the known map (unknown passable, obstacles inflated)."""

    def __init__(self, fld: Field) -> None:
        self.fld = fld
        self.factor = max(1, round(PLAN_RES / fld.resolution))
        h, w = fld.truth.shape
        self.shape = (h // self.factor, w // self.factor)
        hh, ww = self.shape
        idx = np.arange(hh * ww).reshape(hh, ww)
        src, dst, cost = [], [], []
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            # pairs (r, c) -> (r + dr, c + dc) inside the grid
            a = idx[: hh - dr, max(0, -dc) : ww - max(0, dc)]
            b = idx[dr:, max(0, dc) : ww + min(0, dc)]
            src.append(a.ravel())
            dst.append(b.ravel())
            cost.append(np.full(a.size, math.hypot(dr, dc) * PLAN_RES))
        self.src, self.dst, self.cost = np.concatenate(src), np.concatenate(dst), np.concatenate(cost)
        self.blocked = np.zeros(self.shape, dtype=bool)

    def update(self, occ: np.ndarray) -> None:
        f = self.factor
        hh, ww = self.shape
        occ_coarse = (occ[: hh * f, : ww * f] == OCCUPIED).reshape(hh, f, ww, f).any(axis=(1, 3))
        grow = max(1, math.ceil(RADIUS / PLAN_RES))
        self.blocked = ndimage.binary_dilation(occ_coarse, iterations=grow)
        ok = ~self.blocked.ravel()
        keep = ok[self.src] & ok[self.dst]
        n = self.shape[0] * self.shape[1]
        self.graph = csr_matrix((self.cost[keep], (self.src[keep], self.dst[keep])), shape=(n, n))

    def cell(self, xy: tuple[float, float]) -> int:
        c = int((xy[0] - self.fld.origin[0]) / PLAN_RES)
        r = int((xy[1] - self.fld.origin[1]) / PLAN_RES)
        r = min(max(r, 0), self.shape[0] - 1)
        c = min(max(c, 0), self.shape[1] - 1)
        return r * self.shape[1] + c

    def centre(self, k: int) -> tuple[float, float]:
        r, c = divmod(k, self.shape[1])
        return (self.fld.origin[0] + (c + 0.5) * PLAN_RES, self.fld.origin[1] + (r + 0.5) * PLAN_RES)

    def tree(self, xy: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
        """Path lengths and predecessors from ``xy`` (from the nearest open cell when the robot is inside an inflation)."""
        start = self.cell(xy)
        r0, c0 = divmod(start, self.shape[1])
        if self.blocked[r0, c0]:
            rows, cols = np.nonzero(~self.blocked[max(0, r0 - 4) : r0 + 5, max(0, c0 - 4) : c0 + 5])
            if len(rows):
                k = int(np.argmin((rows + max(0, r0 - 4) - r0) ** 2 + (cols + max(0, c0 - 4) - c0) ** 2))
                start = (rows[k] + max(0, r0 - 4)) * self.shape[1] + cols[k] + max(0, c0 - 4)
        dist, pred = dijkstra(self.graph, directed=False, indices=int(start), return_predecessors=True)
        return dist, pred

    def nearest_open(self, xy: tuple[float, float], dist: np.ndarray) -> int | None:
        """The reachable coarse cell nearest to ``xy`` within 0.75 m (a frontier cell may sit in the inflation)."""
        r0, c0 = divmod(self.cell(xy), self.shape[1])
        best: tuple[float, int] | None = None
        for dr in range(-3, 4):
            for dc in range(-3, 4):
                r, c = r0 + dr, c0 + dc
                if 0 <= r < self.shape[0] and 0 <= c < self.shape[1]:
                    k = r * self.shape[1] + c
                    if math.isfinite(dist[k]) and (best is None or math.hypot(dr, dc) < best[0]):
                        best = (math.hypot(dr, dc), k)
        return None if best is None else best[1]

    def path(self, pred: np.ndarray, goal: int) -> list[tuple[float, float]]:
        out = []
        k = goal
        while k >= 0:
            out.append(self.centre(k))
            k = int(pred[k])
        return out[::-1]


@dataclass
class Bot:
    name: str
    xy: tuple[float, float]
    target: FrontierCandidate | None = None
    path: list[tuple[float, float]] = field(default_factory=list)
    done: set[str] = field(default_factory=set)


def coordinated_choice(
    bots: list[Bot], needy: Bot, cands: list[FrontierCandidate], time_limit: float, utility: str = GAIN
) -> tuple[FrontierCandidate | None, bool]:
    """The solver's frontier for ``needy`` (Eq. 7-8, summed gain), the others' frontiers kept."""
    usable = [c for c in cands if c.name not in needy.done]
    if not usable:
        return None, False
    world = FactBase()
    by_name = {c.name: c for c in cands}
    for c in cands:
        world.set("Pos", c.name, value=c.position)
        world.set("gain", c.name, value=c.gain)
    variables = []
    for b in bots:
        world.set("Pos", b.name, value=b.xy)
        world.add_object(b.name, "agents(ExploreFrontiers)")
        if b is needy:
            domain: tuple[str, ...] = tuple(c.name for c in usable)
        elif b.target is not None and b.target.name in by_name:
            domain = (b.target.name,)
        else:
            continue
        variables.append(Var("frontier", b.name, Finite(domain)))
    active = {v.agent for v in variables}
    for b in bots:
        if b.name not in active:  # a robot with no frontier yet is not among the explorers of this solve
            world.remove_object(b.name, "agents(ExploreFrontiers)")
    problem = Problem(
        variables=tuple(variables),
        constraints=(Term("SpreadFrontiers", parse(SPREAD), SPREAD), Term("NearbyFrontiers", parse(NEAR), NEAR)),
        utilities=(Term("InformationGain", parse(utility), utility),),
        belief=world,
    )
    sol = solve(problem, time_limit=time_limit)
    if sol.status == "solved":
        value = sol.of(needy.name)
        name = value.get("frontier") if isinstance(value, dict) else value
        if isinstance(name, str) and name in by_name:
            return by_name[name], False
    # infeasible: the nearest frontier at least 4 m from the others' (greedy fallback)
    others = [b.target.position for b in bots if b is not needy and b.target is not None]
    apart = [c for c in usable if all(math.dist(c.position, o) > 4.0 for o in others)] or usable
    return min(apart, key=lambda c: math.dist(c.position, needy.xy)), True


def run(
    fld: Field, n: int, method: str, args: argparse.Namespace
) -> tuple[float, list[tuple[float, float]], dict[str, int]]:
    occ = np.full(fld.truth.shape, UNKNOWN, dtype=np.int8)
    bots = [Bot(name, fld.starts[name]) for name in ROBOTS[:n]]
    planner = Planner(fld)
    total_free = int(fld.free.sum())
    t = 0.0
    curve: list[tuple[float, float]] = []
    stats = {"solves": 0, "fallbacks": 0, "plans": 0}
    cands: list[FrontierCandidate] = []
    next_frontiers = 0.0
    reached = math.nan
    step = args.speed * args.dt
    while t <= args.max_time:
        for b in bots:
            sense(fld, occ, b.xy, args.range)
        cov = float(((occ != UNKNOWN) & fld.free).sum() / total_free)
        curve.append((t, cov))
        if cov >= 0.9 and math.isnan(reached):
            reached = t
            if not args.full_curves:
                break
        if t >= next_frontiers:
            next_frontiers = t + args.period
            cands = extract_frontiers(occ, fld.resolution, fld.origin, reach=3.0, min_gain=1.0, clearance=RADIUS + 0.1)
            names = {c.name for c in cands}
            planner.update(occ)
            for b in bots:
                if b.target is not None and b.target.name not in names:
                    b.target, b.path = None, []
            if not cands:
                break
        for b in bots:
            if b.path and any(planner.blocked[divmod(planner.cell(p), planner.shape[1])] for p in b.path[1:-1]):
                b.path = []  # runs into something newly seen: plan again
                if b.target is not None:
                    b.path = _plan(planner, b, b.target.position, stats) or []
            if b.target is None or not b.path:
                if b.target is not None:  # unreachable or reached
                    b.done.add(b.target.name)
                b.target, b.path = _assign(bots, b, cands, planner, method, stats, args)
        for b in bots:
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
        t += args.dt
    return reached, curve, stats


def _plan(
    planner: Planner, b: Bot, goal: tuple[float, float], stats: dict[str, int]
) -> list[tuple[float, float]] | None:
    stats["plans"] += 1
    dist, pred = planner.tree(b.xy)
    k = planner.nearest_open(goal, dist)
    if k is None:
        return None
    return planner.path(pred, k) + [goal]


def _assign(
    bots: list[Bot], b: Bot, cands: list[FrontierCandidate], planner: Planner, method: str, stats: dict[str, int], args
) -> tuple[FrontierCandidate | None, list[tuple[float, float]]]:
    for _ in range(5):
        usable = [c for c in cands if c.name not in b.done]
        if not usable:
            return None, []
        if method == "nearest":
            stats["plans"] += 1
            dist, pred = planner.tree(b.xy)
            best: tuple[float, FrontierCandidate, int] | None = None
            for c in usable:
                k = planner.nearest_open(c.position, dist)
                if k is not None and (best is None or dist[k] < best[0]):
                    best = (float(dist[k]), c, k)
            if best is None:
                return None, []
            return best[1], planner.path(pred, best[2]) + [best[1].position]
        stats["solves"] += 1
        utility = GAIN_DIST if method == "gain-dist" else GAIN
        choice, fell_back = coordinated_choice(bots, b, cands, args.time_limit, utility)
        stats["fallbacks"] += int(fell_back)
        if choice is None:
            return None, []
        path = _plan(planner, b, choice.position, stats)
        if path:
            return choice, path
        b.done.add(choice.name)
    return None, []


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
    parser.add_argument("--time-limit", type=float, default=0.2, help="seconds per solve")
    parser.add_argument("--full-curves", action="store_true", help="run to max-time for the plot")
    parser.add_argument("--out", default="build/exploration_coverage.png")
    args = parser.parse_args()
    counts = [int(k) for k in args.robots.split(",")]
    results: dict[tuple[str, int], list[float]] = {}
    curves: dict[tuple[str, int], list[list[tuple[float, float]]]] = {}
    wall: dict[tuple[str, int], list[float]] = {}
    extra: dict[tuple[str, int], dict[str, int]] = {}
    for seed in range(args.seeds):
        fld = make_field(seed, args.resolution)
        for n in counts:
            for method in METHODS:
                start = time.perf_counter()
                reached, curve, stats = run(fld, n, method, args)
                key = (method, n)
                wall.setdefault(key, []).append(time.perf_counter() - start)
                results.setdefault(key, []).append(reached)
                curves.setdefault(key, []).append(curve)
                acc = extra.setdefault(key, {})
                for k, v in stats.items():
                    acc[k] = acc.get(k, 0) + v
                print(
                    f"seed {seed} {method:11s} {n} robots: 90 % at {reached:.0f} s ({wall[key][-1]:.1f} s wall)",
                    flush=True,
                )
    print()
    print(f"Time to 90 % coverage, {args.seeds} seeds, 40 x 40 m, 60 rocks, lidar {args.range:g} m, {args.speed:g} m/s")
    print()
    print(
        "| robots | coordinated (Eq. 7-8), median s | mean s | x of 1 robot | nearest frontier, median s | mean s "
        "| coordinated faster by | solves (fallbacks) | Eq. 7-8 + distance cost, median s | x of 1 robot | faster than nearest by | wall s/run |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    base_gd = statistics.median(results[("gain-dist", counts[0])]) if counts and counts[0] == 1 else math.nan
    base = statistics.median(results[("coordinated", counts[0])]) if counts and counts[0] == 1 else math.nan
    for n in counts:
        co, ne = results[("coordinated", n)], results[("nearest", n)]
        mco, mne = statistics.median(co), statistics.median(ne)
        print(
            f"| {n} | {mco:.0f} | {statistics.fmean(co):.0f} | {mco / base:.2f} | {mne:.0f} | {statistics.fmean(ne):.0f} | "
            f"{100 * (1 - mco / mne):.0f} % | {extra[('coordinated', n)]['solves']} ({extra[('coordinated', n)]['fallbacks']}) | "
            f"{statistics.median(results[('gain-dist', n)]):.0f} | {statistics.median(results[('gain-dist', n)]) / base_gd:.2f} | "
            f"{100 * (1 - statistics.median(results[('gain-dist', n)]) / mne):.0f} % | "
            f"{statistics.fmean([w for m in METHODS for w in wall[(m, n)]]):.1f} |"
        )
    plot(curves, counts, args)


STYLES = {"coordinated": "-", "nearest": "--", "gain-dist": ":"}
LABELS = {
    "coordinated": "Eq. 7-8 (explore.yaml)",
    "nearest": "nearest frontier",
    "gain-dist": "Eq. 7-8 + distance cost",
}


def plot(curves, counts, args) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    grid = np.arange(0.0, args.max_time + args.dt, 5.0)
    colours = {1: "tab:blue", 2: "tab:orange", 3: "tab:green"}
    for (method, n), runs in sorted(curves.items()):
        ys = []
        for curve in runs:
            ts = np.array([c[0] for c in curve])
            cs = np.array([c[1] for c in curve])
            ys.append(np.interp(grid, ts, cs, right=cs[-1]))
        mean = np.mean(ys, axis=0)
        last = grid <= max(c[-1][0] for c in runs) + 5
        ax.plot(
            grid[last],
            mean[last],
            color=colours.get(n, "k"),
            ls=STYLES[method],
            label=f"{n} robot{'s' if n > 1 else ''}, {LABELS[method]}",
        )
    ax.axhline(0.9, color="grey", lw=0.8)
    ax.set_xlabel("simulated time (s)")
    ax.set_ylabel("coverage of the free field")
    ax.set_title(f"Exploration, 40 x 40 m, 60 rocks, mean of {args.seeds} seeds")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"\nplot: {out}")


if __name__ == "__main__":
    main()
