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

The walk through the network is :mod:`facadecli.solver.network`, compiled by Cython where
the install had a C compiler and interpreted where it had none (the same code, the same
answers: :mod:`facadecli.native`); every complete alignment it finds is sized here
(:meth:`_Search.settle`), and its reasons are worded here (:meth:`_Search.why`).
"""

from __future__ import annotations

import gc
import sys
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, NamedTuple

from facadecli import native
from facadecli.patterns import Word
from facadecli.solver import columns, sizing
from facadecli.solver.alignment import INF, Alignment, Move, _Row, prepared_row
from facadecli.solver.budgets import RECURSION_MARGIN, SAME, safety_clock
from facadecli.solver.rows import LetterTraits, Row
from facadecli.spec.model import Spec

if TYPE_CHECKING:
    from facadecli.solver import network
else:  # compiled where it was built from this very source, else interpreted
    network = native.load(native.EXACT_SEARCH)

# the rules a column may break (numbered as network.py numbers them)
NO_OPAQUE, ATTACHED_GAP, NO_COVER, GAP_BEFORE_ATTACHED, COVERED = 1, 2, 3, 4, 5
Column = tuple[Move | None, ...]
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
        if before // 256 != self.used // 256 and safety_clock() > self.deadline:
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
    variables: dict[str, int]  # symbol -> index: sized symbols first, then placeholders
    target: list[float]  # preferred sizes of the sized symbols
    best: Found | None = None
    rejections: dict[str, tuple[int, int]] = field(default_factory=dict)  # (progress, count)
    texts: dict[tuple[int, int, int], str] = field(default_factory=dict)  # text(), by row, ends
    gaps: bool = True  # rows may make room for the opaque letters of rows in front
    sizing_failure: str = ""  # why the last complete alignment could not be sized
    first_only: bool = False  # stop at the first layout found (then nothing is proven)
    existence: bool = False  # stop at the first complete alignment, unsized (see reaches())

    # -- the rules of SPEC 2.4, in the user's words ----------------------------------------
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

    def reasons(self, rejections: list[tuple[int, int, int, int, int, int, int, int]]) -> None:
        """The network's rejections, worded, into the search's (as it counts them)."""
        self.rejections.clear()
        for rule, g, r, above, start, end, progress, count in rejections:
            group = self.groups[g]
            move = None if start < 0 else group.rows[r].spanning(start, end)
            why = self.why(rule, group, r, move, above)
            before, times = self.rejections.get(why, (0, 0))
            self.rejections[why] = (max(before, progress), times + count)

    def leaf(self, cuts: network.Cuts) -> tuple[float, bool]:
        """Size a complete alignment given by its cuts: the incumbent after it, and whether
        the search should stop."""
        if self.existence:
            return self.incumbent, True
        paths = [
            [
                tuple(
                    None if cut is None else group.rows[r].spanning(*cut)
                    for r, cut in enumerate(column)
                )
                for column in columns
            ]
            for group, columns in zip(self.groups, cuts, strict=True)
        ]
        try:
            self.settle(paths)
        except _Perfect:
            return self.incumbent, True
        return self.incumbent, False

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


def _has_opaque(row: Row) -> bool:
    """Only an opaque letter makes a row behind give way (SPEC 2.4)."""
    return any(traits.opaque for traits in row.traits)


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
) -> Outcome:
    """The best layout of a candidate's groups (one set of rows per group), searched
    exactly; only layouts with an objective at most ``incumbent`` are looked for."""
    search = _search_of(spec, groups, canvas, budget, incumbent, prepared_rows, first_only)
    try:
        _run(search)
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
) -> bool:
    """Whether the search reaches a complete alignment of the groups within ``incumbent``,
    unsized: its equalities allow that objective, the sizing's bounds unchecked. A quick,
    one-sided answer: False proves that no layout is within ``incumbent``; the budget
    running out answers True."""
    search = _search_of(spec, groups, canvas, budget, incumbent, prepared_rows, True)
    search.existence = True
    try:
        _run(search)
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
    target = [float(spec.size(name) or 0.0) for name in sized]
    return _Search(
        spec, canvas, prepared, budget, incumbent, variables, target, first_only=first_only
    )


def _run(search: _Search) -> None:
    """Walk the network of a search's groups: first without gaps (most layouts have none,
    and gaps multiply the columns out of every state), then with them, looking only for
    better layouts than that one. Every complete alignment is sized by
    :meth:`_Search.leaf`; the budget, the incumbent and the reasons end up in the search."""
    budget = search.budget
    walk = network.Search(
        [
            [(row.letters, group.above[r], group.covering[r]) for r, row in enumerate(group.rows)]
            for group in search.groups
        ],
        search.variables,
        search.target,
        search.canvas,
        search.incumbent,
        budget.limit,
        budget.used,
        budget.deadline,
        search.first_only,
        search.leaf,
    )
    # the walk recurses a column at a time through every group in turn (interpreted, a
    # frame each): room for the longest path (a column per half-step of every row, at
    # most), whatever the groups
    depth = sum(max(group.ends, default=0) for group in search.groups) + RECURSION_MARGIN
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, depth))
    try:
        if any(any(group.covering) for group in search.groups):
            _walk(search, walk, gaps=False)
        _walk(search, walk, gaps=True)
    finally:
        sys.setrecursionlimit(limit)


def _walk(search: _Search, walk: network.Search, gaps: bool) -> None:
    search.gaps = gaps
    # the walk makes many small objects and no reference cycles: the collector is paused
    # while it runs (it would walk every object of the process, over and over)
    collecting = gc.isenabled()
    gc.disable()
    try:
        status = walk.run(gaps)
    finally:
        if collecting:
            gc.enable()
    search.budget.used = walk.used
    search.budget.timed_out = walk.timed_out
    search.incumbent = walk.incumbent
    if search.best is None:  # the reasons are read only when nothing was found
        search.reasons(walk.rejections())
    if status == network.EXHAUSTED:
        raise BudgetExhausted
    if status == network.PERFECT:
        raise _Perfect


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
