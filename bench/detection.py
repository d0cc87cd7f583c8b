"""Benchmark of sample detection (issue 16's Detection figure): the Verify2DObject tables and confusion matrix.

Run with ``.venv/bin/python bench/detection.py`` (``--seeds 10``, ``--lidar-sigma 0.01``,
``--out build/detection_confusion.png``).

For every seed, a lunar field (40 m, 60 rocks) gets one sample of each of the
six kinds around Scout, 1-5 m away in any direction (its camera has a pan
unit), plus three more rocks and Amparo (a red robot of 0.35 m radius) among
them; Stummel stands where the field puts it. The lidar has 1 cm range noise
(``SensorNoise.lidar_sigma``), the camera its default pixel noise; the skills
place what they see by the robot's pose estimate (``robot.estimate``). Scout
then runs the Verify2DObject steps with the parameters of
``plans/skills/verify_2d_object.yaml`` (DetectCircles waiting for an
unverified candidate within 5 m, CropCandidate turning the camera to it,
BlobDetect, ClassifySample), over and over as LookForSamples does, until
DetectCircles finds no unverified candidate. Ground truth scores the result
only: a reported ``found(s)`` is a true positive when it lies within 0.2 m
of a sample not matched yet; any other is a rock or robot reported as a
sample.

Printed (markdown): precision, recall and kind accuracy within 5 m with the
goals of the issue; the laser stage (candidates, how many were samples); the
confusion table (true kind x reported kind, a row for rocks or robots
reported as samples, a column for missed samples); the cost per scan (lidar
ray cast + circle detection) and per image (turning the camera, rendering
752x480, crop, blobs, decoding), median and p90 in ms, wall time on this
machine. The confusion matrix is also drawn to a PNG.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

PIPELINE = ("DetectCircles", "CropCandidate", "BlobDetect", "ClassifySample")
PLAN = Path(__file__).resolve().parent.parent / "plans" / "skills" / "verify_2d_object.yaml"
#: A reported sample this close (metres) to a true one is that sample.
MATCH = 0.2
#: The row of the confusion matrix for reports where no sample is.
NO_SAMPLE = "rock/robot"


def plan_params() -> dict[str, dict[str, Any]]:
    """The skills' parameters as the Verify2DObject plan gives them."""
    import yaml

    doc = yaml.safe_load(PLAN.read_text(encoding="utf-8"))
    return {b["skill"]: dict(b.get("params") or {}) for b in doc["behaviours"]}


def _clear(xy: tuple[float, float], rocks: list[tuple[float, float, float]], gap: float) -> bool:
    return all(math.dist(xy, (rx, ry)) > rr + gap for rx, ry, rr in rocks)


def _sight(a: tuple[float, float], b: tuple[float, float], rocks: list[tuple[float, float, float]], gap: float) -> bool:
    """No rock (grown by ``gap``) crosses the segment a-b."""
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length2 = dx * dx + dy * dy
    for rx, ry, rr in rocks:
        t = max(0.0, min(1.0, ((rx - ax) * dx + (ry - ay) * dy) / length2))
        if math.dist((ax + t * dx, ay + t * dy), (rx, ry)) < rr + gap:
            return False
    return True


