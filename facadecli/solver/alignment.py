"""The alignment of one group of one axis (Ilčík et al. 2015, section 5.2; SPEC 2.4).

Rows are words; an alignment cuts every row into the same number of entries (possibly
empty) so that the entries of a column can be given one width. It is a path through the
*alignment decision network*: a state is each row's position, a column is a move.

Positions are *half-steps*: ``2k`` is the boundary before letter k, ``2k + 1`` is inside
letter k, which only a transparent letter allows (a transparent split, SPEC 2.4). While a
row is inside a sized letter, the state also holds the length the letter has left, so
its pieces add up to its size.

The search is a depth-first, iterative-deepening search over the total cost (the paper's
choice), with a transposition table of states known to fail within a budget. The cost of
a column is its error (Eq. 9: the spread of the entries' preferred lengths; an entry with
an elastic letter is an interval), plus whatever it adds to the *span* beyond the canvas:
a lower layer that makes room for an opaque letter must get shorter elsewhere. Columns
out of a state are generated around *target widths*: each row takes the entry nearest
the target, or an empty one. They are tried by (cost, letters consumed), so among equal
costs more columns win (the paper's tie-break).
"""

from __future__ import annotations

import bisect
import math
import time
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from facadecli.solver.rows import Row

INF = math.inf
EPS = 1e-9
TARGETS_PER_STATE = 24  # target widths tried from one state, smallest first

# what a row's previous entry means for the attached rule (SPEC 2.4)
FREE, AFTER_EMPTY, AFTER_ATTACHED = 0, 1, 2


class SearchTimeout(Exception):
    """The time limit ran out during an alignment search."""


@dataclass(frozen=True)
class Move:
    """One row's non-empty entry in a column, from position ``start`` to ``end``."""

    start: int
    end: int
    whole_low: float  # preferred length of the letters it holds whole (unsized count 0)
    whole_high: float  # INF when one of them is unsized
    letters: int  # letters and pieces of letters
    lead: bool  # it finishes the split letter it starts inside
    tail: float | None  # size of the letter whose first piece ends it (INF if unsized)
    opaque: bool  # holds only whole opaque letters
    transparent: bool
    unoccludable: bool
    first_attached: bool  # starts, at a letter boundary, with an attached letter
    last_attached: bool  # ends, at a letter boundary, with an attached letter

    @property
    def middle(self) -> bool:
        """Only a middle piece of a split letter: the row stays inside it."""
        return self.start == self.end

    def interval(self, remaining: float) -> tuple[float, float]:
        """Least and greatest preferred length, given what the split letter has left."""
        if self.middle:
            return 0.0, remaining
        low, high = self.whole_low, self.whole_high
        if self.lead:
            if remaining == INF:
                high = INF
            else:
                low += remaining
                high += remaining
        if self.tail is not None:
            high += self.tail
        return low, high


@dataclass(frozen=True)
class Alignment:
    """Columns of one group: ``entries[j][r]`` is row r's entry in column j (None if empty)."""

    rows: tuple[Row, ...]
    entries: tuple[tuple[Move | None, ...], ...]
    error: float

    @property
    def columns(self) -> int:
        return len(self.entries)


