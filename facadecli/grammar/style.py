"""A façade's style as constraints (Bao et al. 2013, section 4), found in a labelled layout
and checked on layouts derived from it.

Found on the (regularised) input, over its elements (the background is not one):

- ``symmetry``: the elements are mirror images of each other about the vertical centre line
  (at least ``MIRRORED`` of them have a partner of their label);
- ``columns``: rows of one label (elements at one height, narrower than ``BAND`` of the
  façade: an element across bays, an attic's ornament, is on no column) whose centres are
  the same set of columns, floor after floor (checked on a derived layout over elements
  narrower than ``CHECKED_BAND``: an element stretched there is not let off);
- ``axis``: every element of another label (narrower than half the façade) is centred on
  one of those columns (a door under a window column: Bao's Figure 16);
- ``spacing``: rows of three or more elements of one label and width at one pitch (a
  row of balconies of two widths is two rows), at least two pitches apart and up to
  ``SKIPPED`` places of the pitch empty between two (the windows each side of a
  staircase's, which sit half a floor lower);
- ``ends`` and ``centre``: a label at both ends of the façade, or on its centre line
  (pilasters at the corners and in the middle: a frequency pattern);
- ``sizes``: a label's elements (bands aside) keep their sizes: at least ``SIZE_SHARE`` of
  a derived layout's are within ``SIZE_TOLERANCE`` of an input element's width and height
  (a narrower façade that squeezes its windows breaks it; one that drops bays does not);
- ``pitch``: the rows of a label on the same columns keep their vertical pitch (each
  pitch of a derived layout within ``SIZE_TOLERANCE`` of one of the input's: a taller
  façade gains whole floors, it does not stretch them).

The style is found on what the drawing shows (:func:`style_of_drawing`: the annotation's
rectangles in their z-order, its edges only joined within the snap tolerance), never on
the tool's own regularised tiling, so a tidy-up that moved or merged elements cannot hide
it.

A derived layout keeps a constraint when it holds there too (for ``columns`` and
``spacing``, in as large a share of the label's rows, or in as many rows: a taller façade
has more floors, and floors copied that did not hold it leave those that do); distances
are compared within ``TOLERANCE`` of the façade's extent.
"""

from __future__ import annotations

import bisect
import itertools
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

from facadecli.grammar.inputs import LabelledLayout, Rect
from facadecli.grammar.model import Constraint, Kept
from facadecli.grammar.tiling import BACKGROUND, Tiling, tile

SKIPPED = 1  # places of a row's pitch that may be empty between two elements
TOLERANCE = 0.01  # of the façade's extent along the axis compared
MIRRORED = 0.9  # share of the elements with a mirror partner for a symmetric façade
BAND = 0.4  # of the input's extent: a longer element is a band across bays, on no column
CHECKED_BAND = 0.5  # ... of a derived layout's (an element stretched there is still checked)
SIZE_TOLERANCE = 0.15  # of a size or pitch: a derived element keeps its size within it
SIZE_SHARE = 0.9  # of a label's derived elements that must keep an input element's size


class Box(NamedTuple):
    """A labelled rectangle."""

    label: str
    x0: float
    y0: float
    x1: float
    y1: float


@dataclass(frozen=True)
class Facade:
    """The elements of a layout, by label and row."""

    boxes: tuple[Box, ...]
    width: float
    height: float

    def rows(self, label: str) -> list[list[Box]]:
        """The elements of a label in rows (one height, within the tolerance), bottom up,
        each left to right."""
        near = TOLERANCE * self.height
        found: list[list[Box]] = []
        open_rows: list[list[Box]] = []  # those a box further up may still join, in order
        for box in sorted((b for b in self.boxes if b.label == label), key=lambda b: (b.y0, b.y1)):
            open_rows = [r for r in open_rows if r[0].y0 >= box.y0 - near]
            row = next((r for r in open_rows if abs(r[0].y1 - box.y1) <= near), None)
            if row is None:
                found.append([box])
                open_rows.append(found[-1])
            else:
                row.append(box)
        return [sorted(row, key=lambda b: b.x0) for row in found]

    def mirrored(self) -> float:
        """The share of elements with a mirror partner of their label (looked for among
        the elements of that label starting near the same height)."""
        near_x, near_y = TOLERANCE * self.width, TOLERANCE * self.height
        by_label: dict[str, list[Box]] = defaultdict(list)
        for box in sorted(self.boxes, key=lambda b: b.y0):
            by_label[box.label].append(box)
        starts = {label: [b.y0 for b in boxes] for label, boxes in by_label.items()}
        partners = 0
        for label, x0, y0, x1, y1 in self.boxes:
            boxes, at = by_label[label], starts[label]
            # a window wider than the test, which then decides as it would over all
            near = boxes[
                bisect.bisect_left(at, y0 - 2 * near_y) : bisect.bisect_right(at, y0 + 2 * near_y)
            ]
            partners += any(
                abs(other.x0 - (self.width - x1)) <= near_x
                and abs(other.x1 - (self.width - x0)) <= near_x
                and abs(other.y0 - y0) <= near_y
                and abs(other.y1 - y1) <= near_y
                for other in near
            )
        return partners / len(self.boxes) if self.boxes else 0.0


