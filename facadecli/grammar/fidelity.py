"""How faithful an output is to what was drawn: the raw annotation (as read, before any
snapping or regularising) and an output layout of the same size, both rasterised the same
way, compared label by label and element by element.

- **Rasterising.** Cells of ``RESOLUTION`` (2.5 cm, in the layout's units), at least
  ``SIDE_MIN`` along the longer side (an annotation without a size, such as a CMP unit
  square, is not in metres) and at most ``CELLS_MAX`` cells in all (a huge façade is
  rasterised coarser, never a memory bomb). A cell takes the label of the front-most
  rectangle over its centre, the background (``facade``) elsewhere. Rectangles are painted
  by their ``z``, and among equal ``z`` in their order: for CMP that is the database's
  z-order by label (``label_names.txt``: a window over a wall, a cornice over a window)
  and, within a label, later objects over earlier ones (``cmp_xml``); for JSON lists the
  ``z`` given, else the order of the list.
- **IoU.** For every label drawn on either raster, intersection over union of its cells;
  ``iou_mean`` is their mean, the background included.
- **Elements.** An annotated element is its *visible* cells (where it is the front-most
  rectangle; one wholly hidden, or smaller than a cell, is not counted), and so is an
  output element. An annotated element is *lost* when no output element of its label
  covers half or more of it. Background rectangles are not elements.
- **Fused** is judged on regions, not rectangles, on both sides: an element is fused
  when the connected region of its label on the output's raster that covers half or more
  of it also covers half or more of another element that lies in another region of the
  annotation (windows given a shared edge, the wall between them sized 0, are one region
  to whoever reads the output, and one to a grammar). Elements drawn touching (a pillar's
  base, shaft and capital) are one region already, and are not fused. ``fused`` counts
  such regions of the output, ``fused_elements`` the annotated elements in them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from facadecli.grammar.inputs import BACKGROUND, LabelledLayout, Rect

RESOLUTION = 0.025  # the side of a cell, in the layout's units (metres)
SIDE_MIN = 400  # cells along the longer side, at least
CELLS_MAX = 4_000_000  # cells of one raster, at most (2000 x 2000; 16 MB a raster)
FAITHFUL = 0.9  # the mean IoU against the drawing a façade's layout must keep (issue 34)
COVERED = 0.5  # share of an annotated element an output element must cover to keep it
IOU_WARN = 0.85  # a mean IoU below this is warned about


@dataclass(frozen=True)
class Grid:
    """The cells of a raster: ``columns`` x ``rows`` of ``cell_w`` x ``cell_h``."""

    width: float
    height: float
    columns: int
    rows: int

    @property
    def cell_w(self) -> float:
        return self.width / self.columns

    @property
    def cell_h(self) -> float:
        return self.height / self.rows


def grid(
    width: float,
    height: float,
    resolution: float = RESOLUTION,
    cells_max: int = CELLS_MAX,
    side_min: int = SIDE_MIN,
) -> Grid:
    """The raster of a ``width`` x ``height`` façade: square cells of ``resolution``, made
    finer to have ``side_min`` cells along the longer side and coarser to have at most
    ``cells_max`` cells."""
    longer = max(width, height)
    cell = min(resolution, longer / side_min)
    cell = max(cell, math.sqrt(width * height / cells_max), longer / cells_max)
    columns = max(1, round(width / cell))
    rows = max(1, round(height / cell))
    while columns * rows > cells_max:  # rounding up may pass the limit by a row or column
        cell *= 1.001
        columns, rows = max(1, round(width / cell)), max(1, round(height / cell))
    return Grid(width, height, columns, rows)


def paint(
    rects: Sequence[Rect], cells: Grid, code: dict[str, int]
) -> tuple[np.ndarray, np.ndarray]:
    """The label (``code`` of it) and the rectangle (its index, -1 for none) at every cell's
    centre, rows bottom up; rectangles painted by ``z``, among equals in their order."""
    labels = np.full((cells.rows, cells.columns), code[BACKGROUND], dtype=np.int32)
    owners = np.full((cells.rows, cells.columns), -1, dtype=np.int32)
    for i in sorted(range(len(rects)), key=lambda k: rects[k].z):  # stable: later wins
        r = rects[i]
        c0, c1 = _span(r.x0, r.x1, cells.cell_w, cells.columns)
        r0, r1 = _span(r.y0, r.y1, cells.cell_h, cells.rows)
        if c1 > c0 and r1 > r0:
            labels[r0:r1, c0:c1] = code[r.label]
            owners[r0:r1, c0:c1] = i
    return labels, owners


def _span(low: float, high: float, cell: float, count: int) -> tuple[int, int]:
    """The cells whose centres lie in ``[low, high)``."""
    first = math.ceil(low / cell - 0.5)
    stop = math.ceil(high / cell - 0.5)
    return min(max(first, 0), count), min(max(stop, 0), count)


@dataclass
class LabelFidelity:
    iou: float
    elements: int = 0  # annotated elements counted (visible on the raster)
    lost: int = 0
    fused: int = 0  # regions of the output covering annotated elements drawn apart

    def summary(self) -> dict[str, object]:
        return {"iou": self.iou, "elements": self.elements, "lost": self.lost, "fused": self.fused}


@dataclass
class Fidelity:
    """An output compared with the annotation (see the module)."""

    cell: float  # the side of a cell used (the larger of the two, when not square)
    columns: int
    rows: int
    labels: dict[str, LabelFidelity] = field(default_factory=dict)
    fused_elements: int = 0  # annotated elements inside those regions
    lost_at: list[int] = field(default_factory=list)  # the lost elements (the annotation's)
    fused_at: list[list[int]] = field(default_factory=list)  # the elements of each fused region

    @property
    def iou_mean(self) -> float:
        values = [entry.iou for entry in self.labels.values()]
        return round(sum(values) / len(values), 4) if values else 1.0

    def iou_per_label(self) -> dict[str, float]:
        return {label: entry.iou for label, entry in self.labels.items()}

    @property
    def elements(self) -> int:
        return sum(entry.elements for entry in self.labels.values())

    @property
    def lost(self) -> int:
        return sum(entry.lost for entry in self.labels.values())

    @property
    def fused(self) -> int:
        return sum(entry.fused for entry in self.labels.values())

    def summary(self) -> dict[str, object]:
        return {
            "against": "annotation",
            "iou_mean": self.iou_mean,
            "iou_per_label": self.iou_per_label(),
            "elements": self.elements,
            "lost": self.lost,
            "fused": self.fused,
            "fused_elements": self.fused_elements,
            "per_label": {label: entry.summary() for label, entry in self.labels.items()},
            "raster": {"columns": self.columns, "rows": self.rows, "cell": round(self.cell, 6)},
        }

    def warnings(self, what: str) -> list[str]:
        """What is unfaithful, said of ``what`` (e.g. "the spec solved at the input's size")."""
        found = []
        if self.iou_mean < IOU_WARN:
            worst = sorted(self.labels.items(), key=lambda item: item[1].iou)[:3]
            found.append(
                f"{what} differs from the annotation: mean IoU {self.iou_mean:.3f} (below "
                f"{IOU_WARN:g}; lowest "
                + ", ".join(f"{label} {entry.iou:.3f}" for label, entry in worst)
                + ")"
            )
        if self.lost or self.fused:
            by_label = ", ".join(
                f"{label}: {entry.lost} lost, {entry.fused} fused"
                for label, entry in self.labels.items()
                if entry.lost or entry.fused
            )
            done = [f"loses {self.lost}"] if self.lost else []
            if self.fused:
                done.append(f"fuses {self.fused_elements} into {self.fused}")
            found.append(
                f"{what} {' and '.join(done)} of the annotation's {self.elements} elements "
                f"({by_label})"
            )
        return found


def fidelity(
    annotation: LabelledLayout,
    output: LabelledLayout,
    drawn: Sequence[Rect] | None = None,
    resolution: float = RESOLUTION,
    cells_max: int = CELLS_MAX,
) -> Fidelity:
    """``output`` (its rectangles are its elements) compared with the raw ``annotation`` at
    the annotation's size (see the module). ``drawn``, when given, is what the output
    shows, when that is not its elements painted (a grammar's terminals)."""
    cells = grid(annotation.width, annotation.height, resolution, cells_max)
    pieces = list(drawn) if drawn is not None else list(output.rects)
    names = sorted({BACKGROUND, *(r.label for r in (*annotation.rects, *output.rects, *pieces))})
    code = {name: k for k, name in enumerate(names)}
    given = _Painted(annotation.rects, cells, code)
    made = _Painted(output.rects, cells, code)
    shown = paint(pieces, cells, code)[0] if drawn is not None else made.labels
    result = Fidelity(max(cells.cell_w, cells.cell_h), cells.columns, cells.rows)
    count = len(names)
    both = np.bincount((given.labels * count + shown).ravel(), minlength=count * count)
    both = both.reshape(count, count)
    for k, name in enumerate(names):
        union = int(both[k, :].sum() + both[:, k].sum() - both[k, k])
        if union:
            result.labels[name] = LabelFidelity(round(float(both[k, k]) / union, 4))
    # an annotated element's cells: where it is the front-most rectangle
    element = (given.owners >= 0) & (given.codes[given.owners] != code[BACKGROUND])
    visible = np.bincount(given.owners[element], minlength=len(annotation.rects))
    kinds = {int(given.codes[e]) for e in np.flatnonzero(visible).tolist()}
    own = given.codes[given.owners]  # the label of the element at each cell
    kept = element & (made.owners >= 0) & (made.codes[made.owners] == own) & (shown == own)
    covered = _covers(given.owners, made.owners, kept, visible)
    for e in np.flatnonzero(visible).tolist():
        entry = result.labels.setdefault(annotation.rects[e].label, LabelFidelity(0.0))
        entry.elements += 1
        entry.lost += e not in covered
        if e not in covered:
            result.lost_at.append(e)
    apart = _regions(given.labels, kinds)  # the annotation's regions of each label
    region_of = {e: found[0] for e, found in _covers(given.owners, apart, element, visible).items()}
    together = _regions(shown, kinds)  # the output's regions
    inside: dict[int, list[int]] = {}  # a region of the output -> the elements it covers
    for e, found in _covers(given.owners, together, element & (shown == own), visible).items():
        inside.setdefault(found[0], []).append(e)
    for elements in inside.values():
        if len({region_of.get(e, -1 - e) for e in elements}) >= 2:
            result.labels[annotation.rects[elements[0]].label].fused += 1
            result.fused_elements += len(elements)
            result.fused_at.append(sorted(elements))
    return result


class _Painted:
    """A layout on the raster: the label code and the rectangle (-1: none) at every cell,
    and the label code of every rectangle (the last one, -1, for none)."""

    def __init__(self, rects: Sequence[Rect], cells: Grid, code: dict[str, int]):
        self.labels, self.owners = paint(rects, cells, code)
        self.codes = np.array([code[r.label] for r in rects] + [-1], dtype=np.int32)


def _covers(
    owners: np.ndarray, others: np.ndarray, where: np.ndarray, visible: np.ndarray
) -> dict[int, list[int]]:
    """For each annotated element (``owners``: its index at its cells), what of ``others``
    (an output element's or a region's number at each cell, -1 for none) covers half or
    more of its visible cells, counting the cells ``where`` holds (largest first)."""
    where = where & (others >= 0)
    span = int(others.max(initial=0)) + 1
    keys, counts = np.unique(
        owners[where].astype(np.int64) * span + others[where], return_counts=True
    )
    found: dict[int, list[tuple[int, int]]] = {}
    for key, overlap in zip(keys.tolist(), counts.tolist(), strict=True):
        e, o = divmod(key, span)
        if overlap >= COVERED * visible[e]:
            found.setdefault(e, []).append((overlap, o))
    return {e: [o for _, o in sorted(pairs, reverse=True)] for e, pairs in found.items()}


def _regions(labels: np.ndarray, kinds: set[int]) -> np.ndarray:
    """The connected regions (4-neighbours) of each label of ``kinds`` on a raster, numbered
    from 0 across labels; -1 elsewhere. Each label is labelled within the box of its
    cells, so the work is the boxes, not the raster times the labels."""
    from scipy import ndimage

    region = np.full(labels.shape, -1, dtype=np.int64)
    boxes = ndimage.find_objects(labels + 1)  # the box of label k at k
    count = 0
    for k in sorted(kinds):
        box = boxes[k] if k < len(boxes) else None
        if box is None:
            continue
        mask = labels[box] == k
        numbered, found = ndimage.label(mask)
        region[box][mask] = numbered[mask] - 1 + count
        count += found
    return region