class _Row:
    """A row prepared for the search: its moves out of each position, cached."""

    def __init__(self, row: Row):
        self.row = row
        self.n = len(row.word)
        self.cache: dict[int, tuple[list[Move], list[float]]] = {}
        self.has_attached = any(t.attached for t in row.traits)

    def moves(self, position: int) -> tuple[list[Move], list[float]]:
        """Entries out of ``position`` sorted by their least whole length, and those lengths."""
        cached = self.cache.get(position)
        if cached is None:
            moves = sorted(self._moves(position), key=lambda m: (m.whole_low, m.letters, m.end))
            cached = self.cache[position] = (moves, [m.whole_low for m in moves])
        return cached

    def size(self, k: int) -> float:
        size = self.row.traits[k].size
        return INF if size is None else size

    def _moves(self, position: int) -> Iterator[Move]:
        k, inside = divmod(position, 2)
        if k >= self.n:
            return
        if inside:  # within transparent letter k: a middle piece, or finish it and go on
            yield self._move(position, position, [], lead=False)
            yield from self._extend(position, k + 1, True, lead=True)
            return
        transparent = self.row.traits[k].transparent
        if transparent:
            yield self._move(position, position + 1, [], lead=False, tail=self.size(k))
        yield from self._extend(position, k, transparent, lead=False)

    def _extend(self, start: int, k: int, transparent: bool, lead: bool) -> Iterator[Move]:
        """Entries from ``start`` holding letters k, k+1, ... whole (of one transparency)."""
        traits = self.row.traits
        if lead:
            yield self._move(start, 2 * k, [], lead=True)
        whole: list[int] = []
        for index in range(k, self.n):
            if traits[index].transparent != transparent:
                return
            whole.append(index)
            yield self._move(start, 2 * (index + 1), whole, lead=lead)
            following = index + 1
            if transparent and following < self.n and traits[following].transparent:
                yield self._move(
                    start, 2 * following + 1, whole, lead=lead, tail=self.size(following)
                )

    def _move(
        self, start: int, end: int, whole: list[int], lead: bool, tail: float | None = None
    ) -> Move:
        traits = [self.row.traits[i] for i in whole]
        sizes = [t.size for t in traits]
        low = sum(s for s in sizes if s is not None)
        pieces = (1 if lead or start == end else 0) + (1 if tail is not None else 0)
        return Move(
            start=start,
            end=end,
            whole_low=low,
            whole_high=INF if None in sizes else low,
            letters=len(whole) + pieces,
            lead=lead,
            tail=tail,
            opaque=bool(traits) and not pieces and all(t.opaque for t in traits),
            transparent=all(t.transparent for t in traits) if traits else True,
            unoccludable=any(t.unoccludable for t in traits),
            first_attached=not lead and bool(traits) and traits[0].attached,
            last_attached=tail is None and bool(traits) and traits[-1].attached,
        )


@dataclass(frozen=True)
class _Column:
    cost: float  # error plus growth of the span beyond the canvas
    error: float
    width: float
    letters: int
    entries: tuple[Move | None, ...]


State = tuple[tuple[int, ...], tuple[int, ...], tuple[float, ...]]  # positions, memory, left