def facade_of(tiles: Sequence[Box], width: float, height: float, background: str) -> Facade:
    """The elements of a layout from its visible tiles (a tiling's cells or a derivation's
    terminals), the background left out. The tiles are cut at every edge of every tile
    (so two ways of cutting one picture give the same cells); cells of one label side by
    side in a row are joined, then such runs stacked in a column (so a window cut by the
    edges of other elements is one window again)."""
    near = 1e-6 * max(width, height)
    boxes = _cells(tiles, near, background)
    rows = _joined(sorted(boxes, key=lambda b: (b.label, b.y0, b.y1, b.x0)), True, near)
    return Facade(
        tuple(_joined(sorted(rows, key=lambda b: (b.label, b.x0, b.x1, b.y0)), False, near)),
        width,
        height,
    )


def _cells(tiles: Sequence[Box], near: float, background: str) -> list[Box]:
    """The tiles cut at every edge of every tile, those of the background left out."""
    xs = _distinct([v for t in tiles for v in (t.x0, t.x1)], near)
    ys = _distinct([v for t in tiles for v in (t.y0, t.y1)], near)
    cells = []
    for label, x0, y0, x1, y1 in tiles:  # the edges within reach, found in the sorted edges
        if label == background:
            continue
        inner_x = xs[bisect.bisect_left(xs, x0 - near) : bisect.bisect_right(xs, x1 + near)]
        inner_y = ys[bisect.bisect_left(ys, y0 - near) : bisect.bisect_right(ys, y1 + near)]
        for a, b in itertools.pairwise(inner_x):
            for c, d in itertools.pairwise(inner_y):
                cells.append(Box(label, a, c, b, d))
    return cells


def _distinct(values: list[float], near: float) -> list[float]:
    found: list[float] = []
    for value in sorted(values):
        if not found or value - found[-1] > near:
            found.append(value)
    return found


def _joined(boxes: list[Box], along_x: bool, near: float) -> list[Box]:
    """Sorted boxes with each one joined to the next where they touch along x (or y) and
    match across it."""
    joined: list[Box] = []
    for box in boxes:
        last = joined[-1] if joined else None
        if last is not None and last.label == box.label:
            if along_x:
                touching = abs(last.x1 - box.x0) <= near
                matching = abs(last.y0 - box.y0) <= near and abs(last.y1 - box.y1) <= near
            else:
                touching = abs(last.y1 - box.y0) <= near
                matching = abs(last.x0 - box.x0) <= near and abs(last.x1 - box.x1) <= near
            if touching and matching:
                x1, y1 = (box.x1, last.y1) if along_x else (last.x1, box.y1)
                joined[-1] = Box(last.label, last.x0, last.y0, x1, y1)
                continue
        joined.append(box)
    return joined


def style_of(tiling: Tiling, background: str = BACKGROUND) -> list[Constraint]:
    """The constraints a tiling holds (as derivations are checked on their terminals)."""
    facade = facade_of(tiles_of(tiling), tiling.xs[-1], tiling.ys[-1], background)
    return find_style(facade)


def style_of_drawing(drawing: LabelledLayout, background: str = BACKGROUND) -> list[Constraint]:
    """The constraints a drawing holds: found on what it shows (:func:`shown_tiles`)."""
    tiles = shown_tiles(drawing.rects, drawing.width, drawing.height)
    return find_style(facade_of(tiles, drawing.width, drawing.height, background))