def build_scene(seed: int, lidar_sigma: float) -> tuple[Any, dict[str, tuple[str, tuple[float, float]]]]:
    """A lunar field with six samples (one per kind), three more rocks and Amparo around Scout."""
    from alica.worldsim.objects import SAMPLE_KINDS
    from alica.worldsim.scenarios import lunar

    world = lunar(seed=seed, rocks=60, samples=0)
    world.noise = replace(world.noise, lidar_sigma=lidar_sigma)
    rng = np.random.default_rng([seed, 16])
    sx, sy, yaw = world.robots["scout"].pose
    here = (sx, sy)
    rocks = [(o.position()[0], o.position()[1], o.radius) for o in world.objects.values() if o.kind == "rock"]
    rx, ry, _ = world.robots["stummel"].pose
    rocks.append((rx, ry, world.robots["stummel"].spec.radius))

    def spot(d_lo: float, d_hi: float) -> tuple[float, float, float]:
        d = float(rng.uniform(d_lo, d_hi))
        b = float(rng.uniform(-math.pi, math.pi))
        return sx + d * math.cos(yaw + b), sy + d * math.sin(yaw + b), b

    for k in range(3):  # rocks among the samples
        for _ in range(200):
            x, y, _b = spot(2.0, 6.0)
            r = float(rng.uniform(0.2, 0.5))
            if _clear((x, y), rocks, r + 0.5) and math.dist((x, y), here) > r + 1.0:
                rocks.append((x, y, r))
                world.add_rock(f"near_rock{k + 1}", (x, y), r, seed=int(rng.integers(2**31)))
                break
    for _ in range(200):  # Amparo among them
        x, y, _b = spot(2.5, 5.0)
        if _clear((x, y), rocks, 0.35 + 0.5):
            world.robots["amparo"].set_pose(x, y, float(rng.uniform(-math.pi, math.pi)))
            rocks.append((x, y, 0.35))
            break
    truth: dict[str, tuple[str, tuple[float, float]]] = {}
    bearings: list[float] = []
    for i, kind in enumerate(rng.permutation(SAMPLE_KINDS)):
        for _attempt in range(20000):
            x, y, b = spot(1.0, 5.0)
            if not _clear((x, y), rocks, 0.3):
                continue
            if not _sight(here, (x, y), rocks, 0.1):
                continue
            if any(math.dist((x, y), p) < 0.5 for _, p in truth.values()):
                continue
            if any(abs(math.remainder(b - o, math.tau)) < math.radians(3.0) for o in bearings):  # none hides another
                continue
            bearings.append(b)
            name = "abcdef"[i]
            world.add_sample(name, str(kind), (x, y))
            truth[name] = (str(kind), (x, y))
            break
    world.step(0.2)
    return world, truth


def costs(world: Any, params: dict[str, dict[str, Any]]) -> tuple[float, float]:
    """Wall ms of one scan with circle detection and one picture (camera turned to a candidate) with crop, blobs, decoding."""
    from alica.skills.vision2d import decode_sections, detect_circles, find_blobs
    from alica.worldsim.robot_camera import robot_camera
    from alica.worldsim.sensors import lidar_angles, lidar_scan

    robot = world.robots["scout"]
    detect = params["DetectCircles"]
    t0 = time.perf_counter()
    ranges = lidar_scan(robot, 1440)
    circles = detect_circles(
        ranges,
        lidar_angles(1440),
        robot.estimate,
        radius=float(detect["radius"]),
        tolerance=float(detect["tolerance"]),
        max_range=float(detect["max_range"]),
        scan_range=robot.spec.lidar_range,
        sigma=max(world.noise.lidar_sigma, 0.005),
    )
    t1 = time.perf_counter()
    limit = robot.spec.camera_pan_limit
    pan = max(-limit, min(limit, circles[0].bearing)) if circles else 0.0
    image = robot_camera(robot, width=752, height=480, pan=pan, believed=True)
    if circles:
        u, v, _ = image.project((circles[0].x, circles[0].y, 0.05))
        if math.isfinite(u):
            u0, v0 = max(0, int(u) - 30), max(0, int(v) - 30)
            crop = image.rgb[v0 : v0 + 60, u0 : u0 + 60]
            blobs = find_blobs(crop, ("green", "red"), 12)
            decode_sections(crop, blobs, (20.0, 10.0, 40.0, 50.0))
    t2 = time.perf_counter()
    return 1000.0 * (t1 - t0), 1000.0 * (t2 - t1)