class _Search:
    def __init__(self, rows: Sequence[Row], canvas: float, mu: float, deadline: float):
        self.rows = [_Row(row) for row in rows]
        self.above = [[j for j, other in enumerate(rows) if other.is_above(row)] for row in rows]
        self.canvas = canvas
        self.limit = canvas + mu  # the span may not exceed this without cost
        self.floor = canvas - mu  # nor fall short of this, unless a column can stretch
        self.mu = mu
        self.deadline = deadline
        self.ends = tuple(2 * r.n for r in self.rows)
        self.failed: dict[tuple[State, bool], float] = {}
        self.nodes = 0
        self.overflow = INF  # least cost beyond the budget seen: the next budget
        self.rejections: Counter[str] = Counter()

    # -- columns out of a state ---------------------------------------------------------
    def columns(self, state: State, span: float) -> list[_Column]:
        """Valid columns out of ``state``, best first."""
        positions = state[0]
        targets: set[float] = set()
        for r, row in enumerate(self.rows):
            if positions[r] < self.ends[r]:
                moves, _ = row.moves(positions[r])
                left = state[2][r]
                for move in moves[:TARGETS_PER_STATE]:
                    low, high = move.interval(left)
                    targets.add(round(low, 9))
                    if high != INF:
                        targets.add(round(high, 9))
        found: dict[tuple[int, ...], _Column] = {}
        for target in sorted(targets)[:TARGETS_PER_STATE]:
            nearest = [self.nearest(r, state, target) for r in range(len(self.rows))]
            for variant in self.variants(nearest, state, target):
                ends = tuple(m.end if m else positions[r] for r, m in enumerate(variant))
                if ends in found and not any(m is not None and m.middle for m in variant):
                    continue
                column = self.score(variant, state, span)
                if column is not None and (ends not in found or column.cost < found[ends].cost):
                    found[ends] = column
        return sorted(found.values(), key=lambda c: (round(c.cost, 9), c.letters, c.width))

    def nearest(self, r: int, state: State, target: float) -> tuple[Move | None, Move | None]:
        """Row r's entries nearest ``target`` with the fewest letters: the best that ends at
        a letter boundary, and the best that ends inside a split letter when as near."""
        position, left = state[0][r], state[2][r]
        if position >= self.ends[r]:
            return None, None
        moves, lows = self.rows[r].moves(position)
        if position % 2 == 0:  # whole lengths are the lengths: look near the target only
            upto = bisect.bisect_right(lows, target + EPS)
            window = moves[max(0, upto - 3) : upto + 1]
            window += [m for m in moves[: max(0, upto - 3)] if m.whole_high == INF or m.tail]
        else:
            window = moves
        best: dict[bool, tuple[tuple[float, int], Move]] = {}
        for move in window:
            low, high = move.interval(left)
            key = (round(max(0.0, low - target, target - high), 9), move.letters)
            split = move.end % 2 == 1
            if split not in best or key < best[split][0]:
                best[split] = (key, move)
        whole, piece = best.get(False), best.get(True)
        if whole is None or (piece is not None and piece[0][0] < whole[0][0]):
            return (piece[1] if piece else None), None
        return whole[1], (piece[1] if piece and piece[0][0] == whole[0][0] else None)

    def variants(
        self, nearest: list[tuple[Move | None, Move | None]], state: State, target: float
    ) -> Iterator[list[Move | None]]:
        """Every row at its nearest entry; the same with split letters where as near; and
        rows that miss the target left empty (making room under opaque rows above)."""
        best = [pair[0] for pair in nearest]
        yield best
        if any(pair[1] is not None for pair in nearest):
            yield [pair[1] if pair[1] is not None else pair[0] for pair in nearest]
        emptied = list(best)
        for r, move in enumerate(best):
            if move is None or state[0][r] % 2 or state[1][r] == AFTER_ATTACHED:
                continue
            low, high = move.interval(state[2][r])
            if max(0.0, low - target, target - high) > EPS:
                emptied[r] = None
        if emptied != best:
            yield emptied

    def score(self, entries: list[Move | None], state: State, span: float) -> _Column | None:
        """The column, or None if it breaks a rule of SPEC 2.4."""
        positions, memory, left = state
        if not any(m is not None and (m.end > m.start) for m in entries):
            return None
        if not any(m is not None and m.opaque for m in entries):
            self.rejections["no opaque backing"] += 1
            return None
        lows: list[float] = []
        highs: list[float] = []
        for r, move in enumerate(entries):
            if move is None:
                if positions[r] % 2:
                    return None  # a split letter has no gaps
                if memory[r] == AFTER_ATTACHED:
                    self.rejections["attached letter separated"] += 1
                    return None
                if not any(entries[a] is not None and entries[a].opaque for a in self.above[r]):  # type: ignore[union-attr]
                    self.rejections["an empty entry with no opaque letter above it"] += 1
                    return None
                continue
            if move.first_attached and memory[r] == AFTER_EMPTY:
                self.rejections["attached letter separated"] += 1
                return None
            if move.unoccludable:
                for above in self.above[r]:
                    other = entries[above]
                    if other is not None and not other.transparent:
                        self.rejections["unoccludable letter covered"] += 1
                        return None
            low, high = move.interval(left[r])
            lows.append(low)
            highs.append(high)
        low, high = max(lows), min(highs)
        error = max(0.0, low - high)
        width = low if error == 0.0 else (low + high) / 2.0
        if width < EPS:
            return None
        for r, move in enumerate(entries):
            if move is None:
                continue
            if move.middle and width >= left[r] - EPS:
                return None  # the piece takes all the letter has left: finish it instead
            if move.tail is not None and width - move.interval(left[r])[0] >= move.tail - EPS:
                return None  # the first piece would be the whole letter: take it whole
        growth = max(0.0, span + width - self.limit) - max(0.0, span - self.limit)
        letters = sum(m.letters for m in entries if m is not None)
        return _Column(error + growth, error, width, letters, tuple(entries))

    # -- the search ---------------------------------------------------------------------
    def after(self, state: State, column: _Column) -> State:
        positions, memory, left = state
        new_positions, new_memory, new_left = [], [], []
        for r, move in enumerate(column.entries):
            if move is None:
                new_positions.append(positions[r])
                keep = memory[r] if memory[r] == AFTER_ATTACHED else AFTER_EMPTY
                new_memory.append(keep if self.rows[r].has_attached else FREE)
                new_left.append(left[r])
                continue
            new_positions.append(move.end)
            attached = self.rows[r].has_attached and move.last_attached
            new_memory.append(AFTER_ATTACHED if attached else FREE)
            if move.middle:
                new_left.append(left[r] if left[r] == INF else max(0.0, left[r] - column.width))
            elif move.tail is not None and move.tail != INF:
                low, _ = move.interval(left[r])
                used = max(0.0, column.width - low)
                new_left.append(round(max(0.0, move.tail - used), 6))
            else:
                new_left.append(INF)
        return tuple(new_positions), tuple(new_memory), tuple(new_left)

    def run(self) -> Alignment | None:
        count = len(self.rows)
        start: State = ((0,) * count, (FREE,) * count, (INF,) * count)
        budget = self.mu
        while True:
            self.overflow = INF
            path = self.dfs(start, 0.0, 0.0, False, budget)
            if path is not None:
                return Alignment(
                    tuple(r.row for r in self.rows),
                    tuple(c.entries for c in path),
                    sum(c.error for c in path),
                )
            if self.overflow == INF or self.overflow > self.canvas:
                return None
            budget = max(self.overflow, budget * 1.5 + EPS)

    def dfs(
        self, state: State, spent: float, span: float, stretchable: bool, budget: float
    ) -> list[_Column] | None:
        """Columns from ``state`` to the ends within ``budget``, best columns first.

        ``stretchable``: a column so far holds only elastic entries, so the span can grow.
        """
        self.nodes += 1
        if self.nodes % 128 == 0 and time.perf_counter() > self.deadline:
            raise SearchTimeout
        if state[0] == self.ends:
            shortfall = 0.0 if stretchable else max(0.0, self.floor - span)
            if spent + shortfall > budget + EPS:
                self.overflow = min(self.overflow, spent + shortfall)
                return None
            return []
        key = (state, stretchable)
        if self.failed.get(key, -1.0) >= budget - spent - EPS:
            return None
        for column in self.columns(state, span):
            cost = spent + column.cost
            if cost > budget + EPS:
                self.overflow = min(self.overflow, cost)
                continue
            elastic = stretchable or all(
                m is None or m.interval(state[2][r])[1] == INF for r, m in enumerate(column.entries)
            )
            rest = self.dfs(self.after(state, column), cost, span + column.width, elastic, budget)
            if rest is not None:
                return [column, *rest]
        self.failed[key] = max(self.failed.get(key, -1.0), budget - spent)
        return None


@dataclass(frozen=True)
class AlignmentResult:
    alignment: Alignment | None
    timed_out: bool
    nodes: int
    reason: str  # why there is none (the rule that rejected most columns)


def align(rows: Sequence[Row], canvas: float, mu: float, deadline: float) -> AlignmentResult:
    """The least-cost alignment of a group's rows, or why there is none."""
    search = _Search(rows, canvas, mu, deadline)
    try:
        found = search.run()
    except SearchTimeout:
        return AlignmentResult(None, True, search.nodes, "time limit reached")
    reason = ""
    if found is None:
        common = search.rejections.most_common(1)
        reason = common[0][0] if common else "the words cannot be cut into matching columns"
    return AlignmentResult(found, False, search.nodes, reason)
