"""One axis end to end: candidates -> alignment per group -> sizing -> placed letters."""

from __future__ import annotations

import heapq
import time
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace

from facadecli.errors import InfeasibleError, SearchLimitError
from facadecli.patterns import (
    CompiledPattern,
    Enumerated,
    Letter,
    Word,
    format_word,
    length_range,
)
from facadecli.solver import columns, construct, exact, sizing, unseen
from facadecli.solver.alignment import (
    INF,
    Alignment,
    AlignmentResult,
    Prefixes,
    _Row,
    align,
)
from facadecli.solver.budgets import (
    CANDIDATE_LIMIT,
    CANDIDATES_TO_TRY,
    CONSTRUCTIONS,
    DEEPENING,
    EFFORT_FACTOR,
    EFFORT_FLOOR,
    EXACT_SHARE,
    EXACT_WORK,
    FEASIBLE_TO_COMPARE,
    FITTED,
    HEURISTIC_WORK,
    MAX_LETTERS,
    MAX_NODES,
    NEAR_CANVAS,
    NEAR_EQUAL,
    PERFECT_REACH,
    REPAIRS,
    SWEEPS,
    TIE,
    TIE_SHARE,
    TIER,
    TRIED,
    VARIANTS,
    WORDS_FITTED,
    safety_clock,
)
from facadecli.solver.candidates import (
    Candidate,
    CandidateSpace,
    PatternUse,
    pattern_uses,
)
from facadecli.solver.rows import (
    Row,
    RowCache,
    WordTraits,
    full_layers,
    letter_traits,
    make_rows,
)
from facadecli.spec.model import Spec
from facadecli.spec.resolve import Axis, layer_pattern

PRECISION = 6  # decimals of metres kept in the layout (micrometres)
# a symbol solved this far from its preferred size is a warning: more than this share of
# it and more than this length (4 cm on a 30 cm string course is no news)
OFF_SHARE, OFF_LENGTH = 0.1, 0.05


@dataclass(frozen=True)
class PlacedLetter:
    """A letter with its solved interval on its axis."""

    symbol: str
    start: float
    end: float
    reflected: bool
    transparent: bool


@dataclass(frozen=True)
class GroupColumns:
    boundaries: tuple[float, ...]
    error: float  # the alignment error (Eq. 9, summed over columns)
    matrix: tuple[tuple[str, ...], ...]  # per row, the text of each entry ("" when empty)
    layers: tuple[tuple[int, ...], ...]  # per row, the layers it stands for


@dataclass(frozen=True)
class AxisLayout:
    axis: Axis
    canvas: float
    letters: Mapping[int, tuple[PlacedLetter, ...]]  # layer index -> letters in order
    symbols: Mapping[str, tuple[float | None, float]]  # name -> (preferred, solved)
    groups: Mapping[str, GroupColumns]
    counters: Mapping[str, int]
    words: Mapping[str, str]  # pattern key -> chosen word, as text
    objective: float
    mu: float
    candidates_tried: int
    warnings: tuple[str, ...] = ()
    proven: bool = False  # no layout has a smaller objective (SPEC 3, ``proof``)
    bound: float = 0.0  # the best lower bound on the objective the solver found
    timings: Mapping[str, float] = field(default_factory=dict)

    def stretched(self, canvas: float) -> AxisLayout:
        """This layout scaled uniformly to another canvas length: every letter, column and
        solved size times ``canvas / self.canvas`` (the words and alignment kept)."""
        k = canvas / self.canvas

        def at(value: float) -> float:
            return round(value * k, PRECISION)

        return replace(
            self,
            canvas=canvas,
            letters={
                layer: tuple(replace(p, start=at(p.start), end=at(p.end)) for p in placed)
                for layer, placed in self.letters.items()
            },
            symbols={name: (pref, at(size)) for name, (pref, size) in self.symbols.items()},
            groups={
                name: replace(g, boundaries=tuple(at(b) for b in g.boundaries))
                for name, g in self.groups.items()
            },
        )


@dataclass
class _Evaluated:
    candidate: Candidate
    groups: dict[str, Alignment]
    program: sizing.Program
    estimate: sizing.Sizing

    @property
    def columns(self) -> int:
        return sum(a.columns for a in self.groups.values())

    @property
    def empties(self) -> int:
        return sum(
            entry is None for a in self.groups.values() for column in a.entries for entry in column
        )

    @property
    def splits(self) -> int:
        """Transparent letters cut into pieces (a last resort, section 5.2): a letter that
        lies across a column boundary rather than on it."""
        return sum(
            entry is not None and entry.tail is not None
            for a in self.groups.values()
            for column in a.entries
            for entry in column
        )

    @property
    def coverage(self) -> float:
        """How much the placeholders cover: the length of all their letters."""
        solved, symbols = self.estimate, self.program.symbols
        return sum(
            solved.of(symbols[letter.symbol])
            for a in self.groups.values()
            for row in a.rows
            for letter, traits in zip(row.word, row.traits, strict=True)
            if traits.size is None
        )

    @property
    def rank(self) -> tuple[float, int, float, int, int, tuple[float, ...]]:
        """SPEC 2.7: least deviation; then most columns; then placeholders covering least;
        then the project's own: fewest sized letters split, fewest holes made (room made
        by layers in front), the candidate order."""
        return (
            self.estimate.objective,
            -self.columns,
            round(self.coverage, 6),
            self.splits,
            self.empties,
            self.candidate.key,
        )


def _beyond_tier(candidate: Candidate, first: Candidate, step: float) -> bool:
    return (
        candidate.need > first.need + step + 1e-9
        or candidate.shortfall > first.shortfall + step + 1e-9
    )


def axis_words(spec: Spec, axis: Axis) -> list[tuple[int, str, str, CompiledPattern]]:
    """(layer index, alignment group, pattern key, pattern) of every enabled layer."""
    found = []
    for index, layer in enumerate(spec.layers):
        if layer.enabled:
            key: str = getattr(layer, axis)
            group: str = getattr(layer.groups, axis)
            found.append((index, group, key, layer_pattern(spec, layer, axis)))
    return found


def _group_rows(
    spec: Spec, uses: Sequence[PatternUse], words: Mapping[str, Enumerated]
) -> dict[str, list[tuple[int, Word]]]:
    groups: dict[str, list[tuple[int, Word]]] = {}
    for use in uses:
        for layer, group in use.layers:
            groups.setdefault(group, []).append((layer, words[use.key].word))
    return groups


@dataclass
class _SearchMemory:
    """Alignments already searched in one axis solve, shared by its candidates."""

    full: frozenset[int]  # layers that show all along the other axis
    traits: WordTraits = field(default_factory=dict)
    groups: dict[tuple[str, tuple[Word, ...]], AlignmentResult] = field(default_factory=dict)
    prefixes: Prefixes = field(default_factory=dict)
    rows: dict[int, dict[str, list[Row]]] = field(default_factory=dict)  # by candidate order
    prepared: dict[Row, _Row] = field(default_factory=dict)  # rows with their moves cached
    made: RowCache = field(default_factory=RowCache)  # make_rows()'s
    counted: dict[tuple[int, bool], exact.Counted] = field(default_factory=dict)
    cores: dict[_CoreKey, _Core] = field(default_factory=dict)  # candidates' relaxations
    relaxed: dict[int, construct.Relaxation] = field(default_factory=dict)  # by order
    bounds: dict[int, float] = field(default_factory=dict)  # candidates' bounds, by order
    sized: sizing.Sized = field(default_factory=dict)  # alignments sized, by what they are


# a candidate without one pattern's layers: that pattern, and the other patterns' words
_CoreKey = tuple[str, tuple[tuple[str, int], ...]]


