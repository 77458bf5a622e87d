"""Primal constructions and the relaxation bound of one candidate (DESIGN.md: primal first).

Before any search, a candidate's words are laid out at given lengths, every row from 0 on,
and cut where all rows agree: a column boundary wherever every row has a letter boundary
or is inside a transparent letter (which may be split, SPEC 2.4). The rules of SPEC 2.4
are then checked column by column, and the sizing QP gives the layout its objective. Laid
at preferred sizes (placeholders sized by the rows' lengths), a façade whose layout keeps
every symbol at its preferred size is found this way with no search; laid again at the
sizes the QP solved, a construction often improves (the paper's cutting of aligned rows).

The *relaxation* of a candidate is the QP over its symbols' sizes alone: a row that no
layer in front may make room in fills the canvas, any other row fits in it. Every layout
of the candidate meets these constraints (its rows are laid out on the canvas, gaps only
under opaque letters in front), so the relaxation's objective is a lower bound on the
candidate's, and its sizes are the first lengths a construction lays the rows at.
"""

from __future__ import annotations

import bisect
import itertools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from facadecli.solver import columns, sizing
from facadecli.solver.alignment import Alignment, Move, _Row, prepared_row
from facadecli.solver.budgets import (
    FAINT,
    FITTING_WORK,
    NEAR,
    ROUNDS,
    SNAP,
)
from facadecli.solver.rows import Row
from facadecli.spec.model import Spec


@dataclass(frozen=True)
class Relaxation:
    """A candidate's relaxation: its objective (a lower bound) and its sizes."""

    bound: float
    lengths: Mapping[str, float]  # symbol -> length (placeholders included)


# whether a row (among its group's rows) may make room for a layer in front
GivesWay = Callable[[Row, Sequence[Row]], bool]


def _covered(row: Row, rows: Sequence[Row]) -> bool:
    return any(other.covers(row) for other in rows)


def relax(
    spec: Spec,
    groups: Mapping[str, Sequence[Row]],
    canvas: float,
    gives_way: GivesWay = _covered,
) -> Relaxation | None:
    """The relaxation of a candidate's rows; None when even it has no solution (then the
    candidate has no layout: its rows cannot all fit the canvas). ``gives_way``: whether a
    row may leave room (then it fits in the canvas rather than fills it); by default, when
    a row of its group covers it."""
    names: list[str] = []
    index: dict[str, int] = {}
    for rows in groups.values():
        for row in rows:
            for letter in row.word:
                if letter.symbol not in index:
                    index[letter.symbol] = len(names)
                    names.append(letter.symbol)
    equalities: list[tuple[dict[int, float], float]] = []
    seen: set[tuple[tuple[int, float], ...]] = set()
    slacks = 0
    for rows in groups.values():
        for row in rows:
            counts: dict[int, float] = {}
            for letter in row.word:
                j = index[letter.symbol]
                counts[j] = counts.get(j, 0.0) + 1.0
            may_give_way = gives_way(row, rows)
            key = (*sorted(counts.items()), (-1, 1.0 if may_give_way else 0.0))
            if key in seen:
                continue
            seen.add(key)
            if may_give_way:  # it fits: its letters and a slack (its gaps) fill the canvas
                counts[len(names) + slacks] = 1.0
                slacks += 1
            equalities.append((counts, canvas))
    n = len(names) + slacks
    target = np.zeros(n)
    weight = np.full(n, FAINT)
    lower = np.zeros(n)
    upper = np.full(n, np.inf)
    sized: list[int] = []
    for name, j in index.items():
        symbol = spec.symbols.get(name)
        if symbol is None or symbol.size is None:
            continue
        target[j], weight[j] = symbol.size, 1.0
        lower[j] = max(sizing.MIN_SIZE, symbol.min or 0.0)
        upper[j] = np.inf if symbol.max is None else symbol.max
        sized.append(j)
    program = sizing.Program(
        names=[*names, *(f"gap {i}" for i in range(slacks))],
        target=target,
        weight=weight,
        lower=lower,
        upper=upper,
        rhs=np.array([rhs for _, rhs in equalities]),
        rows=equalities,
        symbols={name: j for name, j in index.items()},
        columns={},
        pieces={},
        sized=sized,
    )
    solved = sizing.search_solve(program)
    if solved is None:
        return None
    lengths = {name: solved.of(j) for name, j in index.items()}
    for name in index:  # the placeholders' tiny weight moves sizes by noise: drop it
        size = spec.size(name)
        if size is not None and abs(lengths[name] - size) <= NEAR * max(1.0, canvas):
            lengths[name] = size
    return Relaxation(solved.objective, lengths)


