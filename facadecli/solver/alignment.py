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
import functools
import math
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from facadecli.patterns import Letter
from facadecli.solver.budgets import (
    BUDGET_STEP,
    JOINT_ROWS,
    MAX_NODES,
    REFINE_NODES,
    TARGETS_PER_STATE,
    safety_clock,
)
from facadecli.solver.rows import LetterTraits, Row

INF = math.inf
EPS = 1e-9

# what a row's previous entry means for the attached rule (SPEC 2.4)
FREE, AFTER_EMPTY, AFTER_ATTACHED = 0, 1, 2


class SearchTimeout(Exception):
    """The time limit ran out during an alignment search."""


class SearchExhausted(Exception):
    """The search visited MAX_NODES states without finding an alignment."""


Sizes = dict[str, float]  # sizes of unsized symbols fixed so far in a search


@dataclass(frozen=True)
class Move:
    """One row's non-empty entry in a column, from position ``start`` to ``end``."""

    start: int
    end: int
    fixed: float  # preferred length of the sized letters it holds whole
    unsized: tuple[str, ...]  # the unsized (placeholder) letters it holds whole
    letters: int  # letters and pieces of letters
    lead: bool  # it finishes the split letter it starts inside
    piece_of: str | None  # the split letter it starts inside (lead or middle piece)
    tail: float | None  # preferred size of the letter whose first piece ends it (INF if unsized)
    tail_symbol: str | None
    opaque: bool  # holds only whole opaque letters
    transparent: bool
    unoccludable: bool
    first_attached: bool  # starts, at a letter boundary, with an attached letter
    last_attached: bool  # ends, at a letter boundary, with an attached letter
    fixed_only: bool = False  # == plain, stored: interval() is the search's hottest call

    @property
    def middle(self) -> bool:
        """Only a middle piece of a split letter: the row stays inside it."""
        return self.start == self.end

    def tail_size(self, sizes: Sizes) -> float | None:
        if self.tail is None:
            return None
        return sizes.get(self.tail_symbol or "", self.tail)

    @property
    def plain(self) -> bool:
        """Only sized letters, whole: its length does not depend on the search."""
        return not self.unsized and self.piece_of is None and self.tail is None

    def interval(self, left: float, sizes: Sizes) -> tuple[float, float]:
        """Least and greatest length: ``left`` is what the split letter it starts inside
        has left, ``sizes`` the placeholder sizes already fixed."""
        if self.fixed_only:
            return self.fixed, self.fixed
        if self.middle:
            return 0.0, left
        low = high = self.fixed
        for symbol in self.unsized:
            if symbol in sizes:
                low += sizes[symbol]
                high += sizes[symbol]
            else:
                high = INF
        if self.lead:
            if left == INF:
                high = INF
            else:
                low += left
                high += left
        tail = self.tail_size(sizes)
        if tail is not None:
            high += tail
        return low, high


@dataclass(frozen=True)
class Alignment:
    """Columns of one group: ``entries[j][r]`` is row r's entry in column j (None if empty)."""

    rows: tuple[Row, ...]
    entries: tuple[tuple[Move | None, ...], ...]
    error: float
    widths: tuple[float, ...]  # each column's width at preferred sizes (a guide)
    elastic: tuple[bool, ...]  # the column holds only elastic entries

    @property
    def columns(self) -> int:
        return len(self.entries)