@dataclass
class _Core:
    """What the searches learnt of a relaxation that candidates share: the candidate
    without the layers of one pattern that covers no other layer (it makes no room for
    another, so without it every other rule holds as before, and the sizing has fewer
    equalities): a layout of a candidate is a layout of its relaxation, no better."""

    failed: int = 0  # candidates with it that had no layout within their search's target
    reason: str = ""  # why the first of them had none
    none_within: float = -INF  # its search proved no layout within this objective
    reached: float = INF  # it has a complete alignment within this objective


@dataclass(frozen=True)
class _Attempt:
    groups: dict[str, Alignment] | None  # None when some group does not align
    nodes: int  # search states visited
    reason: str = ""
    timed_out: bool = False


def _align_candidate(
    spec: Spec,
    uses: Sequence[PatternUse],
    candidate: Candidate,
    canvas: float,
    deadline: float,
    effort: int,
    memory: _SearchMemory,
) -> _Attempt:
    """Align every group of a candidate's words (each group at most once per solve)."""
    mu = max(spec.solver.tolerance, candidate.need)
    aligned: dict[str, Alignment] = {}
    nodes = 0
    for group, members in sorted(_group_rows(spec, uses, candidate.words).items()):
        rows = make_rows(spec, members, memory.full, memory.traits, memory.made)
        key = (group, tuple(row.word for row in rows))
        if key not in memory.groups:
            memory.groups[key] = align(rows, canvas, mu, deadline, effort, memory.prefixes)
        result = memory.groups[key]
        nodes += result.nodes
        if result.alignment is None:
            return _Attempt(None, nodes, f"group '{group}': {result.reason}", result.timed_out)
        aligned[group] = result.alignment
    return _Attempt(aligned, nodes)


def solve_axis_alternatives(
    spec: Spec, axis: Axis, canvas: float, deadline: float, alternatives: int = 1
) -> list[AxisLayout]:
    """The best layouts of one axis, best first: the best, and up to ``alternatives`` - 1
    others whose sizing objective is within NEAR_EQUAL of it (for ``facade vary``).

    Primal first: candidates are laid out by construction (:mod:`facadecli.solver.construct`)
    in the order of their lower bounds; then the exact search
    (:mod:`facadecli.solver.exact`) looks, candidate by candidate, for better layouts and
    proves that none exists; the heuristic alignment offers variations and is a last
    resort. Each layout says whether it is proven optimal, and the best lower bound found.
    Every budget is counted in work (:mod:`facadecli.solver.budgets`), so the answer does
    not depend on the machine; ``deadline`` (:func:`.safety_clock`: CPU seconds) is only a
    safety net, and when it fires the layout says so.

    Raises :class:`InfeasibleError` when no layout exists (proven), and
    :class:`SearchLimitError` when the search stopped before it found one."""
    _check_lengths(spec, axis, canvas)
    problem = _AxisProblem(spec, axis, canvas, deadline, alternatives)
    if alternatives > 1:  # variations: layouts near the best, as the heuristic meets them
        problem.heuristic_pass()
    problem.construct()
    problem.search()
    return problem.layouts()


def _check_lengths(spec: Spec, axis: Axis, canvas: float) -> None:
    """Raise :class:`InfeasibleError` at once when some layer's words cannot fit the canvas
    whatever the search does: the shortest (every letter at its hard ``min``, 0 without one)
    is longer, or the longest (hard ``max``; unbounded without one, for a placeholder or an
    unbounded counter) is shorter while no layer in front could have it make room (SPEC 2.4;
    a layer behind another may leave parts of the canvas empty). A relaxation of the whole
    problem, so it never rejects a spec that has a layout."""
    least = {name: symbol.min for name, symbol in spec.symbols.items()}
    most = {name: symbol.max for name, symbol in spec.symbols.items()}
    counters = {name: counter.bounds for name, counter in spec.counters.items()}
    slack = spec.solver.tolerance + 1e-9 * max(1.0, canvas)
    words = axis_words(spec, axis)
    front = max((layer for layer, _, _, _ in words), default=-1)
    for layer, _, _, pattern in words:
        low, high = length_range(pattern, least=least, most=most, counters=counters)
        name = spec.layers[layer].name
        if low > canvas + slack:
            raise InfeasibleError(
                f"{axis} axis: no layout exists: layer {name} needs at least {low:.2f} m, "
                f"the canvas is {canvas:.2f} m: make the canvas larger, or the symbols' min "
                "or the counters' min smaller"
            )
        if layer == front and high < canvas - slack:
            raise InfeasibleError(
                f"{axis} axis: no layout exists: layer {name} reaches at most {high:.2f} m, "
                f"the canvas is {canvas:.2f} m: make the canvas smaller, or the symbols' max "
                "or the counters' max larger"
            )