def cut(
    rows: Sequence[Row],
    lengths: Mapping[str, float],
    canvas: float,
    prepared: dict[Row, _Row],
    snap: float = 0.0,
) -> Alignment | None:
    """The rows of one group laid at ``lengths`` and cut where they all agree (within
    ``snap`` metres), as an alignment; None when a row does not fill the canvas or the
    cuts break a rule of SPEC 2.4."""
    near = max(NEAR * max(1.0, canvas), snap)
    laid: list[list[float]] = []
    for row in rows:
        x = boundaries(row, lengths)
        if abs(x[-1] - canvas) > near:
            return None  # a row with gaps: not constructed here
        x[-1] = canvas
        laid.append(x)
    points = sorted({p for x in laid for p in x[1:-1]})
    cuts = [0.0]
    for p in points:
        if p - cuts[-1] <= near or canvas - p <= near:
            continue
        if all(_position(x, row, p, near) is not None for x, row in zip(laid, rows, strict=True)):
            cuts.append(p)
    cuts.append(canvas)
    prepared_rows = [prepared_row(row, prepared) for row in rows]
    entries: list[tuple[Move | None, ...]] = []
    for a, b in itertools.pairwise(cuts):
        column: list[Move | None] = []
        for x, row, ready in zip(laid, rows, prepared_rows, strict=True):
            start, end = _position(x, row, a, near), _position(x, row, b, near)
            assert start is not None and end is not None
            if b == canvas:  # the row's last letters, those of no length too
                end = 2 * len(row.word)
            move = ready.spanning(start, end)
            if move is None:
                return None  # e.g. transparent and visible letters in one entry
            column.append(move)
        if not _valid(rows, column):
            return None
        entries.append(tuple(column))
    return Alignment(
        tuple(rows),
        tuple(entries),
        0.0,
        tuple(b - a for a, b in itertools.pairwise(cuts)),
        tuple(False for _ in entries),
    )


def _position(x: Sequence[float], row: Row, p: float, near: float) -> int | None:
    """Where coordinate ``p`` falls in a laid row, in half-steps: ``2k`` at the boundary
    before letter k, ``2k + 1`` inside transparent letter k; None inside a visible one."""
    k = bisect.bisect_left(x, p - near)
    if k < len(x) and abs(x[k] - p) <= near:
        return 2 * k
    inside = k - 1
    if 0 <= inside < len(row.word) and row.traits[inside].transparent:
        return 2 * inside + 1
    return None


def _valid(rows: Sequence[Row], column: Sequence[Move | None]) -> bool:
    """SPEC 2.4 on a column without gaps: an opaque entry, and nothing visible in front
    of an unoccludable letter."""
    if not any(move is not None and move.opaque for move in column):
        return False
    for r, move in enumerate(column):
        if move is None or not move.unoccludable:
            continue
        for a, other in enumerate(column):
            if other is not None and not other.transparent and rows[a].is_above(rows[r]):
                return False
    return True


Span = tuple[float, float]


@dataclass(frozen=True)
class Laid:
    """What the rows laid in a group ask of a row fitted among them (:func:`laid_for`)."""

    interiors: list[Span] = field(default_factory=list)  # of their visible letters: no cut
    ends: list[float] = field(default_factory=list)  # where they turn transparent: cuts
    guarded: list[Span] = field(default_factory=list)  # their unoccludable letters below it
    covering: list[Span] = field(default_factory=list)  # their visible letters above it


NOTHING_LAID = Laid()


