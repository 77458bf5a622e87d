"""The data of ``facade grammar``'s pipeline (read -> regularise -> extract -> derive ->
write), apart from the stages that make it: the options and what each stage hands the
next (the tidied layout, the extraction, a derived terminal, the candidates and
variations of a size, the layouts of a derived size)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from facadecli.errors import Problem, SpecError
from facadecli.grammar.inputs import EXTENT_MAX, LabelledLayout
from facadecli.grammar.split import DEFAULT_COSTS, Costs, Grammar
from facadecli.grammar.tiling import NO_SNAPPING, Snapping, Tiling

if TYPE_CHECKING:
    from facadecli.grammar.fidelity import Fidelity
    from facadecli.grammar.regularize import Regularization
    from facadecli.grammar.search import SearchResult
    from facadecli.layout import Layout

TIDY_MAX = 0.1  # the largest snap and tolerance
TIME_LIMIT_MAX = 86_400.0  # seconds
COST_MAX = 1e6  # of a rule

Progress = Callable[[str], None]  # told the name of each stage as it starts


@dataclass(frozen=True)
class Options:
    method: str = "adp"
    iterations: int = 2000
    seed: int = 0
    extensions: tuple[str, ...] = ()
    costs: Costs = DEFAULT_COSTS
    snap: float | None = None  # None: by the kind of input (``TIDY``)
    tolerance: float | None = None  # regularisation; None: by the kind of input (``TIDY``)
    size: tuple[float, float] | None = None  # the façade's real size: the layout is scaled
    time_limit: float = 120.0  # seconds for the whole run (see ``deadline``)


DEFAULT_OPTIONS = Options()


def check_options(options: Options) -> None:
    """Every number of the options finite and in its range (the option named on error)."""
    problems = []
    ranges = [
        ("--snap", options.snap, 0.0, TIDY_MAX),
        ("--tolerance", options.tolerance, 0.0, TIDY_MAX),
        ("--split-cost", options.costs.split, 0.0, COST_MAX),
        ("--repeat-cost", options.costs.repeat, 0.0, COST_MAX),
        ("--time-limit", options.time_limit, 0.0, TIME_LIMIT_MAX),
    ]
    for size in options.size or ():
        ranges.append(("--size", size, 0.0, EXTENT_MAX))
    for option, value, low, high in ranges:
        if value is not None and not (math.isfinite(value) and low <= value <= high):
            problems.append(
                Problem(option, None, None, f"{value:g} is not from {low:g} to {high:g}")
            )
    if options.size is not None and min(options.size) <= 0:
        problems.append(Problem("--size", None, None, "a size must be above 0"))
    if problems:
        raise SpecError(problems)


def no_progress(stage: str) -> None:
    """The default ``progress``: stages told to no one."""


@dataclass(frozen=True)
class Constraint:
    """One of Bao et al. 2013's constraints of a façade's style
    (:mod:`facadecli.grammar.style` finds and checks them)."""

    kind: str  # symmetry, columns, axis, spacing, ends, centre, sizes, pitch
    label: str  # the label it is about ("*": every element)
    text: str  # what it says, for people
    share: float = 1.0  # for ``columns`` and ``spacing``: the share of the label's rows
    other: str = ""  # for ``axis``: the label whose columns it is centred on
    rows: int = 0  # for ``columns`` and ``spacing``: how many of the label's rows
    # for ``sizes``: the input elements' (width, height); for ``pitch``: the input's pitches
    sizes: tuple[tuple[float, float], ...] = ()
    pitches: tuple[float, ...] = ()

    def summary(self) -> dict[str, object]:
        return {"kind": self.kind, "label": self.label, "text": self.text}


@dataclass(frozen=True)
class Kept:
    """Which of a style's constraints a layout keeps."""

    kept: tuple[Constraint, ...]
    broken: tuple[Constraint, ...]

    def summary(self) -> dict[str, object]:
        return {"kept": len(self.kept), "broken": [c.text for c in self.broken]}

    def warnings(self) -> list[str]:
        if not self.broken:
            return []
        total = len(self.kept) + len(self.broken)
        broken = "; ".join(c.text for c in self.broken)
        return [
            f"keeps {len(self.kept)} of {total} constraints of the source's style, not: {broken}"
        ]