def run_seed(seed: int, lidar_sigma: float, params: dict[str, dict[str, Any]], max_rounds: int = 30) -> dict[str, Any]:
    """Run the steps as the plan does until no unverified candidate is left within reach; score the result."""
    from alica.skills.testing import run_skill
    from alica.skills.vision2d_data import CANDIDATES
    from alica.worldmodel import WorldModel

    world, truth = build_scene(seed, lidar_sigma)
    try:
        wm = WorldModel("scout", clock=world.clock)
        scratch: dict[str, object] = {}
        rounds = 0
        for rounds in range(1, max_rounds + 1):  # noqa: B007 - the count is reported
            for name in PIPELINE:
                run = run_skill(name, world, "scout", params.get(name, {}), scratch=scratch, world_model=wm)
                if not run.ok:
                    break
            if name == "DetectCircles" and not run.ok:  # nothing left to verify (after the plan's wait)
                break
            if name == "CropCandidate" and not run.ok:
                world.step(1.0)  # the plan's LookAgain state
        circles = CANDIDATES.get(scratch) or ()
        ms_scan, ms_image = costs(world, params)
        robots = {n: r.pose[:2] for n, r in world.robots.items() if n != "scout"}
    finally:
        world.close()
    found = []
    for name, args, value in wm.values():
        if name == "pos" and wm.holds("found", args[0]):
            found.append((str(args[0]), str(wm.get("sample_kind", args[0])), (float(value[0]), float(value[1]))))
    free = dict(truth)
    tp, pairs, false = 0, [], []
    for _name, kind, pos in sorted(found):
        best = min(free, key=lambda n: math.dist(free[n][1], pos), default=None)
        if best is not None and math.dist(free[best][1], pos) <= MATCH:
            pairs.append((free[best][0], kind))
            del free[best]
            tp += 1
        else:
            near_robot = any(math.dist(p, pos) < 0.6 for p in robots.values())
            false.append((kind, "robot" if near_robot else "rock"))
    lidar_true = sum(1 for c in circles if min(math.dist(p, (c.x, c.y)) for _, p in truth.values()) <= 0.1)
    return {
        "seed": seed,
        "samples": len(truth),
        "tp": tp,
        "fp": len(false),
        "false": false,
        "missed": [k for k, _ in free.values()],
        "pairs": pairs,
        "candidates": len(circles),
        "candidates_true": lidar_true,
        "invalid": sum(1 for f in wm.facts() if f.predicate == "invalid"),
        "rounds": rounds,
        "ms_scan": ms_scan,
        "ms_image": ms_image,
    }


def confusion(results: list[dict[str, Any]], kinds: tuple[str, ...]) -> np.ndarray:
    """Counts: rows the true kinds and :data:`NO_SAMPLE`, columns the reported kinds and ``missed`` (-1: no cell)."""
    table = np.zeros((len(kinds) + 1, len(kinds) + 1), dtype=int)
    for r in results:
        for t, k in r["pairs"]:
            table[kinds.index(t), kinds.index(k)] += 1
        for m in r["missed"]:
            table[kinds.index(m), len(kinds)] += 1
        for k, _source in r["false"]:
            table[len(kinds), kinds.index(k)] += 1
    table[len(kinds), len(kinds)] = -1  # no sample there to miss
    return table


