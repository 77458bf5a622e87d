"""The exact alignment search's network: branch and bound over the alignment decision
network of one candidate (the rules of SPEC 2.4 on every column, the linear equalities a
partial path implies and the least squared deviation under them). :mod:`.exact` drives
it, sizes every complete alignment it hands over (``leaf``) and words its reasons.

One implementation, two ways to run: setup.py compiles this file with Cython where there
is a C compiler (its C types are in ``network.pxd`` beside it: this file stays plain
Python), and it runs interpreted where there is none, with the same layouts, reasons and
work units. Numbers live in ``array`` buffers indexed element by element (C arrays once
compiled); sums run in one fixed order, so both ways give the same bits.
"""

from __future__ import annotations

import time
from array import array
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from facadecli.solver import budgets

try:
    import cython
except ImportError:  # interpreted, Cython not installed (it is a build requirement only)
    from facadecli import _cython as cython  # type: ignore[no-redef, unused-ignore]

if cython.compiled:
    from cython.cimports.libc.math import fabs, isfinite, nearbyint, sqrt
else:
    from math import fabs, isfinite, sqrt

    from facadecli._libm import nearbyint


COMPILED_FROM: str | None = None  # setup.py: the digest of the sources it was built from

FREE, AFTER_EMPTY, AFTER_ATTACHED = 0, 1, 2
LEAF_WORK = budgets.LEAF_WORK  # work units of sizing a complete layout
COMBINATION_WORK = budgets.COMBINATION_WORK  # partial columns built per work unit
SAME = budgets.SAME  # objectives this close are equal
GO, EXHAUSTED, PERFECT = 0, 2, 3  # what run() returns
# why a column was rejected (worded by exact._Search.why)
NO_OPAQUE, ATTACHED_GAP, NO_COVER, GAP_BEFORE_ATTACHED, COVERED = 1, 2, 3, 4, 5
NOT_NEAR = 2  # fits(): not even by its own least deviation (see fitting())
INF = float("inf")
NAN = float("nan")
BIG = 2**63 - 1  # the order key of an infinite bound

Cuts = list[list[tuple[tuple[int, int] | None, ...]]]
LetterSpec = tuple[str, float | None, bool, bool, bool, bool, int]
RowSpec = tuple[Sequence[LetterSpec], Sequence[int], Sequence[int]]

_DOUBLES = array("d", [0.0])
_INTS = array("i", [0])
_FLAGS = array("b", [0])


def _doubles(n: int) -> Any:  # array[float]
    return _DOUBLES * n


def _ints(n: int) -> Any:  # array[int]
    return _INTS * n


def _flags(n: int) -> Any:  # array[int], of bytes
    return _FLAGS * n


def r9(x: float) -> float:
    if not isfinite(x):
        return x
    return float(nearbyint(x * 1e9)) / 1e9


def dot(a: array[float], b: array[float], n: int) -> float:
    t = 0.0
    for j in range(n):
        t += a[j] * b[j]
    return t


# -- rows, letters and their moves ------------------------------------------------------
class Move:
    """One row's entry out of a position: ``start`` to ``end`` (a middle piece when they
    are equal), what it holds, and its length at preferred sizes (``low`` .. ``high``)."""

    def __init__(self, start: int, end: int) -> None:
        self.start = start
        self.end = end
        self.fixed = 0.0
        self.unsized = 0
        self.letters = 0
        self.lead = False
        self.opaque = False
        self.transparent = False
        self.unoccludable = False
        self.first_attached = False
        self.last_attached = False
        self.fixed_only = False
        self.piece_of = -1  # the letter it starts inside, or -1
        self.tail = -1  # the letter whose first piece ends it, or -1
        self.tail_size = NAN
        self.low = 0.0
        self.high = 0.0


class Whole:
    """What the whole letters of an entry add up to, a letter at a time."""

    def __init__(self) -> None:
        self.count = 0
        self.unsized = 0
        self.fixed = 0.0
        self.opaque = True
        self.transparent = True
        self.sized_only = True
        self.unoccludable = False
        self.first_attached = False
        self.last_attached = False

    def add(self, row: Row, k: int) -> None:
        size = row.size[k]
        if size != size:  # NaN: a placeholder
            self.unsized += 1
            self.sized_only = False
        else:
            self.fixed += size
        attached = row.attached[k] != 0
        if self.count == 0:
            self.first_attached = attached
        self.last_attached = attached
        self.opaque = self.opaque and row.opaque[k] != 0
        self.transparent = self.transparent and row.transparent[k] != 0
        self.unoccludable = self.unoccludable or row.unoccludable[k] != 0
        self.count += 1


class Options:
    """A row's entries out of a position, each with its length when known (None: a gap,
    or a piece as long as the column), and the order ``fitting()`` checks them in: the
    entries of whole sized letters (by least length), the other ones of known length,
    then those of unknown length (always allowed)."""

    def __init__(self) -> None:
        self.moves: list[Any] = []  # Move, or None (a gap)
        self.lens: array[float] = _DOUBLES  # option i's length: lens[i * nv : (i + 1) * nv] ...
        self.known: array[int] = _INTS  # ... when known[i] (not a gap, not a piece)
        self.n = 0
        self.order: array[int] = _ints(0)
        self.n_whole = 0
        self.n_known = 0