def shown_tiles(rects: Sequence[Rect], width: float, height: float) -> list[Box]:
    """What a drawing shows, as tiles: its tiling with no edge moved (:func:`tile`: cuts at
    every edge, each cell the label of the front-most rectangle), the background left
    out."""
    drawing = tile(LabelledLayout(width, height, tuple(rects)), tolerance=0.0)
    return [box for box in tiles_of(drawing) if box.label != BACKGROUND]


def tiles_of(tiling: Tiling) -> list[Box]:
    """A tiling's cells as tiles."""
    return [
        Box(label, tiling.xs[c], tiling.ys[r], tiling.xs[c + 1], tiling.ys[r + 1])
        for r, row in enumerate(tiling.labels)
        for c, label in enumerate(row)
    ]


def _cx(box: Box) -> float:
    return (box.x0 + box.x1) / 2


def _cy(box: Box) -> float:
    return (box.y0 + box.y1) / 2


def _centres(row: list[Box]) -> list[float]:
    return [_cx(b) for b in row]


def _same(a: list[float], b: list[float], near: float) -> bool:
    return len(a) == len(b) and all(abs(p - q) <= near for p, q in zip(a, b, strict=True))


def _even(row: list[Box], near: float) -> bool:
    """Whether a row's centres are on one pitch: at least two of its gaps are the
    pitch, the others the pitch or up to ``SKIPPED`` more of it."""
    pitches = [b - a for a, b in itertools.pairwise(_centres(row))]
    if len(pitches) < 2:
        return False
    pitch = min(pitches)
    on_pitch = [min(abs(p - k * pitch) for k in range(1, SKIPPED + 2)) <= near for p in pitches]
    return all(on_pitch) and sum(abs(p - pitch) <= near for p in pitches) >= 2


def _shared_columns(
    facade: Facade, label: str, band: float = CHECKED_BAND
) -> tuple[list[list[Box]], int]:
    """The largest set of a label's rows on the same columns, and how many rows it has
    (elements ``band`` of the façade's width or wider left out)."""
    near = TOLERANCE * facade.width
    rows = _column_rows(facade, label, band)
    groups: list[list[list[Box]]] = []
    for row in rows:
        group = next((g for g in groups if _same(_centres(g[0]), _centres(row), near)), None)
        if group is None:
            groups.append([row])
        else:
            group.append(row)
    return max(groups, key=len, default=[]), len(rows)


def _column_rows(facade: Facade, label: str, band: float = CHECKED_BAND) -> list[list[Box]]:
    """A label's rows, bands across the façade left out (a band is on no column)."""
    narrow = ([b for b in row if b.x1 - b.x0 < band * facade.width] for row in facade.rows(label))
    return [row for row in narrow if row]


def shared_rows(facade: Facade, label: str) -> list[list[Box]]:
    """The largest set of a label's rows on the same columns, floor after floor, bottom
    up (none when no two rows share them)."""
    best, _ = _shared_columns(facade, label)
    return best if len(best) >= 2 else []


def _runs(facade: Facade, label: str) -> list[list[Box]]:
    """A label's rows of three or more elements as wide as each other (within the
    tolerance; a row of elements of two widths is two), each left to right."""
    near = TOLERANCE * facade.width
    found = []
    for row in facade.rows(label):
        groups: list[list[Box]] = []
        for box in sorted(row, key=lambda b: b.x1 - b.x0):
            last = groups[-1] if groups else None
            if last is not None and (box.x1 - box.x0) - (last[0].x1 - last[0].x0) <= near:
                last.append(box)
            else:
                groups.append([box])
        found += [sorted(g, key=lambda b: b.x0) for g in groups if len(g) >= 3]
    return found


def _evenly_spaced(facade: Facade, label: str) -> tuple[int, int]:
    """How many of a label's rows of three or more alike are evenly spaced, of how many."""
    near = TOLERANCE * facade.width
    runs = _runs(facade, label)
    return sum(_even(run, near) for run in runs), len(runs)


