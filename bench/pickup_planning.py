"""Benchmark of the manipulation planning: IK, arm paths and whole pick-up plans.

Run with ``.venv/bin/python bench/pickup_planning.py`` (``--cases`` and ``--seed``
to change the workload). The arm is the pybullet_data Franka Panda with its
base 0.3 m above the ground on a box standing for the mobile base. For
``--cases`` random 5 cm blocks on the ground in front of the arm (0.35 to
0.65 m from the base, within +-60 degrees, random yaw) it times, with
``time.perf_counter`` (wall) and ``time.process_time`` (CPU):

* ``solve_ik`` of the first grasp's pre-grasp pose (10 restarts), and the
  same without restarts;
* pybullet's limit-enforcing IK variant (``lowerLimits``/``upperLimits``/
  ``jointRanges``/``restPoses``, 100 iterations, one call from the rest pose),
  its result checked like ours (error, limits, collisions);
* ``plan_arm`` from the transport pose to that pre-grasp configuration, and
  ``plan_arm`` between two configurations on either side of a wall (OMPL);
* ``plan_pickup`` as a whole (IK + straight descent/lift + both free motions).

It also measures IK on random reachable targets (forward kinematics of random
collision-free configurations), the test suite's property. Goals: pick-up
planning median <= 10 ms, IK success >= 95 %. Prints a markdown table.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from alica.skills.manipulation import Box, plan_arm, plan_pickup, solve_ik, top_down_quat, top_grasps
from alica.skills.manipulation.geometry import quat_angle
from alica.worldsim.arm_scene import ArmScene

T = TypeVar("T")

BASE_HEIGHT = 0.3
#: The mobile base under the arm; the arm is mounted 0.15 m behind its front edge.
PLATFORM = Box("platform", (-0.1, 0.0, 0.15), (0.25, 0.25, 0.145))
#: Blocks are placed this far from the arm base (horizontally), within +-60 degrees.
R_MIN, R_MAX = 0.35, 0.65
WALL = Box("wall", (0.5, 0.0, 0.25), (0.08, 0.03, 0.25))


@dataclass(slots=True)
class Series:
    """Timings (ms) and outcomes of one benchmarked operation."""

    name: str
    wall: list[float] = field(default_factory=list)
    cpu: list[float] = field(default_factory=list)
    ok: list[bool] = field(default_factory=list)

    def run(self, fn: Callable[..., T], *args: Any, **kwargs: Any) -> T:
        """Time ``fn(*args, **kwargs)``; its result's truth (or ``.ok``) is the outcome."""
        w, c = time.perf_counter(), time.process_time()
        result = fn(*args, **kwargs)
        self.cpu.append((time.process_time() - c) * 1e3)
        self.wall.append((time.perf_counter() - w) * 1e3)
        self.ok.append(bool(getattr(result, "ok", result)))
        return result


def _p95(xs: list[float]) -> float:
    return float(np.percentile(xs, 95)) if xs else math.nan


def _row(s: Series) -> str:
    rate = 100.0 * sum(s.ok) / len(s.ok) if s.ok else math.nan
    return (
        f"| {s.name} | {len(s.ok)} | {rate:.1f} % | {statistics.median(s.wall):.2f} | {_p95(s.wall):.2f} "
        f"| {statistics.median(s.cpu):.2f} | {_p95(s.cpu):.2f} |"
    )


def _limit_variant_ik(scene: ArmScene, pos: tuple, quat: tuple) -> bool:
    """pybullet's null-space IK with the joint limits, checked like :func:`solve_ik` (5 mm, 0.02 rad)."""
    lower, upper = scene.joint_limits
    extra = len(scene.arm_model.movable_joints) - 7
    lo = list(lower) + [0.0] * extra
    hi = list(upper) + [0.04] * extra
    scene.set_joints(scene.rest_q)
    sol = scene.client.calculateInverseKinematics(
        scene.robot_id,
        scene.arm_model.ee_link,
        pos,
        quat,
        lowerLimits=lo,
        upperLimits=hi,
        jointRanges=[h - lw for lw, h in zip(lo, hi)],
        restPoses=list(scene.rest_q) + [0.04] * extra,
        maxNumIterations=100,
        residualThreshold=1e-7,
    )
    q = np.array(sol[:7])
    p, o = scene.fk(q)
    if np.linalg.norm(np.array(p) - np.array(pos)) > 0.005 or quat_angle(o, quat) > 0.02:
        return False
    if np.any(q < lower) or np.any(q > upper):
        return False
    return not scene.collides(q)