class Row:
    def __init__(
        self,
        nv: int,
        sized: int,
        letters: Sequence[LetterSpec],
        above: Sequence[int],
        covering: Sequence[int],
        variables: dict[str, int],
        count: int,
    ) -> None:
        self.read(letters, above, covering, variables, count, nv, sized)

    def read(
        self,
        letters: Sequence[LetterSpec],
        above: Sequence[int],
        covering: Sequence[int],
        variables: dict[str, int],
        count: int,
        nv: int,
        sized: int,
    ) -> None:
        n = len(letters)
        self.n = n
        self.var = _ints(n + 1)
        self.size = _doubles(n + 1)
        self.transparent = _flags(n + 1)
        self.opaque = _flags(n + 1)
        self.attached = _flags(n + 1)
        self.unoccludable = _flags(n + 1)
        self.segment = _ints(n + 1)
        self.least = 0.0
        self.has_attached = False
        self.counts = _doubles((n + 1) * nv)
        positions = 2 * n + 1
        self.moves: list[list[Move] | None] = [None] * positions
        self.cached: list[list[Options | None]] = [[None] * positions, [None] * positions]
        met = 0
        counts = self.counts
        for k in range(n):
            symbol, size, transparent, opaque, attached, unoccludable, segment = letters[k]
            v = variables[symbol]
            if v < 0 or v >= nv:
                raise ValueError("a letter's symbol is not a variable")
            self.var[k] = v
            self.size[k] = NAN if size is None else float(size)
            if size is not None:
                least = size if size > 0 else 0.0
                if met == 0 or least < self.least:
                    self.least = least
                met += 1
            self.transparent[k] = 1 if transparent else 0
            self.opaque[k] = 1 if opaque else 0
            self.attached[k] = 1 if attached else 0
            self.unoccludable[k] = 1 if unoccludable else 0
            self.segment[k] = segment
            self.has_attached = self.has_attached or bool(attached)
            for j in range(nv):
                counts[(k + 1) * nv + j] = counts[k * nv + j]
            counts[(k + 1) * nv + v] += 1.0
        # what is left to lay out whole from each position (``sized`` numbers a position):
        # sized letters, and (placeholder, count) pairs ended by -1 (``stride`` a position)
        stride = 2 * (nv - sized) + 1
        self.stride = stride
        made = _doubles(positions * sized + 1)
        rem = made
        self.rem = made
        made = _ints(positions * stride + 1)
        pairs = made
        self.rem_ph = made
        for p in range(positions):
            before = (p + 1) // 2
            at = p * stride
            for v in range(sized, nv):
                times = int(counts[n * nv + v] - counts[before * nv + v])
                if times:
                    pairs[at] = v
                    pairs[at + 1] = times
                    at += 2
            pairs[at] = -1
            for v in range(sized):
                rem[p * sized + v] = counts[n * nv + v] - counts[before * nv + v]
        self.above = array("i", above)
        self.covering = array("i", covering)
        self.n_above = len(self.above)
        self.n_covering = len(self.covering)
        for index in (*above, *covering):
            number = index
            if number < 0 or number >= count:
                raise ValueError("a row index out of range")

    def push_move(
        self, moves: list[Move], start: int, end: int, held: Whole, piece_of: int, tail: int
    ) -> None:
        m = Move(start, end)
        pieces = (piece_of >= 0) + (tail >= 0)
        m.fixed = held.fixed
        m.unsized = held.unsized
        m.letters = held.count + pieces
        m.lead = piece_of >= 0 and end != start
        m.piece_of = piece_of
        m.tail = tail
        if tail < 0:
            m.tail_size = NAN
        else:
            m.tail_size = INF if self.size[tail] != self.size[tail] else self.size[tail]
        m.opaque = held.count > 0 and not pieces and held.opaque
        m.transparent = held.transparent
        m.unoccludable = held.unoccludable
        m.first_attached = piece_of < 0 and held.first_attached
        m.last_attached = tail < 0 and held.last_attached
        m.fixed_only = piece_of < 0 and tail < 0 and held.sized_only
        if m.fixed_only:  # interval(INF, {})
            m.low = m.high = m.fixed
        elif start == end:
            m.low = 0.0
            m.high = INF
        else:
            m.low = m.high = m.fixed
            if m.unsized or m.lead:
                m.high = INF
            if tail >= 0:
                m.high += m.tail_size
        moves.append(m)

    def extend_moves(
        self, moves: list[Move], start: int, k: int, transparent: int, piece_of: int
    ) -> None:
        held = Whole()
        if piece_of >= 0:
            self.push_move(moves, start, 2 * k, held, piece_of, -1)
        segment = self.segment[k] if k < self.n else 0
        for index in range(k, self.n):
            if self.transparent[index] != transparent or self.segment[index] != segment:
                return
            held.add(self, index)
            self.push_move(moves, start, 2 * (index + 1), held, piece_of, -1)
            following = index + 1
            if transparent and following < self.n and self.transparent[following]:
                self.push_move(moves, start, 2 * following + 1, held, piece_of, following)

    def moves_of(self, position: int) -> list[Move]:
        """The entries out of ``position``, by (least whole length, letters, end)."""
        found = self.moves[position]
        if found is not None:
            return found
        made: list[Move] = []
        k = position // 2
        if k < self.n:
            if position % 2:
                self.push_move(made, position, position, Whole(), k, -1)
                self.extend_moves(made, position, k + 1, 1, k)
            else:
                transparent = self.transparent[k]
                if transparent:
                    self.push_move(made, position, position + 1, Whole(), -1, k)
                self.extend_moves(made, position, k, transparent, -1)
        made.sort(key=_move_order)
        self.moves[position] = made
        return made

    def spanning(self, start: int, end: int) -> Move | None:
        """The entry from ``start`` to ``end`` (a middle piece when they are equal), if any."""
        for m in self.moves_of(start):
            if m.end == end and (m.start == m.end) == (start == end):
                return m
        return None


def _count(o: Options) -> int:
    return o.n


def _move_order(m: Move) -> tuple[float, int, int]:
    return (m.fixed, m.letters, m.end)


def stands_aside(m: Move | None) -> bool:
    return m is None or m.start == m.end or (m.letters == 1 and m.piece_of < 0 and m.tail >= 0)


def plain(m: Move) -> bool:
    return m.unsized == 0 and m.piece_of < 0 and m.tail < 0


class Group:
    def __init__(self, rows: list[Row]) -> None:
        self.rows = rows
        self.n = len(rows)
        self.ends = _ints(self.n + 1)
        for r in range(self.n):
            self.ends[r] = 2 * rows[r].n


# -- the equalities of a partial path ---------------------------------------------------
class System:
    """The equalities a partial path implies, kept reduced, and the least squared deviation
    of the sized symbols under them (``value``, the bound): placeholder rows solved for a
    pivot placeholder (``npiv`` rows over every symbol), the others orthonormal over the
    sized symbols (``nb`` rows of ``basis``), ``point`` the sizes nearest the preferred
    ones under them. Never changed once made: a child adds rows to a copy."""

    def __init__(self, nv: int, sized: int, npiv: int, nb: int) -> None:
        self.make(nv, sized, npiv, nb)
        self.value = 0.0
        self.probes: dict[bytes, float] | None = None  # probe() of rows already asked about

    def make(self, nv: int, sized: int, npiv: int, nb: int) -> None:
        """Its rows, in one buffer (compiled, views of it; interpreted, copies of its parts)."""
        self.npiv = npiv
        self.nb = nb
        self.piv_var = _ints(npiv + 1)
        made = _doubles(npiv * nv + npiv + nb * sized + nb + sized + 1)
        buffer = made
        at = npiv * nv
        self.piv_row = buffer[0:at]
        self.piv_rhs = buffer[at : at + npiv]
        at += npiv
        self.basis = buffer[at : at + nb * sized]
        at += nb * sized
        self.brhs = buffer[at : at + nb]
        at += nb
        self.point = buffer[at : at + sized]


class Cell:
    """The path: a column, linked back to the one before."""

    def __init__(self, prev: Cell | None, column: list[Move | None]) -> None:
        self.prev = prev
        self.depth: int = 1 if prev is None else prev.depth + 1
        self.column = column


