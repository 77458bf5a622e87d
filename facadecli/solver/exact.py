"""The exact alignment of one candidate: branch and bound over the alignment decision network.

The heuristic search (:mod:`facadecli.solver.alignment`) costs columns with *preferred*
sizes; it is fast but may miss a layout whose sizes differ from them, or settle on columns
that no sizes can realise. This search is its exact counterpart, used when the heuristic
finds nothing for a candidate, to look for a better layout than the heuristic's, and to
prove that a candidate has no layout at all.

Every path through the network (a column per step, SPEC 2.4's rules on every column) is an
alignment; its value is the sizing objective (SPEC 2.7). A partial path implies linear
equalities (the entries of a column are as long as each other, the pieces of a split letter
add up to its size); the least squared deviation that meets them is a lower bound on every
completion, because completing a path only adds equalities and bounds. A node is cut when
its bound is no better than the best complete layout found, or when its equalities have no
solution at all. Nothing is cut on preferred lengths, so the search is exact: when it runs
to the end, the layout it returns is optimal and "none" is a proof.

All work is counted in *work units* (bounds computed, layouts sized), never in seconds, so
the same input gives the same answer on any machine.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from facadecli.solver import columns, sizing
from facadecli.solver.alignment import INF, Alignment, Move, _Row
from facadecli.solver.rows import Row
from facadecli.spec.model import Spec

FREE, AFTER_EMPTY, AFTER_ATTACHED = 0, 1, 2
Equality = tuple[dict[int, float], dict[int, float], float]  # sized, free coefficients, rhs
Length = tuple[dict[int, float], dict[int, float]]  # an entry's length: sized, free parts
Column = tuple[Move | None, ...]
LEAF_WORK = 20  # work units of sizing a complete layout (a bound costs 1)
COMBINATION_WORK = 64  # partial columns built per work unit
WORK_PER_UNIT = 256  # matrix entries of a bound per extra work unit
SAME = 1e-9  # objectives this close are equal (the tie-breaks decide)


class BudgetExhausted(Exception):
    """The search used up its work units before it finished."""


class _Perfect(Exception):
    """A layout with every symbol at its preferred size: the search can stop."""


@dataclass
class Budget:
    """Work units a search may spend; shared by every search of one solve. ``deadline``
    (wall clock) is a safety net only: when it fires, ``timed_out`` says so."""

    limit: int
    deadline: float = INF
    used: int = 0
    timed_out: bool = False

    def spend(self, units: int = 1) -> None:
        before = self.used
        self.used += units
        if self.used > self.limit:
            raise BudgetExhausted
        if before // 256 != self.used // 256 and time.perf_counter() > self.deadline:
            self.timed_out = True
            raise BudgetExhausted

    @property
    def left(self) -> int:
        return max(0, self.limit - self.used)


@dataclass(frozen=True)
class Found:
    """A complete layout of a candidate: its alignment per group and its sizing."""

    groups: dict[str, Alignment]
    program: sizing.Program
    sizing: sizing.Sizing

    @property
    def rank(self) -> tuple[float, int, float, int, int]:
        """Least deviation; fewest split letters; placeholders covering least; fewest
        holes; most columns (SPEC 2.7 and its tie-breaks)."""
        entries = [e for a in self.groups.values() for column in a.entries for e in column]
        splits = sum(e is not None and e.tail is not None and e.tail != INF for e in entries)
        empties = sum(e is None for e in entries)
        columns = sum(a.columns for a in self.groups.values())
        return (
            round(self.sizing.objective, 8),
            splits,
            round(self.sizing.coverage, 6),
            empties,
            -columns,
        )


@dataclass(frozen=True)
class Outcome:
    found: Found | None
    complete: bool  # the whole network was searched: ``found`` is optimal, None a proof
    reason: str = ""  # why nothing was found (the rule that rejected most columns)


class _Equalities:
    """The linear equalities a partial path implies, over sized symbols (with a preferred
    size) and free variables (placeholders, pieces of split letters)."""

    def __init__(self, sized: Mapping[str, float]):
        self.sized_index = {name: i for i, name in enumerate(sorted(sized))}
        self.target = np.array([sized[name] for name in sorted(sized)])
        self.free_index: dict[object, int] = {}
        self.work = 0  # work units of the last bound: it grows with the equalities

    def free(self, key: object) -> int:
        return self.free_index.setdefault(key, len(self.free_index))

    def bound(self, rows: Sequence[Equality]) -> tuple[float, np.ndarray]:
        """Least sum of squared deviations of the sized symbols under ``rows`` (INF when the
        equalities conflict), and the sizes that reach it (unique: the objective is
        strictly convex in them)."""
        self.work = 1
        if not rows:
            return 0.0, self.target
        n_sized, n_free = len(self.target), len(self.free_index)
        a = np.zeros((len(rows), n_sized))
        b = np.zeros((len(rows), n_free))
        d = np.zeros(len(rows))
        for i, (sized, free, rhs) in enumerate(rows):
            for j, value in sized.items():
                a[i, j] += value
            for j, value in free.items():
                b[i, j] += value
            d[i] = rhs
        self.work = 1 + len(rows) * (n_sized + n_free) // WORK_PER_UNIT
        scale = max(1.0, float(np.abs(d).max(initial=0.0)))
        if n_free:  # only what the free variables cannot absorb constrains the sizes
            u, s, _ = np.linalg.svd(b, full_matrices=True)
            rank = int((s > 1e-9 * max(1.0, s.max(initial=0.0))).sum())
            q = u[:, rank:]
            a, d = q.T @ a, q.T @ d
            if a.shape[0] == 0:
                return 0.0, self.target
        residual = d - a @ self.target
        if n_sized == 0:
            ok = float(np.abs(residual).max(initial=0.0)) <= 1e-9 * scale
            return (0.0 if ok else INF), self.target
        step, *_ = np.linalg.lstsq(a, residual, rcond=None)
        if float(np.abs(a @ step - residual).max(initial=0.0)) > 1e-7 * scale:
            return INF, self.target
        return float(step @ step), self.target + step

    def bound_within(
        self, rows: Sequence[Equality], spans: Sequence[np.ndarray], canvas: float
    ) -> float:
        """:meth:`bound` strengthened by the inequalities ``span @ sizes <= canvas`` (what a
        row has laid out and still has to lay out must fit the canvas). The most violated
        one is made an equality: with a strictly convex objective, that is where the
        optimum under it lies, so the bound stays a lower bound."""
        value, sizes = self.bound(rows)
        if value == INF or not spans:
            return value
        worst, chosen = 1e-9, None
        for span in spans:
            norm = float(span @ span)
            if norm > 0.0:
                violation = (float(span @ sizes) - canvas) / math.sqrt(norm)
                if violation > worst:
                    worst, chosen = violation, span
        if chosen is None:
            return value
        tight: Equality = ({i: float(v) for i, v in enumerate(chosen) if v}, {}, canvas)
        return max(value, self.bound([*rows, tight])[0])


@dataclass
class _Group:
    name: str
    rows: list[_Row]
    above: list[list[int]]  # rows that may cover each row
    covering: list[list[int]]  # rows each row may make room for (SPEC 2.4, opaque)
    ends: tuple[int, ...]


@dataclass
class _Search:
    spec: Spec
    canvas: float
    groups: list[_Group]
    budget: Budget
    incumbent: float
    equalities: _Equalities
    best: Found | None = None
    rejections: dict[str, tuple[int, int]] = field(default_factory=dict)  # (progress, count)
    progress: int = 0  # how far the state being expanded is (sum of positions)
    remaining_cache: dict[tuple[int, int, int], np.ndarray] = field(default_factory=dict)
    combinations: int = 0  # partial columns built (a work unit per COMBINATION_WORK)
    sizing_failure: str = ""  # why the last complete alignment could not be sized
    merge: bool = True  # search only columns that do not merge with the one before

    # -- the rules of SPEC 2.4 on one column ----------------------------------------------
    def reject(self, why: str) -> bool:
        progress, count = self.rejections.get(why, (0, 0))
        self.rejections[why] = (max(progress, self.progress), count + 1)
        return False

    def valid(self, group: _Group, entries: Sequence[Move | None], memory: Sequence[int]) -> bool:
        if not any(m is not None for m in entries):
            return False
        if not any(_opaque(m) for m in entries):
            r = next(r for r, m in enumerate(entries) if m is not None)
            return self.reject(
                f"nothing opaque would stand behind or in front of "
                f"{self.text(group, r, entries[r])} of {self.layer(group, r)} (every column "
                "needs an opaque layer: mark a symbol opaque, or let the layers fit)"
            )
        for r, move in enumerate(entries):
            if move is None:
                if memory[r] == AFTER_ATTACHED:
                    return self.reject(
                        f"an attached letter of {self.layer(group, r)} would be separated from "
                        "its neighbour by a gap"
                    )
                if not any(_opaque(entries[a]) for a in group.covering[r]):
                    return self.reject(
                        f"{self.layer(group, r)} would need a gap where no layer in front of it "
                        "has an opaque letter (only opaque letters of layers in front may make "
                        "a layer give way)"
                    )
                continue
            if move.first_attached and memory[r] == AFTER_EMPTY:
                return self.reject(
                    f"{self.text(group, r, move)} of {self.layer(group, r)} is attached, but a "
                    "gap would open before it"
                )
            if move.unoccludable:
                for above in group.above[r]:
                    other = entries[above]
                    if other is not None and not other.transparent:
                        return self.reject(
                            f"{self.layer(group, above)} would cover unoccludable "
                            f"{self.text(group, r, move)} of {self.layer(group, r)}"
                        )
        return True

    def merges(self, group: _Group, last: Column, entries: Column, before: tuple[int, ...]) -> bool:
        """Whether two columns in a row make one valid column. Then a path through both is
        never needed: the path through the one column meets fewer equalities and the same
        rules (and the finest cut of its layout gives the columns back). Without this, a
        placeholder over a long wall is split letter by letter in every possible way."""
        merged: list[Move | None] = []
        for r, (a, b) in enumerate(zip(last, entries, strict=True)):
            if a is None or b is None:
                if a is not b:
                    return False
                merged.append(None)
                continue
            middle = a.start == b.end
            joined = next(
                (
                    m
                    for m in group.rows[r].moves(a.start)[0]
                    if m.end == b.end and (m.start == m.end) == middle
                ),
                None,
            )
            if joined is None:
                return False
            merged.append(joined)
        kept = dict(self.rejections)
        fits = self.valid(group, merged, before)
        self.rejections = kept
        return fits

    def layer(self, group: _Group, r: int) -> str:
        names = [f"'{self.spec.layers[i].name}'" for i in group.rows[r].row.layers]
        return ("layer " if len(names) == 1 else "layers ") + ", ".join(names)

    def text(self, group: _Group, r: int, move: Move | None) -> str:
        if move is None:
            return "a gap"
        whole, parts = sizing.entry_parts(move)
        word = group.rows[r].row.word
        return "'" + " ".join(word[k].symbol for k in sorted({*whole, *parts})) + "'"

    def columns(
        self, group: _Group, positions: tuple[int, ...], memory: tuple[int, ...]
    ) -> Iterator[tuple[Move | None, ...]]:
        """Every valid column out of a state."""
        self.progress = sum(positions)
        options: list[list[Move | None]] = []
        for r, row in enumerate(group.rows):
            position = positions[r]
            if position >= group.ends[r]:
                options.append([None])
                continue
            moves: list[Move | None] = list(row.moves(position)[0])
            if position % 2 == 0:  # inside a split letter a row cannot pause
                moves.append(None)
            options.append(moves)

        def extend(r: int, chosen: list[Move | None]) -> Iterator[tuple[Move | None, ...]]:
            self.combinations += 1
            if self.combinations % COMBINATION_WORK == 0:
                self.budget.spend()
            if r == len(options):
                if self.valid(group, chosen, memory):
                    yield tuple(chosen)
                return
            for move in options[r]:
                chosen.append(move)
                yield from extend(r + 1, chosen)
                chosen.pop()

        yield from extend(0, [])

    # -- equalities -------------------------------------------------------------------------
    def content(
        self, group: int, r: int, j: int, move: Move, word: Sequence[str]
    ) -> tuple[dict[int, float], dict[int, float]]:
        """The length of an entry as (sized coefficients, free coefficients)."""
        sized: dict[int, float] = {}
        free: dict[int, float] = {}
        whole, parts = sizing.entry_parts(move)
        for k in whole:
            self.add_symbol(word[k], sized, free)
        for k in parts:
            index = self.equalities.free(("piece", group, r, k, j))
            free[index] = free.get(index, 0.0) + 1.0
        return sized, free

    def add_symbol(self, name: str, sized: dict[int, float], free: dict[int, float]) -> None:
        if name in self.equalities.sized_index:
            index = self.equalities.sized_index[name]
            sized[index] = sized.get(index, 0.0) + 1.0
        else:
            index = self.equalities.free(("symbol", name))
            free[index] = free.get(index, 0.0) + 1.0

    def column_rows(
        self, g: int, j: int, entries: Sequence[Move | None], path: Sequence[Sequence[Move | None]]
    ) -> tuple[list[Equality], Length]:
        """The equalities a column adds, and its width (the first entry's length)."""
        group = self.groups[g]
        added: list[tuple[dict[int, float], dict[int, float], float]] = []
        width: tuple[dict[int, float], dict[int, float]] | None = None
        for r, move in enumerate(entries):
            if move is None:
                continue
            word = [letter.symbol for letter in group.rows[r].row.word]
            length = self.content(g, r, j, move, word)
            if width is None:
                width = length
            else:
                added.append(_difference(length, width))
            if move.start % 2 == 1 and move.end > move.start:  # a split letter is finished
                added.append(self.finished_letter(g, r, j, move, word, path))
        assert width is not None
        return added, width

    def finished_letter(
        self,
        g: int,
        r: int,
        j: int,
        move: Move,
        word: Sequence[str],
        path: Sequence[Sequence[Move | None]],
    ) -> tuple[dict[int, float], dict[int, float], float]:
        """Its pieces (this column's and the earlier ones where the row was inside it) add
        up to its symbol's size."""
        k = move.start // 2
        sized: dict[int, float] = {}
        free: dict[int, float] = {}
        self.add_symbol(word[k], sized, free)
        sized = {i: -v for i, v in sized.items()}
        free = {i: -v for i, v in free.items()}
        earlier = [c for c, entries in enumerate(path) if _holds_piece(entries[r], k)]
        for column in [*earlier, j]:
            index = self.equalities.free(("piece", g, r, k, column))
            free[index] = free.get(index, 0.0) + 1.0
        return sized, free, 0.0

    # -- the search -------------------------------------------------------------------------
    def run(self) -> None:
        start = self.start_of(0)
        self.dfs(0, start[0], start[1], self.filling(), [], [], [])

    def filling(self) -> list[Equality]:
        """A row that no row in front may make room for has no gap: its letters fill the
        canvas, whatever the alignment (known before the first column)."""
        rows: list[Equality] = []
        for group in self.groups:
            for r, prepared in enumerate(group.rows):
                if group.covering[r]:
                    continue
                sized: dict[int, float] = {}
                free: dict[int, float] = {}
                for letter in prepared.row.word:
                    self.add_symbol(letter.symbol, sized, free)
                rows.append((sized, free, self.canvas))
        return rows

    def start_of(self, g: int) -> tuple[tuple[int, ...], tuple[int, ...]]:
        count = len(self.groups[g].rows)
        return (0,) * count, (FREE,) * count

    def dfs(
        self,
        g: int,
        positions: tuple[int, ...],
        memory: tuple[int, ...],
        rows: list[Equality],
        widths: list[tuple[dict[int, float], dict[int, float]]],
        path: list[tuple[Move | None, ...]],
        done: list[list[tuple[Move | None, ...]]],
        before: tuple[int, ...] = (),
    ) -> None:
        """``before``: the attached rule's memory before the last column of ``path``."""
        group = self.groups[g]
        if positions == group.ends:
            total = [*rows, _sum(widths, self.canvas)]
            bound = self.equalities.bound(total)[0]
            self.budget.spend(self.equalities.work)
            if bound > self.incumbent + SAME:
                return
            finished = [*done, list(path)]
            if g + 1 < len(self.groups):
                start = self.start_of(g + 1)
                self.dfs(g + 1, start[0], start[1], total, [], [], finished)
            else:
                self.leaf(finished)
            return
        span = self.span_of(widths)
        children: list[
            tuple[tuple[float, float, int, int, int, int], Column, list[Equality], Length]
        ] = []
        for entries in self.columns(group, positions, memory):
            if self.merge and path and self.merges(group, path[-1], entries, before):
                continue  # the one column they make is searched too, and is looser
            added, width = self.column_rows(g, len(path), entries, path)
            extended = rows + added
            after = _advance(entries, positions)
            grown = span + self.sized_vector(width[0])
            spans = [grown + self.remaining(g, r, p) for r, p in enumerate(after)]
            bound = self.equalities.bound_within(extended, [grown, *spans], self.canvas)
            self.budget.spend(self.equalities.work)
            if bound > self.incumbent + SAME:
                continue
            present = [m for m in entries if m is not None]
            rank = (
                round(bound, 9),
                _spread(entries),
                sum((m.piece_of is not None) + (m.tail is not None) for m in present),
                len(entries) - len(present),
                sum(m.letters for m in present),
                len(children),
            )
            children.append((rank, entries, extended, width))
        # most promising first: least bound, then the columns that fit at preferred sizes
        # (the paper's column error), whole letters before pieces (split only where
        # needed), no room made before room made, fewer letters (more columns)
        children.sort(key=lambda child: child[0])
        for rank, entries, extended, width in children:
            if rank[0] > self.incumbent + SAME:
                break
            self.dfs(
                g,
                _advance(entries, positions),
                _remember(group, entries, memory),
                extended,
                [*widths, width],
                [*path, entries],
                done,
                memory,
            )

    def sized_vector(self, coefficients: Mapping[int, float]) -> np.ndarray:
        vector = np.zeros(len(self.equalities.target))
        for i, v in coefficients.items():
            vector[i] += v
        return vector

    def span_of(self, widths: Sequence[tuple[dict[int, float], dict[int, float]]]) -> np.ndarray:
        """The sized part of the columns laid out so far (their free parts are >= 0)."""
        total = np.zeros(len(self.equalities.target))
        for sized, _ in widths:
            total += self.sized_vector(sized)
        return total

    def remaining(self, g: int, r: int, position: int) -> np.ndarray:
        """The sized letters a row still has to lay out whole from ``position``."""
        key = (g, r, position)
        cached = self.remaining_cache.get(key)
        if cached is None:
            word = self.groups[g].rows[r].row.word
            sized: dict[int, float] = {}
            first = (position + 1) // 2
            for letter in word[first:]:
                self.add_symbol(letter.symbol, sized, {})
            cached = self.remaining_cache[key] = self.sized_vector(sized)
        return cached

    def leaf(self, paths: list[list[tuple[Move | None, ...]]]) -> None:
        self.budget.spend(LEAF_WORK)
        groups = {
            group.name: _alignment(group, path)
            for group, path in zip(self.groups, paths, strict=True)
        }
        program = sizing.build_program(self.spec, groups, self.canvas)
        solved = sizing.search_solve(program)
        if solved is None:
            self.sizing_failure = sizing.explain_infeasible(program)
            return
        found = Found(*columns.finest(self.spec, self.canvas, groups, program, solved))
        if self.best is None or found.rank < self.best.rank:
            self.best = found
            self.incumbent = min(self.incumbent, solved.objective)
        if solved.objective <= SAME:
            raise _Perfect  # nothing deviates less: the search order broke the tie


def _opaque(move: Move | None) -> bool:
    return move is not None and move.opaque


def _advance(entries: Sequence[Move | None], positions: tuple[int, ...]) -> tuple[int, ...]:
    return tuple(m.end if m is not None else p for m, p in zip(entries, positions, strict=True))


def _holds_piece(move: Move | None, k: int) -> bool:
    return move is not None and k in sizing.entry_parts(move)[1]


def _difference(
    a: tuple[dict[int, float], dict[int, float]], b: tuple[dict[int, float], dict[int, float]]
) -> tuple[dict[int, float], dict[int, float], float]:
    sized = dict(a[0])
    for i, v in b[0].items():
        sized[i] = sized.get(i, 0.0) - v
    free = dict(a[1])
    for i, v in b[1].items():
        free[i] = free.get(i, 0.0) - v
    return sized, free, 0.0


def _sum(
    widths: Sequence[tuple[dict[int, float], dict[int, float]]], canvas: float
) -> tuple[dict[int, float], dict[int, float], float]:
    sized: dict[int, float] = {}
    free: dict[int, float] = {}
    for width_sized, width_free in widths:
        for i, v in width_sized.items():
            sized[i] = sized.get(i, 0.0) + v
        for i, v in width_free.items():
            free[i] = free.get(i, 0.0) + v
    return sized, free, canvas


def _remember(
    group: _Group, entries: Sequence[Move | None], memory: tuple[int, ...]
) -> tuple[int, ...]:
    """The attached rule's memory after a column: did each row's entry end with an attached
    letter, or was it empty?"""
    updated = []
    for r, move in enumerate(entries):
        if not group.rows[r].has_attached:
            updated.append(FREE)
        elif move is None:
            updated.append(memory[r] if memory[r] == AFTER_ATTACHED else AFTER_EMPTY)
        else:
            updated.append(AFTER_ATTACHED if move.last_attached else FREE)
    return tuple(updated)


def _spread(entries: Sequence[Move | None]) -> float:
    """Eq. 9: how far apart the entries' lengths are at preferred sizes (elastic entries
    are intervals)."""
    lows, highs = [], []
    for move in entries:
        if move is not None:
            low, high = move.interval(INF, {})
            lows.append(low)
            highs.append(high)
    return round(max(0.0, max(lows) - min(highs)), 9)


def _alignment(group: _Group, path: Sequence[tuple[Move | None, ...]]) -> Alignment:
    """The path as an :class:`Alignment`, its error (Eq. 9) taken at preferred sizes."""
    error = sum(_spread(entries) for entries in path)
    return Alignment(
        tuple(row.row for row in group.rows),
        tuple(path),
        error,
        tuple(0.0 for _ in path),
        tuple(False for _ in path),
    )


def align_exactly(
    spec: Spec,
    groups: Mapping[str, Sequence[Row]],
    canvas: float,
    budget: Budget,
    incumbent: float = INF,
    merge: bool = True,
) -> Outcome:
    """The best layout of a candidate's groups (one set of rows per group), searched
    exactly; only layouts with an objective at most ``incumbent`` are looked for."""
    prepared = []
    for name, rows in sorted(groups.items()):
        prepared.append(
            _Group(
                name,
                [_Row(row) for row in rows],
                [[j for j, other in enumerate(rows) if other.is_above(row)] for row in rows],
                [[j for j, other in enumerate(rows) if other.covers(row)] for row in rows],
                tuple(2 * len(row.word) for row in rows),
            )
        )
    sized = {
        name: size for name, symbol in spec.symbols.items() if (size := symbol.size) is not None
    }
    search = _Search(spec, canvas, prepared, budget, incumbent, _Equalities(sized))
    search.merge = merge
    try:
        search.run()
    except _Perfect:
        pass
    except BudgetExhausted:
        return Outcome(search.best, False, "the search budget ran out")
    reason = ""
    if search.best is None:
        # the rule that stopped the search furthest along, then the most often
        counts = sorted(
            search.rejections.items(), key=lambda item: (-item[1][0], -item[1][1], item[0])
        )
        reason = search.sizing_failure or (
            counts[0][0] if counts else "the words cannot be cut into matching columns"
        )
    return Outcome(search.best, True, reason)


def candidate_bound(groups: Mapping[str, Sequence[Row]], canvas: float) -> float:
    """A lower bound on the objective of any layout of a candidate's rows, from one row at
    a time (the paper's Eq. 7 with sizes free): a row longer than the canvas at preferred
    sizes must shrink (placeholders only grow); a row without placeholders that is
    shorter must grow, unless opaque letters of the rows in front may cover its gaps: then
    its letters and theirs together must reach the canvas."""
    best = 0.0
    for rows in groups.values():
        for row in rows:
            own = _sized_counts(row, opaque_only=False)
            if not own:
                continue
            longer = _excess(own, canvas)
            best = max(best, longer)
            if any(traits.size is None for traits in row.traits):
                continue  # a placeholder takes up any shortfall
            reach = dict(own)
            for other in rows:
                if other.covers(row):
                    for name, (count, size) in _sized_counts(other, opaque_only=True).items():
                        reach[name] = (reach.get(name, (0, size))[0] + count, size)
            best = max(best, _excess(reach, canvas, shorter=True))
    return best


def _sized_counts(row: Row, opaque_only: bool) -> dict[str, tuple[int, float]]:
    counts: dict[str, tuple[int, float]] = {}
    for letter, traits in zip(row.word, row.traits, strict=True):
        if traits.size is not None and (traits.opaque or not opaque_only):
            counts[letter.symbol] = (counts.get(letter.symbol, (0, 0.0))[0] + 1, traits.size)
    return counts


def _excess(counts: Mapping[str, tuple[int, float]], canvas: float, shorter: bool = False) -> float:
    """Least squared deviation that brings sum(count * size) to the canvas (from above, or
    from below with ``shorter``), all else free."""
    length = sum(count * size for count, size in counts.values())
    miss = canvas - length if shorter else length - canvas
    if miss <= 0.0 or not counts:
        return 0.0
    return miss * miss / sum(count * count for count, _ in counts.values())
