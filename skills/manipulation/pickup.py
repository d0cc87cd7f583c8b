"""Pick-up and put-down planning as data: configurations and joint paths, nothing executed.

A pick-up plan has three paths, to be executed in order::

    paths[0]  q_start -> q_pregrasp     free motion; the object is an obstacle
    paths[1]  q_pregrasp -> q_grasp     straight down to the grasp (gripper open)
              -- close the gripper, attach the object --
    paths[2]  q_grasp -> q_transport    straight up to q_pregrasp, then a free motion, holding it

A put-down plan likewise::

    paths[0]  q_start -> q_above        free motion holding the object
    paths[1]  q_above -> q_place        straight down, the object ``PLACE_CLEARANCE`` over its support
              -- open the gripper, detach the object --
    paths[2]  q_place -> q_transport    straight up to q_above, then a free motion; the object is an obstacle

The scene's obstacles are changed during planning (the object added or
removed) and restored before returning.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from alica.skills.manipulation.arm_paths import interpolate_path, path_is_free, plan_arm
from alica.skills.manipulation.cartesian import straight_line
from alica.skills.manipulation.geometry import Pose, as_configuration, as_vec3, wrap_angle
from alica.skills.manipulation.grasps import (
    APPROACH_HEIGHT,
    Grasp,
    held_box,
    place_poses,
    placed_box,
    top_grasps,
)
from alica.skills.manipulation.ik import solve_ik
from alica.worldsim.arm_interface import ArmPlanningScene
from alica.worldsim.geometry import Box

log = logging.getLogger(__name__)

#: While lifting, the held object is checked only once it is this high above where it rested.
LIFT_CLEARANCE = 0.015


@dataclass(frozen=True, slots=True, eq=False)
class PickupPlan:
    """Result of :func:`plan_pickup` (see the module doc for the meaning of ``paths``).

    Attributes:
        ok: a complete plan was found.
        grasp: the grasp used.
        q_pregrasp: configuration above the object.
        q_grasp: configuration at the grasp.
        paths: three (N, 7) joint paths when ok, else empty.
        reason: ``"ok"`` or why planning failed.
        held: the object as a box in the tool frame (pass it to :func:`plan_place`).
        plan_time_s: wall time of the whole planning, seconds.
    """

    ok: bool
    grasp: Grasp | None
    q_pregrasp: np.ndarray | None
    q_grasp: np.ndarray | None
    paths: list[np.ndarray]
    reason: str
    held: Box | None = None
    plan_time_s: float = 0.0


@dataclass(frozen=True, slots=True, eq=False)
class PlacePlan:
    """Result of :func:`plan_place` (see the module doc for the meaning of ``paths``).

    Attributes:
        ok: a complete plan was found.
        place_pose: tool pose at release.
        q_above: configuration above the place pose.
        q_place: configuration at release.
        placed: where the object will rest (a world box on the support).
        paths: three (N, 7) joint paths when ok, else empty.
        reason: ``"ok"`` or why planning failed.
        plan_time_s: wall time of the whole planning, seconds.
    """

    ok: bool
    place_pose: Pose | None
    q_above: np.ndarray | None
    q_place: np.ndarray | None
    placed: Box | None
    paths: list[np.ndarray]
    reason: str
    plan_time_s: float = 0.0


@contextmanager
def _obstacles(scene: ArmPlanningScene) -> Iterator[tuple[Box, ...]]:
    """Yield the scene's obstacles and restore them afterwards."""
    original = scene.obstacles
    try:
        yield original
    finally:
        scene.set_obstacles(original)


def _natural_order(scene: ArmPlanningScene, xy: Sequence[float], yaws: Sequence[float]) -> list[int]:
    """Indices of ``yaws`` sorted by how close each is to the tool yaw of a plain reach towards ``xy``."""
    base = scene.base_pose()[0]
    heading = math.atan2(xy[1] - base[1], xy[0] - base[0])
    return sorted(range(len(yaws)), key=lambda i: abs(wrap_angle(yaws[i] - heading)))


def _summary(failures: list[tuple[str, str]], what: str) -> str:
    """One line from ``(label, problem)`` pairs, equal problems merged: ``problem (label, label)``."""
    if not failures:
        return f"no {what} to try"
    labels: dict[str, list[str]] = {}
    for label, problem in failures:
        labels.setdefault(problem, [])
        if label not in labels[problem]:
            labels[problem].append(label)
    parts = [f"{problem} ({', '.join(names)})" for problem, names in labels.items()]
    more = f"; ... ({len(parts) - 4} more)" if len(parts) > 4 else ""
    return f"no {what} worked: " + "; ".join(parts[:4]) + more


