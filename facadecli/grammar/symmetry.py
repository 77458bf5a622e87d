"""Repeated regions by hashing (Wu et al. 2014, section 4.3).

Every terminal region (a rectangle of one label that no element crosses) that occurs at
least twice seeds a table from content to occurrences. Each repeated region is then grown
left, right, down and up, by the least step that keeps its border clear of elements; where
two or more of its occurrences grow into equal content, the grown region is repeated too and
joins the table. Growing in four directions finds repeats that are not grids (Figure 7).

Only the largest repeats are kept for the splitting heuristic: a repeated region whose every
occurrence lies inside an occurrence of a larger one, as often repeated, says nothing more.

Growing stops after ``MAX_REPEATS`` repeated regions, or when the run's deadline says the
share of the time limit for it has passed; then the smaller repeats not yet checked against
the larger ones are kept unchecked (``Repeats.complete`` is then False).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facadecli.grammar.deadline import Deadline
from facadecli.grammar.regions import Grid, Region

MAX_REPEATS = 1000  # repeated regions explored before the search stops growing
TIME_SHARE = 0.5  # of the time limit: growing stops when it has passed


@dataclass(frozen=True)
class Repeats:
    """Occurrences of the repeated regions as arrays, for the heuristic's sums, sorted by
    their first row."""

    r0: np.ndarray
    r1: np.ndarray
    c0: np.ndarray
    c1: np.ndarray
    cells: np.ndarray
    kinds: int  # how many different repeated regions
    complete: bool = True  # False when the time limit stopped the growing

    @property
    def count(self) -> int:
        return int(self.r0.size)

    def starting_in(self, r0: int, r1: int) -> Repeats:
        """The occurrences whose first row is one of ``r0 .. r1 - 1``: those that can lie
        in a region of those rows (the arrays are sorted by first row)."""
        a, b = np.searchsorted(self.r0, [r0, r1]).tolist()
        return Repeats(
            self.r0[a:b],
            self.r1[a:b],
            self.c0[a:b],
            self.c1[a:b],
            self.cells[a:b],
            self.kinds,
            self.complete,
        )


def _seeds(grid: Grid) -> list[Region]:
    """Rectangular connected regions of one label."""
    seen = np.zeros(grid.labels.shape, dtype=bool)
    found = []
    for r in range(grid.rows):
        for c in range(grid.columns):
            if seen[r, c]:
                continue
            label = grid.labels[r, c]
            stack, cells = [(r, c)], []
            seen[r, c] = True
            while stack:
                i, j = stack.pop()
                cells.append((i, j))
                for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
                    inside = 0 <= a < grid.rows and 0 <= b < grid.columns
                    if inside and not seen[a, b] and grid.labels[a, b] == label:
                        seen[a, b] = True
                        stack.append((a, b))
            rows = [i for i, _ in cells]
            cols = [j for _, j in cells]
            region = (min(rows), max(rows) + 1, min(cols), max(cols) + 1)
            if len(cells) == (region[1] - region[0]) * (region[3] - region[2]):
                found.append(region)
    return found


DIRECTIONS = {  # direction -> (the axis it grows along, the step)
    "left": ("x", -1),
    "right": ("x", 1),
    "down": ("y", -1),
    "up": ("y", 1),
}


def _grow(grid: Grid, region: Region, direction: str) -> Region | None:
    """The region grown one clean step in a direction, or None if it cannot grow: the new
    part's borders across the axis must cut no element, and it stops at the first line
    along the axis that cuts none."""
    axis, step = DIRECTIONS[direction]
    across = "y" if axis == "x" else "x"
    r0, r1, c0, c1 = region
    lo, hi, side0, side1 = (c0, c1, r0, r1) if axis == "x" else (r0, r1, c0, c1)
    edge = hi if step > 0 else lo
    limit = (grid.columns if axis == "x" else grid.rows) if step > 0 else 0
    while edge != limit:
        edge += step
        start, stop = (hi, edge) if step > 0 else (edge, lo)
        if grid.crossed(across, side0, start, stop) or grid.crossed(across, side1, start, stop):
            return None
        if not grid.crossed(axis, edge, side0, side1):
            new = (lo, edge) if step > 0 else (edge, hi)
            return (r0, r1, *new) if axis == "x" else (*new, c0, c1)
    return None


def _disjoint(regions: list[Region], taken: np.ndarray) -> list[Region]:
    """The regions in order, each kept unless it shares a cell with one kept before
    (``taken`` marks the kept cells meanwhile; it is all False before and after)."""
    kept: list[Region] = []
    for r in sorted(set(regions)):
        cells = taken[r[0] : r[1], r[2] : r[3]]
        if not cells.any():
            cells[...] = True
            kept.append(r)
    for r in kept:
        taken[r[0] : r[1], r[2] : r[3]] = False
    return kept


class _Kept:
    """The kinds of repeated regions kept so far, their occurrences in one growing array
    (a kind's occurrences side by side), so that a new kind is checked against all at once."""

    def __init__(self) -> None:
        self.kinds: list[list[Region]] = []
        self.starts: list[int] = []  # where each kind's occurrences start in ``boxes``
        self.boxes = np.empty((64, 4), dtype=int)
        self.owner = np.empty(64, dtype=int)
        self.size = 0

    def add(self, regions: list[Region]) -> None:
        end = self.size + len(regions)
        if end > len(self.boxes):
            room = max(end, 2 * len(self.boxes))
            self.boxes = np.resize(self.boxes, (room, 4))
            self.owner = np.resize(self.owner, room)
        self.boxes[self.size : end] = regions
        self.owner[self.size : end] = len(self.kinds)
        self.starts.append(self.size)
        self.kinds.append(regions)
        self.size = end

    def hold(self, regions: list[Region]) -> bool:
        """Whether every region lies in an occurrence of one kept kind that is at least as
        often repeated (checked for the first region against all kept kinds at once, then
        in full for the kinds that hold it)."""
        if not self.kinds:
            return False
        boxes, owner = self.boxes[: self.size], self.owner[: self.size]
        inner = np.array(regions, dtype=int)
        for index in np.unique(owner[_within(inner[:1], boxes)[0]]).tolist():
            start, kind = self.starts[index], self.kinds[index]
            if len(kind) < len(regions):
                continue
            if _within(inner, boxes[start : start + len(kind)]).any(1).all():
                return True
        return False


def _within(inner: np.ndarray, outer: np.ndarray) -> np.ndarray:
    """``[i, j]``: region ``inner[i]`` lies inside region ``outer[j]``."""
    a, b = inner[:, None, :], outer[None, :, :]
    return (
        (b[..., 0] <= a[..., 0])
        & (a[..., 1] <= b[..., 1])
        & (b[..., 2] <= a[..., 2])
        & (a[..., 3] <= b[..., 3])
    )


def find_repeats(grid: Grid, limit: int = MAX_REPEATS, deadline: Deadline | None = None) -> Repeats:
    table: dict[int, list[Region]] = {}
    by_content: dict[int, list[Region]] = {}
    taken = np.zeros(grid.labels.shape, dtype=bool)
    for region in _seeds(grid):
        by_content.setdefault(grid.content(region), []).append(region)
    queue = []
    for cid, regions in sorted(by_content.items()):
        kept = _disjoint(regions, taken)
        if len(kept) >= 2:
            table[cid] = kept
            queue.append(cid)
    head, complete = 0, True
    while head < len(queue) and len(table) < limit:
        if deadline is not None and deadline.passed(TIME_SHARE):
            complete = False
            break
        occurrences = table[queue[head]]
        head += 1
        for direction in ("left", "right", "down", "up"):
            grown: dict[int, list[Region]] = {}
            for region in occurrences:
                bigger = _grow(grid, region, direction)
                if bigger is not None:
                    grown.setdefault(grid.content(bigger), []).append(bigger)
            for cid, regions in grown.items():
                if cid in table or grid.content(regions[0]) in grid.terminal:
                    continue
                kept = _disjoint(regions, taken)
                if len(kept) >= 2:
                    table[cid] = kept
                    queue.append(cid)
    # the largest repeats: drop one whose occurrences all sit in those of a larger one
    # (once the time share has passed, the smaller ones are kept unchecked)
    kinds = sorted(table.items(), key=lambda item: -_cells(item[1][0]))
    larger = _Kept()
    for _, regions in kinds:
        if complete and deadline is not None and deadline.passed(TIME_SHARE):
            complete = False
        if not complete or not larger.hold(regions):
            larger.add(regions)
    kept_kinds = larger.kinds
    flat = [r for regions in kept_kinds for r in regions]
    array = np.array(flat, dtype=int).reshape(-1, 4)
    array = array[np.argsort(array[:, 0], kind="stable")]  # by first row (``starting_in``)
    return Repeats(
        array[:, 0],
        array[:, 1],
        array[:, 2],
        array[:, 3],
        (array[:, 1] - array[:, 0]) * (array[:, 3] - array[:, 2]),
        len(kept_kinds),
        complete,
    )


def _cells(region: Region) -> int:
    return (region[1] - region[0]) * (region[3] - region[2])
