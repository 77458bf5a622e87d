"""The alignment of one group of one axis (Ilčík et al. 2015, section 5.2; SPEC 2.4).

Rows are words; an alignment cuts every row into the same number of entries (possibly
empty) so that the entries of a column can be given one width. It is a path through the
*alignment decision network*: a state is each row's position, a column is a move.

Positions are *half-steps*: ``2k`` is the boundary before letter k, ``2k + 1`` is inside
letter k, which only a transparent letter allows (a transparent split, SPEC 2.4).

The search is a depth-first, iterative-deepening search over the total error (the
paper's choice), with a transposition table of states known to fail within a budget.
Columns out of a state are generated lazily around *target widths*: each row takes the
entry whose preferred length is nearest to the target, or an empty entry. Moves are tried
by (column error, letters consumed), so among equal errors more columns win.

Column error (Eq. 9) is the spread of the entries' preferred lengths; an entry with an
elastic letter (an unsized placeholder or a piece of a split letter) is an interval.
The *span* (the widths the columns need, summed) must stay within the canvas, give or take
the tolerance and the budget: a lower layer that makes room must get shorter elsewhere.
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


class SearchTimeout(Exception):
    """The time limit ran out during an alignment search."""


@dataclass(frozen=True)
class Move:
    """One row's entry in a column: from position ``start`` to ``end`` (half-steps)."""

    start: int
    end: int
    low: float  # least preferred length of the entry
    high: float  # greatest (INF when elastic)
    letters: int  # letters (and letter pieces) in the entry
    opaque: bool  # non-empty and made only of opaque letters
    transparent: bool
    unoccludable: bool  # holds a visible unoccludable letter
    first_attached: bool  # starts with an attached letter (at a letter boundary)
    last_attached: bool  # ends with an attached letter (at a letter boundary)

    @property
    def advances(self) -> bool:
        return self.end > self.start


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
    """A row prepared for the search: prefix sums and its moves out of each position."""

    def __init__(self, row: Row):
        self.row = row
        self.n = len(row.word)
        self.moves_cache: dict[int, list[Move]] = {}
        self.lows_cache: dict[int, list[float]] = {}
        self.has_attached = any(t.attached for t in row.traits)

    def moves(self, position: int) -> list[Move]:
        """Non-empty entries out of ``position``, sorted by their least length."""
        cached = self.moves_cache.get(position)
        if cached is None:
            cached = sorted(self._moves(position), key=lambda m: (m.low, m.letters, m.end))
            self.moves_cache[position] = cached
            self.lows_cache[position] = [m.low for m in cached]
        return cached

    def lows(self, position: int) -> list[float]:
        self.moves(position)
        return self.lows_cache[position]

    def _moves(self, position: int) -> Iterator[Move]:
        traits = self.row.traits
        k, inside = divmod(position, 2)
        if k >= self.n:
            return
        if inside:  # a piece of transparent letter k: more pieces, or finish it and go on
            size = traits[k].size
            piece_high = INF if size is None else size
            yield self._move(position, position, 0.0, piece_high, 1, True, ())
            yield from self._extend(position, k, 0.0, piece_high, 1, True, first=False)
            return
        transparent = traits[k].transparent
        if transparent:
            size = traits[k].size
            yield self._move(position, position + 1, 0.0, INF if size is None else size, 1, True, ())
        yield from self._extend(position, k, 0.0, 0.0, 0, transparent, first=True)

    def _extend(
        self, start: int, k: int, low: float, high: float, letters: int, transparent: bool,
        first: bool,
    ) -> Iterator[Move]:
        """Entries that consume letters k, k+1, ... (all of one transparency) from ``start``."""
        traits = self.row.traits
        consumed: list[int] = []
        for index in range(k, self.n):
            trait = traits[index]
            if trait.transparent != transparent:
                return
            size = trait.size
            low += size or 0.0
            high = INF if size is None or high == INF else high + size
            letters += 1
            consumed.append(index)
            yield self._move(start, 2 * (index + 1), low, high, letters, transparent, consumed, first)
            next_index = index + 1
            if transparent and next_index < self.n and traits[next_index].transparent:
                piece = traits[next_index].size
                yield self._move(
                    start, 2 * next_index + 1, low, INF if piece is None else high + piece,
                    letters + 1, True, consumed, first,
                )

    def _move(
        self, start: int, end: int, low: float, high: float, letters: int, transparent: bool,
        consumed: Sequence[int], first: bool = False,
    ) -> Move:
        traits = self.row.traits
        whole = [traits[i] for i in consumed]
        pieces = letters > len(whole)
        return Move(
            start=start,
            end=end,
            low=low,
            high=high,
            letters=letters,
            opaque=bool(whole) and not pieces and all(t.opaque for t in whole),
            transparent=transparent,
            unoccludable=any(t.unoccludable for t in whole),
            first_attached=first and bool(whole) and whole[0].attached,
            last_attached=end % 2 == 0 and bool(whole) and whole[-1].attached,
        )