def _lift_is_free(scene: ArmPlanningScene, descent: np.ndarray, held: Box, z_grasp: float) -> bool:
    """Check the reversed descent holding ``held``, from ``LIFT_CLEARANCE`` above the grasp height ``z_grasp``.

    The lift retraces the descent, which was checked without the object; the
    object rises vertically out of its own footprint, so only its first
    ``LIFT_CLEARANCE`` (where it still touches its support) is not checked with it.
    """
    samples = interpolate_path(descent[::-1])
    low = 0
    while low < len(samples) and scene.fk(samples[low])[0][2] - z_grasp < LIFT_CLEARANCE:
        low += 1  # the tool rises monotonically: only the first few samples are this low
    return not any(scene.collides(q, held) for q in samples[low:].tolist())


def plan_pickup(
    scene: ArmPlanningScene,
    object_box: Box,
    q_start: Sequence[float] | np.ndarray,
    *,
    rng: np.random.Generator,
    retries: int = 1,
    q_transport: Sequence[float] | np.ndarray | None = None,
    kind: str = "box",
    approach_height: float = APPROACH_HEIGHT,
    time_limit: float = 1.0,
    seed: int | None = None,
) -> PickupPlan:
    """Plan picking up ``object_box`` from the top and carrying it to ``q_transport``.

    Grasps are tried in order of wrist comfort; for each, up to ``1 + retries``
    pre-grasp IK solutions (the first seeded at the rest pose, then at random
    configurations) are tried with the rest of the plan.

    Args:
        scene: the arm scene; ``object_box`` may or may not be among its obstacles.
        object_box: the object (world box, upright) to pick.
        q_start: the arm's current configuration.
        rng: generator for IK restarts (plans are deterministic for equal generators,
            except for OMPL paths, see :mod:`alica.skills.manipulation.arm_paths`).
        retries: extra pre-grasp IK solutions per grasp (>= 0).
        q_transport: configuration to carry the object in (default ``scene.home_q``).
        kind: ``"box"`` or ``"cylinder"`` (see :func:`top_grasps`).
        approach_height: height of the pre-grasp pose over the grasp, metres.
        time_limit: budget of each free-motion planning query, seconds.
        seed: OMPL seed (see :func:`plan_arm`).

    Raises:
        ValueError: malformed arguments.
        TypeError: ``object_box`` is not a Box.
    """
    t0 = time.perf_counter()
    if not isinstance(object_box, Box):
        raise TypeError(f"object_box must be a Box, got {object_box!r}")
    if int(retries) != retries or retries < 0:
        raise ValueError(f"retries must be a non-negative integer, got {retries!r}")
    start = as_configuration(q_start, 7, "q_start")
    transport = scene.home_q if q_transport is None else as_configuration(q_transport, 7, "q_transport")

    def fail(reason: str) -> PickupPlan:
        return PickupPlan(False, None, None, None, [], reason, None, time.perf_counter() - t0)

    grasps = top_grasps(
        object_box.center,
        object_box.half_extents,
        object_box.yaw,
        kind=kind,  # type: ignore[arg-type]
        approach_height=approach_height,
        max_width=scene.max_grasp_width - 2.0 * scene.margin,
    )
    if not grasps:
        return fail(f"{object_box.name!r} is wider than the gripper opens ({scene.max_grasp_width:.3f} m)")
    order = _natural_order(scene, object_box.center, [g.yaw for g in grasps])
    failures: list[tuple[str, str]] = []
    with _obstacles(scene) as original:
        others = [b for b in original if b.name != object_box.name]
        with_object = others + [object_box]
        scene.set_obstacles(with_object)
        if scene.collides(start):
            return fail("start configuration in collision")
        for index in order:
            grasp = grasps[index]
            label = f"grasp yaw {grasp.yaw:+.2f}"
            for attempt in range(int(retries) + 1):
                seed_q = None if attempt == 0 else scene.random_configuration(rng)
                pre = solve_ik(scene, grasp.approach_pose[0], grasp.approach_pose[1], rng=rng, q_seed=seed_q)
                if not pre.ok or pre.q is None:
                    failures.append((label, f"pre-grasp IK: {pre.reason}"))
                    break
                descent, why = straight_line(scene, pre.q, grasp.pose, rng=rng)
                if descent is None:
                    failures.append((label, f"descent: {why}"))
                    continue
                if not path_is_free(scene, descent):
                    failures.append((label, "descent in collision"))
                    continue
                q_grasp = descent[-1]
                grasp_pose = scene.fk(q_grasp)
                held = held_box(object_box, grasp_pose)
                scene.set_obstacles(others)
                lift_ok = _lift_is_free(scene, descent, held, grasp_pose[0][2])
                carry = (
                    plan_arm(scene, pre.q, transport, held=held, time_limit=time_limit, seed=seed) if lift_ok else None
                )
                scene.set_obstacles(with_object)
                if not lift_ok:
                    failures.append((label, "lift in collision with the object held"))
                    continue
                assert carry is not None
                if not carry.ok:
                    failures.append((label, f"transport: {carry.reason}"))
                    if carry.status == "invalid_goal":
                        break
                    continue
                approach = plan_arm(scene, start, pre.q, time_limit=time_limit, seed=seed)
                if not approach.ok:
                    failures.append((label, f"approach: {approach.reason}"))
                    continue
                lift_and_carry = np.concatenate([descent[::-1], carry.path[1:]])
                return PickupPlan(
                    True,
                    grasp,
                    pre.q,
                    q_grasp,
                    [approach.path, descent, lift_and_carry],
                    "ok",
                    held,
                    time.perf_counter() - t0,
                )
    return fail(_summary(failures, f"grasp of {object_box.name!r}"))


