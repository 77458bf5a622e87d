"""The grammar search's inner loop (:mod:`facadecli.grammar.search`): the contents of the
tiling's regions, the actions offered for each region, building grammars region by region
(greedy, or ADP's explore-or-exploit choice), the merged cost of a grammar and the value
table it teaches.

One implementation, two ways to run: setup.py compiles this file with Cython where there is
a C compiler (its C types are in ``adp.pxd`` beside it: this file stays plain Python), and
it runs interpreted where there is none, with the same grammars. The data live in flat
``array`` buffers grown by doubling (C arrays once compiled): the value table indexed by
content number, a binary heap of entry numbers, reach sets as 64-bit words, sets of int
sequences by open addressing. The random draws are the ``random.Random`` handed over.

Ids: an *entry* is a region to split (its heap key and content); an *action* is one rule an
entry may take; a *content* is what regions read (``regions.Grid.content``: equal for the
same labels at the same places, numbered as met). An action's parts are written as symbols:
a content for a non-terminal, -1 - label for a terminal.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Sequence
from typing import Any

try:
    import cython
except ImportError:  # interpreted, Cython not installed (it is a build requirement only)
    from facadecli import _cython as cython  # type: ignore[no-redef, unused-ignore]

if cython.compiled:
    from cython.cimports.libc.math import exp, nearbyint
else:
    from math import exp

    from facadecli._libm import nearbyint


COMPILED_FROM: str | None = None  # setup.py: the digest of the sources it was built from

EXT_ABA, EXT_SYMSPLIT, EXT_GRIDSPLIT = 1, 2, 4  # the extensions, as bits
OP_SPLIT, OP_REPEAT, OP_ABA, OP_SYMSPLIT, OP_GRID = 0, 1, 2, 3, 4
OPS = ("split", "repeat", "repeatABA", "symsplit", "gridsplit")
TOP_ACTIONS = 8  # actions per region the search chooses among (the heuristic's best)
GRID_CELLS = 48  # a gridsplit of more cells than this costs more than it can save
TIME_UP = -2  # what choosing an action returns once the clock has passed the stop
FAILED = -9  # what a typed function returns while an exception is raised (adp.pxd)
CLOCK_EVERY = 63  # the clock is read at every 64th region (and the first)
INF = float("inf")
M32 = 2**32 - 1
FNV_OFFSET, FNV_PRIME = 1469598103934665603, 1099511628211  # a sequence's hash
M64 = 2**64 - 1  # 64-bit words: products wrap as C's do
ONE = 1  # a 64-bit word's lowest bit
DE_BRUIJN = 0x03F79D71B4CB0A89  # the lowest set bit's index: (low * this) >> 58, looked up
_BIT_AT = [0] * 64
for _i in range(64):
    _BIT_AT[(((1 << _i) * DE_BRUIJN) & M64) >> 58] = _i

_INTS = array("i", [0])
_LONGS = array("q", [0])
_DOUBLES = array("d", [0.0])
_WORDS = array("Q", [0])
_FLAGS = array("b", [0])


class BudgetError(Exception):
    """The search's work would pass its units (``regions.WORK_MAX``)."""


def _ints(n: int) -> array[int]:
    return _INTS * n


def _longs(n: int) -> array[int]:
    return _LONGS * n


def _doubles(n: int) -> array[float]:
    return _DOUBLES * n


def _words(n: int) -> array[int]:
    return _WORDS * n


def _flags(n: int) -> array[int]:
    return _FLAGS * n


def _capacity(have: int, need: int) -> int:
    """Twice over until ``need`` fits (16 at least)."""
    cap = have if have > 16 else 16
    while cap < need:
        cap *= 2
    return cap


def _more_ints(old: Any, used: int, need: int, fill: int) -> array[int]:
    """``old``'s first ``used`` items in an array of room for ``need``, the rest ``fill``."""
    made = _INTS * _capacity(len(old), need)
    view = made
    view[:used] = old[:used]
    if fill:
        for i in range(used, len(made)):
            view[i] = fill
    return made


def _more_doubles(old: Any, used: int, need: int) -> array[float]:
    made = _DOUBLES * _capacity(len(old), need)
    view = made
    view[:used] = old[:used]
    return made


def _more_longs(old: Any, used: int, need: int) -> array[int]:
    made = _LONGS * _capacity(len(old), need)
    view = made
    view[:used] = old[:used]
    return made


def _more_flags(old: Any, used: int, need: int) -> array[int]:
    made = _FLAGS * _capacity(len(old), need)
    view = made
    view[:used] = old[:used]
    return made


class SeqSet:
    """A set of int sequences numbered as added (content keys, regions, forms, kinds of
    rules, grammars seen), by open addressing: the sequences one after another in a pool
    (each its length, then its items), a slot two words, a number + 1 (0: empty) and the
    sequence's hash, so that a probe reads the pool only when the hashes are equal."""

    def __init__(self) -> None:
        self.pool = _ints(64)
        self.at = _longs(16)
        self.slots = _words(128)
        self.n_slots = 64
        self.n = 0
        self.pool_n = 0
        self.added = False

    def hash(self, v: Any, start: int, n: int) -> int:
        h = FNV_OFFSET ^ n
        for i in range(n):
            h = ((h ^ (v[start + i] & M32)) * FNV_PRIME) & M64
            h ^= h >> 29
        return h

    def add(self, v: Any, start: int, n: int) -> int:
        """The number of ``v[start:start + n]``, added if new (``added`` says so)."""
        if 2 * (self.n + 1) > self.n_slots:
            self.rehash(2 * self.n_slots)
        mask = self.n_slots - 1
        h = self.hash(v, start, n)
        j = h & mask
        while True:
            s = self.slots[2 * j]
            if s == 0:
                break
            if self.slots[2 * j + 1] == h:
                at = self.at[s - 1]
                if self.pool[at] == n:
                    same = True
                    for i in range(n):
                        if self.pool[at + 1 + i] != v[start + i]:
                            same = False
                            break
                    if same:
                        self.added = False
                        return s - 1
            j = (j + 1) & mask
        if self.pool_n + n + 1 > len(self.pool):
            self.pool = _more_ints(self.pool, self.pool_n, self.pool_n + n + 1, 0)
        if self.n + 1 > len(self.at):
            self.at = _more_longs(self.at, self.n, self.n + 1)
        self.at[self.n] = self.pool_n
        self.pool[self.pool_n] = n
        for i in range(n):
            self.pool[self.pool_n + 1 + i] = v[start + i]
        self.pool_n += n + 1
        self.n += 1
        self.slots[2 * j] = self.n
        self.slots[2 * j + 1] = h
        self.added = True
        return self.n - 1

    def clear(self) -> None:
        """Empty, with the room it has (a new array of slots: zeroed by C in both modes)."""
        self.slots = _words(2 * self.n_slots)
        self.n = 0
        self.pool_n = 0

    def rehash(self, n_slots: int) -> None:
        slots = _words(2 * n_slots)
        mask = n_slots - 1
        for i in range(self.n_slots):
            s = self.slots[2 * i]
            if s == 0:
                continue
            h = self.slots[2 * i + 1]
            j = h & mask
            while slots[2 * j] != 0:
                j = (j + 1) & mask
            slots[2 * j] = s
            slots[2 * j + 1] = h
        self.slots = slots
        self.n_slots = n_slots


