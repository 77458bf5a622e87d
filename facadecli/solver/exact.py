"""The exact alignment of one candidate: branch and bound over the alignment decision network.

This is how every axis is solved (:mod:`facadecli.solver.axis` calls it candidate by
candidate, in passes of growing objective thresholds); the heuristic search of
:mod:`facadecli.solver.alignment`, which costs columns with *preferred* sizes, only offers
variations and is a last resort when this search runs out of work.

Every path through the network (a column per step, SPEC 2.4's rules on every column) is an
alignment; its value is the sizing objective (SPEC 2.7). A partial path implies linear
equalities over the symbols (the entries of a column are as long as each other, a split
letter is as long as the columns it spans); the least squared deviation that meets them is a
lower bound on every completion, because completing a path only adds equalities and bounds.
It is kept up to date row by row (:class:`_System`), and strengthened by what every row
still has to lay out within the canvas. A node is cut when its bound exceeds the threshold
or the best complete layout found, or when its equalities have no solution. Nothing is cut
on preferred lengths, so the search is exact: when it runs to the end, the layout it returns
is optimal and "none" is a proof.

All work is counted in *work units* (columns bounded, layouts sized), never in seconds, so
the same input gives the same answer on any machine.

The search runs compiled (``_exact.c``, driven by :class:`_Compiled`; complete layouts are
still sized here). :class:`_Search` is the same search in Python: the reference the tests
compare it with, column for column (the same layouts, reasons and work units).
"""

from __future__ import annotations

import math
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from facadecli.native import EXACT_COMPILED, _exact
from facadecli.patterns import Word
from facadecli.solver import columns, sizing
from facadecli.solver.alignment import INF, Alignment, Move, _Row, prepared_row
from facadecli.solver.budgets import (
    COMBINATION_WORK,
    LEAF_WORK,
    RECURSION_MARGIN,
    SAME,
)
from facadecli.solver.rows import LetterTraits, Row
from facadecli.spec.model import Spec

FREE, AFTER_EMPTY, AFTER_ATTACHED = 0, 1, 2
# the rules a column may break (numbered as in _exact.c)
NO_OPAQUE, ATTACHED_GAP, NO_COVER, GAP_BEFORE_ATTACHED, COVERED = 1, 2, 3, 4, 5
Column = tuple[Move | None, ...]
Option = tuple[Move | None, np.ndarray | None]  # an entry (None: a gap), its length if known
Options = tuple[list[Option], list[int], np.ndarray]  # see _Search.options()
COMPILED = EXACT_COMPILED  # search with _exact.c where built (False: the Python reference)
_EXHAUSTED, _STOPPED = 2, 3  # what _exact.Search.run() returns besides 0 (done)
TEXT_LETTERS = 12  # an entry of more letters is named by its first and last few


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
    def rank(self) -> tuple[float, int, int, float, int]:
        """Least deviation; fewest split letters; fewest holes; placeholders covering
        least; most columns (SPEC 2.7 and its tie-breaks)."""
        entries = [e for a in self.groups.values() for column in a.entries for e in column]
        splits = sum(e is not None and e.tail is not None and e.tail != INF for e in entries)
        empties = sum(e is None for e in entries)
        columns = sum(a.columns for a in self.groups.values())
        return (
            round(self.sizing.objective, 8),
            splits,
            empties,
            round(self.sizing.coverage, 6),
            -columns,
        )


@dataclass(frozen=True)
class Outcome:
    found: Found | None
    complete: bool  # the whole network was searched: ``found`` is optimal, None a proof
    reason: str = ""  # why nothing was found (the rule that rejected most columns)