def plan_place(
    scene: ArmPlanningScene,
    held: Box,
    target_top_center: Sequence[float],
    q_start: Sequence[float] | np.ndarray,
    *,
    rng: np.random.Generator,
    object_yaw: float | None = None,
    q_transport: Sequence[float] | np.ndarray | None = None,
    approach_height: float = APPROACH_HEIGHT,
    time_limit: float = 1.0,
    seed: int | None = None,
) -> PlacePlan:
    """Plan putting the held object down with its bottom centre at ``target_top_center``.

    Args:
        scene: the arm scene (the support, e.g. a block, should be one of its obstacles).
        held: the object as a tool-frame box (``PickupPlan.held``).
        target_top_center: point on the support's top face under the object's centre
            (on the ground: z = 0; on a block: the centre of its top face).
        q_start: the arm's current configuration (holding the object).
        rng: generator for IK restarts.
        object_yaw: desired world yaw of the placed object (default: any of eight tool yaws).
        q_transport: configuration to go to after releasing (default ``scene.home_q``).
        approach_height: height of the pose above the place pose, metres.
        time_limit: budget of each free-motion planning query, seconds.
        seed: OMPL seed (see :func:`plan_arm`).

    Raises:
        ValueError: malformed arguments.
        TypeError: ``held`` is not a Box.
    """
    t0 = time.perf_counter()
    if not isinstance(held, Box):
        raise TypeError(f"held must be a Box, got {held!r}")
    target = as_vec3(target_top_center, "target_top_center")
    start = as_configuration(q_start, 7, "q_start")
    transport = scene.home_q if q_transport is None else as_configuration(q_transport, 7, "q_transport")
    if object_yaw is None:
        yaws = [k * math.pi / 4.0 for k in range(8)]
    else:
        square = math.isclose(held.half_extents[0], held.half_extents[1], rel_tol=1e-6)
        yaws = [float(object_yaw) + held.yaw + k * math.pi / 2.0 for k in range(4) if square or k % 2 == 0]
    poses = place_poses(target, held.half_extents, held.center, yaws=yaws)
    order = _natural_order(scene, target, [yaws[i] for i in range(len(poses))])

    def fail(reason: str) -> PlacePlan:
        return PlacePlan(False, None, None, None, None, [], reason, time.perf_counter() - t0)

    failures: list[tuple[str, str]] = []
    with _obstacles(scene) as original:
        others = [b for b in original if b.name != held.name]
        scene.set_obstacles(others)
        if scene.collides(start, held):
            return fail("start configuration in collision (holding the object)")
        for index in order:
            pose = poses[index]
            label = f"tool yaw {wrap_angle(yaws[index]):+.2f}"
            above = ((pose[0][0], pose[0][1], pose[0][2] + approach_height), pose[1])
            ik = solve_ik(scene, above[0], above[1], rng=rng, held=held)
            if not ik.ok or ik.q is None:
                failures.append((label, f"IK above the place: {ik.reason}"))
                continue
            descent, why = straight_line(scene, ik.q, pose, rng=rng)
            if descent is None:
                failures.append((label, f"descent: {why}"))
                continue
            if not path_is_free(scene, descent, held):
                failures.append((label, "descent in collision holding the object"))
                continue
            q_place = descent[-1]
            release = placed_box(held, scene.fk(q_place))
            resting = Box(
                held.name,
                (release.center[0], release.center[1], target[2] + held.half_extents[2]),
                held.half_extents,
                release.yaw,
            )
            scene.set_obstacles(others + [resting])
            retreat_ok = path_is_free(scene, descent[::-1])
            carry = plan_arm(scene, ik.q, transport, time_limit=time_limit, seed=seed) if retreat_ok else None
            scene.set_obstacles(others)
            if not retreat_ok:
                failures.append((label, "retreat in collision with the placed object"))
                continue
            assert carry is not None
            if not carry.ok:
                failures.append((label, f"transport: {carry.reason}"))
                continue
            approach = plan_arm(scene, start, ik.q, held=held, time_limit=time_limit, seed=seed)
            if not approach.ok:
                failures.append((label, f"approach: {approach.reason}"))
                continue
            return PlacePlan(
                True,
                pose,
                ik.q,
                q_place,
                resting,
                [approach.path, descent, np.concatenate([descent[::-1], carry.path[1:]])],
                "ok",
                time.perf_counter() - t0,
            )
    return fail(_summary(failures, f"place pose for {held.name!r}"))