def find_style(facade: Facade) -> list[Constraint]:
    """The constraints a layout holds (see the module). ``columns`` and ``spacing`` hold
    for a share of a label's rows (``Constraint.share``, ``Constraint.rows``): a derived
    layout keeps them when as large a share of its rows does, however many floors it has,
    or as many rows."""
    found: list[Constraint] = []
    near = TOLERANCE * facade.width
    share = facade.mirrored()
    if share >= MIRRORED and len(facade.boxes) >= 2:
        text = f"mirror-symmetric about the centre line ({share:.0%} of elements)"
        found.append(Constraint("symmetry", "*", text))
    labels = sorted({b.label for b in facade.boxes})
    columned = []
    for label in labels:
        best, rows = _shared_columns(facade, label, BAND)
        if len(best) >= 2:
            text = f"{len(best)} of {rows} rows of {label} on the same {len(best[0])} columns"
            found.append(Constraint("columns", label, text, len(best) / rows, rows=len(best)))
            columned.append(label)
        even, rows = _evenly_spaced(facade, label)
        if even:
            text = f"{even} of {rows} rows of three or more {label} evenly spaced"
            found.append(Constraint("spacing", label, text, even / rows, rows=even))
        if len(best) >= 2:
            pitches = _pitches(best)
            text = f"rows of {label} {_listed(pitches)} m apart"
            found.append(Constraint("pitch", label, text, pitches=pitches))
        boxes = [b for b in facade.boxes if b.label == label]
        sizes = _sizes(boxes, BAND * facade.width)
        if sizes:
            wide, tall = _listed(w for w, _ in sizes), _listed(h for _, h in sizes)
            text = f"{label} {wide} m wide, {tall} m tall"
            found.append(Constraint("sizes", label, text, sizes=sizes))
        if any(b.x0 <= near for b in boxes) and any(b.x1 >= facade.width - near for b in boxes):
            found.append(Constraint("ends", label, f"{label} at both ends"))
        if any(abs(_cx(b) - facade.width / 2) <= near for b in boxes):
            found.append(Constraint("centre", label, f"{label} on the centre line"))
    for label in labels:
        for other in columned:
            axis = Constraint(
                "axis", label, f"{label} centred on the columns of {other}", 1.0, other
            )
            if other != label and holds(axis, facade):
                found.append(axis)
                break
    return found


def holds(constraint: Constraint, facade: Facade) -> bool:
    """Whether a (derived) layout keeps a constraint."""
    near = TOLERANCE * facade.width
    kind, label = constraint.kind, constraint.label
    if kind == "symmetry":
        return facade.mirrored() >= MIRRORED
    boxes = [b for b in facade.boxes if b.label == label]
    if kind == "columns":
        best, rows = _shared_columns(facade, label)
        return len(best) >= 2 and _as_many(constraint, len(best), rows)
    if kind == "spacing":
        even, rows = _evenly_spaced(facade, label)
        return rows > 0 and _as_many(constraint, even, rows)
    if kind == "ends":
        return any(b.x0 <= near for b in boxes) and any(b.x1 >= facade.width - near for b in boxes)
    if kind == "centre":
        return any(abs(_cx(b) - facade.width / 2) <= near for b in boxes)
    if kind == "sizes":
        derived = [b for b in boxes if b.x1 - b.x0 < CHECKED_BAND * facade.width]
        alike = sum(_near_size(b, constraint.sizes) for b in derived)
        return alike >= SIZE_SHARE * len(derived) - 1e-9
    if kind == "pitch":
        best, _ = _shared_columns(facade, label)
        return all(
            any(abs(p - q) <= SIZE_TOLERANCE * q for q in constraint.pitches)
            for p in _pitches(best)
        )
    if kind == "axis":
        best, _ = _shared_columns(facade, constraint.other)
        centres = _centres(best[0]) if best else []
        narrow = [b for b in boxes if b.x1 - b.x0 < CHECKED_BAND * facade.width]
        return bool(narrow) and all(any(abs(_cx(b) - c) <= near for c in centres) for b in narrow)
    raise ValueError(f"unknown constraint kind {kind!r}")


def _sizes(boxes: Sequence[Box], band: float) -> tuple[tuple[float, float], ...]:
    """The distinct sizes of elements narrower than ``band`` (to the centimetre)."""
    found = {(round(b.x1 - b.x0, 2), round(b.y1 - b.y0, 2)) for b in boxes if b.x1 - b.x0 < band}
    return tuple(sorted(found))


def _near_size(box: Box, sizes: Sequence[tuple[float, float]]) -> bool:
    width, height = box.x1 - box.x0, box.y1 - box.y0
    return any(
        abs(width - w) <= SIZE_TOLERANCE * w and abs(height - h) <= SIZE_TOLERANCE * h
        for w, h in sizes
    )


