"""Perception figures: the team map and localization (issue 16, "Map" and "Localization").

**Map.** Per seed, ``lunar(seed)`` (60 rocks, 40 x 40 m): Scout runs
``BuildMap`` (resolution 0.05 m, radius 5 m, 10 m traced) at the start; then
all three robots drive to random goals for ``--map-seconds`` simulated
seconds, each scanning into its layer of the team map twice a second and
publishing the changed tiles (the way an exploring robot maps as it goes).
Columns: the cell agreement of the team map with the ground truth on the
observed (known) cells after BuildMap and after the drive; the grid update
cost per scan (ray tracing the 1257 rays of 10 m that lie a cell apart at
10 m, wall ms, median); the map
sharing rate per robot (bytes of tile writes per simulated second, the mean
over the robots; a tile write's size is its name, arguments and value as the
world model encodes them plus 24 bytes of stamp and framing).

The ground truth (for scoring only) is the occupancy at the lidar's height:
a cell is occupied when its centre lies inside a rock's convex mesh, a
table, or another robot. A known cell agrees when the map says occupied and
a truly occupied cell lies within one cell of it, or the map says free and
the cell is not more than one cell deep inside an obstacle (the one-cell
tolerance covers the cells a rock's surface crosses). Goal: >= 95 %.
``build/perception_map.png``: the first seed's team map after the drive next
to the ground truth, the observed area outlined, disagreeing cells marked.

**Localization.** Per seed, Scout on ``lunar(seed)`` with 2 % odometry drift
(``SensorNoise.odometry_drift = 0.02``) drives ``MoveToPosition`` to random
goals (by its estimate) until it has driven 100 m (``--distance``), mapping
twice a second as above, with ``Localize(continuous=true, period=0.5)``
running next to the driving skill. In the same run the bench integrates the
odometry alone (each step's motion of the estimate, without Localize's
corrections), so *odometry only* is the uncorrected estimate of the very same
drive. The pose error is the distance between the true position and the
estimate after 100 m; the table gives the median and the largest over the
seeds, and the heading error. Goal: median <= 0.10 m with Localize. The
localization cost is the wall time of one scan match (median).
``build/perception_localization.png``: the error against the distance driven,
corrected and odometry only (every seed, and the median).

Run: ``.venv/bin/python bench/perception.py [--seeds 10] [--map-seconds 30]`` (about 2.5 minutes)
(``--only map`` or ``--only localization``; ``--seeds 2 --distance 50`` for
a quick look).
"""

from __future__ import annotations

import argparse
import math
import random
import statistics
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from alica.lang.skill_plugins import default_registry
from alica.skills.context import SkillEnv
from alica.skills.mapping import LogOddsGrid, lidar, map_scan, match_scan, rays_for, robot_mapper, team_map
from alica.skills.navigation import planning_checker
from alica.skills.testing import map_agreement as agreement
from alica.skills.testing import map_truth as truth_grid
from alica.worldmodel import WorldModel
from alica.worldsim.geometry import wrap_angle
from alica.worldsim.scenarios import lunar
from alica.worldsim.world import World

RESOLUTION = 0.05
MAP_RANGE = 10.0
SCAN_PERIOD = 0.5
TICK = 0.1
DRIVE_DISTANCE = 100.0
N_RAYS = rays_for(MAP_RANGE, RESOLUTION)


@dataclass
class Agent:
    """One robot's skills in the bench's little executive."""

    name: str
    wm: WorldModel
    scratch: dict[str, object]
    drive: Any = None
    localize: Any = None


def behaviour(world: World, agent: Agent, skill: str, params: dict[str, object]) -> Any:
    """A skill's behaviour on ``agent``'s robot, set up as the engine would."""
    from alica.engine.behaviours import SkillContext
    from alica.skills.testing import checked_params

    registry = default_registry([])
    values = checked_params(registry.get(skill), params)
    context = SkillContext(
        agent.name, world.now, agent.wm, agent.wm, random.Random(agent.name), world, None, f"bench/{skill}"
    )
    context.scratch = agent.scratch
    b = registry.load(skill)(skill, values, context)
    b.setup(context=context)
    return b


