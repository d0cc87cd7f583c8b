"""The lunar demo's map picture: the team's map, the rocks, the samples with their detected kinds, g, the robots' tracks."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from alica.app.demos.labels import Label, place_labels

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from alica.app.demos.lunar import Operator
    from alica.skills.mapping import LogOddsGrid
    from alica.worldsim.world import World

#: Colours of the robots' tracks.
TRACK_COLOURS = {"scout": "tab:blue", "stummel": "tab:orange", "amparo": "tab:green"}
#: Colour of the collection point's marker.
BASE_COLOUR = "gold"


#: Font sizes of the labels, in points.
ROBOT_FONT = 11.0
SAMPLE_FONT = 9.0
BASE_FONT = 11.0


def map_labels(
    world: World,
    operator: Operator,
    tracks: Mapping[str, Sequence[tuple[float, float]]],
    crashes: Mapping[str, tuple[float, float]],
    bodies: Mapping[str, str] | None = None,
) -> list[Label]:
    """The labels of the map, most important first: the collection point, the robots, the crashes, the samples.

    Every robot is labelled where it ended (its last track point, else its pose in the world); a crashed
    one where it crashed, in red. Every sample is labelled with its true kind and the name the team found
    it under (bold when chosen), or ``not found``.

    Args:
        world: the lunar world (ground truth).
        operator: the demo's operator (found samples, their places, the chosen ones).
        tracks: each robot's positions, one per simulated second.
        crashes: where robots crashed.
        bodies: found name -> the world's sample it is, where known (see :func:`draw_map`).
    """
    labels: list[Label] = []
    for obj in world.objects.values():
        if obj.kind == "collection_point":
            x, y = obj.position()[:2]
            labels.append(
                Label(f"{obj.name} (collection point)", float(x), float(y), "base", size=BASE_FONT, bold=True)
            )
    for name in sorted(world.robots):
        if name in crashes:
            x, y = crashes[name]
            labels.append(
                Label(f"{name} crashed", float(x), float(y), "crash", colour="red", size=ROBOT_FONT, bold=True)
            )
            continue
        points = tracks.get(name) or [world.robots[name].pose[:2]]
        x, y = points[-1]
        labels.append(
            Label(
                name, float(x), float(y), "robot", colour=TRACK_COLOURS.get(name, "black"), size=ROBOT_FONT, bold=True
            )
        )
    found_at = dict(operator.places)
    named = dict(bodies or {})
    for obj in world.objects.values():
        if obj.kind != "sample":
            continue
        x, y = obj.position()[:2]
        # the chosen samples by their bodies (they moved); the others by kind, found nearest
        off = {n: float(np.hypot(p[0] - x, p[1] - y)) for n, p in found_at.items() if n not in named}
        near = [n for n, body in named.items() if body == obj.name] or sorted(
            (n for n, d in off.items() if d < 0.5 and operator.found.get(n, "") in (obj.sample_kind, "")),
            key=off.__getitem__,
        )
        assert obj.sample_kind is not None  # a sample always has its kind
        text = obj.sample_kind + (f"\nfound as {near[0]}" if near else "\nnot found")
        chosen = bool(near) and near[0] in operator.chosen
        labels.append(Label(text, float(x), float(y), "sample", size=SAMPLE_FONT, bold=chosen))
    return labels


def map_figure(
    world: World,
    grid: LogOddsGrid | None,
    operator: Operator,
    tracks: Mapping[str, Sequence[tuple[float, float]]],
    crashes: Mapping[str, tuple[float, float]],
    bodies: Mapping[str, str] | None = None,
) -> Figure:
    """The map as a matplotlib figure (see :func:`draw_map`); the caller closes it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle

    xmin, ymin, xmax, ymax = world.bounds
    fig, ax = plt.subplots(figsize=(9, 9), dpi=100)
    if grid is not None:
        occ = grid.occupancy()
        shade = np.where(occ < 0, 0.75, np.where(occ > 0, 0.0, 1.0))
        x0, y0 = grid.origin
        extent = (x0, x0 + grid.nx * grid.resolution, y0, y0 + grid.ny * grid.resolution)
        ax.imshow(shade, origin="lower", extent=extent, cmap="gray", vmin=0.0, vmax=1.0, interpolation="nearest")
    else:
        ax.set_facecolor((0.75, 0.75, 0.75))
    avoid: list[tuple[float, float]] = []
    for obj in world.objects.values():
        x, y = obj.position()[:2]
        if obj.kind == "rock":
            ax.add_patch(Circle((x, y), obj.radius, fill=False, edgecolor="tab:red", linewidth=0.5))
        elif obj.kind == "sample":
            ax.plot(x, y, marker="o", markersize=5, color="tab:purple")
        elif obj.kind == "collection_point":
            ax.add_patch(Circle((x, y), obj.radius, facecolor="gold", alpha=0.35, edgecolor="darkgoldenrod"))
            ax.plot(x, y, marker="*", markersize=16, color=BASE_COLOUR, markeredgecolor="black")
    for name, points in tracks.items():
        if len(points) > 1:
            xs, ys = zip(*points, strict=True)
            ax.plot(xs, ys, color=TRACK_COLOURS.get(name, "black"), linewidth=1.0, label=name)
            avoid += [(float(px), float(py)) for px, py in points[:: max(1, len(points) // 40)]]
    labels = map_labels(world, operator, tracks, crashes, bodies)
    for label in labels:
        if label.kind == "robot":
            ax.plot(label.x, label.y, marker="o", markersize=9, color=label.colour, markeredgecolor="black")
        elif label.kind == "crash":
            ax.plot(label.x, label.y, marker="x", markersize=12, markeredgewidth=2.5, color="red")
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("lunar mission: the team's map, the samples, g and the robots' tracks")
    if tracks:
        ax.legend(loc="upper right", fontsize=9)
    place_labels(ax, labels, avoid=avoid, marker_px=5.0)
    return fig


def draw_map(
    world: World,
    grid: LogOddsGrid | None,
    operator: Operator,
    tracks: Mapping[str, Sequence[tuple[float, float]]],
    crashes: Mapping[str, tuple[float, float]],
    path: Path,
    bodies: Mapping[str, str] | None = None,
) -> None:
    """Write a PNG of the run to ``path``.

    The team map (grey unknown, white free, black occupied), the rocks' true outlines (thin red), every
    sample where it lies with its true kind and, when the team found it, the name it was found under
    (chosen samples in bold), the collection point g (a gold star in its disc), each robot's track with
    its name where it ended, and an x where a robot crashed. Labels are placed so that they do not
    overlap where the room allows (:func:`alica.app.demos.labels.place_labels`).

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
    import matplotlib.pyplot as plt

    fig = map_figure(world, grid, operator, tracks, crashes, bodies)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