class Table:
    """A tiling's regions, their contents and actions, and the value table of one grammar
    search: ``Table(labels, rows, cols, xs, ys, qx, qy, background)`` (labels int32, rows x
    cols, bottom row first; the cuts float64; the size quanta; the background's label or
    -1), ``prepare`` before the search."""

    def __init__(
        self,
        labels: bytes,
        rows: int,
        cols: int,
        xs: bytes,
        ys: bytes,
        qx: float,
        qy: float,
        background: int,
    ) -> None:
        if not (
            rows > 0
            and cols > 0
            and len(labels) == rows * cols * 4
            and len(xs) == (cols + 1) * 8
            and len(ys) == (rows + 1) * 8
            and qx > 0
            and qy > 0
        ):
            raise ValueError("the tiling's arrays do not match its size")
        made = array("i")
        made.frombytes(labels)
        self.labels = made
        cuts = array("d")
        cuts.frombytes(xs)
        self.xs = cuts
        cuts = array("d")
        cuts.frombytes(ys)
        self.ys = cuts
        self.rows, self.cols, self.qx, self.qy = rows, cols, qx, qy
        self.prepared = False
        self.repeats = _ints(1)
        self.n_repeats = 0
        self.ext = 0
        self.split_cost = self.repeat_cost = 0.0
        self.cells_read = 0
        self.cells_max = 2**63 - 1  # until ``limit``
        self.spent_ = False
        self.keys = SeqSet()
        self.regions = SeqSet()
        self.forms = SeqSet()
        self.entry_map = SeqSet()
        self.kinds = SeqSet()
        self.terminal = _ints(64)
        self.region_cid = _ints(64)
        self.buffer = _ints(64)
        self.form = _ints(64)
        self._prefixes(background)
        # entries: key (5 a row), content, first action, actions (-1: not made yet), odds
        self.n_entries = 0
        self.e_key = _ints(80)
        self.e_cid = _ints(16)
        self.e_first = _ints(16)
        self.e_count = _ints(16)
        self.e_odds = _ints(16)
        # actions
        self.n_actions = 0
        self.a_cost = _doubles(16)
        self.a_heuristic = _doubles(16)
        self.a_int = _ints(16 * A_FIELDS)
        self.pool = _ints(64)
        self.pool_n = 0
        self.odds = _doubles(64)
        self.odds_n = 0
        # per content
        self.n_contents = 0
        self.rule = _ints(64)
        self.pending = _flags(64)
        self.mark = _ints(64)
        self.kind_of = _ints(64)
        self.position = _ints(64)
        self.learned = _doubles(64)
        self.covered = _ints(64)  # where its contents start in ``cover`` (-1: none)
        self.cover = _ints(64)  # each: how many, then the contents
        self.cover_n = 0
        self.first_of = _ints(64)  # by kind: the content met first with it, or -1
        for i in range(64):
            self.first_of[i] = -1
        self.stamp = 0
        self.order = _ints(64)
        self.order_n = 0
        self.heap = _ints(64)
        self.heap_n = 0
        self.scratch = _ints(64)
        # drafting a region's actions (``drafts``): by line, a row per axis of d_stride
        stride = (rows if rows > cols else cols) + 2
        self.d_stride = stride
        self.d_r0 = self.d_r1 = self.d_c0 = self.d_c1 = 0
        self.d_lines, self.d_crosses = _ints(2 * stride), _ints(2 * stride)
        self.d_cost = _doubles(2 * stride)
        self.d_pos, self.d_neg = _doubles(stride), _doubles(stride)
        self.d_full, self.d_runs = _ints(stride), _ints(2 * stride)
        self.d_cheap = _ints(TOP_ACTIONS)
        self.d_bounds = _ints(stride)
        self.d_part = _ints(4)
        self.d_inside, self.d_spans = _ints(1), _ints(4)
        self.n_inside = 0
        self.n_drafts = self.n_order = self.d_pool_n = 0
        self.d_real, self.d_int, self.d_order = _doubles(32), _ints(16 * D_FIELDS), _ints(16)
        self.d_pool = _ints(256)
        self.n_halves = 0  # the cuts in two: heuristic and cost, axis and line
        self.h_real, self.h_int = _doubles(4 * TOP_ACTIONS), _ints(4 * TOP_ACTIONS)
        self.symbols = _ints(64)
        self.symbols_n = 0
        self.bits = _words(64)
        self.words = 0
        self.distinct = _doubles(64)
        self.group = _ints(64)
        self.counts = _ints(64)
        self.bit_at = _ints(64)
        for i in range(64):
            self.bit_at[i] = _BIT_AT[i]
        # how grammars are built (``build``)
        self.greedy_ = True
        self.epsilon = 0.0
        self.optimistic = 0.0
        self.stop_at = INF
        self.ticks = 0
        self.draw: Callable[[], float] = _never
        self.clock: Callable[[], float] = _never

    # -- the tiling's regions ---------------------------------------------------------------

    def _prefixes(self, background: int) -> None:
        """Per x line (between columns c - 1 and c), label changes and element crossings in
        the rows below each row; for y the same across."""
        rows, cols = self.rows, self.cols
        nx = (rows + 1) * (cols - 1 if cols > 1 else 0)
        ny = (rows - 1 if rows > 1 else 0) * (cols + 1)
        self.change_x, self.cross_x = _ints(nx + 1), _ints(nx + 1)
        self.change_y, self.cross_y = _ints(ny + 1), _ints(ny + 1)
        labels = self.labels
        for r in range(rows):
            for c in range(1, cols):
                label = labels[r * cols + c]
                same = label == labels[r * cols + c - 1]
                at = (r + 1) * (cols - 1) + (c - 1)
                below = r * (cols - 1) + (c - 1)
                self.change_x[at] = self.change_x[below] + (0 if same else 1)
                self.cross_x[at] = self.cross_x[below] + (1 if same and label != background else 0)
        for r in range(1, rows):
            for c in range(cols):
                label = labels[r * cols + c]
                same = label == labels[(r - 1) * cols + c]
                at = (r - 1) * (cols + 1) + c + 1
                left = (r - 1) * (cols + 1) + c
                self.change_y[at] = self.change_y[left] + (0 if same else 1)
                self.cross_y[at] = self.cross_y[left] + (1 if same and label != background else 0)

    def grid_content(self, r0: int, r1: int, c0: int, c1: int) -> int:
        """The region's content, numbered as met (``regions.Grid.content``): its key is the
        merged rows and columns' counts, their labels (row by row) and sizes in quanta."""
        box = self.buffer
        box[0], box[1], box[2], box[3] = r0, r1, c0, c1
        at = self.regions.add(box, 0, 4)
        if not self.regions.added:
            return self.region_cid[at]
        if self.spent_:
            raise BudgetError("the contents' budget has run out")
        w, h = c1 - c0, r1 - r0
        need = 2 + w * h + 2 * (w + h) + 4
        if need > len(self.buffer):
            self.buffer = _more_ints(self.buffer, 0, need, 0)
        key = self.buffer
        # the starts of merged columns and rows, kept at the end of the buffer
        starts_c = len(key) - (w + h + 2)
        starts_r = starts_c + w + 1
        nc = nr = 0
        cols1 = self.cols - 1
        for j in range(w):
            if (
                j == 0
                or self.change_x[r1 * cols1 + c0 + j - 1] != self.change_x[r0 * cols1 + c0 + j - 1]
            ):
                key[starts_c + nc] = j
                nc += 1
        cols2 = self.cols + 1
        for i in range(h):
            if (
                i == 0
                or self.change_y[(r0 + i - 1) * cols2 + c1]
                != self.change_y[(r0 + i - 1) * cols2 + c0]
            ):
                key[starts_r + nr] = i
                nr += 1
        key[starts_c + nc] = w
        key[starts_r + nr] = h
        # what the key reads and keeps: counted first, so the budget bounds memory and time
        cost = 2 + nr * nc + nr + nc
        if self.cells_read + cost > self.cells_max:
            self.spent_ = True
            raise BudgetError("the contents' budget has run out")
        self.cells_read += cost
        n = 0
        key[n] = nr
        key[n + 1] = nc
        n = 2
        for i in range(nr):
            row = (r0 + key[starts_r + i]) * self.cols + c0
            for j in range(nc):
                key[n] = self.labels[row + key[starts_c + j]]
                n += 1
        for j in range(nc):
            size = self.xs[c0 + key[starts_c + j + 1]] - self.xs[c0 + key[starts_c + j]]
            key[n] = int(nearbyint(size / self.qx))
            n += 1
        for i in range(nr):
            size = self.ys[r0 + key[starts_r + i + 1]] - self.ys[r0 + key[starts_r + i]]
            key[n] = int(nearbyint(size / self.qy))
            n += 1
        cid = self.keys.add(key, 0, n)
        if self.keys.added:
            if cid + 1 > len(self.terminal):
                self.terminal = _more_ints(self.terminal, cid, cid + 1, 0)
            self.terminal[cid] = key[2] if nr * nc == 1 else -1
        if at + 1 > len(self.region_cid):
            self.region_cid = _more_ints(self.region_cid, at, at + 1, 0)
        self.region_cid[at] = cid
        return cid

    def quantum(self, axis: int, a: int, b: int) -> int:
        """A span's size along an axis (0: x, 1: y) in steps of its size quantum."""
        if axis == 0:
            return int(nearbyint((self.xs[b] - self.xs[a]) / self.qx))
        return int(nearbyint((self.ys[b] - self.ys[a]) / self.qy))

    # -- the actions offered for a region (Wu et al. 2014, section 4.4) --------------------
    # A region's actions are drafted in typed buffers before they are kept: per draft its
    # heuristic and rule cost (``d_real``, two a draft), its int fields (``d_int``, D_FIELDS
    # a draft: where its bounds, columns across and parts' contents start in ``d_pool``),
    # and ``d_order``, the drafts in the order a list of them would hold.

    def drafts(self, r0: int, r1: int, c0: int, c1: int) -> int:
        """The actions of a region before they are kept, best first, in ``d_order`` (their
        number returned): along each axis, a cut at every clean line, cuts that keep
        periodic runs of parts or the repeated regions found by hashing whole, the cuts in
        two the heuristic likes best, and with the extension a two-way grid; each written
        as the cheapest rule that fits its parts."""
        self.d_r0, self.d_r1, self.d_c0, self.d_c1 = r0, r1, c0, c1
        self.n_drafts = self.d_pool_n = self.n_order = self.n_halves = 0
        found0, found1 = self._found_lines(0), self._found_lines(1)
        n0, n1 = self._lines_crossing(0, found0, 0), self._lines_crossing(1, found1, 0)
        if not n0 and not n1:  # every line cuts an element: the fewest cells
            if not found0 and not found1:
                raise ValueError(f"region {(r0, r1, c0, c1)} has one label and no rule")
            least0 = self._least_crossed(0, found0) if found0 else 2**31 - 1
            least1 = self._least_crossed(1, found1) if found1 else 2**31 - 1
            if not found0 or (found1 and least1 < least0):
                n1 = self._lines_crossing(1, found1, least1)
            else:
                n0 = self._lines_crossing(0, found0, least0)
        self._inside()
        self._line_costs(0)
        self._line_costs(1)
        for axis in range(2):
            n = n0 if axis == 0 else n1
            if not n:
                continue
            lo, hi = (c0, c1) if axis == 0 else (r0, r1)
            base = axis * self.d_stride
            self.d_full[0] = lo
            for i in range(n):
                self.d_full[1 + i] = self.d_lines[base + i]
            self.d_full[n + 1] = hi
            for i in range(n + 2):
                self.d_bounds[i] = self.d_full[i]
            self._draft(axis, n + 2)
            self._runs(axis, n + 2)
            self._repeated(axis, n + 2)
            if n > 1:  # cuts in two: the lines the heuristic likes best
                cheap = self._cheapest_lines(axis, n)
                for k in range(cheap):
                    self.d_bounds[0], self.d_bounds[1], self.d_bounds[2] = lo, self.d_cheap[k], hi
                    if not self._has_draft(axis, 3):
                        self._rank_in_two(axis, self.d_cheap[k])
        if self.ext & EXT_GRIDSPLIT and n0 and n1 and (n0 + 1) * (n1 + 1) <= GRID_CELLS:
            self._grid(n0, n1)
        # every structural cut, and the heuristic's best cuts in two to fill up the choice
        self._sort_drafts()
        if self.n_order > TOP_ACTIONS:
            self.n_order = TOP_ACTIONS
        self._sort_halves()
        take = max(TOP_ACTIONS - self.n_order, TOP_ACTIONS // 2)
        for k in range(min(take, self.n_halves)):
            axis, line = self.h_int[2 * k], self.h_int[2 * k + 1]
            lo, hi = (c0, c1) if axis == 0 else (r0, r1)
            self.d_bounds[0], self.d_bounds[1], self.d_bounds[2] = lo, line, hi
            self._draft(axis, 3)
        self._sort_drafts()
        return self.n_order

    def _found_lines(self, axis: int) -> int:
        """The lines along the axis where labels change inside the region, in order, into
        ``d_lines`` (from ``axis * d_stride``), the elements each cuts through into
        ``d_crosses``; how many."""
        r0, r1, c0, c1 = self.d_r0, self.d_r1, self.d_c0, self.d_c1
        base = axis * self.d_stride
        n = 0
        if axis == 0:
            cols1 = self.cols - 1
            for i in range(c1 - c0 - 1):
                if self.change_x[r1 * cols1 + c0 + i] - self.change_x[r0 * cols1 + c0 + i]:
                    self.d_lines[base + n] = c0 + 1 + i
                    self.d_crosses[base + n] = (
                        self.cross_x[r1 * cols1 + c0 + i] - self.cross_x[r0 * cols1 + c0 + i]
                    )
                    n += 1
        else:
            cols2 = self.cols + 1
            for i in range(r1 - r0 - 1):
                at = (r0 + i) * cols2
                if self.change_y[at + c1] - self.change_y[at + c0]:
                    self.d_lines[base + n] = r0 + 1 + i
                    self.d_crosses[base + n] = self.cross_y[at + c1] - self.cross_y[at + c0]
                    n += 1
        return n

    def _lines_crossing(self, axis: int, n: int, crosses: int) -> int:
        """Keeps, in order, the found lines that cut through this many elements; how many
        (none kept: the lines are left as found)."""
        base = axis * self.d_stride
        k = 0
        for i in range(n):
            if self.d_crosses[base + i] == crosses:
                self.d_lines[base + k] = self.d_lines[base + i]
                self.d_crosses[base + k] = crosses
                k += 1
        return k

    def _least_crossed(self, axis: int, n: int) -> int:
        base = axis * self.d_stride
        least = self.d_crosses[base]
        for i in range(1, n):
            if self.d_crosses[base + i] < least:
                least = self.d_crosses[base + i]
        return least

    def _cheapest_lines(self, axis: int, n: int) -> int:
        """The TOP_ACTIONS lines of least cost (then lowest) into ``d_cheap``, in that
        order; how many."""
        base = axis * self.d_stride
        lo = self.d_c0 if axis == 0 else self.d_r0
        k = 0
        for i in range(n):
            line = self.d_lines[base + i]
            c = self.d_cost[base + line - lo]
            j = k  # lines come in order, so a line goes after those of equal cost
            while j > 0 and c < self.d_cost[base + self.d_cheap[j - 1] - lo]:
                j -= 1
            if j >= TOP_ACTIONS:
                continue
            if k < TOP_ACTIONS:
                k += 1
            m = k - 1
            while m > j:
                self.d_cheap[m] = self.d_cheap[m - 1]
                m -= 1
            self.d_cheap[j] = line
        return k

    def _inside(self) -> int:
        """The repeated regions' occurrences inside the region into ``d_inside``: those
        starting in its rows (the occurrences are sorted by first row); how many."""
        r1, c0, c1 = self.d_r1, self.d_c0, self.d_c1
        first, last = self._first_repeat_from(self.d_r0), self._first_repeat_from(r1)
        n = 0
        for k in range(first, last):
            at = 5 * k
            if (
                self.repeats[at + 1] <= r1
                and self.repeats[at + 2] >= c0
                and self.repeats[at + 3] <= c1
            ):
                self.d_inside[n] = k
                n += 1
        self.n_inside = n
        return n

    def _first_repeat_from(self, row: int) -> int:
        a, b = 0, self.n_repeats
        while a < b:
            mid = (a + b) // 2
            if self.repeats[5 * mid] < row:
                a = mid + 1
            else:
                b = mid
        return a

    def _line_costs(self, axis: int) -> int:
        """Eq. 5's cost of each line along the axis into ``d_cost`` (from ``axis *
        d_stride``), indexed from the region's low end: the cells of the repeated regions
        it cuts through over the region's cells (section 4.4); zero where not positive."""
        r0, r1, c0, c1 = self.d_r0, self.d_r1, self.d_c0, self.d_c1
        lo, hi = (c0, c1) if axis == 0 else (r0, r1)
        base = axis * self.d_stride
        size = hi - lo + 1
        for i in range(size + 1):
            self.d_cost[base + i] = 0.0
        if not self.n_inside or hi - lo < 2:
            return 0
        for i in range(size):
            self.d_pos[i] = 0.0
            self.d_neg[i] = 0.0
        for k in range(self.n_inside):
            at = 5 * self.d_inside[k]
            start = self.repeats[at + 2] if axis == 0 else self.repeats[at]
            stop = self.repeats[at + 3] if axis == 0 else self.repeats[at + 1]
            self.d_pos[start + 1 - lo] += float(self.repeats[at + 4])
            self.d_neg[stop - lo] += float(self.repeats[at + 4])
        cells = float(r1 - r0) * float(c1 - c0)
        total = 0.0
        for i in range(size):
            total += self.d_pos[i] - self.d_neg[i]
            if 1 <= i < hi - lo:
                c = total / cells
                self.d_cost[base + i] = c if c > 0 else 0.0
        return 0

    def _lines_cost(self, axis: int, at: int, n: int) -> float:
        """Eq. 5's sum over the lines a rule cuts (its bounds ``d_pool[at:at + n]``), in
        order."""
        base = axis * self.d_stride - (self.d_c0 if axis == 0 else self.d_r0)
        total = 0.0
        for i in range(1, n - 1):
            total += self.d_cost[base + self.d_pool[at + i]]
        return total

    def _new_draft(self, ints: int) -> int:
        """Room for one more draft and ``ints`` more in ``d_pool``; its number."""
        d = self.n_drafts
        if 2 * (d + 1) > len(self.d_real):
            self.d_real = _more_doubles(self.d_real, 2 * d, 2 * (d + 1))
            self.d_int = _more_ints(self.d_int, D_FIELDS * d, D_FIELDS * (d + 1), 0)
            self.d_order = _more_ints(self.d_order, self.n_order, d + 1, 0)
        if self.d_pool_n + ints > len(self.d_pool):
            self.d_pool = _more_ints(self.d_pool, self.d_pool_n, self.d_pool_n + ints, 0)
        return d

    def _add_draft(self, d: int, heuristic: float, rule_cost: float) -> int:
        self.d_real[2 * d] = heuristic
        self.d_real[2 * d + 1] = rule_cost
        self.d_order[self.n_order] = d
        self.n_order += 1
        self.n_drafts = d + 1
        return 0

    def _has_draft(self, axis: int, n: int) -> bool:
        """Whether a draft along the axis (not a gridsplit) has the bounds ``d_bounds[:n]``."""
        for k in range(self.n_order):
            f = D_FIELDS * self.d_order[k]
            if (
                self.d_int[f + D_OP] == OP_GRID
                or self.d_int[f + D_AXIS] != axis
                or self.d_int[f + D_N_BOUNDS] != n
            ):
                continue
            at = self.d_int[f + D_BOUNDS]
            same = True
            for i in range(n):
                if self.d_pool[at + i] != self.d_bounds[i]:
                    same = False
                    break
            if same:
                return True
        return False

    def _draft_less(self, a: int, b: int) -> bool:
        """Draft a ranks before draft b: heuristic, cost, axis, bounds, least first."""
        if self.d_real[2 * a] != self.d_real[2 * b]:
            return self.d_real[2 * a] < self.d_real[2 * b]
        if self.d_real[2 * a + 1] != self.d_real[2 * b + 1]:
            return self.d_real[2 * a + 1] < self.d_real[2 * b + 1]
        fa, fb = D_FIELDS * a, D_FIELDS * b
        if self.d_int[fa + D_AXIS] != self.d_int[fb + D_AXIS]:
            return self.d_int[fa + D_AXIS] < self.d_int[fb + D_AXIS]
        na, nb = self.d_int[fa + D_N_BOUNDS], self.d_int[fb + D_N_BOUNDS]
        at, bt = self.d_int[fa + D_BOUNDS], self.d_int[fb + D_BOUNDS]
        for i in range(na if na < nb else nb):
            if self.d_pool[at + i] != self.d_pool[bt + i]:
                return self.d_pool[at + i] < self.d_pool[bt + i]
        return na < nb

    def _sort_drafts(self) -> int:
        """``d_order`` sorted by rank, ties kept in order (insertion: a few drafts)."""
        for i in range(1, self.n_order):
            d = self.d_order[i]
            j = i
            while j > 0 and self._draft_less(d, self.d_order[j - 1]):
                self.d_order[j] = self.d_order[j - 1]
                j -= 1
            self.d_order[j] = d
        return 0

    def _sort_halves(self) -> int:
        """The cuts in two by rank: heuristic, cost, axis, line."""
        for i in range(1, self.n_halves):
            h, c = self.h_real[2 * i], self.h_real[2 * i + 1]
            axis, line = self.h_int[2 * i], self.h_int[2 * i + 1]
            j = i
            while j > 0:
                ph, pc = self.h_real[2 * j - 2], self.h_real[2 * j - 1]
                pa, pl = self.h_int[2 * j - 2], self.h_int[2 * j - 1]
                if h != ph:
                    if h > ph:
                        break
                elif c != pc:
                    if c > pc:
                        break
                elif axis != pa:
                    if axis > pa:
                        break
                elif line > pl:
                    break
                self.h_real[2 * j], self.h_real[2 * j + 1] = ph, pc
                self.h_int[2 * j], self.h_int[2 * j + 1] = pa, pl
                j -= 1
            self.h_real[2 * j], self.h_real[2 * j + 1] = h, c
            self.h_int[2 * j], self.h_int[2 * j + 1] = axis, line
        return 0

    def _draft(self, axis: int, nb: int) -> int:
        """The cheapest rule over the parts between the bounds ``d_bounds[:nb]`` (none for
        one part)."""
        n = nb - 1
        if n < 2:
            return 0
        r0, r1, c0, c1 = self.d_r0, self.d_r1, self.d_c0, self.d_c1
        d = self._new_draft(nb + n)
        at = self.d_pool_n
        for i in range(nb):
            self.d_pool[at + i] = self.d_bounds[i]
        cids = at + nb
        for i in range(n):
            a, b = self.d_bounds[i], self.d_bounds[i + 1]
            if axis == 0:
                self.d_pool[cids + i] = self.grid_content(r0, r1, a, b)
            else:
                self.d_pool[cids + i] = self.grid_content(a, b, c0, c1)
        self.d_pool_n = cids + n
        pool = self.d_pool
        op, m, count, centre, period = OP_SPLIT, n, 1, 0, 0
        for q in range(1, n // 2 + 1):
            if n % q == 0:
                same = True
                for i in range(q, n):
                    if pool[cids + i] != pool[cids + i - q]:
                        same = False
                        break
                if same:
                    period = q
                    break
        if period:
            op, m, count = OP_REPEAT, period, n // period
        elif self.ext & EXT_ABA and n >= 5 and n % 2 == 1:
            same = True
            for i in range(2, n):
                if pool[cids + i] != pool[cids + i - 2]:
                    same = False
                    break
            if same:
                op, m, count = OP_ABA, 2, n // 2
        if op == OP_SPLIT and self.ext & EXT_SYMSPLIT and n >= 3:
            same = True
            for i in range(n):
                if pool[cids + i] != pool[cids + n - 1 - i]:
                    same = False
                    break
            if same:
                op, m, centre = OP_SYMSPLIT, (n + 1) // 2, n % 2
        repeats = op in (OP_REPEAT, OP_ABA)
        rule_cost = (self.repeat_cost if repeats else self.split_cost) + m
        heuristic = rule_cost + self._lines_cost(axis, at, nb)
        f = D_FIELDS * d
        self.d_int[f + D_AXIS] = axis
        self.d_int[f + D_OP] = op
        self.d_int[f + D_COUNT] = count
        self.d_int[f + D_CENTRE] = centre
        self.d_int[f + D_BOUNDS] = at
        self.d_int[f + D_N_BOUNDS] = nb
        self.d_int[f + D_ACROSS] = at
        self.d_int[f + D_N_ACROSS] = 0
        self.d_int[f + D_CIDS] = cids
        self.d_int[f + D_M] = m
        return self._add_draft(d, heuristic, rule_cost)

    def _grid(self, n0: int, n1: int) -> int:
        """A gridsplit: rows by the usable y lines, columns by the usable x lines."""
        nr, nc = n1 + 2, n0 + 2
        m = (nr - 1) * (nc - 1)
        d = self._new_draft(nr + nc + m)
        rows = self.d_pool_n
        self.d_pool[rows] = self.d_r0
        for i in range(n1):
            self.d_pool[rows + 1 + i] = self.d_lines[self.d_stride + i]
        self.d_pool[rows + nr - 1] = self.d_r1
        columns = rows + nr
        self.d_pool[columns] = self.d_c0
        for i in range(n0):
            self.d_pool[columns + 1 + i] = self.d_lines[i]
        self.d_pool[columns + nc - 1] = self.d_c1
        cids = columns + nc
        k = 0
        for i in range(nr - 1):
            for j in range(nc - 1):
                self.d_pool[cids + k] = self.grid_content(
                    self.d_pool[rows + i],
                    self.d_pool[rows + i + 1],
                    self.d_pool[columns + j],
                    self.d_pool[columns + j + 1],
                )
                k += 1
        self.d_pool_n = cids + m
        rule_cost = self.split_cost + m
        heuristic = rule_cost + self._lines_cost(0, columns, nc)
        heuristic += self._lines_cost(1, rows, nr)
        f = D_FIELDS * d
        self.d_int[f + D_AXIS] = 1
        self.d_int[f + D_OP] = OP_GRID
        self.d_int[f + D_COUNT] = 1
        self.d_int[f + D_CENTRE] = 0
        self.d_int[f + D_BOUNDS] = rows
        self.d_int[f + D_N_BOUNDS] = nr
        self.d_int[f + D_ACROSS] = columns
        self.d_int[f + D_N_ACROSS] = nc
        self.d_int[f + D_CIDS] = cids
        self.d_int[f + D_M] = m
        return self._add_draft(d, heuristic, rule_cost)

    def _runs(self, axis: int, nf: int) -> int:
        """Bounds that keep each maximal periodic run of two or more parts (of the parts
        between ``d_full[:nf]``) as one part."""
        n = nf - 1
        r0, r1, c0, c1 = self.d_r0, self.d_r1, self.d_c0, self.d_c1
        full = self.d_full
        for i in range(n):
            if axis == 0:
                self.d_runs[i] = self.grid_content(r0, r1, full[i], full[i + 1])
            else:
                self.d_runs[i] = self.grid_content(full[i], full[i + 1], c0, c1)
        run = self.d_stride  # run[j] at d_runs[run + j]
        for period in range(1, n // 2 + 1):
            # run[j]: how many parts from j on equal the part a period after them, so the
            # parts from i on hold 1 + run[i] // period copies of the first period
            for j in range(n - period + 1):
                self.d_runs[run + j] = 0
            for j in range(n - period - 1, -1, -1):
                if self.d_runs[j] == self.d_runs[j + period]:
                    self.d_runs[run + j] = self.d_runs[run + j + 1] + 1
            i = 0
            while i + 2 * period <= n:
                k = 1 + self.d_runs[run + i] // period
                if k >= 2 and not (i == 0 and i + k * period == n):
                    end = i + k * period
                    for j in range(i + 1):
                        self.d_bounds[j] = full[j]
                    for j in range(end, nf):
                        self.d_bounds[i + 1 + j - end] = full[j]
                    nb = i + 1 + nf - end
                    if not self._has_draft(axis, nb):
                        self._draft(axis, nb)
                    i = end
                else:
                    i += 1
        return 0

    def _repeated(self, axis: int, nf: int) -> int:
        """Bounds that keep whole the repeated regions spanning the region across the axis
        (the lines ``d_full[:nf]``)."""
        r0, r1, c0, c1 = self.d_r0, self.d_r1, self.d_c0, self.d_c1
        rep = self.repeats
        spans = 0  # (a, b) pairs in d_spans, longest first, then by a and b
        for k in range(self.n_inside):
            at = 5 * self.d_inside[k]
            if axis == 0 and rep[at] == r0 and rep[at + 1] == r1:
                a, b = rep[at + 2], rep[at + 3]
            elif axis == 1 and rep[at + 2] == c0 and rep[at + 3] == c1:
                a, b = rep[at], rep[at + 1]
            else:
                continue
            j = spans
            while j > 0:
                x, y = self.d_spans[2 * j - 2], self.d_spans[2 * j - 1]
                if x - y < a - b or (x - y == a - b and (x < a or (x == a and y <= b))):
                    break
                self.d_spans[2 * j], self.d_spans[2 * j + 1] = x, y
                j -= 1
            self.d_spans[2 * j], self.d_spans[2 * j + 1] = a, b
            spans += 1
        if not spans:
            return 0
        full = self.d_full
        lo, hi = full[0], full[nf - 1]
        blocks = 0  # kept in d_spans after the spans
        at = 2 * spans
        for k in range(spans):
            a, b = self.d_spans[2 * k], self.d_spans[2 * k + 1]
            free = not (a == lo and b == hi)
            for j in range(blocks):
                if not (b <= self.d_spans[at + 2 * j] or self.d_spans[at + 2 * j + 1] <= a):
                    free = False
                    break
            if free:
                self.d_spans[at + 2 * blocks], self.d_spans[at + 2 * blocks + 1] = a, b
                blocks += 1
        if not blocks:
            return 0
        # the bounds: the ends, the blocks' ends, the lines outside every block; sorted, once
        nb = self._mark(0, lo)
        nb = self._mark(nb, hi)
        for j in range(blocks):
            nb = self._mark(nb, self.d_spans[at + 2 * j])
            nb = self._mark(nb, self.d_spans[at + 2 * j + 1])
        for i in range(nf):
            line = full[i]
            free = True
            for j in range(blocks):
                if self.d_spans[at + 2 * j] < line < self.d_spans[at + 2 * j + 1]:
                    free = False
                    break
            if free:
                nb = self._mark(nb, line)
        if not self._has_draft(axis, nb):
            self._draft(axis, nb)
        return 0

    def _mark(self, n: int, line: int) -> int:
        """``line`` into the sorted ``d_bounds[:n]`` unless there; the new count."""
        j = n
        while j > 0 and self.d_bounds[j - 1] > line:
            j -= 1
        if j > 0 and self.d_bounds[j - 1] == line:
            return n
        k = n
        while k > j:
            self.d_bounds[k] = self.d_bounds[k - 1]
            k -= 1
        self.d_bounds[j] = line
        return n + 1

    def _rank_in_two(self, axis: int, line: int) -> int:
        """The rank the cut in two would have as an action, without making it (into the
        halves, ``h_real`` and ``h_int``): a repeat of one part when both parts read the
        same, else a split of two. Two parts whose sizes differ by more than their cells'
        rounding cannot read the same (no content made)."""
        r0, r1, c0, c1 = self.d_r0, self.d_r1, self.d_c0, self.d_c1
        lo, hi = (c0, c1) if axis == 0 else (r0, r1)
        same = abs(self.quantum(axis, lo, line) - self.quantum(axis, line, hi)) <= (hi - lo) + 2
        if same:
            if axis == 0:
                same = self.grid_content(r0, r1, lo, line) == self.grid_content(r0, r1, line, hi)
            else:
                same = self.grid_content(lo, line, c0, c1) == self.grid_content(line, hi, c0, c1)
        rule_cost = self.repeat_cost + 1 if same else self.split_cost + 2
        heuristic = rule_cost + (0.0 + self.d_cost[axis * self.d_stride + line - lo])
        k = self.n_halves
        self.h_real[2 * k], self.h_real[2 * k + 1] = heuristic, rule_cost
        self.h_int[2 * k], self.h_int[2 * k + 1] = axis, line
        self.n_halves = k + 1
        return 0

    def _part(self, d: int, i: int) -> int:
        """The draft's i-th part into ``d_part`` (r0, r1, c0, c1); its cells."""
        f = D_FIELDS * d
        at = self.d_int[f + D_BOUNDS]
        part = self.d_part
        if self.d_int[f + D_OP] == OP_GRID:
            columns = self.d_int[f + D_N_ACROSS] - 1
            across = self.d_int[f + D_ACROSS] + i % columns
            at += i // columns
            part[0], part[1] = self.d_pool[at], self.d_pool[at + 1]
            part[2], part[3] = self.d_pool[across], self.d_pool[across + 1]
        elif self.d_int[f + D_AXIS] == 0:
            part[0], part[1] = self.d_r0, self.d_r1
            part[2], part[3] = self.d_pool[at + i], self.d_pool[at + i + 1]
        else:
            part[0], part[1] = self.d_pool[at + i], self.d_pool[at + i + 1]
            part[2], part[3] = self.d_c0, self.d_c1
        return (part[1] - part[0]) * (part[3] - part[2])

    # -- entries and their actions -------------------------------------------------------

    def entry_of(self, r0: int, r1: int, c0: int, c1: int) -> int:
        """The entry of a region, added the first time."""
        box = self.scratch
        box[0], box[1], box[2], box[3] = r0, r1, c0, c1
        e = self.entry_map.add(box, 0, 4)
        if not self.entry_map.added:
            return e
        cid = self.grid_content(r0, r1, c0, c1)
        self.content_seen(cid)
        if e + 1 > len(self.e_cid):
            n = self.n_entries
            self.e_key = _more_ints(self.e_key, 5 * n, 5 * (e + 1), 0)
            self.e_cid = _more_ints(self.e_cid, n, e + 1, 0)
            self.e_first = _more_ints(self.e_first, n, e + 1, 0)
            self.e_count = _more_ints(self.e_count, n, e + 1, 0)
            self.e_odds = _more_ints(self.e_odds, n, e + 1, 0)
        at = 5 * e
        self.e_key[at] = r0
        self.e_key[at + 1] = c0
        self.e_key[at + 2] = -r1
        self.e_key[at + 3] = -c1
        self.e_key[at + 4] = cid
        self.e_cid[e] = cid
        self.e_first[e] = 0
        self.e_count[e] = -1
        self.e_odds[e] = -1
        self.n_entries = e + 1
        return e

    def content_seen(self, cid: int) -> int:
        """The per-content arrays hold ``cid``."""
        n = cid + 1
        if n <= self.n_contents:
            return 0
        if n > len(self.rule):
            used = self.n_contents
            self.rule = _more_ints(self.rule, used, n, 0)
            self.pending = _more_flags(self.pending, used, n)
            self.mark = _more_ints(self.mark, used, n, 0)
            self.kind_of = _more_ints(self.kind_of, used, n, 0)
            self.position = _more_ints(self.position, used, n, 0)
            self.learned = _more_doubles(self.learned, used, n)
            self.covered = _more_ints(self.covered, used, n, 0)
        for i in range(self.n_contents, n):
            self.rule[i] = -1
            self.pending[i] = 0
            self.mark[i] = 0
            self.kind_of[i] = -1
            self.position[i] = -1
            self.learned[i] = INF
            self.covered[i] = -1
        self.n_contents = n
        return 0

    def pool_room(self, n: int) -> int:
        if self.pool_n + n > len(self.pool):
            self.pool = _more_ints(self.pool, self.pool_n, self.pool_n + n, 0)
        return 0

    def provide(self, e: int) -> int:
        """The entry's actions, made the first time."""
        if self.e_count[e] >= 0:
            return 0
        if not self.prepared:
            raise TypeError("prepare the Table before the search")
        at = 5 * e
        r0, c0 = self.e_key[at], self.e_key[at + 1]
        r1, c1 = -self.e_key[at + 2], -self.e_key[at + 3]
        n = self.drafts(r0, r1, c0, c1)
        first = self.n_actions
        try:
            for k in range(n):
                self._keep(e, self.d_order[k])
        except BaseException:
            self.n_actions = first
            raise
        self.e_first[e] = first
        self.e_count[e] = n
        return 0

    def _keep(self, e: int, d: int) -> int:
        """Draft d made an action of entry e: its parts as symbols, its needs (non-terminal
        contents, larger parts first, once each), its non-terminal parts as entries, its
        form (the rule without its symbols)."""
        g = D_FIELDS * d
        axis, op = self.d_int[g + D_AXIS], self.d_int[g + D_OP]
        count, centre = self.d_int[g + D_COUNT], self.d_int[g + D_CENTRE]
        bounds, n_bounds = self.d_int[g + D_BOUNDS], self.d_int[g + D_N_BOUNDS]
        across, n_across = self.d_int[g + D_ACROSS], self.d_int[g + D_N_ACROSS]
        cids, m = self.d_int[g + D_CIDS], self.d_int[g + D_M]
        a = self.n_actions
        if a + 1 > len(self.a_cost):
            self.a_cost = _more_doubles(self.a_cost, a, a + 1)
            self.a_heuristic = _more_doubles(self.a_heuristic, a, a + 1)
            self.a_int = _more_ints(self.a_int, A_FIELDS * a, A_FIELDS * (a + 1), 0)
        self.pool_room(4 * m + n_bounds + n_across)
        if 4 + n_bounds + n_across + m > len(self.form):
            self.form = _more_ints(self.form, 0, 4 + n_bounds + n_across + m, 0)
        f = A_FIELDS * a
        self.a_cost[a] = self.d_real[2 * d + 1]
        self.a_heuristic[a] = self.d_real[2 * d]
        self.a_int[f + A_OWNER] = e
        self.a_int[f + A_OP] = op
        self.a_int[f + A_AXIS] = axis
        self.a_int[f + A_COUNT] = count
        self.a_int[f + A_CENTRE] = centre
        self.a_int[f + A_BOUNDS] = self.pool_n
        self.a_int[f + A_N_BOUNDS] = n_bounds
        for i in range(n_bounds):
            self.pool[self.pool_n] = self.d_pool[bounds + i]
            self.pool_n += 1
        self.a_int[f + A_ACROSS] = self.pool_n
        self.a_int[f + A_N_ACROSS] = n_across
        for i in range(n_across):
            self.pool[self.pool_n] = self.d_pool[across + i]
            self.pool_n += 1
        self.a_int[f + A_PARTS] = self.pool_n
        self.a_int[f + A_N_PARTS] = m
        for i in range(m):
            cid = self.d_pool[cids + i]
            self.content_seen(cid)
            label = self.terminal[cid]
            self.pool[self.pool_n] = -1 - label if label >= 0 else cid
            self.pool_n += 1
        # needs: non-terminal parts by size (cells), ties in order, each content once: the
        # parts' places sorted by insertion past the end of the pool, then the contents
        order = self.pool_n + m
        k = 0
        for i in range(m):
            if self.terminal[self.d_pool[cids + i]] >= 0:
                continue
            cells = self._part(d, i)
            j = k
            while j > 0:
                if self._part(d, self.pool[order + j - 1]) >= cells:
                    break
                self.pool[order + j] = self.pool[order + j - 1]
                j -= 1
            self.pool[order + j] = i
            k += 1
        needs = self.pool_n
        self.a_int[f + A_NEEDS] = needs
        n_needs = 0
        for j in range(k):
            cid = self.d_pool[cids + self.pool[order + j]]
            seen = False
            for i in range(n_needs):
                if self.pool[needs + i] == cid:
                    seen = True
                    break
            if not seen:
                self.pool[needs + n_needs] = cid
                n_needs += 1
        self.pool_n += n_needs
        self.a_int[f + A_N_NEEDS] = n_needs
        # the form
        form = self.form
        form[0] = op
        n = 1
        if op == OP_GRID:
            form[1] = n_bounds
            n = 2
            for i in range(n_bounds - 1):
                form[n] = self.quantum(1, self.d_pool[bounds + i], self.d_pool[bounds + i + 1])
                n += 1
            for i in range(n_across - 1):
                form[n] = self.quantum(0, self.d_pool[across + i], self.d_pool[across + i + 1])
                n += 1
        else:
            form[1], form[2], form[3] = axis, count, centre
            n = 4
            for i in range(m):
                form[n] = self.quantum(axis, self.d_pool[bounds + i], self.d_pool[bounds + i + 1])
                n += 1
        self.a_int[f + A_FORM] = self.forms.add(form, 0, n)
        # the non-terminal parts as entries (which may add entries)
        kids = self.pool_n
        self.a_int[f + A_KIDS] = kids
        n_kids = 0
        for i in range(m):
            if self.terminal[self.d_pool[cids + i]] >= 0:
                continue
            self._part(d, i)
            part = self.d_part
            kid = self.entry_of(part[0], part[1], part[2], part[3])
            self.pool_room(1)
            self.pool[kids + n_kids] = kid
            n_kids += 1
            self.pool_n = kids + n_kids
        self.a_int[f + A_N_KIDS] = n_kids
        self.n_actions = a + 1
        return 0

    # -- building a grammar --------------------------------------------------------------

    def entry_less(self, a: int, b: int) -> bool:
        """Heap order: bottom to top, left to right, larger first, then by content."""
        x, y = 5 * a, 5 * b
        for i in range(5):
            if self.e_key[x + i] != self.e_key[y + i]:
                return self.e_key[x + i] < self.e_key[y + i]
        return False

    def heap_push(self, e: int) -> int:
        if self.heap_n + 1 > len(self.heap):
            self.heap = _more_ints(self.heap, self.heap_n, self.heap_n + 1, 0)
        i = self.heap_n
        self.heap_n += 1
        while i > 0:
            up = (i - 1) // 2
            if not self.entry_less(e, self.heap[up]):
                break
            self.heap[i] = self.heap[up]
            i = up
        self.heap[i] = e
        return 0

    def heap_pop(self) -> int:
        top = self.heap[0]
        self.heap_n -= 1
        n = self.heap_n
        last = self.heap[n]
        i = 0
        while True:
            c = 2 * i + 1
            if c >= n:
                break
            if c + 1 < n and self.entry_less(self.heap[c + 1], self.heap[c]):
                c += 1
            if not self.entry_less(self.heap[c], last):
                break
            self.heap[i] = self.heap[c]
            i = c
        if n:
            self.heap[i] = last
        return top

    def clear_grammar(self) -> None:
        for i in range(self.order_n):
            self.rule[self.order[i]] = -1
        for i in range(self.heap_n):
            self.pending[self.e_cid[self.heap[i]]] = 0
        self.order_n = 0
        self.heap_n = 0

    def choose(self, e: int) -> int:
        """The action an entry takes: the first (greedy), or ADP's (``search.Search.adp``):
        explore by the heuristic's odds with probability epsilon, else exploit (Eq. 4);
        TIME_UP once the clock has passed the stop."""
        if self.stop_at < INF:
            self.ticks += 1
            if (self.ticks & CLOCK_EVERY) == 1 and self.clock() > self.stop_at:
                return TIME_UP
        self.provide(e)
        first, n = self.e_first[e], self.e_count[e]
        if self.greedy_ or n == 1:
            return first
        x = self.draw()
        if x < self.epsilon:  # exploration: the heuristic's odds
            if self.e_odds[e] < 0:
                if self.odds_n + n > len(self.odds):
                    self.odds = _more_doubles(self.odds, self.odds_n, self.odds_n + n)
                low = self.a_heuristic[first]
                total = 0.0
                for i in range(n):
                    total += exp(low - self.a_heuristic[first + i])
                    self.odds[self.odds_n + i] = total
                self.e_odds[e] = self.odds_n
                self.odds_n += n
            at = self.e_odds[e]
            x = self.draw()
            x = x * (self.odds[at + n - 1] + 0.0)
            lo, hi = 0, n - 1  # bisect.bisect(weights, x, 0, n - 1)
            while lo < hi:
                mid = (lo + hi) // 2
                if x < self.odds[at + mid]:
                    hi = mid
                else:
                    lo = mid + 1
            return first + lo
        chosen = first  # exploitation: Eq. 4 with the value table
        least = INF
        for i in range(n):
            a = first + i
            score = self.a_cost[a]
            self.stamp += 1
            stamp = self.stamp
            needs = self.a_int[A_FIELDS * a + A_NEEDS]
            for j in range(self.a_int[A_FIELDS * a + A_N_NEEDS]):  # larger parts first
                if score >= least:
                    break  # values only add up
                need = self.pool[needs + j]
                if self.rule[need] >= 0 or self.pending[need] or self.mark[need] == stamp:
                    continue
                value = self.learned[need]
                if value == INF:
                    score += self.optimistic
                else:
                    score += value
                    cov = self.covered[need]
                    for k in range(cov + 1, cov + 1 + self.cover[cov]):
                        self.mark[self.cover[k]] = stamp
            if score < least:
                chosen = a
                least = score
        return chosen

    def build(self, start: int) -> int:
        """One grammar from the start entry into ``order`` (rules in ``rule``): regions
        bottom to top, left to right, each content split once. 0, or TIME_UP."""
        self.clear_grammar()
        self.pending[self.e_cid[start]] = 1
        self.heap_push(start)
        while self.heap_n:
            e = self.heap_pop()
            cid = self.e_cid[e]
            self.pending[cid] = 0
            try:
                a = self.choose(e)
            except BaseException:
                self.clear_grammar()
                raise
            if a < 0:
                self.clear_grammar()
                return a
            if self.order_n + 1 > len(self.order):
                self.order = _more_ints(self.order, self.order_n, self.order_n + 1, 0)
            self.rule[cid] = a
            self.order[self.order_n] = cid
            self.order_n += 1
            kids = self.a_int[A_FIELDS * a + A_KIDS]
            for k in range(self.a_int[A_FIELDS * a + A_N_KIDS]):
                kid = self.pool[kids + k]
                sub = self.e_cid[kid]
                if self.rule[sub] >= 0 or self.pending[sub]:
                    continue
                self.pending[sub] = 1
                self.heap_push(kid)
        return 0

    # -- the merged cost and the value table ---------------------------------------------

    def visit(self, cid: int) -> int:
        """The kind of a content's rule (rules that read the same: the same form over the
        same symbols), and the rules it reaches into its reach set."""
        if self.kind_of[cid] >= 0:
            return self.kind_of[cid]
        a = self.rule[cid]
        p = self.position[cid]
        words = self.words
        base = p * words
        self.bits[base + (p >> 6)] |= ONE << (p & 63)
        n = self.a_int[A_FIELDS * a + A_N_PARTS]
        parts = self.a_int[A_FIELDS * a + A_PARTS]
        s = self.symbols_n
        if s + n + 1 > len(self.symbols):
            self.symbols = _more_ints(self.symbols, s, s + n + 1, 0)
        self.symbols_n = s + n + 1
        self.symbols[s] = self.a_int[A_FIELDS * a + A_FORM]
        for i in range(n):
            sub = self.pool[parts + i]
            if sub < 0:
                self.symbols[s + 1 + i] = sub  # a terminal's label
                continue
            self.symbols[s + 1 + i] = self.visit(sub)
            below = self.position[sub] * words
            for w in range(words):
                self.bits[base + w] |= self.bits[below + w]
        kind = self.kinds.add(self.symbols, s, n + 1)
        self.symbols_n = s
        if kind + 1 > len(self.first_of):
            self.first_of = _more_ints(self.first_of, len(self.first_of), kind + 1, -1)
        self.kind_of[cid] = kind
        if self.first_of[kind] < 0:
            self.first_of[kind] = cid
        return kind

    def survey(self) -> float:
        """Eq. 1 over the merged rules of the grammar in ``order`` (rules that read the same
        count once, for the rule met first), and per rule the rules it reaches (``bits``)."""
        n = self.order_n
        words = (n + 63) // 64
        self.words = words
        if n * words + 1 > len(self.bits):
            self.bits = _words(_capacity(len(self.bits), n * words + 1))
        for i in range(n * words):
            self.bits[i] = 0
        for i in range(n):
            self.position[self.order[i]] = i
        try:
            for i in range(n):
                self.visit(self.order[i])
            total = 0.0
            for i in range(n):
                cid = self.order[i]
                if self.first_of[self.kind_of[cid]] == cid:
                    total += self.a_cost[self.rule[cid]]
        finally:
            for i in range(n):  # forget the survey's marks
                cid = self.order[i]
                if self.kind_of[cid] >= 0:
                    self.first_of[self.kind_of[cid]] = -1
                self.kind_of[cid] = -1
            self.kinds.clear()  # kinds are compared within a survey only: a small set
        return total

    def learn(self) -> int:
        """Each content's cost with every rule below it counted once, kept when the least
        yet, with the contents those rules split. The sums run over the distinct rule costs
        in the order met, as ``cost * count`` each."""
        n = self.order_n
        if not n:
            return 0
        if n > len(self.distinct):
            self.distinct = _more_doubles(self.distinct, 0, n)
            self.group = _more_ints(self.group, 0, n, 0)
            self.counts = _more_ints(self.counts, 0, n, 0)
        if n > len(self.scratch):
            self.scratch = _more_ints(self.scratch, 0, n, 0)
        n_distinct = 0
        for i in range(n):
            c = self.a_cost[self.rule[self.order[i]]]
            g = 0
            while g < n_distinct and self.distinct[g] != c:
                g += 1
            if g == n_distinct:
                self.distinct[n_distinct] = c
                n_distinct += 1
            self.group[i] = g
        words = self.words
        for i in range(n):
            for g in range(n_distinct):
                self.counts[g] = 0
            members = 0
            for w in range(words):
                word = self.bits[i * words + w]
                while word:
                    low = word & (M64 ^ (word - 1))  # the lowest set bit
                    word ^= low
                    p = w * 64 + self.bit_at[((low * DE_BRUIJN) & M64) >> 58]
                    self.counts[self.group[p]] += 1
                    self.scratch[members] = self.order[p]
                    members += 1
            total = 0.0
            for g in range(n_distinct):
                total += self.distinct[g] * float(self.counts[g])
            cid = self.order[i]
            if total < self.learned[cid] - 1e-12:
                if self.cover_n + members + 1 > len(self.cover):
                    self.cover = _more_ints(self.cover, self.cover_n, self.cover_n + members + 1, 0)
                at = self.cover_n
                self.cover[at] = members
                for k in range(members):
                    self.cover[at + 1 + k] = self.scratch[k]
                self.cover_n += members + 1
                self.covered[cid] = at
                self.learned[cid] = total
        return 0

    def forget_learned(self) -> None:
        for i in range(self.n_contents):
            self.learned[i] = INF
            self.covered[i] = -1
        self.cover_n = 0

    def set_grammar(self, actions: Sequence[int]) -> None:
        """The grammar whose rules are these actions, in order."""
        self.clear_grammar()
        n = len(actions)
        if n > len(self.order):
            self.order = _more_ints(self.order, 0, n, 0)
        for a in actions:
            if a < 0 or a >= self.n_actions:
                self.clear_grammar()
                raise ValueError("unknown action")
            cid = self.e_cid[self.a_int[A_FIELDS * a + A_OWNER]]
            if self.rule[cid] >= 0:
                self.clear_grammar()
                raise ValueError("two rules for one content")
            self.rule[cid] = a
            self.order[self.order_n] = cid
            self.order_n += 1
        for i in range(n):  # every non-terminal part has its rule
            a = self.rule[self.order[i]]
            parts = self.a_int[A_FIELDS * a + A_PARTS]
            for k in range(self.a_int[A_FIELDS * a + A_N_PARTS]):
                sub = self.pool[parts + k]
                if sub >= 0 and self.rule[sub] < 0:
                    self.clear_grammar()
                    raise ValueError("a part without a rule")

    def _pairs(self, cids: Any, actions: Any, n: int) -> list[tuple[int, int]]:
        return [(cids[i], actions[i]) for i in range(n)]

    def _order_actions(self) -> Any:
        made = _ints(self.order_n + 1)
        for i in range(self.order_n):
            made[i] = self.rule[self.order[i]]
        return made

    # -- what Python asks ---------------------------------------------------------------

    def prepare(self, repeats: bytes, extensions: int, split: float, repeat: float) -> None:
        """The repeated regions' occurrences (int32, five a row: r0, r1, c0, c1, cells, by
        first row), the extensions as bits (1 repeatABA, 2 symsplit, 4 gridsplit) and the
        rule costs; once, before the search."""
        if self.prepared:
            raise TypeError("prepare a made Table, once")
        if len(repeats) % 20:
            raise ValueError("repeats come five int32 a row")
        made = array("i")
        made.frombytes(repeats)
        made.append(0)
        self.repeats = made
        self.n_repeats = len(repeats) // 20
        self.d_inside = _ints(self.n_repeats + 1)
        self.d_spans = _ints(4 * self.n_repeats + 4)  # the spans, then the blocks
        self.ext, self.split_cost, self.repeat_cost = extensions, split, repeat
        self.prepared = True

    def limit(self, cells: int) -> None:
        """The most cells the contents may read and keep (``regions.Grid``)."""
        self.cells_max = cells

    def spent(self) -> bool:
        """Whether a content was refused because the budget ran out."""
        return self.spent_

    def cells(self) -> int:
        """The cells the contents have read so far."""
        return self.cells_read

    def content(self, r0: int, r1: int, c0: int, c1: int) -> tuple[int, int]:
        """The region's content and its label when it is one terminal, else -1."""
        self._check_region(r0, r1, c0, c1)
        cid = self.grid_content(r0, r1, c0, c1)
        return cid, self.terminal[cid]

    def _check_region(self, r0: int, r1: int, c0: int, c1: int) -> None:
        if r0 < 0 or c0 < 0 or r1 > self.rows or c1 > self.cols or r0 >= r1 or c0 >= c1:
            raise ValueError("not a region of the tiling")

    def entry(self, r0: int, r1: int, c0: int, c1: int) -> int:
        """The region's entry, added the first time."""
        self._check_region(r0, r1, c0, c1)
        return self.entry_of(r0, r1, c0, c1)

    def explored(self) -> int:
        """How many regions were offered actions."""
        return sum(1 for e in range(self.n_entries) if self.e_count[e] >= 0)

    def action(self, number: int) -> tuple[Any, ...]:
        """``(region, op, axis, bounds, across, count, centre, cost, heuristic, form)``: the
        region an action splits, its rule (op a name, axis "x" or "y", its cuts along the
        axis, a gridsplit's column cuts, a repeat's count, a symsplit's centre), its costs
        and its form's number (equal for rules that differ only by their symbols)."""
        if number < 0 or number >= self.n_actions:
            raise IndexError("no such action")
        f = A_FIELDS * number
        fields = self.a_int
        at = 5 * fields[f + A_OWNER]
        key = self.e_key
        region = (key[at], -key[at + 2], key[at + 1], -key[at + 3])
        bounds = fields[f + A_BOUNDS]
        across = fields[f + A_ACROSS]
        return (
            region,
            OPS[fields[f + A_OP]],
            "y" if fields[f + A_AXIS] else "x",
            tuple(self.pool[bounds + i] for i in range(fields[f + A_N_BOUNDS])),
            tuple(self.pool[across + i] for i in range(fields[f + A_N_ACROSS])),
            fields[f + A_COUNT],
            bool(fields[f + A_CENTRE]),
            self.a_cost[number],
            self.a_heuristic[number],
            fields[f + A_FORM],
        )

    def actions(self, e: int) -> list[int]:
        """The numbers of the entry's actions (``action``), best first."""
        self._check_entry(e)
        self.provide(e)
        return [self.e_first[e] + i for i in range(self.e_count[e])]

    def _check_entry(self, e: int) -> None:
        if e < 0 or e >= self.n_entries:
            raise ValueError("unknown entry")

    def greedy(self, start: int, stop_at: float, clock: Callable[[], float]) -> Any:
        """``[(content, action)]`` in the order chosen, every region taking its first action,
        or None when ``clock()`` passed ``stop_at`` first."""
        self._check_entry(start)
        self.greedy_, self.stop_at, self.clock, self.ticks = True, stop_at, clock, 0
        if self.build(start) == TIME_UP:
            return None
        out = self._pairs(self.order, self._order_actions(), self.order_n)
        self.clear_grammar()
        return out

    def cost(self, actions: Sequence[int]) -> tuple[float, list[list[int]]]:
        """Eq. 1 over the merged rules of the grammar whose rules are these actions (in
        order), and per rule the positions of the rules it reaches, itself included."""
        self.set_grammar(actions)
        try:
            total = self.survey()
            n, words = self.order_n, self.words
            rows = [
                [p for p in range(n) if (self.bits[i * words + (p >> 6)] >> (p & 63)) & 1]
                for i in range(n)
            ]
        finally:
            self.clear_grammar()
        return total, rows

    def adp(
        self,
        start: int,
        greedy: Sequence[int],
        iterations: int,
        draw: Callable[[], float],
        optimistic: float,
        stop_at: float,
        clock: Callable[[], float],
    ) -> tuple[list[tuple[int, int]], int, int]:
        """``(best, best_at, done)``: the cheapest grammar of ``iterations`` (``search.Search
        .adp``) as ``[(content, action)]``, the iteration it was found in, and the iterations
        done (fewer when ``clock()`` passes ``stop_at`` or the work budget runs out).
        ``greedy``: its actions in order; ``draw``: ``random.Random(seed).random``."""
        self._check_entry(start)
        self.forget_learned()
        seen = SeqSet()
        try:
            self.set_grammar(greedy)
            best_cost = self.survey()
            self.learn()
            best = self._order_actions()
            best_cids = _more_ints(self.order, self.order_n, self.order_n + 1, 0)
            best_n = self.order_n
            best_at, done = 0, iterations
            self.greedy_, self.optimistic, self.draw = False, optimistic, draw
            self.stop_at, self.clock, self.ticks = stop_at, clock, 0
            for it in range(1, iterations):
                self.epsilon = 1.0 - float(it) / float(iterations)
                try:
                    built = self.build(start)
                except BudgetError:  # stops as the time limit does: the best grammar so far
                    done = it
                    break
                if built == TIME_UP:
                    done = it
                    break
                # each action is one region's, so the actions tell the contents too
                if self.order_n + 1 > len(self.scratch):
                    self.scratch = _more_ints(self.scratch, 0, self.order_n + 1, 0)
                for i in range(self.order_n):
                    self.scratch[i] = self.rule[self.order[i]]
                seen.add(self.scratch, 0, self.order_n)
                if not seen.added:
                    continue
                cost = self.survey()
                self.learn()
                if cost < best_cost - 1e-9:
                    best = self._order_actions()
                    best_cids = _more_ints(self.order, self.order_n, self.order_n + 1, 0)
                    best_n = self.order_n
                    best_cost, best_at = cost, it
            return self._pairs(best_cids, best, best_n), best_at, done
        finally:
            self.clear_grammar()
            self.forget_learned()


# an action's int fields, A_FIELDS a row in ``Table.a_int``
A_OWNER, A_OP, A_AXIS, A_COUNT, A_CENTRE, A_FORM = 0, 1, 2, 3, 4, 5
A_BOUNDS, A_N_BOUNDS, A_ACROSS, A_N_ACROSS, A_PARTS, A_N_PARTS = 6, 7, 8, 9, 10, 11
A_NEEDS, A_N_NEEDS, A_KIDS, A_N_KIDS = 12, 13, 14, 15
A_FIELDS = 16
# a draft's int fields, D_FIELDS a row in ``Table.d_int``
D_AXIS, D_OP, D_COUNT, D_CENTRE, D_BOUNDS, D_N_BOUNDS = 0, 1, 2, 3, 4, 5
D_ACROSS, D_N_ACROSS, D_CIDS, D_M = 6, 7, 8, 9
D_FIELDS = 10


def _never() -> float:
    raise AssertionError("a clock or a draw before it was given")
