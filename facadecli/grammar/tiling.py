"""Labelled layouts in, a tiling of terminal regions out (issue 6, step 1).

A labelled layout is a set of rectangles with labels and a z-order, on a façade of a given
size: x left to right, y bottom to top (SPEC 2.1). Rectangles overlap and do not tile; the
tiling cuts the façade at every rectangle edge, gives each cell the label of the top-most
rectangle covering it (later ones win among equals) or the background, after snapping
nearly equal edges together so that hand-drawn annotations line up.

Readers: CMP Facade Database XML (a sequence of ``<object>`` elements without a root;
its two ``<x>`` values are the normalised *row* bounds, its two ``<y>`` values the
normalised *column* bounds, origin top-left), a plain JSON list of
``{label, x0, y0, x1, y1}``, and facadecli's own ``<name>.layout.json`` (visible shapes).
"""

from __future__ import annotations

import bisect
import itertools
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from facadecli.errors import SpecError

BACKGROUND = "facade"

# CMP labels and their z-order (label_names.txt of the database: higher is drawn over lower)
CMP_Z_ORDER = {
    "background": 1,
    "facade": 2,
    "molding": 7,
    "cornice": 11,
    "pillar": 12,
    "window": 10,
    "door": 5,
    "sill": 3,
    "blind": 6,
    "balcony": 4,
    "shop": 9,
    "deco": 8,
}


@dataclass(frozen=True)
class Rect:
    label: str
    x0: float
    y0: float
    x1: float
    y1: float
    z: float = 0.0


@dataclass(frozen=True)
class LabelledLayout:
    width: float
    height: float
    rects: tuple[Rect, ...]


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


def read_cmp(path: Path) -> LabelledLayout:
    """A CMP annotation, on a unit façade (the images' pixel size is not in the XML)."""
    text = path.read_text(encoding="utf-8")
    rects = []
    for number, block in enumerate(re.findall(r"<object>(.*?)</object>", text, re.S)):
        xs = [float(v) for v in re.findall(r"<x>([^<]+)</x>", block)]
        ys = [float(v) for v in re.findall(r"<y>([^<]+)</y>", block)]
        name = re.search(r"<labelname>([^<]+)</labelname>", block)
        if len(xs) != 2 or len(ys) != 2 or name is None:
            raise SpecError.at(
                str(path),
                None,
                None,
                f"object {number + 1} is incomplete",
                "each <object> needs two <x>, two <y> and a <labelname>",
            )
        label = name.group(1).strip()
        top, bottom = sorted(xs)  # rows, from the top
        left, right = sorted(ys)
        rects.append(
            Rect(
                label,
                left,
                1.0 - bottom,
                right,
                1.0 - top,
                CMP_Z_ORDER.get(label, 0) + number * 1e-6,
            )
        )
    return LabelledLayout(1.0, 1.0, tuple(rects))


def read_plain(path: Path) -> LabelledLayout:
    """A JSON list of ``{label, x0, y0, x1, y1}`` (later entries drawn over earlier), or an
    object with that list under ``rects`` and the façade size under ``canvas``."""
    data: Any = json.loads(path.read_text(encoding="utf-8"))
    entries = data["rects"] if isinstance(data, dict) else data
    rects = tuple(
        Rect(
            str(e["label"]),
            float(e["x0"]),
            float(e["y0"]),
            float(e["x1"]),
            float(e["y1"]),
            float(e.get("z", i)),
        )
        for i, e in enumerate(entries)
    )
    for i, r in enumerate(rects):
        if not (r.x1 > r.x0 and r.y1 > r.y0):
            raise SpecError.at(
                str(path),
                None,
                None,
                f"rectangle {i + 1} ({r.label}) has no area: x {r.x0:g}..{r.x1:g}, "
                f"y {r.y0:g}..{r.y1:g}",
                "give x0 < x1 and y0 < y1",
            )
    if isinstance(data, dict) and "canvas" in data:
        width, height = float(data["canvas"]["width"]), float(data["canvas"]["height"])
    else:
        width = max((r.x1 for r in rects), default=1.0)
        height = max((r.y1 for r in rects), default=1.0)
    return LabelledLayout(width, height, rects)


def read_report(path: Path) -> LabelledLayout:
    """The visible shapes of a facadecli layout report, labelled ``<x symbol>.<y symbol>``."""
    report = json.loads(path.read_text(encoding="utf-8"))
    order = {layer["name"]: i for i, layer in enumerate(report["layers"])}
    rects = tuple(
        Rect(f"{s['x']}.{s['y']}", s["x0"], s["y0"], s["x1"], s["y1"], order[s["layer"]])
        for s in report["shapes"]
        if s["visible"]
    )
    return LabelledLayout(report["canvas"]["width"], report["canvas"]["height"], rects)


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


def tile(layout: LabelledLayout, tolerance: float = 0.005, background: str = BACKGROUND) -> Tiling:
    """The tiling of a labelled layout, snapped first (``snap_layout``): cuts at every edge,
    and each cell the label of the top-most rectangle covering it, else the background."""
    layout = snap_layout(layout, tolerance) if tolerance > 0 else layout
    w, h = layout.width, layout.height
    clip = [
        Rect(r.label, max(r.x0, 0.0), max(r.y0, 0.0), min(r.x1, w), min(r.y1, h), r.z)
        for r in layout.rects
    ]
    rects = [r for r in clip if r.x1 > r.x0 and r.y1 > r.y0]
    xs = sorted({0.0, w, *(v for r in rects for v in (r.x0, r.x1))})
    ys = sorted({0.0, h, *(v for r in rects for v in (r.y0, r.y1))})
    ranked = sorted(rects, key=lambda r: r.z)
    labels = []
    for y0, y1 in itertools.pairwise(ys):
        row = []
        cy = (y0 + y1) / 2
        for x0, x1 in itertools.pairwise(xs):
            cx = (x0 + x1) / 2
            label = background
            for rect in ranked:  # the last (top-most) covering rectangle wins
                if rect.x0 <= cx <= rect.x1 and rect.y0 <= cy <= rect.y1:
                    label = rect.label
            row.append(label)
        labels.append(tuple(row))
    return Tiling(tuple(xs), tuple(ys), tuple(labels))