class _AxisProblem:
    """One axis of a spec being solved: its patterns' uses, candidates and their bounds,
    the layouts found (incumbents), the work spent and what is proven. The stages are its
    methods, in the order :func:`solve_axis_alternatives` calls them."""

    def __init__(
        self, spec: Spec, axis: Axis, canvas: float, deadline: float, alternatives: int
    ) -> None:
        self.started = time.perf_counter()
        self.spec, self.axis, self.canvas = spec, axis, canvas
        self.deadline, self.alternatives = deadline, alternatives
        self.uses = pattern_uses(spec, axis_words(spec, axis))
        self.tie = tie_window(canvas)
        # a perfect layout of the first candidates, by construction, is optimal: then no
        # other candidate is made (nor searched). Only words that fit the canvas can make
        # one, so it is looked for among those alone first (a quarter of the letters of
        # the words up to twice the canvas that a search needs)
        self.perfect_built: list[_Evaluated] = []
        space = None
        if alternatives == 1:
            space, self.memory, self.perfect_built = _perfect(spec, axis, self.uses, canvas)
        if not self.perfect_built:
            space = CandidateSpace.of(spec, self.uses, canvas)
            leading = [] if space is None else space.best(CONSTRUCTIONS)
            if space is None or not leading:  # within the caps on words: not a proof
                raise SearchLimitError(_no_candidate_reason(axis, canvas))
            self.memory = _SearchMemory(full_layers(spec, axis))
        assert space is not None
        self.space = space
        self.evaluated: list[_Evaluated] = []
        self.candidates = [] if self.perfect_built else space.best(CANDIDATE_LIMIT)
        self.generated = time.perf_counter()
        self.shared = _relaxations(spec, self.uses, self.candidates, self.memory.full)
        self.budget = exact.Budget(EXACT_WORK, deadline)
        self.failures: list[str] = []
        # candidates beyond the list, or cut by a cap, are unseen
        self.truncated = space.truncated or len(self.candidates) >= CANDIDATE_LIMIT
        self.unproven = self.truncated
        self.timed_out = False
        self.tried = 0
        self.step = max(spec.solver.tolerance, TIER * canvas)
        # once something aligned, a candidate that needs far more search than it did is
        # not pursued; nor are candidates once two in a row did worse
        self.effort = MAX_NODES
        self.worse = 0
        self.compare = max(FEASIBLE_TO_COMPARE, alternatives)
        # what is known of each candidate's objective beyond its bound: none within this
        self.above: dict[int, float] = {}
        self.visited: list[int] = []  # search states of each heuristic alignment
        self.heuristic_done = alternatives > 1
        self.bounds = _InBoundOrder(
            self.candidates,
            lambda c: _candidate_bound(spec, self.uses, c, canvas, self.memory),
            _least_bounds(self.uses, canvas, self.memory.full),
        )
        self.perfect = False

    def best_objective(self) -> float:
        return min((e.estimate.objective for e in self.evaluated), default=INF)

    def _spent(self, share: exact.Budget) -> None:
        self.budget.used += share.used
        self.timed_out = self.timed_out or share.timed_out

    def ruled_out(self, candidate: Candidate, target: float) -> str | None:
        """Why the candidate has no layout within ``target``, when a relaxation of it has
        none: known, or searched for (once a candidate sharing it had none) when it may
        have none; None when that is not known."""
        key = self.shared.get(candidate.order)
        core = None if key is None else self.memory.cores.get(key)
        if key is None or core is None:
            return None
        if target <= core.none_within:
            return core.reason
        if core.failed and target < core.reached:
            share = exact.Budget(min(self.budget.left, EXACT_SHARE), self.deadline)
            rows = _relaxed_rows(self.spec, self.uses, candidate, key[0], self.memory)
            found = not rows or exact.reaches(
                self.spec, rows, self.canvas, share, target, self.memory.prepared
            )
            self._spent(share)
            if not found:
                core.none_within = target
                return core.reason
            core.reached = target
        return None

    def search_exactly(self, candidate: Candidate, target: float, tie: bool) -> None:
        """Search a candidate exactly for a layout with an objective at most ``target``;
        ``tie``: it cannot beat the best found, only tie with it: a search for the
        tie-breaks, which ends at its first layout (the least bound first, so the
        candidate's best as a rule) or after a little work, and proves nothing."""
        above = self.above
        why = self.ruled_out(candidate, target)
        if why is not None:
            self.failures.append(why)
            above[candidate.order] = max(above.get(candidate.order, -INF), target)
            return
        rows = _candidate_rows(self.spec, self.uses, candidate, self.memory)
        share = exact.Budget(
            min(self.budget.left, TIE_SHARE if tie else EXACT_SHARE), self.deadline
        )
        outcome = exact.align_exactly(
            self.spec, rows, self.canvas, share, target, self.memory.prepared, first_only=tie
        )
        self._spent(share)
        self.unproven = self.unproven or not (outcome.complete or tie)
        key = self.shared.get(candidate.order)
        if outcome.found is None:
            self.failures.append(outcome.reason)
            if outcome.complete:
                above[candidate.order] = max(above.get(candidate.order, -INF), target)
                if key is not None:  # proven: its relaxation may have none
                    core = self.memory.cores.setdefault(key, _Core(reason=outcome.reason))
                    core.failed += 1
            return
        found = outcome.found
        if outcome.complete and not tie:  # its best is found: nothing of it is left open
            above[candidate.order] = INF
        if key is not None:
            core = self.memory.cores.setdefault(key, _Core())
            core.reached = min(core.reached, found.sizing.objective)
        self.evaluated.append(_Evaluated(candidate, found.groups, found.program, found.sizing))

    def align_heuristically(self, candidate: Candidate) -> float | None:
        """The heuristic alignment of a candidate, sized: its objective, None if none."""
        self.tried += 1
        attempt = _align_candidate(
            self.spec, self.uses, candidate, self.canvas, self.deadline, self.effort, self.memory
        )
        self.visited.append(attempt.nodes)
        self.timed_out = self.timed_out or attempt.timed_out
        if attempt.groups is None:
            return None
        program = sizing.build_program(self.spec, attempt.groups, self.canvas)
        estimate = sizing.search_solve(program)
        if estimate is None:
            return None
        finest = columns.finest(self.spec, self.canvas, attempt.groups, program, estimate)
        self.evaluated.append(_Evaluated(candidate, *finest))
        self.effort = min(self.effort, max(EFFORT_FLOOR, EFFORT_FACTOR * attempt.nodes))
        return estimate.objective

    def heuristic_pass(self) -> None:
        """The heuristic alignment, candidates in the order of the tolerance they need: the
        tolerance is raised only until something aligns (the paper's order and ties)."""
        self.visited.clear()
        evaluated = self.evaluated
        for candidate in self.candidates[:CANDIDATES_TO_TRY]:
            if sum(self.visited) > HEURISTIC_WORK:
                break
            late = safety_clock() > self.deadline
            if len(evaluated) >= self.compare or self.worse >= 2 or late:
                self.timed_out = self.timed_out or late
                break
            if self.alternatives == 1 and evaluated:
                break
            if evaluated and _beyond_tier(candidate, evaluated[0].candidate, self.step):
                break
            before = self.best_objective()
            objective = self.align_heuristically(candidate)
            if objective is None:
                self.worse += 1 if evaluated else 0
            else:
                worse = before < INF and objective > before + 1e-9
                self.worse = self.worse + 1 if worse else 0

    def construct(self) -> None:
        """Primal first: candidates laid out by construction, least bound first, then each
        cluster of patterns' other options in place of the best one's (a layer's words
        chosen given the others); a candidate whose layout meets its bound needs no
        search."""
        built = self.perfect_built or _constructions(
            self.spec, self.uses, self.space, self.candidates, self.canvas, self.memory, self.tie
        )
        self.evaluated.extend(built)
        for e in built:
            if e.estimate.objective <= self.memory.bounds.get(e.candidate.order, -INF) + self.tie:
                self.above[e.candidate.order] = INF
        # a layout at objective 0 is optimal: no candidate can beat it (only tie, and the
        # constructions chose among those)
        self.perfect = self.alternatives == 1 and self.best_objective() <= self.tie

    def search(self) -> None:
        """The exact search, in passes (the paper's iterative deepening, on the exact
        objective): a pass searches every candidate whose lower bound is within its
        threshold for a layout within it, in the order of those bounds, and ends the solve
        once the best layout found is within it: nothing better can exist. Low thresholds
        cut hopeless columns at once, so the first passes are cheap."""
        near = NEAR_EQUAL if self.alternatives > 1 else self.tie
        for threshold in () if self.perfect else DEEPENING:
            self.failures.clear()  # each pass searches again every candidate it reaches:
            self.unproven = self.truncated  # the last one run says what is proven
            for bound, _, candidate in self.bounds:
                # ties too (SPEC 2.7 breaks them); for variations, layouts near the best
                target = min(threshold, self.best_objective() + near)
                if self.timed_out or bound > target:
                    break
                if self.above.get(candidate.order, -INF) >= target:
                    continue  # its best is known, or it has none within the target
                if self.budget.left == 0:
                    self.unproven = True
                    break
                self.search_exactly(candidate, target, bound > self.best_objective() - self.tie)
            if self.timed_out or self.budget.left == 0 or self.best_objective() <= threshold:
                break
            if not self.evaluated and not self.heuristic_done and self.unproven:
                # nothing within the threshold, and the search ran out of work before it
                # proved so: the heuristic's layout, if it finds one, bounds the next
                # passes (they then only look for better ones). A proof needs no such
                # help: the next pass's own threshold bounds it as well
                self.heuristic_done = True
                self.heuristic_pass()
        if not self.evaluated and self.unproven and not self.timed_out and not self.heuristic_done:
            self.heuristic_pass()  # the exact search ran out of work: the heuristic may align

    def never_made(self) -> float:
        """A lower bound on the candidates never made: where a cap cut the list, what the
        rows every candidate has bound; else those with a word beyond the space's reach
        (:mod:`.unseen`, worked out only when the space's own bound does not reach the
        best layout: the relaxation of those rows is a QP of its own)."""
        if not self.truncated and self.space.beyond >= self.best_objective() - self.tie:
            return self.space.beyond
        found = unseen.unseen_bounds(
            self.spec, self.uses, self.space, self.canvas, self.memory.full
        )
        return found.every if self.truncated else found.beyond

    def layouts(self) -> list[AxisLayout]:
        """The layouts found, best first (SPEC 2.7), sized exactly, each with what is
        proven of it."""
        aligned_at = time.perf_counter()
        if self.perfect or not self.evaluated:
            lower = 0.0
        else:
            lower = _lower_bound(
                self.bounds, self.above, self.best_objective(), self.tie, self.never_made()
            )
        layouts: list[AxisLayout] = []
        first: float | None = None
        for choice in _by_rank(self.evaluated, self.tie):
            if first is not None and (
                len(layouts) >= self.alternatives or choice.estimate.objective > first + NEAR_EQUAL
            ):
                break
            final = sizing.exact(choice.program)
            if final is None:
                self.failures.append(sizing.explain_infeasible(choice.program))
                continue
            first = final.objective if first is None else first
            layouts.append(
                _finish(
                    self.spec,
                    self.axis,
                    self.canvas,
                    choice,
                    final,
                    self.uses,
                    self.timed_out,
                    min(lower, first),
                    self.tie,
                )
            )
        if not layouts:
            if self.timed_out:
                raise SearchLimitError(
                    f"{self.axis} axis: the time limit ({self.spec.solver.time_limit:g} s) "
                    "was reached before any layout was found; raise solver.time_limit"
                )
            if self.unproven:
                raise SearchLimitError(
                    f"{self.axis} axis: no layout was found within the search budget "
                    f"({EXACT_WORK:,} work units); a layout may still exist: simplify the "
                    "patterns or fix more counters"
                )
            raise InfeasibleError(_no_layout_reason(self.axis, self.failures))
        timings = {
            "candidates_ms": (self.generated - self.started) * 1000,
            "alignment_ms": (aligned_at - self.generated) * 1000,
            "sizing_ms": (time.perf_counter() - aligned_at) * 1000,
        }
        return [replace(layout, timings=timings, candidates_tried=self.tried) for layout in layouts]