def laid_for(row: Row, laid: Sequence[tuple[Row, Mapping[str, float]]]) -> Laid:
    """What laid rows ask of the column boundaries of ``row``: the interiors of their
    visible letters (open spans, overlapping ones merged), where none may fall, and
    where they turn between transparent and visible (:func:`_changes`), where one must;
    and SPEC 2.4's unoccludable letters: those of rows below ``row``, which no visible
    letter of it may overlap, and the visible letters of rows above it, which none of its
    unoccludable letters may."""
    spans, guarded, covering = [], [], []
    changes: set[float] = set()
    for other, lengths in laid:
        x = boundaries(other, lengths)
        for k, traits in enumerate(other.traits):
            if traits.transparent or x[k + 1] <= x[k]:
                continue
            spans.append((x[k], x[k + 1]))
            if traits.unoccludable and row.is_above(other):
                guarded.append((x[k], x[k + 1]))
            if other.is_above(row):
                covering.append((x[k], x[k + 1]))
        changes.update(x[k] for k in range(1, len(other.word)) if _changes(other, k))
    return Laid(_merged(spans), sorted(changes), _merged(guarded), _merged(covering))


def _merged(spans: list[Span]) -> list[Span]:
    """Open spans, those that overlap joined; spans that only touch (within rounding: a
    letter's end summed along one row and the next one's start along another) stay apart,
    so that the boundary between them stays free."""
    merged: list[Span] = []
    for a, b in sorted(spans):
        if merged and a < merged[-1][1] - NEAR * max(1.0, abs(merged[-1][1])):
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    return merged


def _overlaps(
    spans: Sequence[Span], starts: Sequence[float], a: float, b: float, near: float
) -> bool:
    """Whether ``(a, b)`` overlaps one of the merged ``spans`` by more than ``near``."""
    at = bisect.bisect_right(starts, b - near) - 1
    return at >= 0 and spans[at][1] > a + near


def shortest_letter(groups: Mapping[str, Sequence[Row]], lengths: Mapping[str, float]) -> float:
    return min(
        (lengths[letter.symbol] for rows in groups.values() for row in rows for letter in row.word),
        default=0.0,
    )


def placeholders_laid(
    groups: Mapping[str, Sequence[Row]], relaxed: Relaxation, canvas: float
) -> dict[str, float] | None:
    """The relaxation's sizes with the placeholders sized so that the rows agree: a
    placeholder that is the only one a row leaves open takes what the row leaves of the
    canvas; where a row leaves several open, they are sized (:func:`fit`) so that the
    row's boundaries fall on those of the rows already laid in its group. None when a row
    cannot be laid so (then the relaxation's own placeholder sizes are all there is)."""
    lengths = {name: size for name, size in relaxed.lengths.items()}
    open_ = {
        letter.symbol
        for rows in groups.values()
        for row in rows
        for letter, traits in zip(row.word, row.traits, strict=True)
        if traits.size is None
    }
    for name in open_:
        del lengths[name]
    # every row laid without gaps (those are all that :func:`cut` makes)
    rows_of = [(name, row) for name, rows in sorted(groups.items()) for row in rows]
    while True:
        progress = False
        for _, row in rows_of:
            missing = {letter.symbol for letter in row.word if letter.symbol not in lengths}
            if len(missing) == 1:
                name = missing.pop()
                count = sum(letter.symbol == name for letter in row.word)
                rest = sum(lengths[letter.symbol] for letter in row.word if letter.symbol != name)
                lengths[name] = max(0.0, (canvas - rest) / count)
                progress = True
        if progress:
            continue
        waiting = [
            (group, row)
            for group, row in rows_of
            if any(letter.symbol not in lengths for letter in row.word)
        ]
        if not waiting:
            return {**relaxed.lengths, **lengths}
        group, row = waiting[0]
        laid = [
            other
            for other in groups[group]
            if all(letter.symbol in lengths for letter in other.word)
        ]
        points = sorted({p for other in laid for p in boundaries(other, lengths)})
        fitted = fit(row, lengths, points, canvas, laid_for(row, [(o, lengths) for o in laid]))
        if fitted is None:  # the rows laid may be the ones in the way: theirs alone
            fitted = fit(row, lengths, points, canvas)
        if fitted is None:
            return None
        lengths.update(fitted)


def coverage(
    row: Row, sizes: Mapping[str, float], points: Sequence[float], canvas: float
) -> float | None:
    """How much the row's placeholders cover (the length of all their letters) when it
    fits ``points`` (:func:`fit`); None when it does not fit."""
    found = fit(row, sizes, points, canvas)
    if found is None:
        return None
    return sum(found.get(letter.symbol, 0.0) for letter in row.word)


def boundaries(row: Row, lengths: Mapping[str, float]) -> list[float]:
    """Where a row laid from 0 at ``lengths`` has its letters' boundaries."""
    return list(itertools.accumulate((lengths[letter.symbol] for letter in row.word), initial=0.0))