class _System:
    """The linear equalities a partial path implies, kept reduced, and the least squared
    deviation of the sized symbols under them (the bound).

    Variables are the symbols of the axis: sized ones (with a preferred size) first, then
    placeholders. A row that holds a placeholder is solved for it (a *pivot*): whatever the
    sized symbols are, the placeholder can meet it, so it does not constrain them. The other
    rows constrain the sized symbols alone; they are kept orthonormal, and the bound is the
    squared distance from the preferred sizes to the affine subspace they span, updated
    row by row. Immutable: a child node adds rows to a copy."""

    __slots__ = ("basis", "pivots", "point", "probes", "rhs", "sized", "value")

    def __init__(
        self,
        sized: int,
        pivots: tuple[tuple[int, np.ndarray, float], ...],
        basis: np.ndarray,
        rhs: np.ndarray,
        point: np.ndarray,
        value: float,
    ):
        self.sized = sized
        self.pivots = pivots
        self.basis = basis  # orthonormal rows over the sized symbols
        self.rhs = rhs
        self.point = point  # the sizes nearest the preferred ones under the rows
        self.value = value
        self.probes: dict[bytes, float] = {}  # probe() of rows already asked about

    @classmethod
    def empty(cls, target: np.ndarray) -> _System:
        return cls(len(target), (), np.zeros((0, len(target))), np.zeros(0), target.copy(), 0.0)

    def add(self, row: np.ndarray, rhs: float, scale: float) -> _System | None:
        """The system with ``row @ symbols == rhs`` added; None when it conflicts."""
        row, rhs = self._reduce(row, rhs)
        free = np.abs(row[self.sized :])
        if free.size and free.max() > 1e-9:
            v = self.sized + int(free.argmax())
            pivot = row / row[v]
            pivot_rhs = rhs / row[v]
            pivots = [
                (u, r - r[v] * pivot, r_rhs - r[v] * pivot_rhs) if r[v] != 0.0 else (u, r, r_rhs)
                for u, r, r_rhs in self.pivots
            ]
            pivots.append((v, pivot, pivot_rhs))
            return _System(self.sized, tuple(pivots), self.basis, self.rhs, self.point, self.value)
        a, rhs = self._orthogonal(row[: self.sized], rhs)
        norm = math.sqrt(float(a @ a))
        if norm <= 1e-9:
            return self if abs(rhs) <= 1e-7 * scale else None
        q = a / norm
        residual = rhs / norm - float(q @ self.point)
        return _System(
            self.sized,
            self.pivots,
            np.vstack([self.basis, q]),
            np.append(self.rhs, rhs / norm),
            self.point + residual * q,
            self.value + residual * residual,
        )

    def probe(self, row: np.ndarray, scale: float) -> float:
        """The bound with ``row @ symbols == 0`` added (INF when it conflicts)."""
        key = row.tobytes()
        value = self.probes.get(key)
        if value is None:
            value = self.probes[key] = self._probe(row, scale)
        return value

    def _probe(self, row: np.ndarray, scale: float) -> float:
        row, rhs = self._reduce(row, 0.0)
        free = np.abs(row[self.sized :])
        if free.size and free.max() > 1e-9:
            return self.value
        a, rhs = self._orthogonal(row[: self.sized], rhs)
        norm2 = float(a @ a)
        if norm2 <= 1e-18:
            return self.value if abs(rhs) <= 1e-7 * scale else INF
        residual = rhs - float(a @ self.point)
        return self.value + residual * residual / norm2

    def implies_zero(self, row: np.ndarray, scale: float) -> bool:
        """Whether the equalities make ``row @ symbols`` zero."""
        row, rhs = self._reduce(row, 0.0)
        free = np.abs(row[self.sized :])
        if free.size and free.max() > 1e-9:
            return False
        a, rhs = self._orthogonal(row[: self.sized], rhs)
        return float(a @ a) <= 1e-18 and abs(rhs) <= 1e-7 * scale

    def _reduce(self, row: np.ndarray, rhs: float) -> tuple[np.ndarray, float]:
        """The row with the pivot placeholders solved out."""
        for v, pivot, pivot_rhs in self.pivots:
            c = row[v]
            if c != 0.0:
                row = row - c * pivot
                rhs -= c * pivot_rhs
        return row, rhs

    def _orthogonal(self, a: np.ndarray, rhs: float) -> tuple[np.ndarray, float]:
        """The part of a row over the sized symbols that the basis does not span."""
        if len(self.rhs):
            for _ in range(2):  # twice: Gram-Schmidt loses orthogonality once
                c = self.basis @ a
                a = a - c @ self.basis
                rhs -= float(c @ self.rhs)
        return a, rhs

    def bound_within(self, spans: Sequence[tuple[np.ndarray, float]], canvas: float) -> float:
        """The bound strengthened by inequalities ``span @ sizes <= most`` (what a row has
        laid out and still has to lay out must fit the canvas): the most binding one is
        made an equality: with a strictly convex objective, that is where the optimum under
        it lies, so the bound stays a lower bound."""
        best = self.value
        for span, most in spans:
            violation = float(span @ self.point) - most
            if violation <= 1e-9 * max(1.0, canvas):
                continue
            a = span - (self.basis @ span) @ self.basis if len(self.rhs) else span
            norm = float(a @ a)
            if norm <= 1e-12:
                return INF  # the rows fix this span, beyond the canvas
            best = max(best, self.value + violation * violation / norm)
        return best


@dataclass
class _Group:
    name: str
    rows: list[_Row]
    above: list[list[int]]  # rows that may cover each row
    covering: list[list[int]]  # rows each row may make room for (SPEC 2.4, opaque)
    ends: tuple[int, ...]


class _Combining(NamedTuple):
    """What :meth:`_Search.combine` builds the columns out of a state from."""

    group: _Group
    memory: tuple[int, ...]
    order: list[int]  # the rows, those with the fewest options first
    chosen: list[Move | None]  # the column being built, an entry per row
    choices: Callable[[int, tuple[int, Move, np.ndarray] | None], list[Option]]


@dataclass(frozen=True)
class _Node:
    """A state of the search: where each row stands in its group, the attached rule's
    memory (before and after the last column), the equalities so far, where the last
    column ends (over the symbols) and what each row has used of the letter it is inside."""

    group: int
    positions: tuple[int, ...]
    memory: tuple[int, ...]
    system: _System
    x: np.ndarray
    used: tuple[np.ndarray | None, ...]
    path: tuple[Column, ...] = ()
    before: tuple[int, ...] = ()