class _Row:
    """A row prepared for the search: its moves out of each position, cached."""

    def __init__(self, row: Row):
        self.row = row
        self.n = len(row.word)
        self.cache: dict[int, tuple[list[Move], list[float]]] = {}
        self.spans: dict[tuple[int, int], Move | None] = {}  # spanning(), cached
        # spanning()'s entries out of each position as made so far, by their end (the first
        # of each end), and what makes the rest (None once it is spent)
        self.made: dict[int, tuple[dict[int, Move], list[Iterator[Move] | None]]] = {}
        self.has_attached = any(t.attached for t in row.traits)
        # from each letter on: preferred length of the sized letters, and the unsized ones
        self.fixed_after = [0.0] * (self.n + 1)
        self.unsized_after: list[dict[str, int]] = [{} for _ in range(self.n + 1)]
        for k in range(self.n - 1, -1, -1):
            size = row.traits[k].size
            self.fixed_after[k] = self.fixed_after[k + 1] + (size or 0.0)
            counts = dict(self.unsized_after[k + 1])
            if size is None:
                counts[row.word[k].symbol] = counts.get(row.word[k].symbol, 0) + 1
            self.unsized_after[k] = counts

    @functools.cached_property
    def symbols(self) -> dict[str, float | None]:
        """Its symbols with their preferred sizes (None for a placeholder)."""
        pairs = zip(self.row.word, self.row.traits, strict=True)
        return {letter.symbol: traits.size for letter, traits in pairs}

    @functools.cached_property
    def letters(self) -> list[tuple[str, float | None, bool, bool, bool, bool, int]]:
        """Its letters as the compiled search reads them: symbol, preferred size (None for
        a placeholder), transparent, opaque, attached, unoccludable, segment."""
        return [
            (
                letter.symbol,
                traits.size,
                traits.transparent,
                traits.opaque,
                traits.attached,
                traits.unoccludable,
                traits.segment,
            )
            for letter, traits in zip(self.row.word, self.row.traits, strict=True)
        ]

    def remaining(self, position: int, left: float, sizes: Sizes) -> float:
        """Least length the row still has to lay out from ``position`` on."""
        k, inside = divmod(position, 2)
        if k >= self.n:
            return 0.0
        start = k + 1 if inside else k
        total = self.fixed_after[start]
        for symbol, count in self.unsized_after[start].items():
            total += count * sizes.get(symbol, 0.0)
        if inside and left != INF:
            total += left
        return total

    def moves(self, position: int) -> tuple[list[Move], list[float]]:
        """Entries out of ``position`` sorted by their least whole length, and those lengths."""
        cached = self.cache.get(position)
        if cached is None:
            moves = sorted(self._moves(position), key=lambda m: (m.fixed, m.letters, m.end))
            cached = self.cache[position] = (moves, [m.fixed for m in moves])
        return cached

    def spanning(self, start: int, end: int) -> Move | None:
        """The entry from ``start`` to ``end`` (a middle piece when they are equal), if any:
        the first the row makes out of ``start`` that ends there. The entries out of a
        position grow toward its segment's end; each is made once, however many ends
        are asked for (a proof's reasons ask for thousands out of a few positions)."""
        key = (start, end)
        found = self.spans.get(key, self)
        if found is self:
            made = self.made.get(start)
            if made is None:
                made = self.made[start] = ({}, [self._moves(start)])
            ends, rest = made
            found = ends.get(end)
            making = rest[0]
            while found is None and making is not None:
                move = next(making, None)
                if move is None:
                    rest[0] = making = None
                else:
                    ends.setdefault(move.end, move)
                    found = move if move.end == end else None
            self.spans[key] = found
        return found  # type: ignore[return-value]

    def size(self, k: int) -> float:
        size = self.row.traits[k].size
        return INF if size is None else size

    def _moves(self, position: int) -> Iterator[Move]:
        k, inside = divmod(position, 2)
        if k >= self.n:
            return
        if inside:  # within transparent letter k: a middle piece, or finish it and go on
            yield self._move(position, position, _Whole(), piece_of=k)
            yield from self._extend(position, k + 1, True, piece_of=k)
            return
        transparent = self.row.traits[k].transparent
        if transparent:
            yield self._move(position, position + 1, _Whole(), tail=k)
        yield from self._extend(position, k, transparent, piece_of=None)

    def _extend(
        self, start: int, k: int, transparent: bool, piece_of: int | None
    ) -> Iterator[Move]:
        """Entries from ``start`` holding letters k, k+1, ... whole (of one transparency),
        their totals kept as they grow (a long row has an entry per letter after k)."""
        traits = self.row.traits
        if piece_of is not None:
            yield self._move(start, 2 * k, _Whole(), piece_of=piece_of)
            if (
                k < self.n
                and traits[k].transparent
                and traits[k].segment == traits[piece_of].segment
            ):
                # the end of one split letter and the start of the next, nothing whole
                yield self._move(start, 2 * k + 1, _Whole(), piece_of=piece_of, tail=k)
        segment = traits[k].segment if k < self.n else 0
        whole = _Whole()
        for index in range(k, self.n):
            if traits[index].transparent != transparent or traits[index].segment != segment:
                return
            whole.add(traits[index], self.row.word[index].symbol)
            yield self._move(start, 2 * (index + 1), whole, piece_of=piece_of)
            following = index + 1
            if transparent and following < self.n and traits[following].transparent:
                yield self._move(start, 2 * following + 1, whole, piece_of=piece_of, tail=following)

    def _move(
        self,
        start: int,
        end: int,
        held: _Whole,
        piece_of: int | None = None,
        tail: int | None = None,
    ) -> Move:
        word = self.row.word
        lead = piece_of is not None and end != start
        pieces = (1 if piece_of is not None else 0) + (1 if tail is not None else 0)
        return Move(
            start=start,
            end=end,
            fixed=held.fixed,
            unsized=held.unsized,
            letters=held.count + pieces,
            lead=lead,
            piece_of=None if piece_of is None else word[piece_of].symbol,
            tail=None if tail is None else self.size(tail),
            tail_symbol=None if tail is None else word[tail].symbol,
            opaque=held.count > 0 and not pieces and held.opaque,
            transparent=held.transparent,
            unoccludable=held.unoccludable,
            first_attached=piece_of is None and held.first_attached,
            last_attached=tail is None and held.last_attached,
            fixed_only=piece_of is None and tail is None and held.sized_only,
        )