def _perfect(
    spec: Spec, axis: Axis, uses: Sequence[PatternUse], canvas: float
) -> tuple[CandidateSpace | None, _SearchMemory, list[_Evaluated]]:
    """The layouts at objective 0 the constructions find among words no longer than the
    canvas (every word that needs no tolerance, Eq. 7, is one of them), with their space
    and its search memory; none when they find none. Ties among perfect layouts are
    broken within that space, which holds every word that can make one."""
    memory = _SearchMemory(full_layers(spec, axis))
    space = CandidateSpace.of(spec, uses, canvas, reach=PERFECT_REACH)
    leading = [] if space is None else space.best(CONSTRUCTIONS)
    if space is None or not leading:
        return None, memory, []
    tie = tie_window(canvas)
    built = _constructions(spec, uses, space, leading, canvas, memory, tie)
    return space, memory, [e for e in built if e.estimate.objective <= tie]


def tie_window(canvas: float) -> float:
    """How close two objectives (m^2) on an axis of this length are equally good: numerical
    noise, relative to the canvas squared (SPEC 2.7)."""
    return TIE * max(1.0, canvas * canvas)


def _candidate_bound(
    spec: Spec,
    uses: Sequence[PatternUse],
    candidate: Candidate,
    canvas: float,
    memory: _SearchMemory,
    above: float = INF,
) -> float:
    """A lower bound on the objective of a candidate: its relaxation's (kept in
    ``memory.relaxed`` for the constructions) or its rows' one at a time, the larger.
    When the rows' bound alone is beyond ``above``, that one is returned (it is all the
    caller needs) and the relaxation is left for later."""
    known = memory.bounds.get(candidate.order)
    if known is not None:
        return known
    rows = _candidate_rows(spec, uses, candidate, memory)
    bound = exact.candidate_bound(rows, canvas, memory.counted)
    if bound > above:
        return bound
    relaxed = construct.relax(spec, rows, canvas)
    if relaxed is None:  # not even the relaxation has sizes: the candidate has no layout
        bound = INF
    else:
        memory.relaxed[candidate.order] = relaxed
        bound = max(bound, relaxed.bound)
    memory.bounds[candidate.order] = bound
    return bound


def _constructions(
    spec: Spec,
    uses: Sequence[PatternUse],
    space: CandidateSpace,
    candidates: Sequence[Candidate],
    canvas: float,
    memory: _SearchMemory,
    tie: float,
) -> list[_Evaluated]:
    """Layouts by construction (:mod:`facadecli.solver.construct`), best first kept:
    the candidates in their order (CONSTRUCTIONS at most) until one has a layout, the
    first also with the other layers' words fitted to the rows at the back
    (:func:`_fitted_to_backs`), then with each cluster's words of least bound; then that
    layout's variants, a cluster of patterns at a time (SWEEPS passes): of the options
    whose rows fit the layout's other boundaries, the TRIED least covering are laid out,
    and one is kept when it ranks better (SPEC 2.7: less objective, then more columns,
    then placeholders covering less)."""
    made: list[_Evaluated] = []

    def build(candidate: Candidate, fitted: Mapping[str, float] | None = None) -> _Evaluated | None:
        _candidate_bound(spec, uses, candidate, canvas, memory)  # its relaxation, once
        relaxed = memory.relaxed.get(candidate.order)
        if relaxed is None:
            return None
        rows = _candidate_rows(spec, uses, candidate, memory)
        built = construct.construct(
            spec, rows, canvas, memory.prepared, relaxed, tie, fitted, memory.sized
        )
        if built is None:
            return None
        found = _Evaluated(candidate, built.groups, built.program, built.sizing)
        made.append(found)
        return found

    def bound(candidate: Candidate, above: float = INF) -> float:
        return _candidate_bound(spec, uses, candidate, canvas, memory, above)

    def descended(candidate: Candidate) -> Candidate:
        """The candidate with each cluster's option of least bound, the others kept, until
        no cluster changes (SWEEPS passes): the words of one layer chosen to fit the
        others', as a perfect layout's must."""
        for _ in range(SWEEPS):
            changed = False
            for cluster in range(len(space.clusters)):
                for variant in space.variants(candidate, cluster, VARIANTS):
                    least = bound(candidate) - tie
                    if bound(variant, least) < least:
                        candidate, changed = variant, True
            if not changed:
                break
        return candidate

    best: _Evaluated | None = None
    for number, candidate in enumerate(candidates[:CONSTRUCTIONS]):
        best = build(candidate)
        if number == 0 and (best is None or best.estimate.objective > tie):
            # the others' words fitted to the rows at the back
            fitted, lengths = _fitted_to_backs(spec, uses, space, candidate, canvas, memory, tie)
            found = build(fitted, lengths)
            if found is not None and (best is None or _better(found, best, tie)):
                best = found
        if best is None and number == 0:  # each cluster's words of least bound
            descent = descended(candidate)
            best = None if descent is candidate else build(descent)
        if best is not None:
            break
    if best is None:
        return made
    pattern_of = _pattern_of(uses)
    laid: tuple[_Evaluated, LaidRows] | None = None  # the best layout's rows, laid once
    for _ in range(SWEEPS):
        improved = False
        if best.estimate.objective <= tie:  # every cluster's tie-break at once
            joint = _least_covering_together(spec, uses, space, best, canvas, memory, tie)
            found = None if joint is None else build(joint)
            if found is not None and _better(found, best, tie):
                best, improved = found, True
        for cluster in range(len(space.clusters)):
            keys = {use.key for use in space.clusters[cluster]}
            if laid is None or laid[0] is not best:
                laid = (best, _laid_rows(best))
            points = _points_without(laid[1], keys, pattern_of)
            # the options whose rows fit the layout's other boundaries, least covering
            # first (SPEC 2.7's last tie-break; those covering as little as the
            # layout's own do not beat it): built until one improves it
            perfect = best.estimate.objective <= tie  # only the tie-breaks can improve it
            words = best.candidate.words
            own = _covering({key: words[key] for key in keys}, canvas)
            others = {key: word for key, word in words.items() if key not in keys}
            fitting = []
            for option in space.options[cluster][:VARIANTS]:
                if all(option[key] is words[key] for key in keys):
                    continue
                if perfect and _covering(option, canvas) >= own - tie:
                    continue  # it cannot improve the tie-breaks
                variant = space.candidate([others, option])
                covered = _fits_among(spec, uses, variant, keys, pattern_of, points, canvas, memory)
                if covered is None:
                    continue  # it cannot fit
                least = 0.0 if perfect else bound(variant, best.estimate.objective + tie)
                if least <= best.estimate.objective + tie:
                    fitting.append((least, covered, variant.order, variant))
            for *_, variant in sorted(fitting, key=lambda item: item[:3])[:TRIED]:
                found = build(variant)
                if found is not None and _better(found, best, tie):
                    best, improved = found, True
                    break
        if not improved:
            break
    return made