@dataclass
class _Search:
    spec: Spec
    canvas: float
    groups: list[_Group]
    budget: Budget
    incumbent: float
    variables: dict[str, int]  # symbol -> index: sized symbols first, then placeholders
    target: np.ndarray  # preferred sizes of the sized symbols
    best: Found | None = None
    rejections: dict[str, tuple[int, int]] = field(default_factory=dict)  # (progress, count)
    progress: int = 0  # how far the state being expanded is (sum of positions)
    remaining_cache: dict[tuple[int, int, int], tuple[np.ndarray, list[tuple[int, int]]]] = field(
        default_factory=dict
    )
    whole_cache: dict[tuple[int, int, int, int], np.ndarray] = field(default_factory=dict)
    counts_cache: dict[tuple[int, int], np.ndarray] = field(default_factory=dict)
    options_cache: dict[tuple[int, int, int, bool], Options] = field(default_factory=dict)
    texts: dict[tuple[int, int, int], str] = field(default_factory=dict)  # text(), by row, ends
    gaps: bool = True  # rows may make room for the opaque letters of rows in front
    combinations: int = 0  # partial columns built (a work unit per COMBINATION_WORK)
    sizing_failure: str = ""  # why the last complete alignment could not be sized
    first_only: bool = False  # stop at the first layout found (then nothing is proven)
    existence: bool = False  # stop at the first complete alignment, unsized (see reaches())

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
            return self.reject(self.why(NO_OPAQUE, group, r, entries[r]))
        for r, move in enumerate(entries):
            if move is None:
                if memory[r] == AFTER_ATTACHED:
                    return self.reject(self.why(ATTACHED_GAP, group, r))
                if not any(_opaque(entries[a]) for a in group.covering[r]):
                    return self.reject(self.why(NO_COVER, group, r))
                continue
            if move.first_attached and memory[r] == AFTER_EMPTY:
                return self.reject(self.why(GAP_BEFORE_ATTACHED, group, r, move))
            if move.unoccludable:
                for above in group.above[r]:
                    other = entries[above]
                    if other is not None and not other.transparent:
                        return self.reject(self.why(COVERED, group, r, move, above))
        return True

    def why(
        self, rule: int, group: _Group, r: int, move: Move | None = None, above: int = -1
    ) -> str:
        """Why a column breaks a rule of SPEC 2.4, in the user's words (row r, its entry
        ``move``, and the row ``above`` that would cover it)."""
        if rule == NO_OPAQUE:
            return (
                f"nothing opaque would stand behind or in front of {self.text(group, r, move)} "
                f"of {self.layer(group, r)} (every column needs an opaque layer: mark a symbol "
                "opaque, or let the layers fit)"
            )
        if rule == ATTACHED_GAP:
            return (
                f"an attached letter of {self.layer(group, r)} would be separated from its "
                "neighbour by a gap"
            )
        if rule == NO_COVER:
            return (
                f"{self.layer(group, r)} would need a gap where no layer in front of it has an "
                "opaque letter (only opaque letters of layers in front may make a layer give way)"
            )
        if rule == GAP_BEFORE_ATTACHED:
            return (
                f"{self.text(group, r, move)} of {self.layer(group, r)} is attached, but a gap "
                "would open before it"
            )
        return (
            f"{self.layer(group, above)} would cover unoccludable {self.text(group, r, move)} "
            f"of {self.layer(group, r)}"
        )

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
            joined = group.rows[r].spanning(a.start, b.end)
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
        """An entry in the user's words: its letters, a long one's first and last few and
        how many (a reason names entries of a long row thousands of times)."""
        if move is None:
            return "a gap"
        row = group.rows[r].row
        key = (id(row), move.start, move.end)
        found = self.texts.get(key)
        if found is None:
            whole, parts = sizing.entry_parts(move)
            letters = [row.word[k].symbol for k in sorted({*whole, *parts})]
            if len(letters) > TEXT_LETTERS:
                shown = " ".join(letters[:3]) + " ... " + " ".join(letters[-2:])
                found = f"'{shown}' ({len(letters)} letters)"
            else:
                found = "'" + " ".join(letters) + "'"
            self.texts[key] = found
        return found

    def columns(self, g: int, node: _Node) -> Iterator[tuple[Move | None, ...]]:
        """Every valid column out of a state, but not those where two entries of
        known length could not be as long as each other within the incumbent."""
        group = self.groups[g]
        positions, memory = node.positions, node.memory
        self.progress = sum(positions)
        # each option with its length when known (None: a gap, or a piece as long as the
        # column); the options of a row that fit the first known entry, once per node
        sized = [self.options(g, r, position, node) for r, position in enumerate(positions)]
        fitting: dict[tuple[int, int, int, int], list[Option]] = {}
        # rows with the fewest options first: the first entry of known length is the one
        # the others are checked against
        order = sorted(range(len(sized)), key=lambda r: (len(sized[r][0]), r))

        def choices(r: int, first: tuple[int, Move, np.ndarray] | None) -> list[Option]:
            options, known, lengths = sized[r]
            if first is None:
                return options
            key = (first[0], first[1].start, first[1].end, r)
            kept = fitting.get(key)
            if kept is None:
                fit = self.fitting(lengths, first[2], node.system)
                fine = {j for j, ok in zip(known, fit, strict=True) if ok}
                kept = fitting[key] = [
                    option for j, option in enumerate(options) if option[1] is None or j in fine
                ]
            return kept

        combining = _Combining(group, memory, order, [None] * len(sized), choices)
        yield from self.combine(combining, 0, None, False)

    def combine(
        self, c: _Combining, i: int, first: tuple[int, Move, np.ndarray] | None, solid: bool
    ) -> Iterator[tuple[Move | None, ...]]:
        """The valid columns that complete ``c.chosen`` from its ``i``-th row in
        ``c.order`` on (a method: a closure calling itself would be a cycle holding the
        search, its caches megabytes for a long row, until the garbage collector ran)."""
        self.combinations += 1
        if self.combinations % COMBINATION_WORK == 0:
            self.budget.spend()
        chosen = c.chosen
        if i == len(c.order):
            if self.valid(c.group, chosen, c.memory):
                yield tuple(chosen)
            return
        r = c.order[i]
        last = i == len(c.order) - 1
        for move, length in c.choices(r, first):
            if last and not solid and move is not None and move.plain and move.letters > 1:
                continue  # a stretch of several letters: searched a letter at a time
            chosen[r] = move
            held = solid or not _stands_aside(move)
            if first is None and length is not None and move is not None:
                yield from self.combine(c, i + 1, (r, move, length), held)
            else:
                yield from self.combine(c, i + 1, first, held)
        chosen[r] = None

    def options(self, g: int, r: int, position: int, node: _Node) -> Options:
        """The entries of a row out of ``position`` (None: a gap) with their lengths when
        known, the indices of those, and those lengths as a matrix. At a letter boundary
        this depends on the position alone (cached); inside a split letter, the piece that
        finishes it is as long as what the row has not used of it yet."""
        inside = position % 2 == 1
        key = (g, r, position, self.gaps)
        cached = None if inside else self.options_cache.get(key)
        if cached is not None:
            return cached
        group = self.groups[g]
        moves: list[Move | None] = []
        if position < group.ends[r]:
            moves.extend(group.rows[r].moves(position)[0])
            if self.gaps and not inside and group.covering[r]:
                moves.append(None)  # a gap (not inside a split letter; only under cover)
        else:
            moves.append(None)
        options = [(m, None if m is None else self.known(g, r, m, node)) for m in moves]
        known = [j for j, (_, length) in enumerate(options) if length is not None]
        lengths = np.array([options[j][1] for j in known])
        cached = (options, known, lengths)
        if not inside:
            self.options_cache[key] = cached
        return cached

    def fitting(self, lengths: np.ndarray, first: np.ndarray, system: _System) -> list[bool]:
        """Which entries of known ``lengths`` may be as long as ``first`` within the
        incumbent: first alone (their preferred lengths apart), then with the equalities
        so far."""
        if not len(lengths):
            return []
        differences = lengths - first
        alone = np.zeros(len(lengths))
        plain = ~differences[:, self.sized :].any(axis=1)
        if plain.any():
            d = differences[plain]
            norms = np.einsum("ij,ij->i", d, d)
            misses = d[:, : self.sized] @ self.target
            alone[plain] = np.divide(
                misses * misses, norms, out=np.zeros_like(norms), where=norms > 0
            )
        limit = self.incumbent + SAME
        return [
            bool(value <= limit and system.probe(difference, self.canvas) <= limit)
            for value, difference in zip(alone, differences, strict=True)
        ]

    # -- equalities -------------------------------------------------------------------------
    # A column's entries are as long as each other; the width of a column is the length of
    # an entry of whole letters (an opaque one always is). A row inside a split letter
    # carries the length it has used of it so far; the entry that finishes the letter holds
    # what is left. So lengths are linear in the symbols alone, with no variable per piece.
    @property
    def sized(self) -> int:
        return len(self.target)

    def whole(self, g: int, r: int, move: Move) -> np.ndarray:
        """The length of the letters an entry holds whole, over the symbols."""
        key = (g, r, move.start, move.end)
        vector = self.whole_cache.get(key)
        if vector is None:
            counts = self.counts(g, r)  # the letters (start + 1) // 2 ... end // 2 - 1
            first, last = (move.start + 1) // 2, max(move.end // 2, (move.start + 1) // 2)
            vector = self.whole_cache[key] = counts[last] - counts[first]
        return vector

    def counts(self, g: int, r: int) -> np.ndarray:
        """Row k: how many of each symbol the row's first k letters hold."""
        found = self.counts_cache.get((g, r))
        if found is None:
            word = self.groups[g].rows[r].row.word
            found = np.zeros((len(word) + 1, len(self.variables)))
            for k, letter in enumerate(word):
                found[k + 1] = found[k]
                found[k + 1, self.variables[letter.symbol]] += 1.0
            self.counts_cache[(g, r)] = found
        return found

    def letter(self, g: int, r: int, k: int) -> int:
        return self.variables[self.groups[g].rows[r].row.word[k].symbol]

    def known(self, g: int, r: int, move: Move, node: _Node) -> np.ndarray | None:
        """The length of an entry when it does not depend on the column's width: whole
        letters, and what is left of a split letter it finishes (None for pieces)."""
        if move.tail is not None or move.start == move.end:
            return None
        length = self.whole(g, r, move)
        if move.piece_of is not None:
            length = length.copy()
            length[self.letter(g, r, move.start // 2)] += 1.0
            length -= node.used[r]
        return length

    def child(
        self, g: int, entries: Column, node: _Node
    ) -> tuple[_System | None, np.ndarray, tuple[np.ndarray | None, ...]]:
        """The system, the column's width and what each row has used of the letter it is
        inside, after a column."""
        width = next(
            self.whole(g, r, m)
            for r, m in enumerate(entries)
            if m is not None and m.piece_of is None and m.tail is None
        )
        used = list(node.used)
        system: _System | None = node.system
        for r, move in enumerate(entries):
            if move is None:
                continue
            known = self.whole(g, r, move)
            if move.piece_of is not None:  # inside letter k since an earlier column
                if move.start == move.end:
                    used[r] = used[r] + width
                    continue
                known = known.copy()
                known[self.letter(g, r, move.start // 2)] += 1.0
                known -= used[r]
                used[r] = None
            if move.tail is not None:  # a split letter starts: this column has a piece of it
                used[r] = width - known
            elif known is not width and system is not None:
                system = system.add(known - width, 0.0, self.canvas)
        if system is not None and any(
            self.empty_piece(g, r, move, used[r], system) for r, move in enumerate(entries)
        ):
            system = None
        return system, width, tuple(used)

    def empty_piece(
        self, g: int, r: int, move: Move | None, used: np.ndarray | None, system: _System
    ) -> bool:
        """Whether an entry ends with the first piece of a split letter that the equalities
        make empty, after whole letters. Then the same layout has the letter start in the
        next column (this entry without the piece: the same equalities, one split fewer),
        and that path is searched instead. Not when the letter and the next are of two
        segments: the next column's entries then differ."""
        if move is None or move.tail is None or used is None or move.start == move.end - 1:
            return False
        traits = self.groups[g].rows[r].row.traits
        k = move.end // 2
        if k + 1 < len(traits) and traits[k].segment != traits[k + 1].segment:
            return False
        return system.implies_zero(used, self.canvas)

    def filling(self, system: _System | None) -> _System | None:
        """A row without gaps (no row in front may make room for it, or the run allows
        none) has letters that fill the canvas, whatever the alignment (known before the
        first column)."""
        for group in self.groups:
            for r, prepared in enumerate(group.rows):
                if (self.gaps and group.covering[r]) or system is None:
                    continue
                total = np.zeros(len(self.variables))
                for letter in prepared.row.word:
                    total[self.variables[letter.symbol]] += 1.0
                system = system.add(total, self.canvas, self.canvas)
        return system

    # -- the search -------------------------------------------------------------------------
    def run(self) -> None:
        system = self.filling(_System.empty(self.target))
        if system is None:
            return
        self.dfs(self.start_of(0, system), [])

    def start_of(self, g: int, system: _System) -> _Node:
        count = len(self.groups[g].rows)
        return _Node(
            g, (0,) * count, (FREE,) * count, system, np.zeros(len(self.variables)), (None,) * count
        )

    def dfs(self, node: _Node, done: list[list[Column]]) -> None:
        g = node.group
        group = self.groups[g]
        positions = node.positions
        path = node.path
        if positions == group.ends:
            closed = node.system.add(node.x, self.canvas, self.canvas)
            self.budget.spend()
            if closed is None or closed.value > self.incumbent + SAME:
                return
            finished = [*done, list(path)]
            if g + 1 < len(self.groups):
                self.dfs(self.start_of(g + 1, closed), finished)
            else:
                self.leaf(finished)
            return
        children: list[tuple[tuple[float, int, float, int, int, int], _Node]] = []
        for entries in self.columns(g, node):
            stretch = _stretch(entries)
            if stretch is not None:
                if stretch.letters > 1:  # see _stretch
                    continue
            elif path and self.merges(group, path[-1], entries, node.before):
                continue  # the one column they make is searched too, and is looser
            self.budget.spend()
            system, width, used = self.child(g, entries, node)
            if system is None:
                continue
            after = _advance(entries, positions)
            x = node.x + width
            bound = system.bound_within(self.spans(g, system, x, used, after), self.canvas)
            if bound > self.incumbent + SAME:
                continue
            present = [m for m in entries if m is not None]
            rank = (
                round(bound, 9),
                len(entries) - len(present),
                _spread(entries),
                sum((m.piece_of is not None) + (m.tail is not None) for m in present),
                sum(m.letters for m in present),
                len(children),
            )
            memory = _remember(group, entries, node.memory)
            children.append(
                (rank, _Node(g, after, memory, system, x, used, (*path, entries), node.memory))
            )
        # most promising first: least bound, then the columns that fit at preferred sizes
        # (the paper's column error), whole letters before pieces (split only where
        # needed), no room made before room made, fewer letters (more columns)
        children.sort(key=lambda child: child[0])
        for rank, child in children:
            if rank[0] > self.incumbent + SAME:
                break
            self.dfs(child, done)

    def spans(
        self,
        g: int,
        system: _System,
        x: np.ndarray,
        used: Sequence[np.ndarray | None],
        positions: Sequence[int],
    ) -> list[tuple[np.ndarray, float]]:
        """Inequalities ``span @ sizes <= rhs`` over the sized symbols: where the column ends
        is within the canvas, and so is it plus what each row still has to lay out. A
        placeholder still to come is as long as its expression once the equalities fix it,
        and at least what a row inside it has used so far (the rest is >= 0)."""
        sized = self.sized
        fixed: dict[int, tuple[np.ndarray, float]] = {}
        for v, pivot, rhs in system.pivots:  # v + pivot[sized] @ sizes == rhs
            if np.count_nonzero(pivot[sized:]) == 1:
                fixed[v] = (-pivot[:sized], rhs)
        least: dict[int, tuple[np.ndarray, float]] = {}
        for r, amount in enumerate(used):
            if amount is None:
                continue
            v = self.letter(g, r, positions[r] // 2)
            if (
                v >= sized
                and v not in fixed
                and (amount[sized:] >= -1e-12).all()
                and (v not in least or amount[:sized] @ self.target > least[v][0] @ self.target)
            ):
                least[v] = (amount[:sized], 0.0)
        least.update(fixed)
        grown = x[:sized]
        spans = [(grown, self.canvas)]
        for r, position in enumerate(positions):
            sized_part, counts = self.remaining(g, r, position)
            span, rhs = grown + sized_part, self.canvas
            for v, count in counts:
                if v in least:
                    span = span + count * least[v][0]
                    rhs -= count * least[v][1]
            spans.append((span, rhs))
        return spans

    def remaining(self, g: int, r: int, position: int) -> tuple[np.ndarray, list[tuple[int, int]]]:
        """The sized letters a row still has to lay out whole from ``position``, and how many
        of each placeholder."""
        key = (g, r, position)
        cached = self.remaining_cache.get(key)
        if cached is None:
            vector = np.zeros(self.sized)
            counts: dict[int, int] = {}
            word = self.groups[g].rows[r].row.word
            for letter in word[(position + 1) // 2 :]:
                index = self.variables[letter.symbol]
                if index < self.sized:
                    vector[index] += 1.0
                else:
                    counts[index] = counts.get(index, 0) + 1
            cached = self.remaining_cache[key] = (vector, sorted(counts.items()))
        return cached

    def leaf(self, paths: list[list[Column]]) -> None:
        self.budget.spend(LEAF_WORK)
        if self.existence:
            raise _Perfect
        self.settle(paths)

    def settle(self, paths: list[list[Column]]) -> None:
        """Size a complete alignment (a path per group); keep it if it ranks best."""
        groups = {
            group.name: _alignment(group, path)
            for group, path in zip(self.groups, paths, strict=True)
        }
        program = sizing.build_program(self.spec, groups, self.canvas)
        solved = sizing.search_solve(program)
        if solved is None:
            self.sizing_failure = sizing.explain_infeasible(program)
            return
        # cut into its finest columns, a layout keeps its sizes and has no fewer split
        # letters or holes: one already behind the best before the cut stays behind
        behind = self.best is not None and (
            Found(groups, program, solved).rank[:4] > self.best.rank[:4]
        )
        found = (
            None
            if behind
            else Found(*columns.finest(self.spec, self.canvas, groups, program, solved))
        )
        if found is not None and (self.best is None or found.rank < self.best.rank):
            errors = {
                group.name: _error(path) for group, path in zip(self.groups, paths, strict=True)
            }
            self.best = Found(
                {name: replace(a, error=errors[name]) for name, a in found.groups.items()},
                found.program,
                found.sizing,
            )
            self.incumbent = min(self.incumbent, solved.objective)
        if solved.objective <= SAME or self.first_only:
            raise _Perfect  # nothing deviates less (the search order broke the tie), or
            # only a layout was asked for


class _Compiled:
    """The search of ``_exact.c`` over a :class:`_Search`'s groups: it walks the network
    as :meth:`_Search.run` does, and hands every complete alignment to
    :meth:`_Search.settle` by its cuts; the budget, the incumbent and the rejections end
    up where the Python search keeps them."""

    def __init__(self, search: _Search):
        self.search = search
        groups = [
            [(row.letters, group.above[r], group.covering[r]) for r, row in enumerate(group.rows)]
            for group in search.groups
        ]
        budget = search.budget
        self.table: _exact.Search | None = _exact.Search(
            groups,
            search.variables,
            search.target.tolist(),
            search.canvas,
            search.incumbent,
            budget.limit,
            budget.used,
            budget.deadline,
            search.first_only,
            self.leaf,
        )

    def close(self) -> None:
        """Let the compiled search go: it holds leaf(), which holds it (a cycle that only
        the garbage collector would find), and its moves and options."""
        self.table = None

    def run(self) -> None:
        search = self.search
        assert self.table is not None, "a closed search"
        status = self.table.run(search.gaps)
        search.budget.used = self.table.used
        search.budget.timed_out = self.table.timed_out
        search.incumbent = self.table.incumbent
        if search.best is None:  # the reasons are read only when nothing was found
            self.reasons()
        if status == _EXHAUSTED:
            raise BudgetExhausted
        if status == _STOPPED:
            raise _Perfect

    def reasons(self) -> None:
        """The compiled search's rejections, worded, into the search's (as it counts them)."""
        search = self.search
        search.rejections.clear()
        assert self.table is not None, "a closed search"
        for rule, g, r, above, start, end, progress, count in self.table.rejections():
            group = search.groups[g]
            move = None if start < 0 else group.rows[r].spanning(start, end)
            why = search.why(rule, group, r, move, above)
            before, times = search.rejections.get(why, (0, 0))
            search.rejections[why] = (max(before, progress), times + count)

    def leaf(self, cuts: list[list[tuple[tuple[int, int] | None, ...]]]) -> tuple[float, bool]:
        """Size a complete alignment given by its cuts: the incumbent after it, and whether
        the search should stop."""
        search = self.search
        if search.existence:
            return search.incumbent, True
        paths = [
            [
                tuple(
                    None if cut is None else group.rows[r].spanning(*cut)
                    for r, cut in enumerate(column)
                )
                for column in columns
            ]
            for group, columns in zip(search.groups, cuts, strict=True)
        ]
        try:
            search.settle(paths)
        except _Perfect:
            return search.incumbent, True
        return search.incumbent, False


def _has_opaque(row: Row) -> bool:
    """Only an opaque letter makes a row behind give way (SPEC 2.4)."""
    return any(traits.opaque for traits in row.traits)


def _opaque(move: Move | None) -> bool:
    return move is not None and move.opaque


def _advance(entries: Sequence[Move | None], positions: tuple[int, ...]) -> tuple[int, ...]:
    return tuple(m.end if m is not None else p for m, p in zip(entries, positions, strict=True))


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


def _stands_aside(move: Move | None) -> bool:
    """An entry that leaves a column to the others (see _stretch): empty, inside a
    placeholder, or starting one with nothing before it."""
    return (
        move is None
        or move.middle
        or (move.letters == 1 and move.piece_of is None and move.tail is not None)
    )


def _stretch(entries: Column) -> Move | None:
    """The entry of a *stretch*: a column where one row holds whole sized letters and every
    other row is empty, inside a placeholder it does not finish, or starting one. A stretch
    of several letters is the same layout as a stretch per letter (they add no equality;
    each of its letters is opaque if the column is valid, so each column is covered), so
    the search takes stretches one letter at a time and never merges them: under a long
    placeholder, the row of letters is one column per letter, not every way of grouping
    them."""
    found = None
    for move in entries:
        if move is None or _stands_aside(move):
            continue
        if found is not None or not move.plain:
            return None
        found = move
    return found


def _error(path: Sequence[tuple[Move | None, ...]]) -> float:
    """Eq. 9 summed over a path's columns."""
    return sum(_spread(entries) for entries in path)


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
    """The path as an :class:`Alignment`; its error is left 0 until it is the best (then
    :func:`_error`: most complete layouts a search meets are not)."""
    return Alignment(
        tuple(row.row for row in group.rows),
        tuple(path),
        0.0,
        tuple(0.0 for _ in path),
        tuple(False for _ in path),
    )


def align_exactly(
    spec: Spec,
    groups: Mapping[str, Sequence[Row]],
    canvas: float,
    budget: Budget,
    incumbent: float = INF,
    prepared_rows: dict[Row, _Row] | None = None,
    first_only: bool = False,
    compiled: bool | None = None,
) -> Outcome:
    """The best layout of a candidate's groups (one set of rows per group), searched
    exactly; only layouts with an objective at most ``incumbent`` are looked for.
    ``compiled``: run the search of ``_exact.c`` (the default, :data:`COMPILED`) or the
    Python reference, :class:`_Search`."""
    search = _search_of(spec, groups, canvas, budget, incumbent, prepared_rows, first_only)
    try:
        _run(search, compiled)
    except _Perfect:
        best = search.best
        if best is not None and best.sizing.objective > SAME:  # the first layout, asked for
            return Outcome(best, False, "stopped at the first layout found")
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


def reaches(
    spec: Spec,
    groups: Mapping[str, Sequence[Row]],
    canvas: float,
    budget: Budget,
    incumbent: float,
    prepared_rows: dict[Row, _Row] | None = None,
    compiled: bool | None = None,
) -> bool:
    """Whether the search reaches a complete alignment of the groups within ``incumbent``,
    unsized: its equalities allow that objective, the sizing's bounds unchecked. A quick,
    one-sided answer: False proves that no layout is within ``incumbent``; the budget
    running out answers True."""
    search = _search_of(spec, groups, canvas, budget, incumbent, prepared_rows, True)
    search.existence = True
    try:
        _run(search, compiled)
    except (_Perfect, BudgetExhausted):
        return True
    return False


def _search_of(
    spec: Spec,
    groups: Mapping[str, Sequence[Row]],
    canvas: float,
    budget: Budget,
    incumbent: float,
    prepared_rows: dict[Row, _Row] | None,
    first_only: bool,
) -> _Search:
    known = {} if prepared_rows is None else prepared_rows
    prepared = []
    for name, rows in sorted(groups.items()):
        prepared.append(
            _Group(
                name,
                [prepared_row(row, known) for row in rows],
                [[j for j, other in enumerate(rows) if other.is_above(row)] for row in rows],
                [
                    [j for j, other in enumerate(rows) if other.covers(row) and _has_opaque(other)]
                    for row in rows
                ],
                tuple(2 * len(row.word) for row in rows),
            )
        )
    symbols = {
        name: size for group in prepared for row in group.rows for name, size in row.symbols.items()
    }
    sized = sorted(name for name, size in symbols.items() if size is not None)
    placeholders = sorted(name for name, size in symbols.items() if size is None)
    variables = {name: i for i, name in enumerate([*sized, *placeholders])}
    target = np.array([spec.size(name) for name in sized], dtype=float)
    return _Search(
        spec, canvas, prepared, budget, incumbent, variables, target, first_only=first_only
    )


def _run(search: _Search, compiled: bool | None) -> None:
    """Run a search, compiled (the default, :data:`COMPILED`) or in Python: first without
    gaps (most layouts have none, and gaps multiply the columns out of every state), then
    with them, looking only for better layouts than that one."""
    # the search recurses a column at a time through every group in turn: room for the
    # longest path (a column per half-step of every row, at most), whatever the groups
    depth = sum(max(group.ends, default=0) for group in search.groups) + RECURSION_MARGIN
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, depth))
    table = _Compiled(search) if (COMPILED if compiled is None else compiled) else None
    run = search.run if table is None else table.run
    try:
        if any(any(group.covering) for group in search.groups):
            search.gaps = False
            run()
            search.gaps = True
        run()
    finally:
        sys.setrecursionlimit(limit)
        if table is not None:
            table.close()


Counts = dict[str, tuple[int, float]]  # symbol -> (letters, preferred size)


class Counted(NamedTuple):
    """What :func:`candidate_bound` needs of a word (kept by the word's identity, with the
    word, so that the identity stays its own)."""

    word: Word
    counts: Counts  # its sized letters (only the opaque ones, when asked for those)
    longer: float  # the bound of the word alone, too long for the canvas
    placeholder: bool  # it holds a placeholder (which takes up any shortfall)


def candidate_bound(
    groups: Mapping[str, Sequence[Row]],
    canvas: float,
    counted: dict[tuple[int, bool], Counted] | None = None,
) -> float:
    """A lower bound on the objective of any layout of a candidate's rows, from one row at
    a time (the paper's Eq. 7 with sizes free): a row longer than the canvas at preferred
    sizes must shrink (placeholders only grow); a row without placeholders that is
    shorter must grow, unless opaque letters of the rows in front may cover its gaps: then
    its letters and theirs together must reach the canvas. ``counted``: words counted
    before, on this canvas (the caller keeps it)."""
    known = {} if counted is None else counted

    def counts(row: Row, opaque_only: bool) -> Counted:
        return _counted_word(row.word, row.traits, canvas, opaque_only, known)

    best = 0.0
    for rows in groups.values():
        for row in rows:
            own = counts(row, opaque_only=False)
            if not own.counts:
                continue
            best = max(best, own.longer)
            if own.placeholder:
                continue  # a placeholder takes up any shortfall
            reach = dict(own.counts)
            for other in rows:
                if other.covers(row):
                    for name, (count, size) in counts(other, opaque_only=True).counts.items():
                        reach[name] = (reach.get(name, (0, size))[0] + count, size)
            best = max(best, _excess(reach, canvas, shorter=True))
    return best


def _counted_word(
    word: Word,
    traits: Sequence[LetterTraits],
    canvas: float,
    opaque_only: bool,
    counted: dict[tuple[int, bool], Counted],
) -> Counted:
    """A word counted for :func:`candidate_bound` (kept in ``counted`` by its identity: a
    candidate's words are shared with the others)."""
    found = counted.get((id(word), opaque_only))
    if found is None:
        sized = _sized_counts(word, traits, opaque_only)
        found = counted[id(word), opaque_only] = Counted(
            word, sized, _excess(sized, canvas), any(t.size is None for t in traits)
        )
    return found


def _sized_counts(word: Word, traits: Sequence[LetterTraits], opaque_only: bool) -> Counts:
    """A word's sized letters (opaque ones only, if asked) by symbol, in the order they
    first come (letters are counted at C speed: a word has few distinct ones)."""
    traits_of = dict(zip(word, traits, strict=True))
    counts: Counts = {}
    for letter, count in Counter(word).items():
        its = traits_of[letter]
        if its.size is not None and (its.opaque or not opaque_only):
            before = counts.get(letter.symbol, (0, 0.0))[0]
            counts[letter.symbol] = (before + count, its.size)
    return counts


def _excess(counts: Mapping[str, tuple[int, float]], canvas: float, shorter: bool = False) -> float:
    """Least squared deviation that brings sum(count * size) to the canvas (from above, or
    from below with ``shorter``), all else free."""
    length = sum(count * size for count, size in counts.values())
    miss = canvas - length if shorter else length - canvas
    if miss <= 0.0 or not counts:
        return 0.0
    return miss * miss / sum(count * count for count, _ in counts.values())