def _pitches(rows: Sequence[Sequence[Box]]) -> tuple[float, ...]:
    """The distinct vertical distances between rows one above the other (bottom up), to
    the centimetre."""
    bottoms = sorted(row[0].y0 for row in rows)
    return tuple(sorted({round(b - a, 2) for a, b in itertools.pairwise(bottoms)}))


def _listed(values: Iterable[float]) -> str:
    found = sorted(set(values))
    shown = ", ".join(f"{v:g}" for v in found[:4])
    return shown + (f" (and {len(found) - 4} more)" if len(found) > 4 else "")


def _as_many(constraint: Constraint, holding: int, rows: int) -> bool:
    """Whether as large a share of the rows, or as many rows, hold a constraint as in the
    input (floors copied that did not hold it leave the ones that do)."""
    return holding >= constraint.share * rows - 1e-9 or holding >= constraint.rows > 0


# -- equations that make a derived layout keep its style --------------------------------

Equation = tuple[tuple[tuple[float, float], ...], float]  # sum(coefficient * x) == rhs


def equations(style: Sequence[Constraint], facade: Facade, near: float) -> list[Equation]:
    """Linear equations over x coordinates of element edges (each term is a coordinate and
    its coefficient) that make a layout keep a constraint where it nearly does already
    (every coordinate it moves moves less than ``near``): the alignment QP takes them."""
    found: list[Equation] = []
    width = facade.width
    for constraint in style:
        label = constraint.label
        boxes = [b for b in facade.boxes if b.label == label]
        if constraint.kind == "centre":
            nearest = min(boxes, key=lambda b: abs(_cx(b) - width / 2), default=None)
            if nearest is not None and abs(_cx(nearest) - width / 2) <= near:
                found.append((((nearest.x0, 1.0), (nearest.x1, 1.0)), width))
        elif constraint.kind == "axis":
            best, _ = _shared_columns(facade, constraint.other)
            columns = best[0] if best else []
            for box in (b for b in boxes if b.x1 - b.x0 < CHECKED_BAND * width):
                column = min(columns, key=lambda c: abs(_cx(c) - _cx(box)), default=None)
                if column is not None and 0 < abs(_cx(column) - _cx(box)) <= near:
                    found.append((_same_centre(box, column), 0.0))
        elif constraint.kind == "columns":
            rows = _column_rows(facade, label)
            counts = [len(row) for row in rows]
            common = max(set(counts), key=lambda n: (counts.count(n), n), default=0)
            same = [row for row in rows if len(row) == common]
            for row in same[1:]:
                for box, model in zip(row, same[0], strict=True):
                    if 0 < abs(_cx(box) - _cx(model)) <= near:
                        found.append((_same_centre(box, model), 0.0))
        elif constraint.kind == "spacing":
            for row in _runs(facade, label):
                centres = _centres(row)
                pitches = [b - a for a, b in itertools.pairwise(centres)]
                if 0 < max(pitches) - min(pitches) <= near:
                    for a, b, c in zip(row, row[1:], row[2:], strict=False):
                        terms = ((a.x0, 1.0), (a.x1, 1.0), (b.x0, -2.0), (b.x1, -2.0))
                        found.append(((*terms, (c.x0, 1.0), (c.x1, 1.0)), 0.0))
        elif constraint.kind == "symmetry":
            for box in facade.boxes:
                partner = min(
                    (o for o in facade.boxes if o.label == box.label and o.x0 >= box.x0),
                    key=lambda o: abs(o.x1 - (width - box.x0)) + abs(o.y0 - box.y0),
                    default=None,
                )
                if (
                    partner is not None
                    and 0 < abs(partner.x1 - (width - box.x0)) <= near
                    and abs(partner.y0 - box.y0) <= near
                ):
                    found.append((((box.x0, 1.0), (partner.x1, 1.0)), width))
                    found.append((((box.x1, 1.0), (partner.x0, 1.0)), width))
    return found


def _same_centre(box: Box, other: Box) -> tuple[tuple[float, float], ...]:
    return ((box.x0, 1.0), (box.x1, 1.0), (other.x0, -1.0), (other.x1, -1.0))


def check(style: Sequence[Constraint], facade: Facade) -> Kept:
    results: dict[bool, list[Constraint]] = defaultdict(list)
    for constraint in style:
        results[holds(constraint, facade)].append(constraint)
    return Kept(tuple(results[True]), tuple(results[False]))