class _Whole:
    """The letters an entry holds whole, summed as the entry grows a letter at a time."""

    __slots__ = (
        "count",
        "first_attached",
        "fixed",
        "last_attached",
        "opaque",
        "sized_only",
        "transparent",
        "unoccludable",
        "unsized",
    )

    def __init__(self) -> None:
        self.count = 0
        self.fixed = 0.0
        self.unsized: tuple[str, ...] = ()
        self.opaque = self.transparent = self.sized_only = True
        self.unoccludable = self.first_attached = self.last_attached = False

    def add(self, traits: LetterTraits, symbol: str) -> None:
        if traits.size is None:
            self.unsized = (*self.unsized, symbol)
            self.sized_only = False
        else:
            self.fixed += traits.size
        if self.count == 0:
            self.first_attached = traits.attached
        self.last_attached = traits.attached
        self.opaque = self.opaque and traits.opaque
        self.transparent = self.transparent and traits.transparent
        self.unoccludable = self.unoccludable or traits.unoccludable
        self.count += 1


@dataclass(frozen=True)
class _Column:
    error: float
    width: float
    letters: int
    entries: tuple[Move | None, ...]
    stretchable: bool  # only elastic entries: the column can grow to fill the canvas

    def cost(self, span: float, limit: float) -> float:
        """Its error plus how much it pushes the span beyond ``limit``."""
        return self.error + max(0.0, span + self.width - limit) - max(0.0, span - limit)

    @property
    def empties(self) -> int:
        return sum(m is None for m in self.entries)

    @property
    def pieces(self) -> int:
        return sum(
            (m.piece_of is not None) + (m.tail is not None) for m in self.entries if m is not None
        )


@dataclass(frozen=True)
class State:
    """Where the search stands: each row's position, the attached rule's memory, what the
    split letter each row is inside has left and has used, and the placeholder sizes
    fixed so far (every occurrence of a placeholder has one size, SPEC 2.3)."""

    positions: tuple[int, ...]
    memory: tuple[int, ...]
    left: tuple[float, ...]
    used: tuple[float, ...]
    sizes: tuple[tuple[str, float], ...]

    def key(self) -> tuple[object, ...]:
        return (self.positions, self.memory, self.left, self.used, self.sizes)


