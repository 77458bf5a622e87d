"""Regions of a tiling: rectangles of whole cells, their content, and the lines that may cut
them (Wu et al. 2014, section 3.1).

A region is ``(r0, r1, c0, c1)``: rows ``r0 <= r < r1`` (bottom up) and columns
``c0 <= c < c1`` of the tiling. Two regions have the same *content* when their labels and
cell sizes match, so one rule can derive both; contents are numbered as they are met.

A line *crosses an element* where the same label (other than the background) lies on both
sides of it; such lines are not cut while a clean one exists.
"""

from __future__ import annotations

import struct

import numpy as np

from facadecli.grammar.tiling import BACKGROUND, Tiling

Region = tuple[int, int, int, int]
SIZE_QUANTUM = 1e-6  # sizes are compared in steps of this (x the façade's extent)
_SHAPE = struct.Struct("=ii")  # a content key's shape: two native int32, as numpy writes them


class Grid:
    """A tiling's cells as integers, with prefix sums for fast line tests."""

    def __init__(self, tiling: Tiling, background: str = BACKGROUND):
        self.tiling = tiling
        self.background = background
        names = sorted({label for row in tiling.labels for label in row})
        self.names = names
        ids = {name: i for i, name in enumerate(names)}
        self.labels = np.array([[ids[label] for label in row] for row in tiling.labels], dtype=int)
        self._labels32 = self.labels.astype(np.int32)  # as content keys hold them
        self.rows, self.columns = self.labels.shape
        self._xs, self._ys = np.array(tiling.xs, dtype=float), np.array(tiling.ys, dtype=float)
        self.quantum_x = SIZE_QUANTUM * (tiling.xs[-1] - tiling.xs[0])
        self.quantum_y = SIZE_QUANTUM * (tiling.ys[-1] - tiling.ys[0])
        self.background_id = bg = ids.get(background, -1)
        lab = self.labels
        # x lines: between columns c-1 and c, per row; y lines: between rows r-1 and r
        same_x = lab[:, 1:] == lab[:, :-1]
        same_y = lab[1:, :] == lab[:-1, :]
        self._change_x = _prefix(~same_x, axis=0)  # [r, c-1] change counts up to row r
        self._cross_x = _prefix(same_x & (lab[:, 1:] != bg), axis=0)
        self._change_y = _prefix(~same_y, axis=1)
        self._cross_y = _prefix(same_y & (lab[1:, :] != bg), axis=1)
        self.contents: dict[bytes, int] = {}
        self._content_of: dict[Region, int] = {}
        self.terminal: dict[int, str] = {}  # content -> its label, for one-label regions

    def content(self, region: Region) -> int:
        """The region's content number: equal for regions with the same labels at the same
        places, whatever cuts other elements make through them (neighbouring rows and
        columns with the same labels are merged first)."""
        cid = self._content_of.get(region)
        if cid is not None:
            return cid
        r0, r1, c0, c1 = region
        block = self._labels32[r0:r1, c0:c1]
        # a column (row) starts a new one where the labels change across the line before it
        keep_c = np.ones(c1 - c0, dtype=bool)
        keep_c[1:] = self._change_x[r1, c0 : c1 - 1] != self._change_x[r0, c0 : c1 - 1]
        keep_r = np.ones(r1 - r0, dtype=bool)
        keep_r[1:] = self._change_y[r0 : r1 - 1, c1] != self._change_y[r0 : r1 - 1, c0]
        starts_c, starts_r = keep_c.nonzero()[0], keep_r.nonzero()[0]
        reduced = block[starts_r][:, starts_c]
        # a merged column's width is the difference of its cuts (one rounding, as the
        # compiled search computes it too)
        ends_c, ends_r = np.append(starts_c[1:], c1 - c0), np.append(starts_r[1:], r1 - r0)
        widths = (self._xs[c0 + ends_c] - self._xs[c0 + starts_c]) / self.quantum_x
        heights = (self._ys[r0 + ends_r] - self._ys[r0 + starts_r]) / self.quantum_y
        key = b"".join(
            (
                _SHAPE.pack(*reduced.shape),
                reduced.tobytes(),
                np.rint(widths).astype(np.int64).tobytes(),
                np.rint(heights).astype(np.int64).tobytes(),
            )
        )
        cid = self.contents.get(key)
        if cid is None:
            cid = self.contents[key] = len(self.contents)
            if reduced.size == 1:
                self.terminal[cid] = self.names[int(reduced[0, 0])]
        self._content_of[region] = cid
        return cid

    def contents_of(self, regions: list[Region]) -> list[int]:
        """``content`` of each region (most are known: looked up at once)."""
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
