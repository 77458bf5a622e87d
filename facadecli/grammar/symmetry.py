"""Repeated regions by hashing (Wu et al. 2014, section 4.3).

Every terminal region (a rectangle of one label that no element crosses) that occurs at
least twice seeds a table from content to occurrences. Each repeated region is then grown
left, right, down and up, by the least step that keeps its border clear of elements; where
two or more of its occurrences grow into equal content, the grown region is repeated too and
joins the table. Growing in four directions finds repeats that are not grids (Figure 7).

Only the largest repeats are kept for the splitting heuristic: a repeated region whose every
occurrence lies inside an occurrence of a larger one, as often repeated, says nothing more.

Every step counts against the search's work budget (``regions.WORK_MAX``, which the
contents read here count against too): a cell looked at for the seeds, a step of growing, a
region checked for overlap, a box compared in the check for larger repeats, at
``regions.STEP_UNITS`` units each for Python steps (a unit a box compared). Growing stops
after ``MAX_REPEATS`` repeated regions, before a step would take the work past
``WORK_SHARE`` of the budget (the rest is the grammar search's), or when the run's deadline
says the share of the time limit for it has passed; then the smaller repeats not yet
checked against the larger ones are kept unchecked, and ``Repeats.stopped`` says why.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facadecli.grammar import regions as regions_module
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.regions import Grid, Region

MAX_REPEATS = 1000  # repeated regions explored before the search stops growing
TIME_SHARE = 0.5  # of the time limit: growing stops when it has passed
WORK_SHARE = 0.5  # of the search's work budget: growing stops before it would pass it


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
    stopped: str = ""  # what stopped the growing early: "", "time" or "work"

    @property
    def complete(self) -> bool:
        return not self.stopped

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
            self.stopped,
        )


def _seeds(grid: Grid) -> list[Region]:
    """Rectangular connected regions of one label (4-connected), by their first cell row by
    row. Compiled (a labelling per label), so that a cell costs a unit of work."""
    from scipy import ndimage  # the grammar's only user of it, loaded when a search runs

    found = []
    for label in np.unique(grid.labels).tolist():
        parts, count = ndimage.label(grid.labels == label)
        sizes = np.bincount(parts.ravel(), minlength=count + 1)
        for number, box in enumerate(ndimage.find_objects(parts), start=1):
            rows, cols = box
            region = (rows.start, rows.stop, cols.start, cols.stop)
            if sizes[number] == (region[1] - region[0]) * (region[3] - region[2]):
                found.append(region)
    found.sort(key=lambda region: (region[0], region[2]))
    return found


DIRECTIONS = {  # direction -> (the axis it grows along, the step)
    "left": ("x", -1),
    "right": ("x", 1),
    "down": ("y", -1),
    "up": ("y", 1),
}


def _grow(grid: Grid, region: Region, direction: str) -> tuple[Region | None, int]:
    """The region grown one clean step in a direction, or None if it cannot grow: the new
    part's borders across the axis must cut no element, and it stops at the first line
    along the axis that cuts none. With the lines it tried (its work)."""
    axis, step = DIRECTIONS[direction]
    across = "y" if axis == "x" else "x"
    r0, r1, c0, c1 = region
    lo, hi, side0, side1 = (c0, c1, r0, r1) if axis == "x" else (r0, r1, c0, c1)
    edge = hi if step > 0 else lo
    limit = (grid.columns if axis == "x" else grid.rows) if step > 0 else 0
    tried = 0
    while edge != limit:
        edge += step
        tried += 1
        start, stop = (hi, edge) if step > 0 else (edge, lo)
        if grid.crossed(across, side0, start, stop) or grid.crossed(across, side1, start, stop):
            return None, tried
        if not grid.crossed(axis, edge, side0, side1):
            new = (lo, edge) if step > 0 else (edge, hi)
            return ((r0, r1, *new) if axis == "x" else (*new, c0, c1)), tried
    return None, tried


def _disjoint(regions: list[Region], taken: np.ndarray) -> list[Region]:
    """The regions in order, each kept unless it shares a cell with one kept before
    (``taken`` marks the kept cells meanwhile; it is all False before and after). Its work:
    ``_disjoint_work``."""
    kept: list[Region] = []
    for r in sorted(set(regions)):
        cells = taken[r[0] : r[1], r[2] : r[3]]
        if not cells.any():
            cells[...] = True
            kept.append(r)
    for r in kept:
        taken[r[0] : r[1], r[2] : r[3]] = False
    return kept


def _disjoint_work(regions: list[Region]) -> int:
    """Units of work ``_disjoint`` does: a step a region, and the cells it looks at."""
    return sum(regions_module.STEP_UNITS + 2 * _cells(r) for r in regions)


class _Kept:
    """The kinds of repeated regions kept so far, their occurrences in one growing array
    (a kind's occurrences side by side), so that a new kind is checked against all at once."""

    def __init__(self) -> None:
        self.kinds: list[list[Region]] = []
        self.starts: list[int] = []  # where each kind's occurrences start in ``boxes``
        self.boxes = np.empty((64, 4), dtype=int)
        self.owner = np.empty(64, dtype=int)
        self.size = 0
        self.compared = 0  # boxes compared by ``hold`` so far (its work, a unit each)

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
        self.compared += self.size
        for index in np.unique(owner[_within(inner[:1], boxes)[0]]).tolist():
            start, kind = self.starts[index], self.kinds[index]
            if len(kind) < len(regions):
                continue
            self.compared += len(regions) * len(kind)
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


class _Work:
    """The work ``find_repeats`` may do: ``WORK_SHARE`` of the search's budget, counted on
    the grid (``Grid.charge``; the contents it reads count there themselves)."""

    def __init__(self, grid: Grid):
        self.grid = grid
        self.allowed = int(WORK_SHARE * regions_module.WORK_MAX)

    def afford(self, units: int) -> bool:
        """Whether ``units`` more stay within the share (counted when they do)."""
        if self.grid.work + units > self.allowed:
            return False
        self.grid.charge(units)
        return True

    def left(self) -> bool:
        return self.grid.work < self.allowed


def find_repeats(grid: Grid, limit: int = MAX_REPEATS, deadline: Deadline | None = None) -> Repeats:
    work = _Work(grid)
    if not work.afford(grid.rows * grid.columns * len(np.unique(grid.labels))):
        return _repeats([], "work")  # no seeds: not even the cells can be looked at
    table: dict[int, list[Region]] = {}
    by_content: dict[int, list[Region]] = {}
    taken = np.zeros(grid.labels.shape, dtype=bool)
    for region in _seeds(grid):
        by_content.setdefault(grid.content(region), []).append(region)
    queue = []
    for cid, regions in sorted(by_content.items()):
        if not work.afford(_disjoint_work(regions)):
            return _repeats([], "work")
        kept = _disjoint(regions, taken)
        if len(kept) >= 2:
            table[cid] = kept
            queue.append(cid)
    head, stopped = 0, ""
    while head < len(queue) and len(table) < limit:
        if deadline is not None and deadline.passed(TIME_SHARE):
            stopped = "time"
            break
        grown = _grown(grid, table[queue[head]], work)
        if grown is None:  # the share of the work ran out: this kind's growing is dropped
            stopped = "work"
            break
        head += 1
        for cid, regions in grown:
            if cid in table or grid.content(regions[0]) in grid.terminal:
                continue
            if not work.afford(_disjoint_work(regions)):
                stopped = "work"
                break
            kept = _disjoint(regions, taken)
            if len(kept) >= 2:
                table[cid] = kept
                queue.append(cid)
        if stopped:
            break
    # the largest repeats: drop one whose occurrences all sit in those of a larger one
    # (once a share has passed, the smaller ones are kept unchecked)
    kinds = sorted(table.items(), key=lambda item: -_cells(item[1][0]))
    larger = _Kept()
    for _, regions in kinds:
        if not stopped and deadline is not None and deadline.passed(TIME_SHARE):
            stopped = "time"
        if not stopped and not work.left():
            stopped = "work"
        if stopped or not larger.hold(regions):
            larger.add(regions)
        if larger.compared and not stopped:
            work.grid.charge(larger.compared)
            larger.compared = 0
    return _repeats(larger.kinds, stopped)


def _grown(
    grid: Grid, occurrences: list[Region], work: _Work
) -> list[tuple[int, list[Region]]] | None:
    """The occurrences grown left, right, down and up, by content (in the order met); None
    when the work would pass its share first."""
    found: list[tuple[int, list[Region]]] = []
    for direction in ("left", "right", "down", "up"):
        grown: dict[int, list[Region]] = {}
        for region in occurrences:
            if not work.left():
                return None
            bigger, tried = _grow(grid, region, direction)
            grid.charge(tried * regions_module.STEP_UNITS)
            if bigger is not None:
                grown.setdefault(grid.content(bigger), []).append(bigger)
        found.extend(grown.items())
    return found


def _repeats(kept_kinds: list[list[Region]], stopped: str) -> Repeats:
    """The kinds kept as arrays, sorted by first row (``Repeats.starting_in``)."""
    flat = [r for regions in kept_kinds for r in regions]
    array = np.array(flat, dtype=int).reshape(-1, 4)
    array = array[np.argsort(array[:, 0], kind="stable")]
    return Repeats(
        array[:, 0],
        array[:, 1],
        array[:, 2],
        array[:, 3],
        (array[:, 1] - array[:, 0]) * (array[:, 3] - array[:, 2]),
        len(kept_kinds),
        stopped,
    )


def _cells(region: Region) -> int:
    return (region[1] - region[0]) * (region[3] - region[2])