class Node:
    """A state of the search: where each row stands in its group, the attached rule's
    memory (after the last column, and before it), the equalities so far, where the last
    column ends (over the symbols) and what each row has used of the letter it is inside."""

    def __init__(self, nv: int, count: int) -> None:
        self.make(nv, count)
        self.system: Any = None  # System, once made
        self.path: Cell | None = None

    def make(self, nv: int, count: int) -> None:
        """Its numbers, in two buffers (compiled, views of them; interpreted, copies)."""
        made = _ints(4 * count + 1)
        numbers = made
        self.positions = numbers[0:count]
        self.memory = numbers[count : 2 * count]
        self.before = numbers[2 * count : 3 * count]
        self.has_used = numbers[3 * count : 4 * count]
        made = _doubles(nv + count * nv + 1)
        lengths = made
        self.x = lengths[0:nv]
        self.used = lengths[nv : nv + count * nv]


class Child:
    def __init__(self, node: Node, bound: float, index: int) -> None:
        self.node = node
        self.bound = bound
        self.index = index
        self.key = BIG if not isfinite(bound) or bound > 9e9 else int(nearbyint(bound * 1e9))
        self.empties = 0
        self.pieces = 0
        self.letters = 0
        self.spread = 0.0

    def order(self) -> tuple[int, int, float, int, int, int]:
        return (self.key, self.empties, self.spread, self.pieces, self.letters, self.index)


def _child_order(child: Child) -> tuple[int, int, float, int, int, int]:
    return child.order()