def random_goal(world: World, robot: str, rng: np.random.Generator) -> tuple[float, float]:
    """A drivable goal 5-15 m from the robot (chosen on the true map: the bench's choice, not a skill's)."""
    checker = planning_checker(world, world.robots[robot].spec.radius + 0.3)
    x, y, _ = world.robots[robot].pose
    xmin, ymin, xmax, ymax = world.bounds
    for _ in range(500):
        d, a = rng.uniform(5.0, 15.0), rng.uniform(-math.pi, math.pi)
        gx, gy = x + d * math.cos(a), y + d * math.sin(a)
        if xmin + 1.5 < gx < xmax - 1.5 and ymin + 1.5 < gy < ymax - 1.5 and checker.valid_xy(gx, gy):
            return (gx, gy)
    return (0.0, 0.0)


def sync(agents: list[Agent]) -> None:
    """A perfect network: every agent's delta reaches every other."""
    for sender in agents:
        delta = sender.wm.take_delta()
        if delta is not None:
            for receiver in agents:
                if receiver is not sender:
                    receiver.wm.merge(delta)


Pose = tuple[float, float, float]


def compose(a: Pose, b: Pose) -> Pose:
    """``a`` followed by the motion ``b`` (in ``a``'s frame)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle(a[2] + b[2]))


def between(a: Pose, b: Pose) -> Pose:
    """The motion from ``a`` to ``b``, in ``a``'s frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, wrap_angle(b[2] - a[2]))


def drive_team(
    world: World,
    agents: list[Agent],
    *,
    seed: int,
    seconds: float = math.inf,
    distance: float = math.inf,
    localize: bool = False,
    timings: dict[str, list[float]] | None = None,
    trace: list[tuple[float, float, float, float]] | None = None,
) -> Pose:
    """Drive the agents to random goals, mapping twice a second, until ``seconds`` pass or the first drove ``distance``.

    Returns the first robot's odometry alone: its estimate moved by each step's odometry, never by
    Localize. ``trace`` gets (distance driven, error of the estimate, error of the odometry alone,
    heading error of the odometry alone in degrees) at every scan.
    """
    rng = np.random.default_rng([seed, 99])
    start = world.now()
    next_scan = start
    first = world.robots[agents[0].name]
    d0 = first.odometry.distance
    odometry: Pose = first.estimate
    for agent in agents:
        if localize:
            agent.localize = behaviour(world, agent, "Localize", {"continuous": True, "period": 0.5})
    while world.now() - start < seconds and first.odometry.distance - d0 < distance:
        if world.now() - start > 600.0:
            break
        now = world.now()
        for agent in agents:
            if agent.drive is None or agent.drive.status.value in ("SUCCESS", "FAILURE"):
                goal = random_goal(world, agent.name, rng)
                agent.drive = behaviour(world, agent, "MoveToPosition", {"goal": list(goal), "timeout": 60.0})
            agent.drive.tick_once()
            if agent.localize is not None:
                agent.localize.tick_once()
        if now >= next_scan:
            for agent in agents:
                env = SkillEnv(agent.name, world.now, random.Random(0), world, agent.wm, scratch=agent.scratch)
                mapper = robot_mapper(env, agent.name, world.bounds, RESOLUTION)
                t0 = time.perf_counter()
                map_scan(world.robots[agent.name], mapper, max_range=MAP_RANGE, now=now)
                if timings is not None:
                    timings.setdefault("map", []).append(time.perf_counter() - t0)
            sync(agents)
            next_scan = now + SCAN_PERIOD
            if trace is not None:
                x, y, _ = first.pose
                ex, ey, _ = first.estimate
                trace.append(
                    (
                        first.odometry.distance - d0,
                        math.hypot(x - ex, y - ey),
                        math.hypot(x - odometry[0], y - odometry[1]),
                        abs(math.degrees(wrap_angle(first.pose[2] - odometry[2]))),
                    )
                )
        before = first.estimate
        world.step(TICK)
        odometry = compose(odometry, between(before, first.estimate))  # Localize corrects only between steps
    for agent in agents:
        if agent.drive is not None:
            agent.drive.stop(agent.drive.status.__class__.INVALID)
        if agent.localize is not None:
            agent.localize.stop(agent.localize.status.__class__.INVALID)
    return odometry


