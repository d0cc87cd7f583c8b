"""Simulation speed of the lunar scenario: real-time factor with 3 robots driving and one arm moving (goal: >= 20x).

Each setting builds ``alica.worldsim.scenarios.lunar`` (60 rocks, 2 samples, seed 0),
then simulates ``--seconds`` seconds in 0.1 s chunks (as a 10 Hz skill loop
would): scout, stummel and amparo drive circles of 1 m radius in the start
area (commands re-sent every chunk) while stummel's Panda follows a 7-joint
path back and forth. The table gives physics steps per wall second and the
real-time factor (simulated seconds per wall second), the median of
``--repeat`` runs, for time steps 1/240 and 1/120 and 50 (pybullet's default)
or 10 solver iterations.

The peer, in the same run: the same field with the three robots loaded as
``pybullet_data`` ``husky/husky.urdf`` driven by wheel velocity motors (the
motion notes measured about 9x for three huskies), without an arm and with one
fixed Panda following the same path on position motors.

Run: ``.venv/bin/python bench/sim_speed.py [--seconds 10] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pybullet_data

from alica.worldsim._quiet import quiet_stdout
from alica.worldsim.scenarios import lunar
from alica.worldsim.world import World

CHUNK = 0.1
V, W = 0.4, 0.4  # 1 m turning circles
HUSKY_WHEEL_RADIUS = 0.1651
HUSKY_TRACK = 0.5708
HUSKY_WHEELS = (2, 3, 4, 5)  # front left, front right, rear left, rear right


@dataclass(frozen=True, slots=True)
class Row:
    """One line of the table."""

    label: str
    time_step: float
    solver: int | None
    steps_per_s: float
    rtf: float
    bumps: int


def arm_path(home: np.ndarray) -> np.ndarray:
    """A there-and-back path through 40 waypoints, about 2.5 s at the joint speed limits."""
    goal = home + np.array([0.9, 0.6, -0.4, 0.7, 0.5, -0.6, 0.8])
    there = np.linspace(home, goal, 20)
    return np.vstack([there, there[::-1]])


def build_ours(time_step: float, solver: int | None) -> tuple[World, Callable[[], int]]:
    """Our kinematic robots; returns the world and a function that runs one chunk (returns bumps)."""
    world = lunar(seed=0, time_step=time_step)
    if solver is not None:
        world.client.setPhysicsEngineParameter(numSolverIterations=solver)
    robots = list(world.robots.values())
    arm = world.robots["stummel"].arm
    assert arm is not None
    path = arm_path(arm.home_q)

    def chunk() -> int:
        bumps = 0
        for r in robots:
            bumps += int(r.bumped)
            r.drive(V, W)
        if not arm.busy:
            arm.follow(path)
        world.step(CHUNK)
        return bumps

    return world, chunk


def build_husky(time_step: float, solver: int | None, with_arm: bool) -> tuple[World, Callable[[], int]]:
    """The peer: the same field, the robots as huskies on wheel motors (and a fixed Panda on position motors)."""
    world = lunar(seed=0, time_step=time_step)
    c = world.client
    if solver is not None:
        c.setPhysicsEngineParameter(numSolverIterations=solver)
    poses = {n: r.pose for n, r in world.robots.items()}
    home = world.robots["stummel"].arm.home_q  # type: ignore[union-attr]
    for name in list(world.robots):
        world.remove(name)
    huskies = []
    with quiet_stdout():
        for x, y, yaw in poses.values():
            huskies.append(
                c.loadURDF(
                    os.path.join(pybullet_data.getDataPath(), "husky/husky.urdf"),
                    (x, y, 0.2),
                    c.getQuaternionFromEuler((0.0, 0.0, yaw)),
                )
            )
        panda = (
            c.loadURDF(
                os.path.join(pybullet_data.getDataPath(), "franka_panda/panda.urdf"),
                (0.0, -4.0, 0.0),
                useFixedBase=True,
            )
            if with_arm
            else None
        )
    left = (V - 0.5 * W * HUSKY_TRACK) / HUSKY_WHEEL_RADIUS
    right = (V + 0.5 * W * HUSKY_TRACK) / HUSKY_WHEEL_RADIUS
    path = arm_path(home)
    dt = world.time_step
    n_steps = round(CHUNK / dt)
    seg = (np.abs(np.diff(path, axis=0)) / 2.175).max(axis=1)
    times = np.concatenate([[0.0], np.cumsum(seg)])
    state = {"t": 0.0}
    joints = list(range(7))
    step = c.stepSimulation
    motor = c.setJointMotorControlArray

    def chunk() -> int:
        for h in huskies:
            motor(
                h,
                list(HUSKY_WHEELS),
                c.VELOCITY_CONTROL,
                targetVelocities=[left, right, left, right],
                forces=[50.0] * 4,
            )
        for _ in range(n_steps):
            if panda is not None:
                state["t"] = (state["t"] + dt) % times[-1]
                q = [float(np.interp(state["t"], times, path[:, j])) for j in joints]
                motor(panda, joints, c.POSITION_CONTROL, targetPositions=q, forces=[87.0] * 7)
            step()
        world.clock.advance(n_steps * dt)
        return 0

    return world, chunk


def measure(
    label: str,
    build: Callable[[], tuple[World, Callable[[], int]]],
    seconds: float,
    repeat: int,
    time_step: float,
    solver: int | None,
) -> Row:
    """Median steps/s and real-time factor over ``repeat`` fresh worlds."""
    rates, bumps = [], 0
    chunks = max(1, round(seconds / CHUNK))
    for _ in range(repeat):
        world, chunk = build()
        try:
            for _ in range(5):  # warm-up
                chunk()
            start_time = world.now()
            t0 = time.perf_counter()
            for _ in range(chunks):
                bumps += chunk()
            wall = time.perf_counter() - t0
            rates.append((world.now() - start_time, wall))
        finally:
            world.close()
    rtf = statistics.median(s / w for s, w in rates)
    steps = statistics.median(s / w / time_step for s, w in rates)
    return Row(label, time_step, solver, steps, rtf, bumps)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per run")
    parser.add_argument("--repeat", type=int, default=5, help="runs per setting (median)")
    args = parser.parse_args()
    rows: list[Row] = []
    for time_step in (1.0 / 240.0, 1.0 / 120.0):
        for solver in (None, 10):
            rows.append(
                measure(
                    "worldsim: 3 kinematic robots + 1 Panda moving",
                    lambda ts=time_step, s=solver: build_ours(ts, s),
                    args.seconds,
                    args.repeat,
                    time_step,
                    solver,
                )
            )
    for solver in (None, 10):
        rows.append(
            measure(
                "peer: 3 huskies on wheel motors",
                lambda s=solver: build_husky(1 / 240, s, False),
                args.seconds,
                args.repeat,
                1 / 240,
                solver,
            )
        )
    rows.append(
        measure(
            "peer: 3 huskies + 1 Panda on position motors",
            lambda: build_husky(1 / 240, None, True),
            args.seconds,
            args.repeat,
            1 / 240,
            None,
        )
    )
    print(f"Lunar scenario (60 rocks, 2 samples), {args.seconds:g} s simulated per run, median of {args.repeat} runs\n")
    print("| setting | time step | solver iterations | steps/s | real-time factor |")
    print("| --- | --- | --- | --- | --- |")
    for r in rows:
        solver = "50 (default)" if r.solver is None else str(r.solver)
        print(f"| {r.label} | 1/{round(1 / r.time_step)} | {solver} | {r.steps_per_s:,.0f} | {r.rtf:.1f}x |")
    bumps = sum(r.bumps for r in rows)
    if bumps:
        print(f"\n(robots bumped {bumps} times; their commands were re-sent every {CHUNK} s)")
    goal = rows[0].rtf
    print(f"\nGoal >= 20x at 1/240 with default settings: {'met' if goal >= 20 else 'NOT met'} ({goal:.1f}x).")


if __name__ == "__main__":
    main()