class Search:
    """The exact search of one candidate's groups (see :mod:`facadecli.solver.exact`)."""

    def __init__(
        self,
        groups: Sequence[Sequence[RowSpec]],
        variables: dict[str, int],
        target: Sequence[float],
        canvas: float,
        incumbent: float,
        limit: int,
        used: int,
        deadline: float,
        first_only: bool,
        leaf: Callable[[Cuts], tuple[float, bool]],
    ) -> None:
        nv = len(variables)
        sized = len(target)
        if sized > nv:
            raise ValueError("more sized symbols than variables")
        self.nv = nv
        self.sized = sized
        self.target = _doubles(sized + 1)
        for j in range(sized):
            self.target[j] = float(target[j])
        self.canvas = float(canvas)
        self.incumbent = float(incumbent)
        self.limit = int(limit)
        self.used = int(used)
        self.deadline = float(deadline)
        self.timed_out = False
        self.first_only = bool(first_only)
        self.gaps = True
        self.combinations = 0
        self.stop = GO
        self.progress = 0
        self.recording = True
        self.leaf = leaf
        self.rejected: dict[tuple[int, int, int, int, int, int], list[int]] = {}
        self.groups: list[Group] = []
        for rows in groups:
            made = [Row(nv, sized, *row, variables, len(rows)) for row in rows]
            self.groups.append(Group(made))
        self.done: list[Cell | None] = [None] * len(self.groups)
        self.builders = [Builder(g, self.groups[g].n) for g in range(len(self.groups))]
        # scratch rows (no call that uses one calls another that does)
        extra = nv - sized if nv > sized else 1
        self.row = _doubles(nv + 1)
        self.known = _doubles(nv + 1)
        self.width = _doubles(nv + 1)
        self.diff = _doubles(nv)  # fits()'s difference, an array (the probe's key) ...
        self.diff_view = self.diff  # ... and a view of it
        self.shifted = _doubles(sized + 1)
        self.reduced = _doubles(nv + 1)
        self.coef = _doubles(sized + 2)
        self.span = _doubles(sized + 1)
        self.a = _doubles(sized + 1)
        self.least = _doubles(extra * sized + 1)
        self.held = _doubles(extra * sized + 1)
        self.least_rhs = _doubles(extra)
        self.has = _flags(extra)
        self.fixed = _flags(extra)

    # -- work ---------------------------------------------------------------------------
    def spend(self, units: int) -> int:
        """Spend work units: 1 when the budget (or the deadline) says stop, else 0. The
        walk stops by these returns, not by an exception: one raised through every level
        of a deep path costs more than the walk itself."""
        before = self.used
        self.used += units
        if self.used > self.limit:
            self.stop = EXHAUSTED
            return 1
        if (
            before // 256 != self.used // 256
            and isfinite(self.deadline)
            and time.process_time() > self.deadline  # budgets.safety_clock()
        ):
            self.timed_out = True
            self.stop = EXHAUSTED
            return 1
        return 0

    # -- the system of equalities -------------------------------------------------------
    def reduce(self, y: System, row: array[float], rhs: float) -> float:
        """The row with the pivot placeholders solved out (in place)."""
        nv = self.nv
        piv_row = y.piv_row
        for i in range(y.npiv):
            c = row[y.piv_var[i]]
            if c != 0.0:
                base = i * nv
                for j in range(nv):
                    row[j] -= c * piv_row[base + j]
                rhs -= c * y.piv_rhs[i]
        return rhs

    def orthogonal(self, y: System, a: array[float], rhs: float) -> float:
        """The part of a row over the sized symbols that the basis does not span (in place)."""
        sz = self.sized
        nb = y.nb
        if not nb:
            return rhs
        basis = y.basis
        c = self.coef
        for _ in range(2):  # twice: Gram-Schmidt loses orthogonality once
            for i in range(nb):
                t = 0.0
                base = i * sz
                for j in range(sz):
                    t += basis[base + j] * a[j]
                c[i] = t
            for i in range(nb):
                base = i * sz
                ci = c[i]
                for j in range(sz):
                    a[j] -= ci * basis[base + j]
                rhs -= ci * y.brhs[i]
        return rhs

    def system_add(self, y: System, given: array[float], rhs: float, scale: float) -> System | None:
        """The system with ``given @ symbols == rhs`` added (``y`` itself when it adds
        nothing); None when it conflicts."""
        nv = self.nv
        sz = self.sized
        row = self.row
        for j in range(nv):
            row[j] = given[j]
        rhs = self.reduce(y, row, rhs)
        v = -1
        most = 1e-9
        for j in range(sz, nv):
            if fabs(row[j]) > most:
                most = fabs(row[j])
                v = j
        if v >= 0:
            z = System(nv, sz, y.npiv + 1, y.nb)
            pv = row[v]
            base = y.npiv * nv
            for j in range(nv):
                z.piv_row[base + j] = row[j] / pv
            pivot_rhs = rhs / pv
            for i in range(y.npiv):
                z.piv_var[i] = y.piv_var[i]
                c = y.piv_row[i * nv + v]
                if c != 0.0:
                    for j in range(nv):
                        z.piv_row[i * nv + j] = y.piv_row[i * nv + j] - c * z.piv_row[base + j]
                    z.piv_rhs[i] = y.piv_rhs[i] - c * pivot_rhs
                else:
                    for j in range(nv):
                        z.piv_row[i * nv + j] = y.piv_row[i * nv + j]
                    z.piv_rhs[i] = y.piv_rhs[i]
            z.piv_var[y.npiv] = v
            z.piv_rhs[y.npiv] = pivot_rhs
            for j in range(y.nb * sz):
                z.basis[j] = y.basis[j]
            for j in range(y.nb):
                z.brhs[j] = y.brhs[j]
            for j in range(sz):
                z.point[j] = y.point[j]
            z.value = y.value
            return z
        rhs = self.orthogonal(y, row, rhs)
        norm = sqrt(dot(row, row, sz))
        if norm <= 1e-9:
            if fabs(rhs) <= 1e-7 * scale:
                return y
            return None
        z = System(nv, sz, y.npiv, y.nb + 1)
        for i in range(y.npiv):
            z.piv_var[i] = y.piv_var[i]
        for j in range(y.npiv * nv):
            z.piv_row[j] = y.piv_row[j]
        for j in range(y.npiv):
            z.piv_rhs[j] = y.piv_rhs[j]
        for j in range(y.nb * sz):
            z.basis[j] = y.basis[j]
        for j in range(y.nb):
            z.brhs[j] = y.brhs[j]
        base = y.nb * sz
        for j in range(sz):
            z.basis[base + j] = row[j] / norm
        z.brhs[y.nb] = rhs / norm
        t = 0.0
        for j in range(sz):
            t += z.basis[base + j] * y.point[j]
        residual = rhs / norm - t
        for j in range(sz):
            z.point[j] = y.point[j] + residual * z.basis[base + j]
        z.value = y.value + residual * residual
        return z

    def probe(self, y: System) -> float:
        """The bound with ``diff @ symbols == 0`` added (fits()'s difference; INF when it
        conflicts), kept with the system (a child that adds no equality shares its
        parent's)."""
        if y.probes is None:
            y.probes = {}
        key = self.diff.tobytes()
        found = y.probes.get(key)
        if found is not None:
            return float(found)
        value = self.probe_of(y, self.diff_view)
        y.probes[key] = value
        return value

    def probe_of(self, y: System, given: array[float]) -> float:
        nv = self.nv
        sz = self.sized
        row = self.row
        for j in range(nv):
            row[j] = given[j]
        rhs = self.reduce(y, row, 0.0)
        for j in range(sz, nv):
            if fabs(row[j]) > 1e-9:
                return y.value
        rhs = self.orthogonal(y, row, rhs)
        norm2 = dot(row, row, sz)
        if norm2 <= 1e-18:
            return y.value if fabs(rhs) <= 1e-7 * self.canvas else INF
        residual = rhs - dot(row, y.point, sz)
        return y.value + residual * residual / norm2

    def implies_zero(self, y: System, given: array[float], offset: int) -> bool:
        """Whether the equalities make ``given[offset:] @ symbols`` zero."""
        nv = self.nv
        sz = self.sized
        row = self.row
        for j in range(nv):
            row[j] = given[offset + j]
        rhs = self.reduce(y, row, 0.0)
        for j in range(sz, nv):
            if fabs(row[j]) > 1e-9:
                return False
        rhs = self.orthogonal(y, row, rhs)
        return dot(row, row, sz) <= 1e-18 and fabs(rhs) <= 1e-7 * self.canvas

    # -- rejections ---------------------------------------------------------------------
    def reject(self, code: int, g: int, r: int, a: int, m: Move | None) -> bool:
        if not self.recording:
            return False
        key = (code, g, r, a, -1 if m is None else m.start, -1 if m is None else m.end)
        seen = self.rejected.get(key)
        if seen is None:
            self.rejected[key] = [self.progress, 1]
        else:
            if self.progress > seen[0]:
                seen[0] = self.progress
            seen[1] += 1
        return False

    def rejections(self) -> list[tuple[int, int, int, int, int, int, int, int]]:
        """(rule, group, row, other row, start, end, progress, count) of every rejection."""
        return [(*key, seen[0], seen[1]) for key, seen in self.rejected.items()]

    # -- the rules of SPEC 2.4 on one column --------------------------------------------
    def valid(self, g: int, entries: list[Move | None], memory: array[int]) -> bool:
        group = self.groups[g]
        first = -1
        any_opaque = False
        for r in range(group.n):
            m = entries[r]
            if m is not None:
                if first < 0:
                    first = r
                if m.opaque:
                    any_opaque = True
        if first < 0:
            return False
        if not any_opaque:
            return self.reject(NO_OPAQUE, g, first, -1, entries[first])
        for r in range(group.n):
            m = entries[r]
            row = group.rows[r]
            if m is None:
                if memory[r] == AFTER_ATTACHED:
                    return self.reject(ATTACHED_GAP, g, r, -1, None)
                covered = False
                for i in range(row.n_covering):
                    o = entries[row.covering[i]]
                    if o is not None and o.opaque:
                        covered = True
                        break
                if not covered:
                    return self.reject(NO_COVER, g, r, -1, None)
                continue
            if m.first_attached and memory[r] == AFTER_EMPTY:
                return self.reject(GAP_BEFORE_ATTACHED, g, r, -1, m)
            if m.unoccludable:
                for i in range(row.n_above):
                    o = entries[row.above[i]]
                    if o is not None and not o.transparent:
                        return self.reject(COVERED, g, r, row.above[i], m)
        return True

    def merges(
        self, g: int, last: list[Move | None], entries: list[Move | None], before: array[int]
    ) -> bool:
        """Whether two columns in a row make one valid column (then the path through both
        is never needed)."""
        group = self.groups[g]
        merged: list[Move | None] = [None] * group.n
        for r in range(group.n):
            a = last[r]
            b = entries[r]
            if a is None or b is None:
                if a is not b:
                    return False
                continue
            row = group.rows[r]
            joined = row.spanning(a.start, b.end)
            if joined is None:
                return False
            merged[r] = joined
        recording = self.recording
        self.recording = False
        fits = self.valid(g, merged, before)
        self.recording = recording
        return fits

    # -- options and columns ------------------------------------------------------------
    def whole_into(self, row: Row, m: Move, into: array[float], at: int) -> None:
        """The length of the letters an entry holds whole, over the symbols, into
        ``into[at:]`` (the row's counts after them less those before: made afresh, as
        cheap as a copy)."""
        nv = self.nv
        first = (m.start + 1) // 2
        last = m.end // 2
        if last < first:
            last = first
        counts = row.counts
        for j in range(nv):
            into[at + j] = counts[last * nv + j] - counts[first * nv + j]

    def known_length(
        self, row: Row, m: Move, node: Node, r: int, into: array[float], at: int
    ) -> bool:
        """The length of an entry when it does not depend on the column's width (whole
        letters, and what is left of a split letter it finishes), into ``into[at:]``;
        False for pieces."""
        if m.tail >= 0 or m.start == m.end:
            return False
        self.whole_into(row, m, into, at)
        nv = self.nv
        if m.piece_of < 0:
            return True
        into[at + row.var[m.start // 2]] += 1.0
        used = node.used
        base = r * nv
        for j in range(nv):
            into[at + j] -= used[base + j]
        return True

    def holds_placeholder(self, length: array[float], at: int) -> bool:
        for k in range(self.sized, self.nv):  # noqa: SIM110 (a C loop once compiled)
            if length[at + k] != 0.0:
                return True
        return False

    def options_of(self, g: int, r: int, node: Node) -> Options:
        group = self.groups[g]
        row = group.rows[r]
        position = node.positions[r]
        inside = position % 2 == 1
        gaps = 1 if self.gaps else 0
        if not inside:
            cached: Options | None = row.cached[gaps][position]
            if cached is not None:
                return cached
        o = Options()
        nv = self.nv
        moves: list[Move] = []
        gap = True
        if position < group.ends[r]:
            moves = row.moves_of(position)
            gap = self.gaps and not inside and row.n_covering > 0
        o.moves = list(moves)
        if gap:
            o.moves.append(None)
        o.n = len(o.moves)
        made = _doubles(o.n * nv + 1)
        lens = made
        o.lens = lens
        made = _ints(o.n + 1)
        known = made
        o.known = known
        for i in range(len(moves)):
            m = moves[i]
            known[i] = 1 if self.known_length(row, m, node, r, lens, i * nv) else 0
        made = _ints(o.n + 1)
        order = made
        at = 0
        for i in range(o.n):
            m = o.moves[i]
            if known[i] and plain(m) and not self.holds_placeholder(lens, i * nv):
                order[at] = i
                at += 1
        o.n_whole = at
        for i in range(o.n):
            m = o.moves[i]
            if known[i] and not (plain(m) and not self.holds_placeholder(lens, i * nv)):
                order[at] = i
                at += 1
        o.n_known = at - o.n_whole
        for i in range(o.n):
            if not known[i]:
                order[at] = i
                at += 1
        o.order = order
        if not inside:
            row.cached[gaps][position] = o
        return o

    def fits(
        self, b: Builder, length: array[float], at: int, pinned: bool, rest: float
    ) -> tuple[int, float]:
        """Whether an option of known ``length`` may be as long as the builder's first
        entry: 1 it may, 0 it may not, NOT_NEAR it may not by its own least deviation
        (the equality alone: see fitting()); and its miss at preferred sizes."""
        nv = self.nv
        sz = self.sized
        first = b.first
        fat = b.first_at
        target = self.target
        d = self.diff_view
        shifted = self.shifted
        reduced = self.reduced
        placeholders = False
        own = False
        for k in range(nv):
            d[k] = length[at + k] - first[fat + k]
        for k in range(sz, nv):
            if d[k] != 0.0:
                placeholders = True
            if length[at + k] != 0.0:
                own = True
        use_shifted = False
        alone = 0.0
        norm = 0.0
        off = 0.0
        miss = -1.0
        if not placeholders:
            norm = dot(d, d, sz)
            miss = dot(d, target, sz)
            alone = miss * miss / norm if norm > 0 else 0.0
        elif pinned and not own:
            for k in range(sz):
                shifted[k] = length[at + k] + reduced[k]
            use_shifted = True
            off = rest
            norm = dot(shifted, shifted, sz)
            miss = dot(shifted, target, sz) - rest
            alone = miss * miss / norm if norm > 0 and miss * miss / norm > b.margin else 0.0
        if alone > b.limit:
            return (NOT_NEAR if norm > 0 and alone > b.margin else 0), miss
        if norm > 0 and (not placeholders or (pinned and not own)):
            # the bound with the equality: its residual at the system's point is the
            # probe's, over a row no longer than this one (the probe is at least this)
            y = b.node.system
            residual = off - dot(shifted if use_shifted else d, y.point, sz)
            if y.value + residual * residual / norm > b.margin:
                return 0, miss
        value = self.probe(b.node.system)
        return (1 if value <= b.limit else 0), miss

    def fitting(self, b: Builder, fr: int, j: int, r: int) -> int:
        """Which options of row r may be as long as the first entry (row fr, option j)
        within the incumbent (a mask: where it starts in ``b.masks``): first alone (their
        preferred lengths apart), then with the equalities.

        A first entry holding placeholders: with the equalities' pivots solved out of it
        (when they fix every placeholder it holds), an entry of sized letters must meet
        (len + reduced) @ sizes == rest; when the least deviation under that equality
        alone is beyond the limit, so is the probe (it adds the other equalities).

        The entries of whole sized letters out of one position are each the one before
        and more letters: each letter adds at least the row's least size to the miss and
        at most 1 to the norm. So once one longer than the first is not near, nor are the
        longer ones; once one shorter is not, nor are the shorter ones (when the least
        size squared is beyond the limit): they are checked outward from the first's
        length, until both sides stop."""
        key = (b.base[fr] + j) * b.R + r
        found = b.fits.get(key)
        if found is not None:
            return int(found)
        nv = self.nv
        sz = self.sized
        o = b.opts[r]
        at = b.reserve(o.n)
        mask = b.masks
        fo = b.opts[fr]
        first = fo.lens
        fat = j * nv
        b.first = first
        b.first_at = fat
        limit = self.incumbent + SAME
        b.limit = limit
        b.margin = limit + 1e-9 * (1.0 + limit)
        y = b.node.system
        reduced = self.reduced
        pinned = False
        rest = 0.0
        for k in range(sz, nv):
            if first[fat + k] != 0.0:
                pinned = True
        if pinned:
            for k in range(nv):
                reduced[k] = -first[fat + k]
            rest = self.reduce(y, reduced, 0.0)
            for k in range(sz, nv):
                if fabs(reduced[k]) > 1e-9:
                    pinned = False
        group = self.groups[b.g]
        row = group.rows[r]
        least = row.least
        ordered = least * least > b.margin
        order = o.order
        nw = o.n_whole
        nk = o.n_known
        for u in range(nw + nk, o.n):
            mask[at + order[u]] = 1
        # with the whole entries first when they are not checked outward
        lens = o.lens
        for w in range(0 if not ordered else nw, nw + nk):
            fit, miss = self.fits(b, lens, order[w] * nv, pinned, rest)
            mask[at + order[w]] = 1 if fit == 1 else 0
        if ordered:
            # the first whole entry at least as long as the first, at preferred sizes
            total = rest if pinned else 0.0
            for k in range(sz):
                total += (-reduced[k] if pinned else first[fat + k]) * self.target[k]
            low = 0
            high = nw
            while low < high:  # binary search: the whole entries are sorted by least length
                mid = (low + high) // 2
                if o.moves[order[mid]].fixed < total:
                    low = mid + 1
                else:
                    high = mid
            start = low
            for w in range(start, nw):  # longer, outward
                fit, miss = self.fits(b, lens, order[w] * nv, pinned, rest)
                mask[at + order[w]] = 1 if fit == 1 else 0
                if fit == NOT_NEAR and miss >= 0:
                    break
            for w in range(start - 1, -1, -1):  # shorter, outward
                fit, miss = self.fits(b, lens, order[w] * nv, pinned, rest)
                mask[at + order[w]] = 1 if fit == 1 else 0
                if fit == NOT_NEAR and miss < 0:
                    break
        b.fits[key] = at
        return at

    def extend(self, b: Builder, i: int, fr: int, fj: int, solid: bool) -> int:
        self.combinations += 1
        if self.combinations % COMBINATION_WORK == 0 and self.spend(1):
            return 1
        if i == b.R:
            if self.valid(b.g, b.chosen, b.node.memory):
                b.out.append(list(b.chosen))
            return 0
        r = b.order[i]
        o = b.opts[r]
        masked = fr >= 0
        at = self.fitting(b, fr, fj, r) if masked else -1
        for k in range(o.n):
            if masked and not b.masks[at + k]:
                continue
            m = o.moves[k]
            if i == b.last and not solid and m is not None and plain(m) and m.letters > 1:
                continue  # a stretch of several letters: searched a letter at a time
            b.chosen[r] = m
            held = solid or not stands_aside(m)
            if fr < 0 and o.known[k] and m is not None:
                if self.extend(b, i + 1, r, k, held):
                    return 1
            elif self.extend(b, i + 1, fr, fj, held):
                return 1
        b.chosen[r] = None
        return 0

    def columns_of(self, g: int, node: Node, opts: list[Options]) -> list[list[Move | None]] | None:
        """Every valid column out of a node, but not those where two entries of known
        length could not be as long as each other within the incumbent."""
        count = self.groups[g].n
        b = self.builders[g]
        b.start(node, opts)
        order = b.order
        for i in range(count):
            order[i] = i
        for i in range(1, count):  # insertion sort: fewest options first, then r
            v = order[i]
            k = i
            while k > 0 and _count(opts[order[k - 1]]) > _count(opts[v]):
                order[k] = order[k - 1]
                k -= 1
            order[k] = v
        stopped = self.extend(b, 0, -1, -1, False)
        columns = b.out
        b.done()
        if stopped:
            return None
        return columns

    # -- nodes --------------------------------------------------------------------------
    def bound_within(self, g: int, y: System, child: Node) -> float:
        """The bound strengthened by what each row has laid out and still has to lay out:
        it must fit the canvas (a placeholder still to come is as long as its expression
        once the equalities fix it, and at least what a row inside it has used so far)."""
        group = self.groups[g]
        sz = self.sized
        nv = self.nv
        count = group.n
        x = child.x
        target = self.target
        least = self.least
        least_rhs = self.least_rhs
        held = self.held
        has = self.has
        fixed = self.fixed
        for v in range(nv - sz):
            has[v] = 0
            fixed[v] = 0
        for i in range(y.npiv):
            base = i * nv
            nonzero = 0
            for j in range(sz, nv):
                if y.piv_row[base + j] != 0.0:
                    nonzero += 1
            if nonzero == 1:
                v = y.piv_var[i] - sz
                fixed[v] = 1
                for j in range(sz):
                    least[v * sz + j] = -y.piv_row[base + j]
                least_rhs[v] = y.piv_rhs[i]
        for r in range(count):
            if not child.has_used[r]:
                continue
            base = r * nv
            row = group.rows[r]
            v = row.var[child.positions[r] // 2]
            if v < sz or fixed[v - sz]:
                continue
            fine = True
            for j in range(sz, nv):
                if child.used[base + j] < -1e-12:
                    fine = False
            if not fine:
                continue
            v -= sz
            if has[v]:
                mine = 0.0
                theirs = 0.0
                for j in range(sz):
                    mine += child.used[base + j] * target[j]
                for j in range(sz):
                    theirs += held[v * sz + j] * target[j]
                if not mine > theirs:
                    continue
            has[v] = 1
            for j in range(sz):
                held[v * sz + j] = child.used[base + j]
        for v in range(nv - sz):
            if fixed[v]:
                has[v] = 1
            elif has[v]:
                for j in range(sz):
                    least[v * sz + j] = held[v * sz + j]
                least_rhs[v] = 0.0
        best = y.value
        span = self.span
        a = self.a
        c = self.coef
        point = y.point
        basis = y.basis
        tol = 1e-9 * (self.canvas if self.canvas > 1.0 else 1.0)
        for k in range(-1, count):
            most = self.canvas
            for j in range(sz):
                span[j] = x[j]
            if k >= 0:
                row = group.rows[k]
                position = child.positions[k]
                rem = row.rem
                base = position * sz
                for j in range(sz):
                    span[j] += rem[base + j]
                pairs = row.rem_ph
                p = position * row.stride
                while pairs[p] >= 0:
                    v = pairs[p] - sz
                    times = pairs[p + 1]
                    if has[v]:
                        for j in range(sz):
                            span[j] += times * least[v * sz + j]
                        most -= times * least_rhs[v]
                    p += 2
            violation = dot(span, point, sz) - most
            if violation <= tol:
                continue
            for j in range(sz):
                a[j] = span[j]
            if y.nb:
                for i in range(y.nb):
                    t = 0.0
                    for j in range(sz):
                        t += basis[i * sz + j] * span[j]
                    c[i] = t
                for i in range(y.nb):
                    ci = c[i]
                    for j in range(sz):
                        a[j] -= ci * basis[i * sz + j]
            norm = dot(a, a, sz)
            if norm <= 1e-12:
                return INF
            value = y.value + violation * violation / norm
            if value > best:
                best = value
        return best

    def empty_piece(self, row: Row, m: Move | None, used: array[float], r: int, y: System) -> bool:
        """Whether an entry ends with the first piece of a split letter that the equalities
        make empty, after whole letters: the same layout has the letter start in the next
        column, and that path is searched instead (not when the letter and the next are
        of two segments: the next column's entries then differ)."""
        if m is None or m.tail < 0 or m.start == m.end - 1:
            return False
        k = m.end // 2
        if k + 1 < row.n and row.segment[k] != row.segment[k + 1]:
            return False
        return self.implies_zero(y, used, r * self.nv)

    def child_of(self, g: int, node: Node, entries: list[Move | None]) -> Node | None:
        """The child of a node through a column: None when its equalities conflict."""
        group = self.groups[g]
        count = group.n
        nv = self.nv
        wr = -1
        for r in range(count):
            m = entries[r]
            if m is not None and m.piece_of < 0 and m.tail < 0:
                wr = r
                break
        row = group.rows[wr]
        width = self.width
        self.whole_into(row, entries[wr], width, 0)  # type: ignore[arg-type]
        c = Node(nv, count)
        used = c.used
        for j in range(count * nv):
            used[j] = node.used[j]
        for r in range(count):
            c.has_used[r] = node.has_used[r]
        y: System | None = node.system
        known = self.known
        for r in range(count):
            if y is None:
                break
            m = entries[r]
            if m is None:
                continue
            row = group.rows[r]
            self.whole_into(row, m, known, 0)
            base = r * nv
            if m.piece_of >= 0:
                if m.start == m.end:
                    for j in range(nv):
                        used[base + j] += width[j]
                    continue
                known[row.var[m.start // 2]] += 1.0
                for j in range(nv):
                    known[j] -= used[base + j]
                c.has_used[r] = 0
                for j in range(nv):
                    used[base + j] = 0.0
            if m.tail >= 0:
                for j in range(nv):
                    used[base + j] = width[j] - known[j]
                c.has_used[r] = 1
            elif r != wr:
                for j in range(nv):
                    known[j] -= width[j]
                y = self.system_add(y, known, 0.0, self.canvas)
        if y is not None:
            for r in range(count):
                row = group.rows[r]
                if self.empty_piece(row, entries[r], used, r, y):
                    y = None
                    break
        if y is None:
            return None
        c.system = y
        for j in range(nv):
            c.x[j] = node.x[j] + width[j]
        for r in range(count):
            m = entries[r]
            c.positions[r] = node.positions[r] if m is None else m.end
            c.before[r] = node.memory[r]
            row = group.rows[r]
            if not row.has_attached:
                c.memory[r] = FREE
            elif m is None:
                c.memory[r] = AFTER_ATTACHED if node.memory[r] == AFTER_ATTACHED else AFTER_EMPTY
            else:
                c.memory[r] = AFTER_ATTACHED if m.last_attached else FREE
        return c

    def start_of(self, g: int, y: System) -> Node:
        node = Node(self.nv, self.groups[g].n)
        node.system = y
        return node  # positions 0, memory FREE, x 0, nothing used, no path

    def call_leaf(self, node: Node) -> int:
        if self.spend(LEAF_WORK):
            return 1
        paths: Cuts = []
        for g in range(len(self.groups)):
            end = self.done[g] if g + 1 < len(self.groups) else node.path
            columns: list[tuple[tuple[int, int] | None, ...]] = []
            cell = end
            while cell is not None:
                columns.append(
                    tuple([None if m is None else (m.start, m.end) for m in cell.column])
                )
                cell = cell.prev
            columns.reverse()
            paths.append(columns)
        incumbent, stop = self.leaf(paths)
        self.incumbent = float(incumbent)
        if stop:
            self.stop = PERFECT
            return 1
        return 0

    def finish_group(self, g: int, node: Node) -> int:
        assert node.system is not None
        closed = self.system_add(node.system, node.x, self.canvas, self.canvas)
        if self.spend(1):
            return 1
        if closed is None or closed.value > self.incumbent + SAME:
            return 0
        if g + 1 < len(self.groups):
            self.done[g] = node.path
            return self.dfs(g + 1, self.start_of(g + 1, closed))
        return self.call_leaf(node)

    def dfs(self, g: int, node: Node) -> int:
        """Walk on from a node: 1 when the walk stops (see spend()), else 0."""
        group = self.groups[g]
        count = group.n
        at_end = True
        progress = 0
        for r in range(count):
            if node.positions[r] != group.ends[r]:
                at_end = False
            progress += node.positions[r]
        if at_end:
            return self.finish_group(g, node)
        self.progress = progress
        opts = [self.options_of(g, r, node) for r in range(count)]
        children: list[Child] = []
        columns = self.columns_of(g, node, opts)
        if columns is None:
            return 1
        for entries in columns:
            stretch = self.stretch_of(entries, count)
            if stretch is not None:
                if stretch.letters > 1:
                    continue
            elif node.path is not None and self.merges(g, node.path.column, entries, node.before):
                continue  # the one column they make is searched too, and is looser
            if self.spend(1):
                return 1
            c = self.child_of(g, node, entries)
            if c is None:
                continue
            assert c.system is not None
            bound = self.bound_within(g, c.system, c)
            if bound > self.incumbent + SAME:
                continue
            c.path = Cell(node.path, entries)
            child = Child(c, bound, len(children))
            lows = -INF
            highs = INF
            for r in range(count):
                m = entries[r]
                if m is None:
                    child.empties += 1
                    continue
                child.pieces += (m.piece_of >= 0) + (m.tail >= 0)
                child.letters += m.letters
                if m.low > lows:
                    lows = m.low
                if m.high < highs:
                    highs = m.high
            d = lows - highs
            child.spread = r9(d if d > 0.0 else 0.0)
            children.append(child)
        # most promising first: least bound, then no room made before room made, the
        # columns that fit at preferred sizes (the paper's column error), whole letters
        # before pieces (split only where needed), fewer letters (more columns)
        children.sort(key=_child_order)
        for child in children:
            if r9(child.bound) > self.incumbent + SAME:
                break
            if self.dfs(g, child.node):
                return 1
        return 0

    def stretch_of(self, entries: list[Move | None], count: int) -> Move | None:
        found: Move | None = None
        for r in range(count):
            m = entries[r]
            if stands_aside(m):
                continue
            assert m is not None
            if found is not None or not plain(m):
                return None
            found = m
        return found

    # -- the search ---------------------------------------------------------------------
    def filling(self, y: System | None) -> System | None:
        """A row without gaps has letters that fill the canvas, whatever the alignment."""
        nv = self.nv
        total = _doubles(nv)
        for group in self.groups:
            for r in range(group.n):
                if y is None:
                    return None
                row = group.rows[r]
                if self.gaps and row.n_covering:
                    continue
                for j in range(nv):
                    total[j] = row.counts[row.n * nv + j]
                y = self.system_add(y, total, self.canvas, self.canvas)
        return y

    def run(self, gaps: bool) -> int:
        """0: done, 2: the budget ran out, 3: stopped by leaf()."""
        self.gaps = bool(gaps)
        self.stop = GO
        self.recording = True
        if not self.groups:
            raise ValueError("a search needs a group of rows")
        empty = System(self.nv, self.sized, 0, 0)
        for j in range(self.sized):
            empty.point[j] = self.target[j]
        y = self.filling(empty)
        if y is None:
            return GO
        self.dfs(0, self.start_of(0, y))
        return self.stop


class Builder:
    """What columns_of() builds the columns out of a node with: one a group, set again
    for each node (columns_of() never runs inside another)."""

    def __init__(self, g: int, count: int):
        self.g = g
        self.R = count
        self.last = count - 1
        self.node = Node(0, count)  # the node of the columns it builds (start())
        self.opts: list[Options] = []
        self.order = _ints(count + 1)  # the rows, fewest options first (columns_of())
        self.base = _ints(count + 1)  # where each row's options start in fits' keys
        self.chosen: list[Move | None] = [None] * count
        self.fits: dict[int, int] = {}  # by (first row, option) and row: where its mask is
        self.out: list[list[Move | None]] = []
        self.masks = _flags(64)  # fitting()'s masks, one after another ...
        self.size = 64
        self.filled = 0  # ... up to here
        self.first: array[float] = _DOUBLES  # fitting()'s first entry: first[first_at:]
        self.first_at = 0
        self.limit = 0.0
        self.margin = 0.0

    def start(self, node: Node, opts: list[Options]) -> None:
        self.node = node
        self.opts = opts
        total = 0
        for r in range(self.R):
            self.base[r] = total
            total += opts[r].n
        self.out = []

    def done(self) -> None:
        """Its node's columns handed over: what it held of them let go (the node stays
        until the next one)."""
        self.opts = []
        self.out = []
        self.fits.clear()
        self.filled = 0

    def reserve(self, n: int) -> int:
        """Room for a mask of ``n`` options, cleared: where it starts in ``masks``."""
        at = self.filled
        if at + n > self.size:
            size = 2 * self.size + n
            made = _flags(size)
            masks = made
            for k in range(at):
                masks[k] = self.masks[k]
            self.masks = masks
            self.size = size
        else:
            for k in range(at, at + n):
                self.masks[k] = 0
        self.filled = at + n
        return at


# -- the sizing's elimination (sizing._parametrized) ------------------------------------
def eliminate(
    rows: Sequence[tuple[Mapping[int, float], float]], n: int, zero: float, tolerance: float
) -> tuple[list[float], list[int], list[tuple[int, int, float]]] | None:
    """Every solution of the sparse equalities ``rows`` ((coefficients by variable, rhs)
    pairs) over ``n`` variables, as (constants, free variables, (variable, free index,
    coefficient) triples); None when they contradict each other.

    Gaussian elimination, a row at a time, shortest rows first: the row is written over
    the variables still free, and one of them (the largest coefficient; the latest
    variable on a tie) becomes its expression in the others, which replaces it in every
    expression that named it (``users`` says which, maybe no more)."""
    m = len(rows)
    for i in range(m):
        if not isinstance(rows[i][0], dict):
            raise TypeError("a row's coefficients must be a dict")
    order = [i for _, i in sorted([(len(rows[i][0]), i) for i in range(m)])]
    names: list[list[int]] = [[] for _ in range(n)]  # per solved variable: its expression
    values: list[list[float]] = [[] for _ in range(n)]
    users: list[list[int]] = [[] for _ in range(n)]
    konst = _doubles(n + 1)
    solved = _flags(n + 1)
    acc = _doubles(n + 1)
    at = _ints(n + 1)
    touched = _ints(n + 1)
    for v in range(n):
        at[v] = -1
    for i in range(m):
        coefficients, rhs = rows[order[i]]
        left = float(rhs)
        count = 0
        for key, value in coefficients.items():
            v = key
            c = float(value)
            if v < 0 or v >= n:
                raise IndexError("a row names a variable out of range")
            if solved[v]:
                left -= c * konst[v]
                ev = names[v]
                ec = values[v]
                for j in range(len(ev)):
                    u = ev[j]
                    if at[u] < 0:
                        at[u] = count
                        touched[count] = u
                        count += 1
                        acc[u] = 0.0
                    acc[u] += c * ec[j]
            else:
                if at[v] < 0:
                    at[v] = count
                    touched[count] = v
                    count += 1
                    acc[v] = 0.0
                acc[v] += c
        pivot = -1
        terms = 0
        best = 0.0
        for j in range(count):
            u = touched[j]
            at[u] = -1
            if fabs(acc[u]) <= zero:
                continue
            touched[terms] = u
            terms += 1
            size = fabs(acc[u])
            if pivot < 0 or size > best or (size == best and u > pivot):
                pivot = u
                best = size
        if pivot < 0:
            if fabs(left) > tolerance:
                return None  # the equalities contradict each other
            continue
        a = acc[pivot]
        xv = names[pivot]
        xc = values[pivot]
        for j in range(terms):
            u = touched[j]
            if u != pivot:
                xv.append(u)
                xc.append(-acc[u] / a)
        konst[pivot] = left / a
        for v in users[pivot]:
            _substitute(names, values, users, konst, at, v, pivot, zero)
        users[pivot] = []
        solved[pivot] = 1
        for u in xv:
            users[u].append(pivot)
    constants: list[float] = []
    free: list[int] = []
    columns = 0
    for v in range(n):
        if solved[v]:
            at[v] = -1
            constants.append(konst[v])
        else:
            at[v] = columns
            columns += 1
            constants.append(0.0)
            free.append(v)
    entries: list[tuple[int, int, float]] = []
    for v in range(n):
        if solved[v]:
            ev = names[v]
            ec = values[v]
            for j in range(len(ev)):
                entries.append((v, at[ev[j]], ec[j]))
    return constants, free, entries


def _substitute(
    names: list[list[int]],
    values: list[list[float]],
    users: list[list[int]],
    konst: array[float],
    at: array[int],
    v: int,
    p: int,
    zero: float,
) -> None:
    """Substitute pivot ``p`` (its expression and constant) into the expression of solved
    variable ``v``, if it still names it."""
    ev = names[v]
    ec = values[v]
    xv = names[p]
    xc = values[p]
    k = -1
    for i in range(len(ev)):
        if ev[i] == p:
            k = i
            break
    if k < 0:
        return  # named it once, not any more
    c = ec[k]
    last = len(ev) - 1  # p out, the last in its place
    ev[k] = ev[last]
    ec[k] = ec[last]
    ev.pop()
    ec.pop()
    for i in range(len(ev)):
        at[ev[i]] = i
    for i in range(len(xv)):
        u = xv[i]
        value = c * xc[i]
        j = at[u]
        if j >= 0:
            value += ec[j]
            ec[j] = value
        else:
            ev.append(u)
            ec.append(value)
            at[u] = len(ev) - 1
            users[u].append(v)
    kept = 0  # drop what cancelled
    for i in range(len(ev)):
        at[ev[i]] = -1
        if fabs(ec[i]) > zero:
            ev[kept] = ev[i]
            ec[kept] = ec[i]
            kept += 1
    del ev[kept:]
    del ec[kept:]
    konst[v] += c * konst[p]