def map_row(seed: int, seconds: float) -> dict[str, Any]:
    """Map figures of one seed (and, under ``"images"``, the team map and the truth for the plot)."""
    with lunar(seed=seed) as world:
        agents = [Agent(name, WorldModel(name, clock=world.clock), {}) for name in sorted(world.robots)]
        scout = next(a for a in agents if a.name == "scout")
        build = behaviour(world, scout, "BuildMap", {"resolution": RESOLUTION, "radius": 5.0, "max_range": MAP_RANGE})
        while build.status.value not in ("SUCCESS", "FAILURE"):
            build.tick_once()
            world.step(TICK)
        sync(agents)
        grid = team_map(scout.wm)
        assert grid is not None
        truth = truth_grid(world, grid, skip=("scout",))
        after_build = agreement(grid.occupancy(), truth)
        strict_build = agreement(grid.occupancy(), truth, strict=True)
        # the cost of one update: a scan of 10 m into a fresh layer, at the robot's pose
        layer = LogOddsGrid.covering(world.bounds, RESOLUTION)
        ranges, angles = lidar(world.robots["scout"], N_RAYS, MAP_RANGE)
        costs = []
        for _ in range(20):
            t0 = time.perf_counter()
            layer.update(world.robots["scout"].estimate, ranges, angles, MAP_RANGE)
            costs.append(time.perf_counter() - t0)
        mappers = {a.name: robot_mapper_of(a) for a in agents}
        sent0 = {n: m.bytes_sent if m else 0 for n, m in mappers.items()}
        t_start = world.now()
        drive_team(world, agents, seed=seed, seconds=seconds)
        elapsed = world.now() - t_start
        sync(agents)
        grids = [team_map(a.wm) for a in agents]
        same = all(g is not None and np.array_equal(g.logodds, grids[0].logodds) for g in grids)  # type: ignore[union-attr]
        grid = grids[0]
        assert grid is not None
        truth = truth_grid(world, grid)
        after_drive = agreement(grid.occupancy(), truth)
        rates = []
        for agent in agents:
            mapper = robot_mapper_of(agent)
            rates.append(((mapper.bytes_sent if mapper else 0) - sent0[agent.name]) / elapsed)
        return {
            "build": after_build,
            "strict": strict_build,
            "drive": after_drive,
            "known": float((grid.occupancy() >= 0).mean()),
            "update_ms": 1000.0 * statistics.median(costs),
            "bytes_s": statistics.mean(rates),
            "same": float(same),
            "images": (grid.occupancy(), truth, grid.origin, grid.resolution),
            "robots": [tuple(world.robots[a.name].pose[:2]) for a in agents],
        }


def robot_mapper_of(agent: Agent) -> Any:
    """The agent's mapper, if it has one."""
    return agent.scratch.get("mapping.mapper")


def localization_row(seed: int, drift: float = 0.02, distance: float = DRIVE_DISTANCE) -> dict[str, Any]:
    """Pose error after ``distance`` metres of driving with odometry drift: with Localize, and the odometry alone."""
    with lunar(seed=seed) as world:
        world.faults.set_sensor_noise(odometry_drift=drift)
        agent = Agent("scout", WorldModel("scout", clock=world.clock), {})
        build = behaviour(world, agent, "BuildMap", {"resolution": RESOLUTION, "radius": 5.0, "max_range": MAP_RANGE})
        while build.status.value not in ("SUCCESS", "FAILURE"):
            build.tick_once()
            world.step(TICK)
        trace: list[tuple[float, float, float, float]] = []
        odometry = drive_team(world, [agent], seed=seed, distance=distance, localize=True, trace=trace)
        robot = world.robots["scout"]
        x, y, yaw = robot.pose
        ex, ey, eyaw = robot.estimate
        return {
            "error": math.hypot(x - ex, y - ey),
            "yaw": abs(math.degrees(wrap_angle(yaw - eyaw))),
            "odo_error": math.hypot(x - odometry[0], y - odometry[1]),
            "odo_yaw": abs(math.degrees(wrap_angle(yaw - odometry[2]))),
            "distance": robot.odometry.distance,
            "time": world.now(),
            "trace": trace,
        }


