"""The lunar demo's map picture: the team's map, the rocks, the samples with their detected kinds, the robots' tracks."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

#: Colours of the robots' tracks.
TRACK_COLOURS = {"scout": "tab:blue", "stummel": "tab:orange", "amparo": "tab:green"}


def draw_map(
    world: Any,
    grid: Any,
    operator: Any,
    tracks: Mapping[str, Sequence[tuple[float, float]]],
    crashes: Mapping[str, tuple[float, float]],
    path: Path,
    bodies: Mapping[str, str] | None = None,
) -> None:
    """Write a PNG of the run to ``path``.

    The team map (grey unknown, white free, black occupied), the rocks' true outlines (thin red), every
    sample where it lies with its true kind and, when the team found it, the name it was found under
    (chosen samples in bold), the collection point g, each robot's track, and an x where a robot crashed.

    Args:
        world: the lunar world (ground truth, drawn for comparison).
        grid: the team map (``LogOddsGrid``), or None when nobody mapped.
        bodies: found name -> the world's sample it is, where known (the chosen ones: they move); the
            others are matched by kind and place.
        operator: the demo's operator (found samples, their places, the chosen ones).
        tracks: each robot's positions, one per simulated second.
        crashes: where robots crashed.
        path: the PNG file.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle

    xmin, ymin, xmax, ymax = world.bounds
    fig, ax = plt.subplots(figsize=(8, 8), dpi=100)
    if grid is not None:
        occ = grid.occupancy()
        shade = np.where(occ < 0, 0.75, np.where(occ > 0, 0.0, 1.0))
        x0, y0 = grid.origin
        extent = (x0, x0 + grid.nx * grid.resolution, y0, y0 + grid.ny * grid.resolution)
        ax.imshow(shade, origin="lower", extent=extent, cmap="gray", vmin=0.0, vmax=1.0, interpolation="nearest")
    else:
        ax.set_facecolor((0.75, 0.75, 0.75))
    found_at = dict(operator.places)
    named = dict(bodies or {})
    labelled: list[tuple[float, float]] = []  # sample labels so far: close ones are stacked, not overprinted
    for obj in world.objects.values():
        x, y = obj.position()[:2]
        if obj.kind == "rock":
            ax.add_patch(Circle((x, y), obj.radius, fill=False, edgecolor="tab:red", linewidth=0.5))
        elif obj.kind == "sample":
            ax.plot(x, y, marker="o", markersize=5, color="tab:purple")
            # the chosen samples by their bodies (they moved); the others by kind, found nearest
            off = {n: float(np.hypot(p[0] - x, p[1] - y)) for n, p in found_at.items() if n not in named}
            near = [n for n, body in named.items() if body == obj.name] or sorted(
                (n for n, d in off.items() if d < 0.5 and operator.found.get(n, "") in (obj.sample_kind, "")),
                key=off.__getitem__,
            )
            label = obj.sample_kind + (f"\nfound as {near[0]}" if near else "\nnot found")
            weight = "bold" if near and near[0] in operator.chosen else "normal"
            below = sum(1 for p in labelled if np.hypot(p[0] - x, p[1] - y) < 1.5)
            labelled.append((x, y))
            ax.annotate(
                label, (x, y), xytext=(4, 4 - 18 * below), textcoords="offset points", fontsize=6, fontweight=weight
            )
        elif obj.kind == "marker":
            ax.plot(x, y, marker="*", markersize=12, color="gold", markeredgecolor="black")
            ax.annotate(obj.name, (x, y), xytext=(6, -10), textcoords="offset points", fontsize=8)
    for name, points in tracks.items():
        if len(points) > 1:
            xs, ys = zip(*points, strict=True)
            ax.plot(xs, ys, color=TRACK_COLOURS.get(name, "black"), linewidth=1.0, label=name)
    for name, (x, y) in crashes.items():
        ax.plot(x, y, marker="x", markersize=12, markeredgewidth=2.5, color="red")
        ax.annotate(f"{name} crashed", (x, y), xytext=(6, 6), textcoords="offset points", fontsize=7, color="red")
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("lunar mission: the team's map, the samples and the robots' tracks")
    if tracks:
        ax.legend(loc="upper right", fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