Fits = list[tuple[str, Row, dict[str, float]]]  # (group, row, every letter's size) per row
Placed = dict[str, list[tuple[Row, Mapping[str, float]]]]  # per group, rows laid and sizes


def _fitted_to_backs(
    spec: Spec,
    uses: Sequence[PatternUse],
    space: CandidateSpace,
    candidate: Candidate,
    canvas: float,
    memory: _SearchMemory,
    tie: float,
) -> tuple[Candidate, dict[str, float] | None]:
    """The candidate with each cluster's words chosen on their own to fit the rows at the
    back of their groups (the base: its boundaries laid at the relaxation's sizes): the
    first option (best first, VARIANTS at most) whose rows end every visible letter on
    one of those boundaries and fill the canvas (:func:`construct.fit`). Layers that meet
    only through the base's columns align independently given them. With it, the sizes
    the fits found (every symbol's, when each row was laid; else None)."""
    pattern_of = _pattern_of(uses)
    rows = _candidate_rows(spec, uses, candidate, memory)
    # the patterns of the rows at the back (a layer's place in its group is the spec's)
    at_back = {pattern_of[layer] for members in rows.values() for layer in members[0].layers}
    candidate, tied = _backs_chosen(spec, uses, space, candidate, canvas, memory, tie, at_back)
    fitting = _BackFitting.of(
        spec, uses, space, candidate, canvas, memory, tied, pattern_of, at_back
    )
    if fitting is None:
        return candidate, None
    # the clusters with fewest placeholders first: their rows have least choice; passes
    # again with the clusters in conflict first (their rows are the rigid ones)
    order = sorted(
        range(len(space.clusters)), key=lambda c: (fitting.open_letters(candidate, c), c)
    )
    for _ in range(REPAIRS):
        candidate, conflicted = fitting.laid_in(order, candidate)
        if not conflicted:
            break
        order = conflicted + [cluster for cluster in order if cluster not in conflicted]
    return candidate, fitting.sizes_found()


def _backs_chosen(
    spec: Spec,
    uses: Sequence[PatternUse],
    space: CandidateSpace,
    candidate: Candidate,
    canvas: float,
    memory: _SearchMemory,
    tie: float,
    at_back: set[str],
) -> tuple[Candidate, dict[int, list[dict[str, Enumerated]]]]:
    """The candidate with each cluster holding a group's back row (one of the patterns
    ``at_back``) at the option whose back rows fit the canvas best on their own; with,
    per such cluster, its options as good (VARIANTS at most)."""
    tied: dict[int, list[dict[str, Enumerated]]] = {}
    for cluster, members in enumerate(space.clusters):
        keys = {use.key for use in members}
        if not keys & at_back:
            continue
        options = [candidate, *space.variants(candidate, cluster, VARIANTS)]
        bounds = [_backs_bound(spec, uses, option, canvas, memory) for option in options]
        least = min(bounds)
        tied[cluster] = [
            {key: option.words[key] for key in keys}
            for option, bound in zip(options, bounds, strict=True)
            if bound <= least + tie
        ]
        candidate = options[bounds.index(least)]
    return candidate, tied


def _pattern_of(uses: Sequence[PatternUse]) -> dict[int, str]:
    """The pattern of every layer (by index) on the axis."""
    return {layer: use.key for use in uses for layer, _ in use.layers}


