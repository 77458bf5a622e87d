"""Regions of a tiling: rectangles of whole cells, their content, and the lines that may cut
them (Wu et al. 2014, section 3.1).

A region is ``(r0, r1, c0, c1)``: rows ``r0 <= r < r1`` (bottom up) and columns
``c0 <= c < c1`` of the tiling. Two regions have the same *content* when their labels and
cell sizes match, so one rule can derive both; contents are numbered as they are met.

A line *crosses an element* where the same label (other than the background) lies on both
sides of it; such lines are not cut while a clean one exists.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from facadecli import native
from facadecli.grammar.tiling import BACKGROUND, Tiling
from facadecli.limits import GRAMMAR_WORK_MAX

if TYPE_CHECKING:
    from facadecli.grammar import adp
else:  # compiled where it was built from this very source, else interpreted
    adp = native.load(native.GRAMMAR_SEARCH)

Region = tuple[int, int, int, int]
SIZE_QUANTUM = 1e-6  # sizes are compared in steps of this (x the façade's extent)
WORK_MAX = GRAMMAR_WORK_MAX  # work units of one search: cells its contents read, and ``charge``
# units a step of Python work counts (growing a region a line, checking one for overlap):
# such a step costs what reading 100-200 cells costs compiled; at 50, the 12 CMP samples'
# searches for repeats use 0.1-15 % of their share, and 600 squares on a slant stop there
STEP_UNITS = 50


BudgetError = adp.BudgetError  # the search's work would pass ``WORK_MAX`` units
BUDGET_ERRORS: tuple[type[Exception], ...] = (BudgetError,)  # what a spent budget raises


class Grid:
    """A tiling's cells as integers, with prefix sums for fast line tests."""

    def __init__(self, tiling: Tiling, background: str = BACKGROUND):
        self.tiling = tiling
        self.background = background
        names = sorted({label for row in tiling.labels for label in row})
        self.names = names
        ids = {name: i for i, name in enumerate(names)}
        self.labels = np.array([[ids[label] for label in row] for row in tiling.labels], dtype=int)
        self.rows, self.columns = self.labels.shape
        self.quantum_x = SIZE_QUANTUM * (tiling.xs[-1] - tiling.xs[0])
        self.quantum_y = SIZE_QUANTUM * (tiling.ys[-1] - tiling.ys[0])
        bg = ids.get(background, -1)
        lab = self.labels
        # x lines: between columns c-1 and c, per row; y lines: between rows r-1 and r
        same_x = lab[:, 1:] == lab[:, :-1]
        same_y = lab[1:, :] == lab[:-1, :]
        self._change_x = _prefix(~same_x, axis=0)  # [r, c-1] change counts up to row r
        self._cross_x = _prefix(same_x & (lab[:, 1:] != bg), axis=0)
        self._change_y = _prefix(~same_y, axis=1)
        self._cross_y = _prefix(same_y & (lab[1:, :] != bg), axis=1)
        self._content_of: dict[Region, int] = {}
        self.terminal: dict[int, str] = {}  # content -> its label, for one-label regions
        self._xs = np.asarray(tiling.xs, dtype=np.float64)
        self._ys = np.asarray(tiling.ys, dtype=np.float64)
        # the contents, and the search over this tiling (:mod:`facadecli.grammar.adp`)
        self.table = adp.Table(
            self.labels.astype(np.int32).tobytes(),
            self.rows,
            self.columns,
            self._xs.tobytes(),
            self._ys.tobytes(),
            self.quantum_x,
            self.quantum_y,
            bg,
        )
        self.table.limit(WORK_MAX)
        self._charged = 0  # work other than the contents' (``charge``)

    def content(self, region: Region) -> int:
        """The region's content number: equal for regions with the same labels at the same
        places, whatever cuts other elements make through them (neighbouring rows and
        columns with the same labels are merged first, and a merged row or column's size is
        the difference of its cuts, in steps of the size quantum). The search's table
        (:mod:`facadecli.grammar.adp`) keeps them, for the search too.

        A region's key holds a label per merged cell, so a layout whose regions all differ
        (squares on a slant) makes keys of a size that grows with the square of the region's
        side: the keys read, over the whole run, are counted as work (a unit a cell, before
        each is made), past ``WORK_MAX`` units :class:`BudgetError` is raised."""
        cid = self._content_of.get(region)
        if cid is None:
            cid, label = self.table.content(*region)
            self._content_of[region] = cid
            if label >= 0:
                self.terminal[cid] = self.names[label]
        return cid

    @property
    def cells_read(self) -> int:
        """Cells the contents have read so far (a unit of work each)."""
        return self.table.cells()

    @property
    def work(self) -> int:
        """Units of work done so far, counted against ``WORK_MAX``: the contents' cells and
        what ``charge`` counted."""
        return self.cells_read + self._charged

    def charge(self, units: int) -> None:
        """Count work other than the contents' against the same budget (it leaves the
        contents, and the search after it, that much less)."""
        self._charged += units
        self.table.limit(WORK_MAX - self._charged)

    @property
    def spent(self) -> bool:
        """Whether a content was refused because ``WORK_MAX`` was reached."""
        return self.table.spent()

    def contents_of(self, regions: list[Region]) -> list[int]:
        """``content`` of each region."""
        known = self._content_of
        cids = [known.get(region, -1) for region in regions]
        if -1 in cids:
            cids = [self.content(region) for region in regions]
        return cids

    def lines(self, region: Region, axis: str) -> tuple[list[int], list[int]]:
        """Lines inside the region along an axis (column indices for x, row indices for y)
        that separate labels somewhere, and how many element cells each crosses."""
        r0, r1, c0, c1 = region
        if axis == "x":
            if c1 - c0 < 2:
                return [], []
            changes = self._change_x[r1, c0 : c1 - 1] - self._change_x[r0, c0 : c1 - 1]
            crosses = self._cross_x[r1, c0 : c1 - 1] - self._cross_x[r0, c0 : c1 - 1]
            offset = c0 + 1
        else:
            if r1 - r0 < 2:
                return [], []
            changes = self._change_y[r0 : r1 - 1, c1] - self._change_y[r0 : r1 - 1, c0]
            crosses = self._cross_y[r0 : r1 - 1, c1] - self._cross_y[r0 : r1 - 1, c0]
            offset = r0 + 1
        at = np.nonzero(changes > 0)[0]
        return [int(i) + offset for i in at], [int(crosses[i]) for i in at]

    def crossed(self, axis: str, line: int, start: int, stop: int) -> bool:
        """Whether the line (a column index for x, a row index for y) crosses an element
        between ``start`` and ``stop`` (rows for x, columns for y). Façade edges never do."""
        if axis == "x":
            if line <= 0 or line >= self.columns:
                return False
            return bool(self._cross_x[stop, line - 1] - self._cross_x[start, line - 1])
        if line <= 0 or line >= self.rows:
            return False
        return bool(self._cross_y[line - 1, stop] - self._cross_y[line - 1, start])

    def size(self, axis: str, start: int, stop: int) -> float:
        cuts = self.tiling.xs if axis == "x" else self.tiling.ys
        return cuts[stop] - cuts[start]


def _prefix(values: np.ndarray, axis: int) -> np.ndarray:
    """Prefix sums with a leading zero along the axis."""
    summed = np.cumsum(values.astype(np.int32), axis=axis)
    pad = [(0, 0), (0, 0)]
    pad[axis] = (1, 0)
    return np.pad(summed, pad)