def _changes(row: Row, k: int) -> bool:
    """Whether the row turns between transparent and visible before letter k: a column
    boundary, as no entry holds both."""
    return row.traits[k - 1].transparent != row.traits[k].transparent


def fit(
    row: Row,
    lengths: Mapping[str, float],
    points: Sequence[float],
    canvas: float,
    laid: Laid = NOTHING_LAID,
) -> dict[str, float] | None:
    """Sizes of a row's open placeholders that end each of them on one of ``points`` and
    the row on the canvas' end, with no boundary the row needs inside a visible letter
    of the rows ``laid`` (:func:`laid_for`), nor one they need inside a visible letter
    of the row, and no visible letter over an unoccludable one (SPEC 2.4): the first
    found, depth first, nearest first, within FITTING_WORK; None when none is found."""
    fitting = _Fitting(row, lengths, sorted(points), canvas, laid)
    fitting.lay(0, 0.0, {})
    return fitting.best


class _Fitting:
    """The depth-first search of :func:`fit`: placeholders sized in the order the row
    meets them, each to end on one of the points, nearest first."""

    def __init__(
        self,
        row: Row,
        lengths: Mapping[str, float],
        points: Sequence[float],
        canvas: float,
        laid: Laid,
    ) -> None:
        self.row, self.lengths, self.points, self.canvas, self.laid = (
            row,
            lengths,
            points,
            canvas,
            laid,
        )
        self.near = NEAR * max(1.0, canvas)
        self.word = [letter.symbol for letter in row.word]
        n = len(self.word)
        self.starts = [a for a, _ in laid.interiors]
        self.guarded_starts = [a for a, _ in laid.guarded]
        self.covering_starts = [a for a, _ in laid.covering]
        # boundaries before letter k that a visible letter starts or ends at: they are
        # cuts, so they must fall on the laid rows' boundaries
        traits = row.traits
        self.edge = [
            k == 0 or k == n or not traits[k - 1].transparent or not traits[k].transparent
            for k in range(n + 1)
        ]
        self.turns = [0 < k < n and _changes(row, k) for k in range(n + 1)]
        self.open = [s for s in dict.fromkeys(self.word) if s not in lengths]
        # per letter k: the sized letters' length from k on, and each open one's count
        self.known_after = [0.0] * (n + 1)
        self.open_after = {s: [0] * (n + 1) for s in self.open}
        for k in range(n - 1, -1, -1):
            symbol = self.word[k]
            self.known_after[k] = self.known_after[k + 1] + lengths.get(symbol, 0.0)
            for s, after in self.open_after.items():
                after[k] = after[k + 1] + (s == symbol)
        self.work = 0
        self.best: dict[str, float] | None = None

    def _on_point(self, x: float) -> bool:
        at = bisect.bisect_left(self.points, x - self.near)
        return at < len(self.points) and self.points[at] <= x + self.near

    def _inside(self, x: float) -> bool:
        """``x`` strictly inside a visible letter laid."""
        interiors = self.laid.interiors
        at = bisect.bisect_right(self.starts, x - self.near) - 1
        return at >= 0 and interiors[at][1] > x + self.near

    def _across(self, a: float, b: float) -> bool:
        """A boundary the laid rows need strictly between ``a`` and ``b``."""
        ends = self.laid.ends
        at = bisect.bisect_right(ends, a + self.near)
        return at < len(ends) and ends[at] < b - self.near

    def _hides(self, k: int, a: float, b: float) -> bool:
        """Letter k, laid over ``(a, b)``, and an unoccludable letter meet, one over the
        other."""
        laid, near = self.laid, self.near
        if self.row.traits[k].unoccludable and _overlaps(
            laid.covering, self.covering_starts, a, b, near
        ):
            return True
        return _overlaps(laid.guarded, self.guarded_starts, a, b, near)

    def _advance(self, k: int, x: float, sizes: Mapping[str, float]) -> tuple[int, float] | None:
        """The row laid from letter k at ``x`` up to its next letter of unknown size (or
        its end): where that is, or None when a rule is broken on the way."""
        word, lengths, traits = self.word, self.lengths, self.row.traits
        while k < len(word):
            self.work += 1
            if self.work > FITTING_WORK or x > self.canvas + self.near:
                return None
            if self.edge[k] and not self._on_point(x):
                return None
            if self.turns[k] and self._inside(x):
                return None
            symbol = word[k]
            size = lengths.get(symbol, sizes.get(symbol))
            if size is None:
                return k, x
            if not traits[k].transparent and (
                self._across(x, x + size) or self._hides(k, x, x + size)
            ):
                return None
            x += size
            k += 1
        return k, x

    def lay(self, k: int, x: float, sizes: dict[str, float]) -> bool:
        """Lay the row from letter k at ``x`` with the placeholders sized so far; keep the
        first fit found (every fit of a row covers as much: what its sized letters leave
        of the canvas)."""
        reached = self._advance(k, x, sizes)
        if reached is None:
            return False
        k, x = reached
        word = self.word
        if k == len(word):
            if abs(x - self.canvas) > self.near:
                return False
            self.best = sizes
            return True
        symbol = word[k]
        still = [s for s in self.open if s not in sizes and self.open_after[s][k]]
        # what the rest of the row takes besides this placeholder
        rest = self.known_after[k] + sum(size * self.open_after[s][k] for s, size in sizes.items())
        ahead = self.open_after[symbol][k]
        if len(still) == 1:  # the last open one takes what the row leaves
            size = (self.canvas - x - rest) / ahead
            return size > self.near and self.lay(k, x, {**sizes, symbol: size})
        # its ends the rest of the row leaves room for (it comes ``ahead`` times more),
        # nearest first
        points = self.points
        first = bisect.bisect_right(points, x + self.near)
        last = bisect.bisect_right(points, x + (self.canvas - x - rest) / ahead + self.near)
        for end in points[first:last]:
            if self.work > FITTING_WORK:
                return False
            if self.lay(k, x, {**sizes, symbol: end - x}):
                return True
        return False