@dataclass
class _BackFitting:
    """The other clusters' words fitted to the backs laid at their relaxation's sizes
    (:func:`_fitted_to_backs`): the backs' boundaries, the sizes known, and the rows
    placed so far (a row chosen later keeps its turns between transparent and visible
    out of their visible letters, and theirs out of its own)."""

    spec: Spec
    uses: Sequence[PatternUse]
    space: CandidateSpace
    canvas: float
    memory: _SearchMemory
    tied: dict[int, list[dict[str, Enumerated]]]  # per back cluster, its options as good
    pattern_of: dict[int, str]
    at_back: set[str]  # patterns with a row at the back of a group
    backs: dict[str, Row]  # per group
    laid: dict[str, float]  # the backs' sizes
    points: dict[str, list[float]]  # per group, the backs' boundaries
    sizes: dict[str, float]  # sized symbols, at the relaxation's sizes
    placed: Placed = field(default_factory=dict)

    @classmethod
    def of(
        cls,
        spec: Spec,
        uses: Sequence[PatternUse],
        space: CandidateSpace,
        candidate: Candidate,
        canvas: float,
        memory: _SearchMemory,
        tied: dict[int, list[dict[str, Enumerated]]],
        pattern_of: dict[int, str],
        at_back: set[str],
    ) -> _BackFitting | None:
        """The backs of the candidate laid; None when their relaxation has no solution."""
        rows = _candidate_rows(spec, uses, candidate, memory)
        backs = {group: members[0] for group, members in rows.items() if members}
        alone = {group: [row] for group, row in backs.items()}
        relaxed = construct.relax(spec, alone, canvas)
        if relaxed is None:
            return None
        laid = construct.placeholders_laid(alone, relaxed, canvas) or dict(relaxed.lengths)
        return cls(
            spec,
            uses,
            space,
            canvas,
            memory,
            tied,
            pattern_of,
            at_back,
            backs,
            laid,
            {group: construct.boundaries(row, laid) for group, row in backs.items()},
            {name: size for name, size in relaxed.lengths.items() if spec.size(name) is not None},
        )

    def own_rows(self, variant: Candidate, keys: set[str]) -> list[tuple[str, Row]]:
        """The rows of the patterns ``keys`` in ``variant``, with their groups."""
        grouped = _candidate_rows(self.spec, self.uses, variant, self.memory)
        return [
            (group, row)
            for group, members in grouped.items()
            for row in members
            if any(self.pattern_of[layer] in keys for layer in row.layers)
        ]

    def open_letters(self, candidate: Candidate, cluster: int) -> int:
        """How many placeholders the cluster's rows have in the candidate."""
        keys = {use.key for use in self.space.clusters[cluster]}
        rows = self.own_rows(candidate, keys)
        return sum(traits.size is None for _, row in rows for traits in row.traits)

    def fitted(
        self, variant: Candidate, keys: set[str], apart: bool, more: Placed | None = None
    ) -> Fits | None:
        """The rows of the patterns ``keys`` in ``variant`` fitted to the backs' points,
        and (``apart``) to the rows placed, ``more`` and each other; None when one does
        not fit."""
        own = self.own_rows(variant, keys)
        known = {**_sized(self.spec, [row for _, row in own]), **self.sizes}
        found: Fits = []
        for group, row in own:
            if group not in self.points:
                return None
            back = self.backs[group]
            if row == back:
                continue  # laid
            if any(layer in back.layers for layer in row.layers):
                return None  # another word at the back: the backs are laid
            laid = construct.NOTHING_LAID
            if apart:  # one cluster's words must fit each other as well as the others'
                mine = [(other, lengths) for g, other, lengths in found if g == group]
                extra = [] if more is None else more.get(group, [])
                laid = construct.laid_for(row, [*self.placed[group], *extra, *mine])
            fit = construct.fit(row, known, self.points[group], self.canvas, laid)
            if fit is None:
                return None
            found.append((group, row, {**known, **fit}))
        return found

    def options_of(self, candidate: Candidate, cluster: int, keys: set[str]) -> Iterable[Candidate]:
        """The candidate, then with the cluster's other options to try, in order."""
        if cluster not in self.tied:
            return _least_covering_first(self.space, candidate, cluster, FITTED)
        # the backs' words are chosen: only their options as good
        others = {key: word for key, word in candidate.words.items() if key not in keys}
        return [candidate] + [
            self.space.candidate([others, option])
            for option in self.tied[cluster]
            if any(option[key] is not candidate.words[key] for key in keys)
        ]

    def piecewise(self, candidate: Candidate, cluster: int) -> tuple[Candidate, Fits] | None:
        """The cluster's words chosen a pattern at a time, given the counters set so far
        (the back's first): a pattern's alternatives are independent of the others' once
        the counters they share agree, so each takes its first word (least tolerance
        first) whose rows fit the backs and the rows placed, its own cluster's included.
        None when a pattern has no such word among WORDS_FITTED."""
        space = self.space
        members = space.clusters[cluster]
        chosen = {u.key: candidate.words[u.key] for u in members if u.key in self.at_back}
        counters: dict[str, int] = {}
        for item in chosen.values():
            counters.update(item.choice.counters)
        mine: Placed = {}
        found: Fits = []
        for use in members:
            if use.key in chosen:
                continue
            for item in space.words[use.key][:WORDS_FITTED]:
                values = item.choice.counters
                if any(counters.get(name, value) != value for name, value in values.items()):
                    continue
                variant = space.candidate([dict(candidate.words), {**chosen, use.key: item}])
                fits = self.fitted(variant, {use.key}, True, mine)
                if fits is not None:
                    chosen[use.key] = item
                    counters.update(values)
                    for group, row, lengths in fits:
                        mine.setdefault(group, []).append((row, lengths))
                    found.extend(fits)
                    break
            else:
                return None
        return space.candidate([dict(candidate.words), chosen]), found

    def laid_in(self, order: Sequence[int], candidate: Candidate) -> tuple[Candidate, list[int]]:
        """One pass over the clusters in ``order``: each takes its first option whose rows
        fit the backs and the rows placed so far (or its words chosen a pattern at a time,
        :meth:`piecewise`; or, failing that, an option that fits the backs alone: it is in
        conflict)."""
        self.placed = {group: [(row, self.laid)] for group, row in self.backs.items()}
        conflicted = []
        for cluster in order:
            keys = {use.key for use in self.space.clusters[cluster]}
            for apart in (True, False):
                tried = self.options_of(candidate, cluster, keys)
                chosen = next(
                    ((v, f) for v in tried if (f := self.fitted(v, keys, apart)) is not None),
                    None,
                )
                if chosen is None and apart and len(self.space.clusters[cluster]) > 1:
                    chosen = self.piecewise(candidate, cluster)
                if chosen is not None:
                    candidate = chosen[0]
                    for group, row, lengths in chosen[1]:
                        self.placed[group].append((row, lengths))
                    if not apart:
                        conflicted.append(cluster)
                    break
        return candidate, conflicted

    def sizes_found(self) -> dict[str, float]:
        """Every size the rows placed were laid at."""
        found: dict[str, float] = {}
        for rows in self.placed.values():
            for _, lengths in rows:
                found.update(lengths)
        return found


def _least_covering_together(
    spec: Spec,
    uses: Sequence[PatternUse],
    space: CandidateSpace,
    layout: _Evaluated,
    canvas: float,
    memory: _SearchMemory,
    tie: float,
) -> Candidate | None:
    """A perfect layout's candidate with every cluster's option that covers least of those
    covering less than its own and fitting the layout's other boundaries
    (:func:`_fits_among`), all at once: one layout to build where a sweep builds one per
    cluster. None when no cluster has such an option."""
    pattern_of = _pattern_of(uses)
    words = layout.candidate.words
    chosen: dict[str, Enumerated] = {}
    laid = _laid_rows(layout)
    for cluster, members in enumerate(space.clusters):
        keys = {use.key for use in members}
        points = _points_without(laid, keys, pattern_of)
        own = _covering({key: words[key] for key in keys}, canvas)
        others = {key: word for key, word in words.items() if key not in keys}
        options = space.options[cluster][:VARIANTS]
        covers = sorted(
            ((_covering(option, canvas), i) for i, option in enumerate(options)),
        )
        for cover, i in covers:
            option = options[i]
            if cover >= own - tie:
                break
            variant = space.candidate([others, option])
            if (
                _fits_among(spec, uses, variant, keys, pattern_of, points, canvas, memory)
                is not None
            ):
                chosen.update(option)
                break
    if not chosen:
        return None
    return space.candidate([dict(words), chosen])


def _least_covering_first(
    space: CandidateSpace, candidate: Candidate, cluster: int, most: int
) -> Iterator[Candidate]:
    """The candidate with each of a cluster's first ``most`` options (its own too), those
    whose placeholders cover least first (:func:`_covering`), made as they are needed."""
    keys = {use.key for use in space.clusters[cluster]}
    words = candidate.words
    others = {key: word for key, word in words.items() if key not in keys}
    chosen = [{key: words[key] for key in keys}, *space.options[cluster][:most]]
    for i in sorted(range(len(chosen)), key=lambda i: (_covering(chosen[i], space.canvas), i)):
        if i == 0:
            yield candidate
        elif any(chosen[i][key] is not words[key] for key in keys):
            yield space.candidate([others, chosen[i]])


def _covering(option: Mapping[str, Enumerated], canvas: float) -> float:
    """How much the placeholders of an option's words cover when they fill the canvas at
    preferred sizes (what the words' sized letters leave of it; SPEC 2.7's last
    tie-break); infinite when a word fits the canvas only with sizes off their preferred."""
    total = 0.0
    for word in option.values():
        if word.elastic and word.length <= canvas:
            total += canvas - word.length
        elif abs(word.length - canvas) > NEAR_CANVAS * canvas:
            return INF
    return total


@dataclass(frozen=True)
class LaidRows:
    """A sized layout's rows laid out, per group: each row's boundaries, and how many rows
    have a boundary at each point (so the points of all rows but a few are found by
    taking those few away)."""

    rows: dict[str, list[tuple[Row, list[float]]]]
    counts: dict[str, Counter[float]]


def _laid_rows(layout: _Evaluated) -> LaidRows:
    """Per group, a sized layout's rows with their boundaries."""
    program, solved = layout.program, layout.estimate
    lengths = {name: solved.of(index) for name, index in program.symbols.items()}
    rows = {
        group: [(row, construct.boundaries(row, lengths)) for row in alignment.rows]
        for group, alignment in layout.groups.items()
    }
    counts = {group: Counter(p for _, x in laid for p in set(x)) for group, laid in rows.items()}
    return LaidRows(rows, counts)


