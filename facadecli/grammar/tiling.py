"""Labelled layouts in, a tiling of terminal regions out (issue 6, step 1).

A labelled layout (``inputs``) is a set of rectangles with labels and a z-order; they
overlap and do not tile. The tiling cuts the façade at every rectangle edge, gives each cell
the label of the top-most rectangle covering it (later ones win among equals) or the
background, after snapping nearly equal edges together so that hand-drawn annotations line
up.

The readers live in ``cmp_xml`` (CMP Facade Database XML) and ``json_layouts`` (a plain
JSON list of ``{label, x0, y0, x1, y1}``, and facadecli's own ``<name>.layout.json``); they
are named here too.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np

from facadecli.grammar.cmp_xml import read_cmp
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.inputs import BACKGROUND, CMP_Z_ORDER, LabelledLayout, Rect
from facadecli.grammar.json_layouts import read_plain, read_report

__all__ = [
    "BACKGROUND",
    "CMP_Z_ORDER",
    "LabelledLayout",
    "Rect",
    "Tiling",
    "read_cmp",
    "read_plain",
    "read_report",
    "snap",
    "snap_layout",
    "tile",
]


@dataclass(frozen=True)
class Tiling:
    """Cuts on each axis and the label of every cell: ``labels[row][column]``, bottom up."""

    xs: tuple[float, ...]
    ys: tuple[float, ...]
    labels: tuple[tuple[str, ...], ...]

    def label_at(self, x: float, y: float) -> str:
        column = min(max(bisect.bisect_right(self.xs, x) - 1, 0), len(self.xs) - 2)
        row = min(max(bisect.bisect_right(self.ys, y) - 1, 0), len(self.ys) - 2)
        return self.labels[row][column]


def snap(
    values: list[float], tolerance: float, anchors: tuple[float, ...] = ()
) -> dict[float, float]:
    """Each value mapped to the mean of its cluster (values within ``tolerance`` in a row),
    or to the anchor in its cluster if it holds one (the façade's edges stay put)."""
    ordered = sorted(set(values) | set(anchors))
    clusters: list[list[float]] = []
    for value in ordered:
        if clusters and value - clusters[-1][-1] <= tolerance:
            clusters[-1].append(value)
        else:
            clusters.append([value])
    mapping = {}
    for cluster in clusters:
        held = [a for a in anchors if a in cluster]
        target = held[0] if held else sum(cluster) / len(cluster)
        for value in cluster:
            mapping[value] = target
    return mapping


def snap_layout(layout: LabelledLayout, tolerance: float = 0.005) -> LabelledLayout:
    """The layout with edges closer than ``tolerance`` x the façade's size moved to their
    mean (the façade's own edges stay where they are), clipped to the façade; rectangles
    that vanish are dropped."""
    w, h = layout.width, layout.height
    xmap = snap([v for r in layout.rects for v in (r.x0, r.x1)], tolerance * w, (0.0, w))
    ymap = snap([v for r in layout.rects for v in (r.y0, r.y1)], tolerance * h, (0.0, h))
    for mapping, extent in ((xmap, w), (ymap, h)):
        for value, target in mapping.items():
            mapping[value] = min(max(target, 0.0), extent)
    rects = tuple(
        Rect(r.label, xmap[r.x0], ymap[r.y0], xmap[r.x1], ymap[r.y1], r.z)
        for r in layout.rects
        if xmap[r.x1] > xmap[r.x0] and ymap[r.y1] > ymap[r.y0]
    )
    return LabelledLayout(w, h, rects)


def tile(
    layout: LabelledLayout,
    tolerance: float = 0.005,
    background: str = BACKGROUND,
    deadline: Deadline | None = None,
) -> Tiling:
    """The tiling of a labelled layout, snapped first (``snap_layout``): cuts at every edge,
    and each cell the label of the top-most rectangle covering it, else the background.
    Rectangles are painted bottom up over the cells they cover (numpy), so the work is the
    cells covered, not the cells times the rectangles."""
    deadline = deadline or Deadline()
    layout = snap_layout(layout, tolerance) if tolerance > 0 else layout
    w, h = layout.width, layout.height
    clip = [
        Rect(r.label, max(r.x0, 0.0), max(r.y0, 0.0), min(r.x1, w), min(r.y1, h), r.z)
        for r in layout.rects
    ]
    rects = [r for r in clip if r.x1 > r.x0 and r.y1 > r.y0]
    xs = sorted({0.0, w, *(v for r in rects for v in (r.x0, r.x1))})
    ys = sorted({0.0, h, *(v for r in rects for v in (r.y0, r.y1))})
    column = {x: i for i, x in enumerate(xs)}
    row = {y: i for i, y in enumerate(ys)}
    names = [background, *sorted({r.label for r in rects} - {background})]
    code = {name: i for i, name in enumerate(names)}
    cells = np.zeros((len(ys) - 1, len(xs) - 1), dtype=np.int32)
    for r in sorted(rects, key=lambda r: r.z):  # stable: among equals the later wins
        deadline.check("tiling")
        cells[row[r.y0] : row[r.y1], column[r.x0] : column[r.x1]] = code[r.label]
    labels = np.array(names, dtype=object)[cells].tolist()
    return Tiling(tuple(xs), tuple(ys), tuple(tuple(line) for line in labels))
