"""Labels for the demos' pictures: what each label says and where it points, placed so that labels do not overlap.

:class:`Label` is the data a picture's labels are computed as (testable without drawing);
:func:`place_labels` draws them on matplotlib axes, trying a few offsets around each anchor and
keeping the first one that overlaps no label placed before, no marker to avoid and stays inside
the axes (else the one that overlaps least, where covering a label or leaving the axes counts
:data:`CLASH` times as much as covering a marker).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.backend_bases import RendererBase
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.text import Annotation
    from matplotlib.transforms import Bbox

__all__ = ["BESIDE", "OFFSETS", "Label", "overlap", "place_labels", "text_extent"]

#: Offsets tried around an anchor, in points, with the text's alignment: (dx, dy, ha, va).
OFFSETS: tuple[tuple[float, float, str, str], ...] = (
    (5.0, 5.0, "left", "bottom"),
    (-5.0, 5.0, "right", "bottom"),
    (5.0, -5.0, "left", "top"),
    (-5.0, -5.0, "right", "top"),
    (0.0, 8.0, "center", "bottom"),
    (0.0, -8.0, "center", "top"),
    (8.0, 0.0, "left", "center"),
    (-8.0, 0.0, "right", "center"),
)
#: Offsets for labels of small things in a row or column (blocks): on the anchor, then beside it at its height.
BESIDE: tuple[tuple[float, float, str, str], ...] = (
    (0.0, 0.0, "center", "center"),
    (8.0, 0.0, "left", "center"),
    (-8.0, 0.0, "right", "center"),
    (0.0, 8.0, "center", "bottom"),
    (0.0, -8.0, "center", "top"),
)
#: Distances tried, as multiples of :data:`OFFSETS` (the farther ones draw a leader line).
REACH = (1.0, 2.5, 4.5, 7.0, 10.0)
#: Pixels kept free around every label.
GAP = 1.5
#: How much worse covering another label or leaving the axes is than covering a marker (per pixel).
CLASH = 10.0


@dataclass(frozen=True, slots=True)
class Label:
    """A text pointing at a place of a picture.

    Attributes:
        text: what it says.
        x: the anchor's x (data coordinates of the axes: metres on a map, pixels on a camera image).
        y: the anchor's y.
        kind: what it names (``block``, ``robot``, ``sample``, ``base``, ``crash``).
        colour: text colour.
        size: font size in points.
        bold: bold text.
    """

    text: str
    x: float
    y: float
    kind: str
    colour: str = "black"
    size: float = 10.0
    bold: bool = False


Box = tuple[float, float, float, float]


def overlap(a: Box, b: Box) -> float:
    """The area two ``(x0, y0, x1, y1)`` boxes share (0 when apart)."""
    width = min(a[2], b[2]) - max(a[0], b[0])
    height = min(a[3], b[3]) - max(a[1], b[1])
    return width * height if width > 0 and height > 0 else 0.0


def text_extent(annotation: Annotation, renderer: RendererBase) -> Bbox:
    """The display box of an annotation's text alone (matplotlib's own extent takes in the leader line too)."""
    from matplotlib.text import Text

    annotation.update_positions(renderer)
    return Text.get_window_extent(annotation, renderer)


def place_labels(
    ax: Axes,
    labels: Sequence[Label],
    *,
    avoid: Iterable[tuple[float, float]] = (),
    marker_px: float = 8.0,
    box: dict[str, Any] | None = None,
    offsets: Mapping[str, Sequence[tuple[float, float, str, str]]] | None = None,
) -> list[Annotation]:
    """Draw ``labels`` on ``ax`` where they overlap least, in order (put the important ones first).

    The axes' limits and aspect must be set before: placement works in display pixels.

    Args:
        ax: matplotlib axes.
        labels: the labels.
        avoid: further points (data coordinates) no label should cover, besides every label's anchor.
        marker_px: half the side of the square kept free around each anchor and avoided point, in pixels.
        box: ``bbox`` properties of every text (a white backing by default).
        offsets: the offsets tried (points, with alignments) by label kind, each at every distance of
            :data:`REACH` (an offset of 0 once); :data:`OFFSETS` for the kinds not named.

    Returns:
        The matplotlib annotations, one per label, in order.
    """
    fig = ax.figure
    fig.canvas.draw()  # fixes the axes' position (aspect) before anything is measured
    renderer = cast("FigureCanvasAgg", fig.canvas).get_renderer()  # the demos draw with Agg (its canvases measure text)
    frame = ax.get_window_extent(renderer)
    to_px = ax.transData.transform
    points = [(lb.x, lb.y) for lb in labels] + list(avoid)
    blocked: list[Box] = []
    for x, y in points:
        px, py = to_px((x, y))
        blocked.append((px - marker_px, py - marker_px, px + marker_px, py + marker_px))
    backing = box if box is not None else {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.75}
    placed: list[Box] = []
    drawn: list[Annotation] = []
    for index, label in enumerate(labels):
        best: tuple[float, Annotation, Box] | None = None
        for reach in REACH:
            for dx, dy, ha, va in (offsets or {}).get(label.kind, OFFSETS):
                if reach > 1.0 and dx == dy == 0.0:
                    continue
                arrow = {"arrowstyle": "-", "color": label.colour, "lw": 0.6} if reach > 1.0 else None
                text = ax.annotate(
                    label.text,
                    (label.x, label.y),
                    xytext=(dx * reach, dy * reach),
                    textcoords="offset points",
                    ha=ha,
                    va=va,
                    fontsize=label.size,
                    fontweight="bold" if label.bold else "normal",
                    color=label.colour,
                    bbox=backing,
                    arrowprops=arrow,
                    annotation_clip=False,
                )
                ext = text_extent(text, renderer)
                area: Box = (ext.x0 - GAP, ext.y0 - GAP, ext.x1 + GAP, ext.y1 + GAP)
                outside = ext.width * ext.height - overlap(
                    (ext.x0, ext.y0, ext.x1, ext.y1), (frame.x0, frame.y0, frame.x1, frame.y1)
                )
                cost = CLASH * (outside + sum(overlap(area, other) for other in placed))
                cost += sum(overlap(area, other) for k, other in enumerate(blocked) if k != index)
                if best is None or cost < best[0]:
                    if best is not None:
                        best[1].remove()
                    best = (cost, text, area)
                else:
                    text.remove()
                if cost == 0.0:
                    break
            if best is not None and best[0] == 0.0:
                break
        assert best is not None  # OFFSETS and REACH are not empty
        placed.append(best[2])
        drawn.append(best[1])
    return drawn