# per-row memory of the previous column, for the attached rule
FREE, AFTER_EMPTY, AFTER_ATTACHED = 0, 1, 2


class _Search:
    def __init__(self, rows: Sequence[Row], canvas: float, mu: float, deadline: float):
        self.rows = [_Row(row) for row in rows]
        self.above = [
            [j for j, other in enumerate(rows) if other.is_above(row)] for row in rows
        ]
        self.canvas = canvas
        self.mu = mu
        self.deadline = deadline
        self.ends = tuple(2 * r.n for r in self.rows)
        self.failed: dict[tuple[tuple[int, ...], tuple[int, ...], bool], float] = {}
        self.nodes = 0
        self.overflow = INF  # least cost beyond the budget seen (the next budget)
        self.rejections: Counter[str] = Counter()

    # -- columns out of a state ---------------------------------------------------------
    def columns(
        self, state: tuple[int, ...], memory: tuple[int, ...]
    ) -> list[tuple[float, float, int, tuple[Move | None, ...]]]:
        """Valid columns out of ``state`` as (error, width, letters, entries), best first."""
        rows = self.rows
        targets: list[float] = []
        for r, row in enumerate(rows):
            if state[r] < self.ends[r]:
                targets.extend(self.distinct_lows(row.lows(state[r])))
        targets = sorted(set(round(t, 9) for t in targets))[:TARGETS_PER_STATE]
        if not targets:
            return []
        found: dict[tuple[int, ...], tuple[float, float, int, tuple[Move | None, ...]]] = {}
        for target in targets:
            nearest = [self.nearest(r, state[r], target) for r in range(len(rows))]
            for variant in self.variants(nearest, state, memory, target):
                ends = tuple(m.end if m else state[r] for r, m in enumerate(variant))
                if ends in found:
                    continue
                scored = self.score(variant, state, memory)
                if scored is not None:
                    found[ends] = scored
        return sorted(found.values(), key=lambda c: (round(c[0], 9), c[2], c[1]))

    @staticmethod
    def distinct_lows(lows: list[float]) -> list[float]:
        return lows[:TARGETS_PER_STATE]

    def nearest(self, r: int, position: int, target: float) -> tuple[Move | None, Move | None]:
        """Row r's entries nearest ``target``, fewest letters first: the one that ends at a
        letter boundary, and the one that ends inside a split letter (when as near)."""
        if position >= self.ends[r]:
            return None, None
        moves = self.rows[r].moves(position)
        lows = self.rows[r].lows(position)
        upto = bisect.bisect_right(lows, target + EPS)
        window = moves[max(0, upto - 3) : upto + 1]
        # an elastic entry with fewer letters may reach the target from below
        window += [m for m in moves[: max(0, upto - 3)] if m.high >= target - EPS]
        best: dict[bool, tuple[tuple[float, int], Move]] = {}
        for move in window:
            distance = max(0.0, move.low - target, target - move.high)
            key = (round(distance, 9), move.letters)
            split = move.end % 2 == 1
            if split not in best or key < best[split][0]:
                best[split] = (key, move)
        whole = best.get(False)
        piece = best.get(True)
        if whole is None or (piece is not None and piece[0][0] < whole[0][0]):
            return (piece[1] if piece else None), None
        return whole[1], (piece[1] if piece and piece[0][0] == whole[0][0] else None)

    def variants(
        self,
        nearest: list[tuple[Move | None, Move | None]],
        state: tuple[int, ...],
        memory: tuple[int, ...],
        target: float,
    ) -> Iterator[list[Move | None]]:
        """Every row at its nearest entry; the same with split letters where as near; and
        rows that miss the target left empty (making room under opaque rows above)."""
        best = [pair[0] for pair in nearest]
        yield best
        if any(pair[1] is not None for pair in nearest):
            yield [pair[1] if pair[1] is not None else pair[0] for pair in nearest]
        emptied = list(best)
        changed = False
        for r, move in enumerate(best):
            if move is None or state[r] % 2 or memory[r] == AFTER_ATTACHED:
                continue
            if max(0.0, move.low - target, target - move.high) > EPS:
                emptied[r] = None
                changed = True
        if changed:
            yield emptied

    def score(
        self, entries: list[Move | None], state: tuple[int, ...], memory: tuple[int, ...]
    ) -> tuple[float, float, int, tuple[Move | None, ...]] | None:
        """(error, width, letters, entries) of a column, or None if it breaks a rule."""
        if not any(m is not None and m.advances for m in entries):
            return None
        if not any(m is not None and m.opaque for m in entries):
            self.rejections["no opaque backing"] += 1
            return None
        for r, move in enumerate(entries):
            if move is None:
                if state[r] < self.ends[r] and state[r] % 2:
                    return None  # a split letter cannot have a gap
                if not any(
                    entries[above] is not None and entries[above].opaque  # type: ignore[union-attr]
                    for above in self.above[r]
                ):
                    self.rejections["an empty entry with no opaque letter above it"] += 1
                    return None
                if memory[r] == AFTER_ATTACHED:
                    self.rejections["attached letter separated"] += 1
                    return None
            elif move.first_attached and memory[r] == AFTER_EMPTY:
                self.rejections["attached letter separated"] += 1
                return None
            if move is not None and move.unoccludable:
                for above in self.above[r]:
                    other = entries[above]
                    if other is not None and not other.transparent:
                        self.rejections["unoccludable letter covered"] += 1
                        return None
        present = [m for m in entries if m is not None]
        low = max(m.low for m in present)
        high = min(m.high for m in present)
        error = max(0.0, low - high)
        width = low if error == 0.0 else (low + high) / 2.0
        letters = sum(m.letters for m in present)
        return error, width, letters, tuple(entries)

    # -- the search ---------------------------------------------------------------------
    def memory_after(self, entries: tuple[Move | None, ...], memory: tuple[int, ...]) -> tuple[int, ...]:
        updated = []
        for r, move in enumerate(entries):
            if not self.rows[r].has_attached:
                updated.append(FREE)
            elif move is None:
                updated.append(AFTER_EMPTY if memory[r] != AFTER_ATTACHED else AFTER_ATTACHED)
            else:
                updated.append(AFTER_ATTACHED if move.last_attached else FREE)
        return tuple(updated)

    def run(self) -> Alignment | None:
        start = tuple(0 for _ in self.rows)
        memory = tuple(FREE for _ in self.rows)
        budget = self.mu
        while True:
            self.overflow = INF
            path = self.dfs(start, memory, 0.0, 0.0, False, budget)
            if path is not None:
                error = sum(c[0] for c in path)
                return Alignment(
                    tuple(r.row for r in self.rows), tuple(c[3] for c in path), error
                )
            if self.overflow == INF or self.overflow > self.canvas + self.mu:
                return None
            budget = max(self.overflow, budget * 1.5 + EPS)

    def dfs(
        self,
        state: tuple[int, ...],
        memory: tuple[int, ...],
        spent: float,
        span: float,
        stretchable: bool,
        budget: float,
    ) -> list[tuple[float, float, int, tuple[Move | None, ...]]] | None:
        """A path from ``state`` to the ends within ``budget``, trying best columns first.

        ``stretchable``: some column so far has only elastic entries, so the span can grow.
        """
        self.nodes += 1
        if self.nodes % 256 == 0 and time.perf_counter() > self.deadline:
            raise SearchTimeout
        if state == self.ends:
            shortfall = 0.0 if stretchable else max(0.0, self.canvas - self.mu - span)
            if spent + shortfall > budget + EPS:
                self.overflow = min(self.overflow, spent + shortfall)
                return None
            return []
        key = (state, memory, stretchable)
        if self.failed.get(key, -1.0) >= budget - spent - EPS:
            return None
        for column in self.columns(state, memory):
            error, width, _, entries = column
            cost = spent + error + max(0.0, span + width - self.canvas - self.mu)
            cost -= max(0.0, span - self.canvas - self.mu)
            if cost > budget + EPS:
                self.overflow = min(self.overflow, cost)
                continue
            following = tuple(m.end if m else state[r] for r, m in enumerate(entries))
            elastic = stretchable or all(m is None or m.high == INF for m in entries)
            rest = self.dfs(
                following, self.memory_after(entries, memory), cost, span + width, elastic, budget
            )
            if rest is not None:
                return [column, *rest]
        self.failed[key] = max(self.failed.get(key, -1.0), budget - spent)
        return None


@dataclass(frozen=True)
class AlignmentResult:
    alignment: Alignment | None
    timed_out: bool
    nodes: int
    reason: str  # why there is none (the constraint that rejected most columns)


def align(rows: Sequence[Row], canvas: float, mu: float, deadline: float) -> AlignmentResult:
    """The best alignment of a group's rows found before ``deadline``, best effort."""
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