def _points_without(
    laid: LaidRows, keys: set[str], pattern_of: Mapping[int, str]
) -> dict[str, list[float]]:
    """Per group, the boundaries of a sized layout's rows (:func:`_laid_rows`), but those
    of the patterns ``keys`` (the rows another option of theirs must meet)."""
    points: dict[str, list[float]] = {}
    for group, rows in laid.rows.items():
        counts = laid.counts[group]
        left = [set(x) for row, x in rows if any(pattern_of[layer] in keys for layer in row.layers)]
        if not left:
            points[group] = sorted(counts)
            continue
        counts = counts.copy()
        for own in left:
            counts.subtract(own)
        points[group] = sorted(p for p, n in counts.items() if n > 0)
    return points


def _fits_among(
    spec: Spec,
    uses: Sequence[PatternUse],
    candidate: Candidate,
    keys: set[str],
    pattern_of: Mapping[int, str],
    points: Mapping[str, list[float]],
    canvas: float,
    memory: _SearchMemory,
) -> float | None:
    """How much the placeholders of the patterns ``keys`` in a candidate cover when their
    rows fit ``points`` at preferred sizes (:func:`construct.coverage`); None when one
    does not fit. Rows of a group with no points fit and cover nothing."""
    rows = _candidate_rows(spec, uses, candidate, memory)
    total = 0.0
    for group, members in rows.items():
        own = [row for row in members if any(pattern_of[i] in keys for i in row.layers)]
        if not own or not points.get(group):
            continue
        sizes = _sized(spec, own)
        for row in own:
            covered = construct.coverage(row, sizes, points[group], canvas)
            if covered is None:
                return None
            total += covered
    return total


def _backs_bound(
    spec: Spec,
    uses: Sequence[PatternUse],
    candidate: Candidate,
    canvas: float,
    memory: _SearchMemory,
) -> float:
    """How far the back row of each group is from fitting the canvas on its own (the
    rows' bound of :func:`exact.candidate_bound`, over those rows alone)."""
    rows = _candidate_rows(spec, uses, candidate, memory)
    backs = {group: [members[0]] for group, members in rows.items() if members}
    return exact.candidate_bound(backs, canvas, memory.counted)


def _sized(spec: Spec, rows: Sequence[Row]) -> dict[str, float]:
    """The preferred sizes of the rows' sized symbols."""
    sizes = {}
    for row in rows:
        for letter in row.word:
            size = spec.size(letter.symbol)
            if size is not None:
                sizes[letter.symbol] = size
    return sizes


def _better(a: _Evaluated, b: _Evaluated, tie: float) -> bool:
    """Whether ``a`` ranks before ``b`` (SPEC 2.7, objectives within ``tie`` equal)."""
    if abs(a.estimate.objective - b.estimate.objective) > tie:
        return a.estimate.objective < b.estimate.objective
    return a.rank[1:] < b.rank[1:]


def _lower_bound(
    bounds: _InBoundOrder,
    above: Mapping[int, float],
    best: float,
    tie: float,
    never_made: float,
) -> float:
    """The best lower bound on the axis' objective once the searches are done: the least
    bound of a candidate whose layouts were not all ruled out below ``best`` (each beyond
    what its searches proved), or ``best`` itself when there is none, and ``never_made``,
    the bound of the candidates never generated (:meth:`_AxisProblem.never_made`)."""
    lower = min(best, never_made)
    for bound, _, candidate in bounds:
        if bound >= lower - tie:
            break
        lower = min(lower, max(bound, above.get(candidate.order, -INF)))
    return lower


def _by_rank(evaluated: Sequence[_Evaluated], tie: float) -> list[_Evaluated]:
    """Best first (SPEC 2.7): layouts within ``tie`` of the least objective are equally good,
    and among them the tie-breaks decide (placeholders covering least, more columns)."""
    if not evaluated:
        return []
    best: dict[object, _Evaluated] = {}  # one layout a candidate (the heuristic and the
    for e in evaluated:  # exact search may both have aligned it): its best
        kept = best.get(e.candidate.key)
        if kept is None or e.estimate.objective < kept.estimate.objective - 1e-12:
            best[e.candidate.key] = e
    evaluated = list(best.values())
    least = min(e.estimate.objective for e in evaluated)
    good = sorted(
        (e for e in evaluated if e.estimate.objective <= least + tie), key=lambda e: e.rank[1:]
    )
    rest = sorted(
        (e for e in evaluated if e.estimate.objective > least + tie), key=lambda e: e.rank
    )
    return [*good, *rest]


def _candidate_rows(
    spec: Spec, uses: Sequence[PatternUse], candidate: Candidate, memory: _SearchMemory
) -> dict[str, list[Row]]:
    rows = memory.rows.get(candidate.order)
    if rows is None:
        rows = memory.rows[candidate.order] = _rows_of(spec, uses, candidate, memory)
    return rows


def _rows_of(
    spec: Spec, uses: Sequence[PatternUse], candidate: Candidate, memory: _SearchMemory
) -> dict[str, list[Row]]:
    """The rows of each group that the layers of ``uses`` make with the candidate's words."""
    return {
        group: make_rows(spec, members, memory.full, memory.traits, memory.made)
        for group, members in _group_rows(spec, uses, candidate.words).items()
    }


class _InBoundOrder:
    """Candidates with their lower bounds (``bound``), least first (on a tie by key), as
    the passes of the exact search read them: a candidate's rows are made and its bound
    found only once the passes get near it. ``least`` is a bound on ``bound`` that needs no
    rows: candidates are taken in its order, and one is handed on once no candidate left
    can come before it (``least`` is beyond its bound)."""

    def __init__(
        self,
        candidates: Sequence[Candidate],
        bound: Callable[[Candidate], float],
        least: Callable[[Candidate], float],
    ):
        self.bound = bound
        self.waiting = sorted((least(c), c.key, c) for c in candidates)
        self.next = 0  # the first waiting candidate whose bound is not found yet
        self.found: list[tuple[float, tuple[float, float, float, int], Candidate]] = []  # a heap
        self.ordered: list[tuple[float, tuple[float, float, float, int], Candidate]] = []

    def __iter__(self) -> Iterator[tuple[float, tuple[float, float, float, int], Candidate]]:
        at = 0
        while True:
            if at == len(self.ordered):
                while self.next < len(self.waiting) and (
                    not self.found or self.waiting[self.next][0] <= self.found[0][0]
                ):
                    _, key, candidate = self.waiting[self.next]
                    self.next += 1
                    heapq.heappush(self.found, (self.bound(candidate), key, candidate))
                if not self.found:
                    return
                self.ordered.append(heapq.heappop(self.found))
            yield self.ordered[at]
            at += 1


def _least_bounds(
    uses: Sequence[PatternUse], canvas: float, full: frozenset[int]
) -> Callable[[Candidate], float]:
    """A bound on a candidate's bound from its words' lengths alone (no rows, no letters
    looked at): what :func:`exact.candidate_bound` finds of a row, a word too long for the
    canvas, or too short when nothing in front can make room in it and it has no
    placeholder, is the miss squared over the sum of its symbols' counts squared, and
    that sum is at most the word's letters squared."""
    uncovered = {
        use.key: not any(
            other > layer and other in full and other_group == group
            for layer, group in use.layers
            for other_use in uses
            for other, other_group in other_use.layers
        )
        for use in uses
    }

    def least(candidate: Candidate) -> float:
        best = 0.0
        for use in uses:
            item = candidate.words[use.key]
            miss = item.length - canvas
            if miss < 0.0 and uncovered[use.key] and not item.elastic:
                miss = -miss
            if miss > 0.0 and item.word:
                best = max(best, miss * miss / (len(item.word) * len(item.word)))
        return best

    return least