def plot_confusion(table: np.ndarray, rows: list[str], cols: list[str], title: str, out: Path) -> None:
    """Draw a confusion table as an annotated image (``out``, PNG; missing folders are made; -1: no cell)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(0.75 * len(cols) + 2.5, 0.5 * len(rows) + 2.0))
    shown = np.where(table > 0, table, np.nan)
    ax.imshow(shown, cmap="Blues", vmin=0, vmax=max(1, int(table.max())))
    top = max(1, int(table.max()))
    for i in range(table.shape[0]):
        for j in range(table.shape[1]):
            if table[i, j] >= 0:  # -1: no such cell
                colour = "white" if table[i, j] > 0.6 * top else "black"
                ax.text(j, i, str(table[i, j]), ha="center", va="center", fontsize=9, color=colour)
    ax.set_xticks(range(len(cols)), cols, rotation=35, ha="right", fontsize=8)
    ax.set_yticks(range(len(rows)), rows, fontsize=8)
    ax.set_xlabel("reported")
    ax.set_ylabel("true")
    ax.set_title(title, fontsize=9)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    print(f"\nplot: {out}")


def p90(values: list[float]) -> float:
    """The 90th percentile (nearest rank)."""
    values = sorted(values)
    return values[min(len(values) - 1, int(0.9 * len(values)))]


def main() -> None:
    """Print the Verify2DObject tables and draw the confusion matrix."""
    from alica.worldsim.objects import SAMPLE_KINDS

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--lidar-sigma", type=float, default=0.01)
    parser.add_argument("--out", default="build/detection_confusion.png", help="the confusion matrix PNG")
    args = parser.parse_args()
    params = plan_params()
    results = []
    started = time.perf_counter()
    for seed in range(args.seeds):
        results.append(run_seed(seed, args.lidar_sigma, params))
    wall = time.perf_counter() - started
    tp = sum(r["tp"] for r in results)
    fp = sum(r["fp"] for r in results)
    total = sum(r["samples"] for r in results)
    right = sum(1 for r in results for t, k in r["pairs"] if t == k)
    precision = tp / (tp + fp) if tp + fp else 1.0
    recall = tp / total if total else 0.0
    kind_ok = right / tp if tp else 0.0
    print(
        f"## Verify2DObject: {args.seeds} seeds x 6 samples at 1-5 m all around Scout, 63 rocks, Amparo and "
        f"Stummel near, lidar sigma {args.lidar_sigma} m, pixel sigma 2, plan parameters\n"
    )
    print("| figure | value | goal | met |")
    print("|---|---|---|---|")
    print(
        f"| precision within 5 m | {precision:.3f} ({tp} of {tp + fp}) | >= 0.95 | {'yes' if precision >= 0.95 else 'no'} |"
    )
    print(f"| recall within 5 m | {recall:.3f} ({tp} of {total}) | >= 0.90 | {'yes' if recall >= 0.90 else 'no'} |")
    print(
        f"| kind correct | {100 * kind_ok:.1f} % ({right} of {tp}) | >= 95 % | {'yes' if kind_ok >= 0.95 else 'no'} |"
    )
    cand = sum(r["candidates"] for r in results)
    cand_true = sum(r["candidates_true"] for r in results)
    print(f"| laser candidates within 5 m (last scan) | {cand}, {cand_true} of them samples | | |")
    print(f"| candidates a closer look refused (invalid) | {sum(r['invalid'] for r in results)} | | |")
    print()
    kinds = tuple(SAMPLE_KINDS)
    table = confusion(results, kinds)
    short = {k: "".join(p[0].upper() for p in k.split("-")) for k in kinds}
    print("### Confusion (rows: true kind, columns: reported kind)\n")
    print("| true \\ reported | " + " | ".join(short[k] for k in kinds) + " | missed |")
    print("|---|" + "---|" * (len(kinds) + 1))
    for i, t in enumerate(kinds):
        print(f"| {t} ({short[t]}) | " + " | ".join(str(v) for v in table[i]) + " |")
    sources = [s for r in results for _, s in r["false"]]
    label = f"{NO_SAMPLE} reported as sample ({sources.count('rock')} rock, {sources.count('robot')} robot)"
    print(f"| {label} | " + " | ".join(str(v) for v in table[-1, :-1]) + " | - |")
    print()
    scans = [r["ms_scan"] for r in results]
    images = [r["ms_image"] for r in results]
    print("### Cost (wall ms on this machine)\n")
    print("| step | median | p90 |")
    print("|---|---|---|")
    print(f"| scan: 1440 rays + circle detection | {statistics.median(scans):.1f} | {p90(scans):.1f} |")
    print(
        f"| image: pan, render 752x480 + crop + blobs + decode | {statistics.median(images):.1f} | {p90(images):.1f} |"
    )
    print()
    print("### Per seed\n")
    print("| seed | found | false | missed | laser candidates | refused | rounds |")
    print("|---|---|---|---|---|---|---|")
    for r in results:
        print(
            f"| {r['seed']} | {r['tp']} | {r['fp']} | {', '.join(r['missed']) or '-'} | "
            f"{r['candidates']} | {r['invalid']} | {r['rounds']} |"
        )
    print(f"\n{args.seeds} seeds in {wall:.0f} s wall.")
    plot_confusion(
        table,
        [*kinds, f"{NO_SAMPLE} (no sample)"],
        [*kinds, "missed"],
        f"Verify2DObject, {args.seeds} seeds x 6 samples: precision {precision:.3f}, recall {recall:.3f}",
        Path(args.out),
    )


if __name__ == "__main__":
    main()