@dataclass(frozen=True)
class Constructed:
    """A candidate's layout by construction: its alignments, sizing program and sizes."""

    groups: dict[str, Alignment]
    program: sizing.Program
    sizing: sizing.Sizing


def construct(
    spec: Spec,
    groups: Mapping[str, Sequence[Row]],
    canvas: float,
    prepared: dict[Row, _Row],
    relaxed: Relaxation,
    same: float,
    fitted: Mapping[str, float] | None = None,
    known: sizing.Sized | None = None,
) -> Constructed | None:
    """The best layout the constructions find for a candidate's rows: laid at the
    relaxation's sizes (cut where the rows agree exactly, then within growing shares of
    the shortest letter), then again at each layout's solved sizes while that improves;
    it stops as soon as a layout reaches the relaxation's bound (``same``: objectives this
    close are equal). ``fitted``: sizes found to lay the rows (every letter's; see
    ``axis._fitted_to_backs``), tried first; ``known``: alignments sized before
    (:func:`sizing.sized_alignments`). None when no construction gives a valid layout."""
    best: Constructed | None = None
    shortest = shortest_letter(groups, relaxed.lengths)
    laid = placeholders_laid(groups, relaxed, canvas)
    # at shares of 0: the sizes fitted, the placeholders laid to fit, then the
    # relaxation's own sizes; then snapped within growing shares of the shortest letter
    exact = [relaxed.lengths] if laid is None else [laid, relaxed.lengths]
    names = {letter.symbol for rows in groups.values() for row in rows for letter in row.word}
    if fitted is not None and names <= fitted.keys():
        exact.insert(0, fitted)
    tries = [(0.0, lengths) for lengths in exact]
    tries += [(share, laid or relaxed.lengths) for share in SNAP[1:]]
    for share, start in tries:
        lengths = start
        snap = share * shortest
        for _ in range(1 + ROUNDS):
            aligned = {}
            for name, rows in sorted(groups.items()):
                alignment = cut(rows, lengths, canvas, prepared, snap)
                if alignment is None:
                    break
                aligned[name] = alignment
            else:
                program, solved = sizing.sized_alignments(spec, aligned, canvas, known)
                if solved is None:
                    break
                finer, program, solved = columns.finest(
                    spec, canvas, aligned, program, solved, known
                )
                if best is not None and solved.objective >= best.sizing.objective - same:
                    break
                best = Constructed(finer, program, solved)
                if solved.objective <= relaxed.bound + same:
                    return best
                lengths = {name: solved.of(j) for name, j in program.symbols.items()}
                snap = 0.0
                continue
            break
    return best