def _relaxations(
    spec: Spec, uses: Sequence[PatternUse], candidates: Sequence[Candidate], full: frozenset[int]
) -> dict[int, _CoreKey]:
    """Per candidate (by its order), the relaxation it shares with the most others, if
    any: without a pattern whose layers cover no other layer and whose word has no opaque
    letter (so that no column loses its opaque backing; see :class:`_Core`)."""
    covering_none = [use.key for use in uses if not any(i in full for i, _ in use.layers)]
    opaque: dict[Letter, bool] = {}
    keys: dict[int, list[_CoreKey]] = {}
    sharing: dict[_CoreKey, int] = {}
    for candidate in candidates:
        words = [(use.key, id(candidate.words[use.key].word)) for use in uses]
        droppable = []
        for pattern in covering_none:
            letters = set(candidate.words[pattern].word)
            for letter in letters.difference(opaque):
                opaque[letter] = letter_traits(spec, letter).opaque
            if not any(opaque[letter] for letter in letters):
                droppable.append(pattern)
        keys[candidate.order] = [
            (left_out, tuple(pair for pair in words if pair[0] != left_out))
            for left_out in droppable
        ]
        for key in keys[candidate.order]:
            sharing[key] = sharing.get(key, 0) + 1
    best = {}
    for order, found in keys.items():
        most = max(found, key=lambda key: sharing[key], default=None)  # the first on a tie
        if most is not None and sharing[most] > 1:
            best[order] = most
    return best


def _relaxed_rows(
    spec: Spec,
    uses: Sequence[PatternUse],
    candidate: Candidate,
    left_out: str,
    memory: _SearchMemory,
) -> dict[str, list[Row]]:
    """A candidate's rows without the layers of one pattern (groups left empty dropped)."""
    return _rows_of(spec, [use for use in uses if use.key != left_out], candidate, memory)


def solve_axis(spec: Spec, axis: Axis, canvas: float, deadline: float) -> AxisLayout:
    """Solve one axis; raises :class:`InfeasibleError` with the reason when nothing fits."""
    return solve_axis_alternatives(spec, axis, canvas, deadline, alternatives=1)[0]


def _finish(
    spec: Spec,
    axis: Axis,
    canvas: float,
    choice: _Evaluated,
    final: sizing.Sizing,
    uses: Sequence[PatternUse],
    timed_out: bool,
    lower: float,
    tie: float,
) -> AxisLayout:
    """The placed letters of a chosen candidate, with the warnings a user should see;
    ``lower``: the best lower bound found on its objective. It is proven when the bound
    reaches its objective as sized exactly or as the searches sized it (the same program:
    on a large objective, two QP solvers' optima differ by their precision, 1e-8 of it,
    more than the noise of the canvas, ``tie``)."""
    warnings = []
    proven = lower >= min(final.objective, choice.estimate.objective) - tie
    if not proven:
        warnings.append(
            f"{axis}: the layout is not proven optimal: its objective is {final.objective:.6g} "
            f"m2, the best lower bound found {lower:.6g} m2 (the search stopped at its work "
            "budget, or a cap on the words left candidates unseen)"
        )
    if timed_out:
        warnings.append(
            f"{axis}: the time limit ({spec.solver.time_limit:g} s) ran out; "
            "this is the best layout found so far"
        )
    layout = _place(spec, axis, canvas, choice, final, uses)
    layout = replace(layout, proven=proven, bound=round(min(lower, final.objective), 9))
    for name, (preferred, size) in layout.symbols.items():
        if preferred and abs(size - preferred) > max(OFF_SHARE * preferred, OFF_LENGTH):
            warnings.append(
                f"{axis}: symbol '{name}' is {size:.3f} m, more than 10% off its "
                f"preferred {preferred:g} m"
            )
    return replace(layout, warnings=tuple(warnings))


def _place(
    spec: Spec,
    axis: Axis,
    canvas: float,
    choice: _Evaluated,
    final: sizing.Sizing,
    uses: Sequence[PatternUse],
) -> AxisLayout:
    program = choice.program
    letters: dict[int, tuple[PlacedLetter, ...]] = {}
    groups: dict[str, GroupColumns] = {}
    for group, alignment in sorted(choice.groups.items()):
        starts = sizing.column_starts(final, program, group, alignment.columns)
        bounds = [round(b, PRECISION) for b in starts]
        bounds[-1] = round(canvas, PRECISION)
        for r, row in enumerate(alignment.rows):
            spans: dict[int, list[float]] = {}
            for j, entries in enumerate(alignment.entries):
                move = entries[r]
                if move is None:
                    continue
                whole, parts = sizing.entry_parts(move)
                order = sorted([(k, False) for k in whole] + [(k, True) for k in parts])
                cursor, exact = bounds[j], starts[j]  # rounded, and as solved: the letters
                # are laid out by the solved sizes (rounding each end alone, so that no
                # rounding adds up along an entry of many letters)
                for position, (k, is_piece) in enumerate(order):
                    if is_piece:
                        length = final.of(program.pieces[sizing.Piece(group, r, k, j)])
                    else:
                        length = final.of(program.symbols[row.word[k].symbol])
                    exact += length
                    end = bounds[j + 1] if position == len(order) - 1 else round(exact, PRECISION)
                    span = spans.setdefault(k, [cursor, end])
                    span[1] = end
                    cursor = end
            placed = tuple(
                PlacedLetter(
                    symbol=letter.symbol,
                    start=spans[k][0],
                    end=spans[k][1],
                    reflected=letter.reflected,
                    transparent=row.traits[k].transparent,
                )
                for k, letter in enumerate(row.word)
            )
            for layer in row.layers:
                letters[layer] = placed
        groups[group] = GroupColumns(
            boundaries=tuple(bounds),
            error=round(alignment.error, PRECISION),
            matrix=tuple(
                tuple(_entry_text(row.word, entries[r]) for entries in alignment.entries)
                for r, row in enumerate(alignment.rows)
            ),
            layers=tuple(row.layers for row in alignment.rows),
        )
    symbols = {
        name: (spec.size(name), round(final.of(index), PRECISION))
        for name, index in sorted(program.symbols.items())
    }
    counters = dict(choice.candidate.counters)
    for use in uses:
        for name in use.pattern.counter_names():
            counters.setdefault(name, spec.counters[name].min)
    return AxisLayout(
        axis=axis,
        canvas=canvas,
        letters=letters,
        symbols=symbols,
        groups=groups,
        counters=counters,
        words={key: format_word(item.word) for key, item in choice.candidate.words.items()},
        objective=round(final.objective, 9),
        mu=round(max(spec.solver.tolerance, choice.candidate.need), PRECISION),
        candidates_tried=0,
    )


def _entry_text(word: Word, move: object) -> str:
    if move is None:
        return ""
    whole, parts = sizing.entry_parts(move)  # type: ignore[arg-type]
    items = sorted([(k, "") for k in whole] + [(k, "~") for k in parts])
    return " ".join(word[k].symbol + mark for k, mark in items)


def _no_candidate_reason(axis: Axis, canvas: float) -> str:
    return (
        f"{axis} axis: the patterns share counters whose values agree on no words up to "
        f"twice the canvas ({2 * canvas:g} m) and {MAX_LETTERS:,} letters; a layout may "
        "still exist with every symbol shrunk by half or more: make the canvas larger, or "
        "the symbols or the counters' minimums smaller"
    )


def _no_layout_reason(axis: Axis, failures: list[str]) -> str:
    common = max(set(failures), key=failures.count) if failures else "nothing aligns"
    return f"{axis} axis: no layout exists: {common}"