def _blocks(rng: np.random.Generator, n: int) -> list[Box]:
    out = []
    for i in range(n):
        r = rng.uniform(R_MIN, R_MAX)
        a = rng.uniform(-math.pi / 3.0, math.pi / 3.0)
        out.append(
            Box(f"block{i}", (r * math.cos(a), r * math.sin(a), 0.025), (0.025,) * 3, rng.uniform(-math.pi, math.pi))
        )
    return out


def main(argv: list[str] | None = None) -> None:
    """Run the benchmark and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=300)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)

    scene = ArmScene(base_pose=((0.0, 0.0, BASE_HEIGHT), (0.0, 0.0, 0.0, 1.0)), obstacles=[PLATFORM])
    rng = np.random.default_rng(args.seed)
    ik10 = Series("IK, pre-grasp pose, 10 restarts")
    ik0 = Series("IK, pre-grasp pose, no restarts")
    iklim = Series("pybullet limit-enforcing IK, pre-grasp pose")
    path = Series("plan_arm transport -> pre-grasp")
    pickup = Series("plan_pickup (IK + paths)")
    fk10 = Series("IK, random reachable targets, 10 restarts")
    fk0 = Series("IK, random reachable targets, no restarts")
    fklim = Series("pybullet limit-enforcing IK, random targets")
    wall = Series("plan_arm around a wall (RRTConnect)")
    direct = 0

    for block in _blocks(rng, args.cases):
        scene.set_obstacles([PLATFORM, block])
        grasp = top_grasps(block.center, block.half_extents, block.yaw)[0]
        pos, quat = grasp.approach_pose
        ik = ik10.run(solve_ik, scene, pos, quat, rng=rng)
        ik0.run(solve_ik, scene, pos, quat, rng=rng, restarts=0)
        iklim.run(_limit_variant_ik, scene, pos, quat)
        if ik.ok:
            arm = path.run(plan_arm, scene, scene.home_q, ik.q, seed=args.seed)
            direct += arm.reason.startswith("direct")
        pickup.run(plan_pickup, scene, block, scene.home_q, rng=rng, seed=args.seed)

    scene.set_obstacles([PLATFORM])
    targets = []
    while len(targets) < args.cases:
        q = scene.random_configuration(rng)
        if not scene.collides(q):
            targets.append(scene.fk(q))
    for pos, quat in targets:
        fk10.run(solve_ik, scene, pos, quat, rng=rng)
        fk0.run(solve_ik, scene, pos, quat, rng=rng, restarts=0)
        fklim.run(_limit_variant_ik, scene, pos, quat)

    wall_scene = ArmScene(obstacles=[WALL])
    for _ in range(min(args.cases, 50)):
        y = 0.2 + 0.1 * rng.random()
        a = solve_ik(wall_scene, (0.5, y, 0.15), top_down_quat(0.0), rng=rng)
        b = solve_ik(wall_scene, (0.5, -y, 0.15), top_down_quat(0.0), rng=rng)
        if a.ok and b.ok:
            wall.run(plan_arm, wall_scene, a.q, b.q, seed=args.seed)
    wall_scene.close()
    scene.close()

    print(f"Pick-up planning benchmark: {args.cases} blocks, seed {args.seed}, Franka Panda, base at {BASE_HEIGHT} m")
    print()
    print("| operation | runs | success | median ms | p95 ms | median CPU ms | p95 CPU ms |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for s in (ik10, ik0, iklim, fk10, fk0, fklim, path, wall, pickup):
        print(_row(s))
    print()
    print(f"transport -> pre-grasp: {direct} of {len(path.ok)} paths were the direct segment (no OMPL call)")
    med = statistics.median(pickup.wall)
    rate = 100.0 * sum(ik10.ok) / len(ik10.ok)
    print(
        f"goal pick-up median <= 10 ms: {'met' if med <= 10.0 else 'NOT met'} ({med:.2f} ms); "
        f"goal IK success >= 95 %: {'met' if rate >= 95.0 else 'NOT met'} ({rate:.1f} %)"
    )


if __name__ == "__main__":
    main()