class _Search:
    def __init__(self, rows: Sequence[Row], canvas: float, mu: float, deadline: float):
        self.rows = [_Row(row) for row in rows]
        self.above = [[j for j, other in enumerate(rows) if other.is_above(row)] for row in rows]
        self.covering = [[j for j, other in enumerate(rows) if other.covers(row)] for row in rows]
        self.canvas = canvas
        self.limit = canvas + mu  # the span may not exceed this without cost
        self.floor = canvas - mu  # nor fall short of this, unless a column can stretch
        self.mu = mu
        self.deadline = deadline
        self.ends = tuple(2 * r.n for r in self.rows)
        self.failed: dict[tuple[object, ...], float] = {}
        self.column_cache: dict[tuple[object, ...], list[_Column]] = {}
        self.nodes = 0
        self.node_limit = self.max_nodes = MAX_NODES
        self.overflow = INF  # least cost beyond the budget seen: the next budget
        self.rejections: Counter[str] = Counter()

    # -- columns out of a state ---------------------------------------------------------
    def columns(self, state: State) -> list[_Column]:
        """Valid columns out of ``state`` (cached: iterations revisit the same states)."""
        key = state.key()
        cached = self.column_cache.get(key)
        if cached is None:
            cached = self.column_cache[key] = self.generate(state)
        return cached

    def generate(self, state: State) -> list[_Column]:
        positions = state.positions
        sizes = dict(state.sizes)
        targets: set[float] = set()
        for r, row in enumerate(self.rows):
            if positions[r] < self.ends[r]:
                moves, _ = row.moves(positions[r])
                for move in moves[:TARGETS_PER_STATE]:
                    low, high = move.interval(state.left[r], sizes)
                    targets.add(round(low, 9))
                    if high != INF:
                        targets.add(round(high, 9))
        found: dict[tuple[int, ...], _Column] = {}
        for target in sorted(targets)[:TARGETS_PER_STATE]:
            nearest = [self.nearest(r, state, sizes, target) for r in range(len(self.rows))]
            for variant in self.variants(nearest, state, sizes, target):
                ends = tuple(m.end if m else positions[r] for r, m in enumerate(variant))
                if ends in found and not any(m is not None and m.middle for m in variant):
                    continue
                column = self.score(variant, state, sizes)
                if column is not None and (ends not in found or column.error < found[ends].error):
                    found[ends] = column
        return list(found.values())

    def nearest(
        self, r: int, state: State, sizes: Sizes, target: float
    ) -> tuple[Move | None, Move | None]:
        """Row r's entries nearest ``target`` with the fewest letters: the best that ends at
        a letter boundary, and the best that ends inside a split letter when as near."""
        position, left = state.positions[r], state.left[r]
        if position >= self.ends[r]:
            return None, None
        moves, lows = self.rows[r].moves(position)
        if position % 2 == 0:  # fixed lengths bound the lengths: look near the target only
            upto = bisect.bisect_right(lows, target + EPS)
            window = moves[max(0, upto - 3) : upto + 1]
            window += [m for m in moves[: max(0, upto - 3)] if m.unsized or m.tail is not None]
        else:
            window = moves
        best: dict[bool, tuple[tuple[float, int], Move]] = {}
        for move in window:
            low, high = move.interval(left, sizes)
            key = (round(max(0.0, low - target, target - high), 9), move.letters)
            split = move.end % 2 == 1
            if split not in best or key < best[split][0]:
                best[split] = (key, move)
        whole, piece = best.get(False), best.get(True)
        if whole is None or (piece is not None and piece[0][0] < whole[0][0]):
            return (piece[1] if piece else None), None
        return whole[1], (piece[1] if piece and piece[0][0] == whole[0][0] else None)

    def variants(
        self,
        nearest: list[tuple[Move | None, Move | None]],
        state: State,
        sizes: Sizes,
        target: float,
    ) -> Iterator[list[Move | None]]:
        """Every row at its nearest entry; the same with split letters where as near; and
        rows that miss the target left empty (making room under opaque rows above)."""
        best = [pair[0] for pair in nearest]
        split = [pair[1] if pair[1] is not None else pair[0] for pair in nearest]
        yield best
        tied = [r for r, pair in enumerate(nearest) if pair[1] is not None]
        if tied:
            yield split
        if len(tied) > 1:  # each row alone may split, or alone stop splitting
            for r in tied:
                yield [split[i] if i == r else move for i, move in enumerate(best)]
                yield [best[i] if i == r else move for i, move in enumerate(split)]
        emptied = list(best)
        room = list(best)
        for r, move in enumerate(best):
            if move is None or state.positions[r] % 2 or state.memory[r] == AFTER_ATTACHED:
                continue
            low, high = move.interval(state.left[r], sizes)
            if max(0.0, low - target, target - high) > EPS:
                emptied[r] = None
            if any(_opaque(best[above]) for above in self.covering[r]):
                room[r] = None
        if emptied != best:
            yield emptied
        if room != best and room != emptied:
            yield room

    def score(self, entries: list[Move | None], state: State, sizes: Sizes) -> _Column | None:
        """The column, or None if it breaks a rule of SPEC 2.4."""
        if not any(m is not None and (m.end > m.start) for m in entries):
            return None
        if not any(m is not None and m.opaque for m in entries):
            self.rejections["no opaque backing"] += 1
            return None
        lows: list[float] = []
        highs: list[float] = []
        for r, move in enumerate(entries):
            if move is None:
                if state.positions[r] % 2:
                    return None  # a split letter has no gaps
                if state.memory[r] == AFTER_ATTACHED:
                    self.rejections["attached letter separated"] += 1
                    return None
                if not any(_opaque(entries[a]) for a in self.covering[r]):
                    self.rejections["an empty entry with no opaque letter above it"] += 1
                    return None
                continue
            if move.first_attached and state.memory[r] == AFTER_EMPTY:
                self.rejections["attached letter separated"] += 1
                return None
            if move.unoccludable:
                for above in self.above[r]:
                    other = entries[above]
                    if other is not None and not other.transparent:
                        self.rejections["unoccludable letter covered"] += 1
                        return None
            low, high = move.interval(state.left[r], sizes)
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
            if move.middle and width >= state.left[r] - EPS:
                return None  # the piece takes all the letter has left: finish it instead
            tail = move.tail_size(sizes)
            if tail is not None and width - move.interval(state.left[r], sizes)[0] >= tail - EPS:
                return None  # the first piece would be the whole letter: take it whole
        letters = sum(m.letters for m in entries if m is not None)
        stretchable = all(
            m is None or m.interval(state.left[r], sizes)[1] == INF for r, m in enumerate(entries)
        )
        return _Column(error, width, letters, tuple(entries), stretchable)

    # -- the search ---------------------------------------------------------------------
    def after(self, state: State, column: _Column) -> State:
        """The state after ``column``: positions advance, split letters use up length, and
        placeholders met for the first time get their size (the column's leftover)."""
        sizes = dict(state.sizes)
        positions, memory, left, used = [], [], [], []
        width = column.width
        for r, move in enumerate(column.entries):
            attached = self.rows[r].has_attached
            if move is None:
                positions.append(state.positions[r])
                kept = state.memory[r] if state.memory[r] == AFTER_ATTACHED else AFTER_EMPTY
                memory.append(kept if attached else FREE)
                left.append(state.left[r])
                used.append(state.used[r])
                continue
            positions.append(move.end)
            memory.append(AFTER_ATTACHED if attached and move.last_attached else FREE)
            if move.middle:
                left.append(state.left[r] if state.left[r] == INF else state.left[r] - width)
                used.append(round(state.used[r] + width, 6))
                continue
            low, _ = move.interval(state.left[r], sizes)
            free = max(0.0, width - low)  # what the elastic parts of the entry share
            if move.tail is not None:  # the tail piece takes it; other placeholders none
                share = 0.0
            else:
                unknown = [s for s in move.unsized if s not in sizes]
                lead_unknown = move.lead and state.left[r] == INF
                share = free / max(1, len(unknown) + lead_unknown)
            for symbol in move.unsized:
                sizes.setdefault(symbol, round(share, 6))
            if move.lead and state.left[r] == INF and move.piece_of:
                sizes.setdefault(move.piece_of, round(state.used[r] + share, 6))
            tail = move.tail_size(sizes)
            if tail is None:
                left.append(INF)
                used.append(0.0)
            else:
                left.append(INF if tail == INF else round(max(0.0, tail - free), 6))
                used.append(round(free, 6))
        return State(
            tuple(positions), tuple(memory), tuple(left), tuple(used), tuple(sorted(sizes.items()))
        )

    def run(self) -> Alignment | None:
        """Look for a perfect path, then deepen the budget (to the tolerance, then doubling)
        until a path is found; then tighten the budget below the best path's cost until no
        cheaper path exists (branch and bound, with a bounded extra effort). Out of nodes or
        time after a path was found, that path stands."""
        count = len(self.rows)
        start = State((0,) * count, (FREE,) * count, (INF,) * count, (0.0,) * count, ())
        best: list[_Column] | None = None
        budget = 0.0  # a perfect alignment is the common case, and quick to find
        while True:
            self.overflow = INF
            try:
                found = self.dfs(start, 0.0, 0.0, False, budget)
            except (SearchTimeout, SearchExhausted):
                if best is None:
                    raise
                break
            if found is not None:
                best, cost = found
                if cost <= EPS:
                    break
                budget = cost - max(BUDGET_STEP * self.canvas / 10, EPS * 10)
                extra = max(REFINE_NODES, self.nodes // 2)
                self.node_limit = min(self.max_nodes, self.nodes + extra)
            elif best is not None or self.overflow == INF or self.overflow > self.canvas:
                break
            else:  # deepen: to the tolerance, then doubling, at least 1% of the canvas
                step = BUDGET_STEP * self.canvas
                budget = max(self.overflow, self.mu, budget * 2.0, budget + step)
        if best is None:
            return None
        return Alignment(
            tuple(r.row for r in self.rows),
            tuple(c.entries for c in best),
            sum(c.error for c in best),
            tuple(c.width for c in best),
            tuple(c.stretchable for c in best),
        )

    def estimate(self, state: State, span: float) -> float:
        """A lower bound on the cost still to come: every row must still lay out what it has
        left, and what runs past the canvas costs (an admissible heuristic)."""
        sizes = dict(state.sizes)
        longest = max(
            row.remaining(state.positions[r], state.left[r], sizes)
            for r, row in enumerate(self.rows)
        )
        return max(0.0, span + longest - self.limit) - max(0.0, span - self.limit)

    def dfs(
        self, state: State, spent: float, span: float, stretchable: bool, budget: float
    ) -> tuple[list[_Column], float] | None:
        """Columns from ``state`` to the ends within ``budget``, best columns first, and the
        total cost of the path they complete.

        ``stretchable``: a column so far holds only elastic entries, so the span can grow.
        """
        self.nodes += 1
        if self.nodes % 128 == 0 and safety_clock() > self.deadline:
            raise SearchTimeout
        if self.nodes > self.node_limit:
            raise SearchExhausted
        if state.positions == self.ends:
            shortfall = 0.0 if stretchable else max(0.0, self.floor - span)
            if spent + shortfall > budget + EPS:
                self.overflow = min(self.overflow, spent + shortfall)
                return None
            return [], spent + shortfall
        key = (state.key(), stretchable)
        if self.failed.get(key, -1.0) >= budget - spent - EPS:
            return None
        bound = spent + self.estimate(state, span)
        if bound > budget + EPS:
            self.overflow = min(self.overflow, bound)
            return None
        ranked = []
        sizes = dict(state.sizes)
        for column in self.columns(state):
            cost = column.cost(span, self.limit)
            # a cheap lower bound after the column: positions advance, sizes as they are
            longest = max(
                row.remaining(m.end if m is not None else state.positions[r], INF, sizes)
                for r, (row, m) in enumerate(zip(self.rows, column.entries, strict=True))
            )
            grown = span + column.width
            guess = cost + max(0.0, grown + longest - self.limit) - max(0.0, grown - self.limit)
            ranked.append((guess, cost, column))
        # equal estimates: whole letters before pieces (split only where needed, section
        # 5.2), no room made before room made, then fewer letters (more columns)
        ranked.sort(
            key=lambda item: (
                round(item[0], 9),
                item[2].pieces,
                item[2].empties,
                item[2].letters,
                item[2].width,
            )
        )
        for guess, cost, column in ranked:
            total = spent + cost
            if spent + guess > budget + EPS:
                self.overflow = min(self.overflow, spent + guess)
                continue
            rest = self.dfs(
                self.after(state, column),
                total,
                span + column.width,
                stretchable or column.stretchable,
                budget,
            )
            if rest is not None:
                return [column, *rest[0]], rest[1]
        self.failed[key] = max(self.failed.get(key, -1.0), budget - spent)
        return None


def _opaque(move: Move | None) -> bool:
    return move is not None and move.opaque


@dataclass(frozen=True)
class AlignmentResult:
    alignment: Alignment | None
    timed_out: bool
    nodes: int
    reason: str  # why there is none (the rule that rejected most columns)


def align_jointly(
    rows: Sequence[Row], canvas: float, mu: float, deadline: float, nodes: int = MAX_NODES
) -> AlignmentResult:
    """The least-cost alignment of rows searched all together, visiting at most ``nodes``
    states."""
    search = _Search(rows, canvas, mu, deadline)
    search.node_limit = search.max_nodes = nodes
    try:
        found = search.run()
    except SearchTimeout:
        return AlignmentResult(None, True, search.nodes, "time limit reached")
    except SearchExhausted:
        return AlignmentResult(
            None, False, search.nodes, f"no alignment within {search.max_nodes:,} search states"
        )
    reason = ""
    if found is None:
        common = search.rejections.most_common(1)
        reason = common[0][0] if common else "the words cannot be cut into matching columns"
    return AlignmentResult(found, False, search.nodes, reason)


Prefixes = dict[tuple[object, ...], "AlignmentResult"]  # alignments of leading rows, reused


def align(
    rows: Sequence[Row],
    canvas: float,
    mu: float,
    deadline: float,
    nodes: int = MAX_NODES,
    prefixes: Prefixes | None = None,
) -> AlignmentResult:
    """The alignment of a group's rows (back to front).

    Up to three rows are searched together. More are added one at a time: the
    columns found so far become the letters of one *composite* row, and the next row is
    aligned against it (the paper's pre-alignment, generalised). A composite letter is one
    column: never split; backed (every column has an opaque entry); unoccludable if it
    holds an unoccludable letter; attached if it holds an attached one at either end; and
    two neighbouring columns merge only where no row changes between transparent and
    visible content or between empty and not. Each step is a two-row search, so the work
    grows with the number of rows instead of exponentially.
    """
    if len(rows) <= JOINT_ROWS:
        return align_jointly(rows, canvas, mu, deadline, nodes)
    prefixes = {} if prefixes is None else prefixes
    prepared = [_Row(row) for row in rows]
    key: tuple[object, ...] = (canvas, mu, *((r.layers, r.word) for r in rows[:JOINT_ROWS]))
    result = prefixes.get(key) or align_jointly(rows[:JOINT_ROWS], canvas, mu, deadline, nodes)
    if not result.timed_out:
        prefixes[key] = result
    visited = result.nodes
    current = result.alignment
    for index, row in enumerate(rows[JOINT_ROWS:], start=JOINT_ROWS):
        if current is None:
            break
        key = (*key, (row.layers, row.word))
        if key in prefixes:
            result = prefixes[key]
            current = result.alignment
            continue
        composite, parts = composite_row(current, prepared[:index])
        result = align_jointly([composite, row], canvas, mu, deadline, nodes)
        visited += result.nodes
        if result.alignment is None:
            current = None
        else:
            try:
                current = compose(current, parts, result.alignment, row, prepared[:index])
            except _NoEntry:
                current = None
                result = AlignmentResult(
                    None, False, result.nodes, "the columns of the layers cannot be merged"
                )
            else:
                result = AlignmentResult(current, False, result.nodes, "")
        if not result.timed_out:
            prefixes[key] = result
        if current is None:
            break
    if current is None:
        return AlignmentResult(None, result.timed_out, visited, result.reason)
    return AlignmentResult(current, False, visited, "")


@dataclass(frozen=True)
class _Part:
    """A letter of a composite row: sub-letter ``index`` of ``count`` of column ``column``."""

    column: int
    index: int
    count: int


def _subdivision(column: Sequence[Move | None], rows: Sequence[_Row]) -> int | None:
    """The row whose letters may subdivide a column: its entry is the only visible one
    and holds several whole letters, and every other entry is one transparent letter (or
    a piece of one), which may be split anywhere. None if the column stays whole."""
    visible = [q for q, m in enumerate(column) if m is not None and not m.transparent]
    if len(visible) != 1:
        return None
    entry = column[visible[0]]
    assert entry is not None
    if entry.letters < 2 or entry.piece_of is not None or entry.tail is not None:
        return None
    for q, move in enumerate(column):
        if q != visible[0] and move is not None and move.letters != 1:
            return None
    return visible[0]


def composite_row(alignment: Alignment, rows: Sequence[_Row]) -> tuple[Row, list[_Part]]:
    """The columns of an alignment as the letters of one row (see :func:`align`), with
    columns subdivided where one row's letters may cut them."""
    traits: list[LetterTraits] = []
    parts: list[_Part] = []
    segment = 0
    entries = alignment.entries
    for j, column in enumerate(entries):
        if j and _must_stay_apart(entries[j - 1], column):
            segment += 1
        present = [m for m in column if m is not None]
        # a row inside a split letter at the column's start or end: the letter goes on in
        # the column before or after, so no empty column may come between (as if attached)
        split_before = any(m.start % 2 for m in present)
        split_after = any(m.end % 2 for m in present)
        cutter = _subdivision(column, rows)
        if cutter is None:
            parts.append(_Part(j, 0, 1))
            traits.append(
                LetterTraits(
                    size=None if alignment.elastic[j] else alignment.widths[j],
                    transparent=False,
                    opaque=True,
                    attached=split_before
                    or split_after
                    or any(m.first_attached or m.last_attached for m in present),
                    unoccludable=any(m.unoccludable for m in present),
                    segment=segment,
                )
            )
            continue
        entry = column[cutter]
        assert entry is not None
        letters = range(entry.start // 2, entry.end // 2)
        # the other rows' entries span the whole column: an empty column between two of
        # its parts would cut them (as if its parts were attached; before the first and
        # after the last too, the one flag there is)
        spanned = any(m is not None for q, m in enumerate(column) if q != cutter)
        for index, k in enumerate(letters):
            own = rows[cutter].row.traits[k]
            parts.append(_Part(j, index, len(letters)))
            traits.append(
                LetterTraits(
                    size=own.size,
                    transparent=False,
                    opaque=own.opaque,
                    attached=own.attached
                    or (spanned and len(letters) > 1)
                    or (index == 0 and split_before)
                    or (index == len(letters) - 1 and split_after),
                    unoccludable=own.unoccludable,
                    segment=segment,
                )
            )
    layers = tuple(sorted({layer for row in alignment.rows for layer in row.layers}))
    word = tuple(Letter(f"#part{i}") for i in range(len(parts)))
    return Row(layers, word, tuple(traits)), parts


def _must_stay_apart(left: Sequence[Move | None], right: Sequence[Move | None]) -> bool:
    for a, b in zip(left, right, strict=True):
        if (a is None) != (b is None):
            return True
        if a is not None and b is not None and a.transparent != b.transparent:
            return True
    return False


def _part_entry(move: Move | None, part: _Part, first: int, last: int) -> tuple[int, int] | None:
    """Positions of the share of ``move`` (an entry of the part's column) that sub-letters
    ``first`` to ``last`` (inclusive) of the column cover."""
    if move is None:
        return None
    if part.count == 1:
        return move.start, move.end
    if move.letters > 1:  # the cutting row: whole letters
        return move.start + 2 * first, move.start + 2 * (last + 1)
    # one transparent letter (or a piece of one): a piece of it
    k = move.start // 2 if move.start % 2 == 0 else (move.start - 1) // 2
    start = move.start if first == 0 else 2 * k + 1
    end = move.end if last == part.count - 1 else 2 * k + 1
    return start, end


def compose(
    previous: Alignment, parts: list[_Part], step: Alignment, row: Row, rows: Sequence[_Row]
) -> Alignment:
    """The alignment of ``previous``'s rows plus ``row``, from the two-row ``step`` that
    aligned ``row`` with the composite row of ``parts``."""
    entries = []
    for column in step.entries:
        composite, own = column
        merged: list[Move | None] = []
        covered = [] if composite is None else parts[composite.start // 2 : composite.end // 2]
        by_column: dict[int, list[_Part]] = {}
        for part in covered:
            by_column.setdefault(part.column, []).append(part)
        for q, prepared in enumerate(rows):
            spans = []
            for j, group in by_column.items():
                share = _part_entry(
                    previous.entries[j][q], group[0], group[0].index, group[-1].index
                )
                if share is not None:
                    spans.append(share)
            merged.append(_entry(prepared, spans[0][0], spans[-1][1]) if spans else None)
        entries.append((*merged, own))
    return Alignment(
        (*previous.rows, row),
        tuple(entries),
        previous.error + step.error,
        step.widths,
        step.elastic,
    )


def prepared_row(row: Row, known: dict[Row, _Row]) -> _Row:
    """A row with its moves cached, kept in ``known`` (shared by the searches and
    constructions of one axis)."""
    found = known.get(row)
    if found is None:
        found = known[row] = _Row(row)
    return found


def _entry(row: _Row, start: int, end: int) -> Move:
    """The entry of a row from ``start`` to ``end`` (positions in half-steps)."""
    moves, _ = row.moves(start)
    for move in moves:
        if move.end == end:
            return move
    raise _NoEntry(f"no entry from {start} to {end}")


class _NoEntry(Exception):
    """A composed column asks a row for an entry its word cannot give (e.g. transparent
    and visible letters together): the composition is abandoned, never the solve."""


def score_alignment(
    rows: Sequence[Row],
    cuts: Sequence[Sequence[tuple[int, int] | None]],
    canvas: float,
    mu: float,
) -> float | None:
    """The cost of a given alignment, or None if it breaks a rule (SPEC 2.4).

    ``cuts[r][j]`` is row r's entry in column j as (first letter, end letter), or None for
    an empty entry; letters are whole (no splits). For checking and explaining alignments.
    """
    search = _Search(rows, canvas, mu, INF)
    count = len(rows)
    state = State((0,) * count, (FREE,) * count, (INF,) * count, (0.0,) * count, ())
    total = span = 0.0
    stretchable = False
    for j in range(len(cuts[0])):
        entries: list[Move | None] = []
        for r, row in enumerate(search.rows):
            cut = cuts[r][j]
            if cut is None:
                entries.append(None)
                continue
            moves, _ = row.moves(2 * cut[0])
            match = [m for m in moves if m.start == 2 * cut[0] and m.end == 2 * cut[1]]
            if not match:
                return None  # e.g. transparent and visible letters in one entry
            entries.append(match[0])
        column = search.score(entries, state, dict(state.sizes))
        if column is None:
            return None
        stretchable = stretchable or column.stretchable
        total += column.cost(span, search.limit)
        span += column.width
        state = search.after(state, column)
    if state.positions != search.ends:
        return None
    return total + (0.0 if stretchable else max(0.0, search.floor - span))