NOTHING_KEPT = Kept((), ())  # of an empty style


@dataclass(frozen=True)
class Tidied:
    """A labelled layout as read, resized, snapped and regularised, and what that changed."""

    layout: LabelledLayout
    snapping: Snapping
    regularization: Regularization
    snapped: LabelledLayout  # before regularising: its rectangles in the same order
    raw: LabelledLayout  # as read (stretched to the size): what fidelity is measured against
    warnings: tuple[str, ...] = ()  # about the input as read (``tidy.read_warnings``)


@dataclass
class Extraction:
    source: str
    layout: LabelledLayout
    tiling: Tiling
    found: SearchResult
    regularization: Regularization
    options: Options
    time_ms: float = 0.0
    problems: list[str] = field(default_factory=list)
    snapping: Snapping = NO_SNAPPING  # what snapping changed
    fidelity: Fidelity | None = None  # the derivation at the input's size vs the annotation
    # the annotation as drawn, only its edges within the snap tolerance joined (its tiling
    # is within the cell limit checked before the work, unlike the raw drawing's)
    drawn: LabelledLayout | None = None
    # Bao's constraints the input holds, found on what the annotation shows (its
    # rectangles in their z-order: ``style.style_of_drawing``)
    style: list[Constraint] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # what the tidy-up and search met

    @property
    def grammar(self) -> Grammar:
        return self.found.grammar


@dataclass(frozen=True)
class Piece:
    """A derived terminal rectangle and its size in the source layout."""

    label: str
    x0: float
    y0: float
    x1: float
    y1: float
    source_w: float
    source_h: float


Shuffle = tuple[str, tuple[str, ...]]  # a split rule, its parts' symbols in a new order
Proportions = tuple[tuple[str, str, float], ...]  # (axis, part size, factor on that size)


@dataclass(frozen=True)
class Candidate:
    """A layout considered for a size, before tidying: its score (how far its sizes are
    from the source's, plus how far copied walls stretched), what made it (repeat-count
    offsets, a shuffle, drawn proportions, or how whole bays were copied: ``retarget``),
    its pieces and the source's style they keep."""

    score: float
    offsets: tuple[tuple[str, int], ...]
    shuffle: Shuffle | None
    pieces: list[Piece]
    kept: Kept
    proportions: Proportions = ()
    retarget: str = ""

    @property
    def rank(
        self,
    ) -> tuple[int, bool, float, tuple[tuple[str, int], ...], Shuffle, Proportions, str]:
        """Most of the style kept, the best fit (unchanged: the grammar's, or whole bays
        copied) first, nearest the source."""
        changed = bool(self.offsets) or self.shuffle is not None or bool(self.proportions)
        return (
            -len(self.kept.kept),
            changed,
            self.score,
            self.offsets,
            self.shuffle or ("", ()),
            self.proportions,
            self.retarget,
        )


@dataclass(frozen=True)
class Variation:
    """One derived layout of a size: ``offsets`` to the best-fitting repeat counts (rule,
    offset; empty for the best fit), ``shuffle`` (a split rule and its parts' symbols in
    their new order; None when none is shuffled), its ``score``, the mean squared
    log-ratio of its elements' sizes to their sizes in the source (lower is nearer the
    source), the source's style it keeps, and its terminals (tidied) with their sizes in
    the source."""

    layout: Layout
    offsets: tuple[tuple[str, int], ...]
    score: float
    kept: Kept = NOTHING_KEPT
    shuffle: Shuffle | None = None
    proportions: Proportions = ()
    pieces: tuple[Piece, ...] = ()
    retarget: str = ""


@dataclass(frozen=True)
class DerivedSize:
    """The grammar at one new size: its layouts (the best fit first, then the variations)
    and the warnings of the draw (fewer variations than asked)."""

    width: float
    height: float
    layouts: list[Layout]
    notes: list[str]
    kept: list[Kept] = field(default_factory=list)  # the input's style each layout keeps
    made: list[str] = field(default_factory=list)  # how: "grammar", or bays copied