def match_cost(seed: int) -> float:
    """Wall ms of one scan match (median of 20) against the map BuildMap made."""
    with lunar(seed=seed) as world:
        agent = Agent("scout", WorldModel("scout", clock=world.clock), {})
        build = behaviour(world, agent, "BuildMap", {"resolution": RESOLUTION, "radius": 5.0, "max_range": MAP_RANGE})
        while build.status.value not in ("SUCCESS", "FAILURE"):
            build.tick_once()
            world.step(TICK)
        grid = team_map(agent.wm)
        assert grid is not None
        robot = world.robots["scout"]
        ranges, angles = lidar(robot, 720, 15.0)
        x, y, yaw = robot.pose
        costs = []
        for _ in range(20):
            t0 = time.perf_counter()
            match_scan(grid, (x + 0.2, y - 0.1, yaw + 0.03), ranges, angles, 15.0)
            costs.append(time.perf_counter() - t0)
        return 1000.0 * statistics.median(costs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=10, help="seeds (lunar fields) per figure")
    parser.add_argument("--map-seconds", type=float, default=30.0, help="simulated seconds of the team's mapping drive")
    parser.add_argument("--distance", type=float, default=DRIVE_DISTANCE, help="metres driven for the localization")
    parser.add_argument("--only", choices=("map", "localization"), help="run one of the two figures")
    parser.add_argument("--out-dir", default="build", help="folder of the PNG plots")
    args = parser.parse_args()
    if args.seeds < 1 or not args.map_seconds > 0 or not args.distance > 0:
        raise SystemExit("--seeds must be >= 1, --map-seconds and --distance > 0")
    seeds = list(range(args.seeds))
    out = Path(args.out_dir)
    if args.only != "localization":
        map_table(seeds, args.map_seconds, out)
    if args.only != "map":
        localization_table(seeds, args.distance, out)


def map_table(seeds: list[int], seconds: float, out: Path) -> None:
    """The Map table and ``perception_map.png``."""
    t0 = time.perf_counter()
    rows = [map_row(s, seconds) for s in seeds]
    print(f"### Map (lunar, 60 rocks, {len(seeds)} seeds, resolution {RESOLUTION} m)\n")
    print("| figure | median | worst | goal |")
    print("|---|---|---|---|")
    build = [r["build"] for r in rows]
    drive = [r["drive"] for r in rows]
    strict = [r["strict"] for r in rows]
    print(
        f"| cell agreement after BuildMap (observed cells) | {100 * statistics.median(build):.2f} % | {100 * min(build):.2f} % | >= 95 % |"
    )
    print(
        f"| the same without the one-cell tolerance | {100 * statistics.median(strict):.2f} % | {100 * min(strict):.2f} % | |"
    )
    print(
        f"| cell agreement after {seconds:g} s of 3 robots mapping | {100 * statistics.median(drive):.2f} % "
        f"| {100 * min(drive):.2f} % | >= 95 % |"
    )
    known = [r["known"] for r in rows]
    print(f"| field known after the drive | {100 * statistics.median(known):.1f} % | {100 * min(known):.1f} % | |")
    cost = [r["update_ms"] for r in rows]
    print(f"| grid update per scan ({N_RAYS} rays, 10 m) | {statistics.median(cost):.1f} ms | {max(cost):.1f} ms | |")
    rate = [r["bytes_s"] for r in rows]
    print(
        f"| map sharing per robot (2 scans/s, tiles published once a second, driving) | {statistics.median(rate) / 1000:.1f} kB/s | {max(rate) / 1000:.1f} kB/s | |"
    )
    print(f"| replicas with identical team maps | {sum(r['same'] for r in rows):.0f} / {len(rows)} | | all |")
    ok = min(build) >= 0.95 and min(drive) >= 0.95
    print(
        f"\nGoal: cell agreement >= 95 % on every seed: {'met' if ok else 'MISSED'} ({time.perf_counter() - t0:.0f} s wall)"
    )
    plot_map(rows[0], seeds[0], seconds, out / "perception_map.png")


def localization_table(seeds: list[int], distance: float, out: Path) -> None:
    """The Localization table and ``perception_localization.png``."""
    t0 = time.perf_counter()
    res = [localization_row(s, distance=distance) for s in seeds]
    print(f"\n### Localization (lunar, 60 rocks, {len(seeds)} seeds, 2 % odometry drift, {distance:g} m driven)\n")
    print("| | median error | worst error | median heading error | goal |")
    print("|---|---|---|---|---|")
    for label, key, yaw, goal in (
        ("odometry only (same drive, uncorrected)", "odo_error", "odo_yaw", ""),
        ("with Localize", "error", "yaw", "<= 0.10 m"),
    ):
        err = [r[key] for r in res]
        print(
            f"| {label} | {statistics.median(err):.3f} m | {max(err):.3f} m | {statistics.median([r[yaw] for r in res]):.2f} deg | {goal} |"
        )
    driven = [r["distance"] for r in res]
    print(f"\nDistance driven: {min(driven):.1f} to {max(driven):.1f} m (a drive ends after 600 simulated s at most).")
    med = statistics.median([r["error"] for r in res])
    print(f"Goal: median error <= 0.10 m with Localize: {med:.3f} m -> {'met' if med <= 0.10 else 'MISSED'}")
    print(f"One scan match (720 rays, 15 m, ICP): {match_cost(seeds[0]):.1f} ms (median of 20, wall).")
    print(f"({time.perf_counter() - t0:.0f} s wall)")
    plot_localization(res, seeds, distance, out / "perception_localization.png")


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_map(row: dict[str, Any], seed: int, seconds: float, path: Path) -> None:
    """The team map next to the ground truth; the observed area outlined, disagreeing cells in red."""
    from matplotlib.colors import ListedColormap
    from scipy.ndimage import binary_dilation, binary_erosion

    plt = _pyplot()
    occ, truth, origin, res = row["images"]
    ny, nx = occ.shape
    extent = (origin[0], origin[0] + nx * res, origin[1], origin[1] + ny * res)
    known = occ >= 0
    good = np.where(occ == 1, binary_dilation(truth, iterations=1), ~binary_erosion(truth, iterations=1))
    wrong = known & ~good
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 6))
    # team map: unknown grey, free white, occupied black
    left.imshow(occ + 1, origin="lower", extent=extent, cmap=ListedColormap(["0.6", "white", "black"]), vmin=0, vmax=2)
    left.set_title(f"team map of 3 robots (BuildMap + {seconds:g} s driving), seed {seed}\n(grey: unknown)", fontsize=9)
    right.imshow(truth, origin="lower", extent=extent, cmap=ListedColormap(["white", "black"]), vmin=0, vmax=1)
    right.imshow(np.where(known, np.nan, 1.0), origin="lower", extent=extent, cmap=ListedColormap(["0.5"]), alpha=0.45)
    xs = origin[0] + (np.arange(nx) + 0.5) * res
    ys = origin[1] + (np.arange(ny) + 0.5) * res
    right.contour(xs, ys, known.astype(float), levels=[0.5], colors="tab:blue", linewidths=0.8)
    wy, wx = np.nonzero(wrong)
    right.scatter(xs[wx], ys[wy], s=1, c="red", marker="s", linewidths=0)
    rx, ry = zip(*row["robots"], strict=True)
    right.scatter(rx, ry, s=40, facecolors="none", edgecolors="tab:green", label="robots at the end (truth: occupied)")
    right.legend(fontsize=8, loc="lower left")
    right.set_title(
        f"ground truth; observed area outlined (grey: not observed)\n"
        f"{int(wrong.sum())} of {int(known.sum())} known cells disagree (red): {100 * row['drive']:.2f} % agree",
        fontsize=9,
    )
    for ax in (left, right):
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    print(f"plot: {path}")


def plot_localization(res: list[dict[str, Any]], seeds: list[int], distance: float, path: Path) -> None:
    """Position error against the distance driven: corrected by Localize and odometry alone."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    grid = np.linspace(0.0, distance, 101)
    for key, colour, label in ((2, "tab:red", "odometry only"), (1, "tab:blue", "with Localize")):
        ys = []
        for r in res:
            d = np.array([t[0] for t in r["trace"]])
            e = np.array([t[key] for t in r["trace"]])
            ax.plot(d, e, color=colour, lw=0.6, alpha=0.35)
            ys.append(np.interp(grid, d, e))
        ax.plot(grid, np.median(ys, axis=0), color=colour, lw=2, label=f"{label}, median of {len(seeds)} seeds")
    ax.axhline(0.10, color="grey", lw=0.8, ls="--", label="goal 0.10 m")
    ax.set_yscale("log")
    ax.set_ylim(bottom=1e-3)
    ax.set_xlabel("distance driven (m)")
    ax.set_ylabel("position error (m)")
    ax.set_title("Scout, 2 % odometry drift, lunar field (60 rocks)", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    print(f"plot: {path}")


if __name__ == "__main__":
    main()
