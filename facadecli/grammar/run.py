"""``facade grammar``'s pipeline, without the writing: read a labelled layout, snap and
regularise it, tile it, find a grammar, and check that it derives the tiling exactly.

Every number reaching the stages is finite: the readers check the file's, ``check_options``
the options'. The work is bounded before it starts (``RECTS_MAX`` rectangles when reading,
``CELLS_MAX`` cells of the snapped tiling) and while it runs (one ``Deadline`` for all
stages, from ``--time-limit``)."""

from __future__ import annotations

import bisect
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

from facadecli.errors import Problem, SpecError
from facadecli.grammar import regions, symmetry
from facadecli.grammar.cmp_xml import read_cmp
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.fidelity import Fidelity, fidelity
from facadecli.grammar.inputs import EXTENT_MAX, LabelledLayout, Rect
from facadecli.grammar.json_layouts import read_plain, read_report
from facadecli.grammar.regularize import Regularization, regularize
from facadecli.grammar.search import SearchResult, extract
from facadecli.grammar.split import DEFAULT_COSTS, Costs, Grammar, derive
from facadecli.grammar.style import Constraint, Kept, style_of, style_of_drawing
from facadecli.grammar.tiling import NO_SNAPPING, Snapping, Tiling, snap_and_count, tile
from facadecli.limits import LAYOUT_CELLS_MAX

if TYPE_CHECKING:
    from facadecli.layout import Layout

# How much each kind of input is tidied, as fractions of the façade's size: edges closer
# than ``snap`` become one, and repeated elements closer in size than ``tolerance`` get one
# size. CMP annotations are drawn by hand on photographs (a few pixels off); plain lists may
# be measured or detected; facadecli layouts are exact.
TIDY = {"cmp": (0.005, 0.01), "plain": (0.001, 0.005), "report": (0.0, 0.0)}
SCALE_NOTED = 8.0  # a derived size this many times the input's (or less) is noted
REDERIVE_TOLERANCE = 1e-4  # x the façade's size: a derived edge this near a tiling edge is on it
CELLS_MAX = LAYOUT_CELLS_MAX  # cells of the snapped tiling (a plain list at its snap)
TIDY_MAX = 0.1  # the largest snap and tolerance
TIME_LIMIT_MAX = 86_400.0  # seconds
COST_MAX = 1e6  # of a rule


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

    @cached_property
    def style(self) -> list[Constraint]:
        """Bao's constraints the input holds: found on what the annotation shows (its
        rectangles in their z-order), or on the tiling when there is no annotation."""
        return style_of(self.tiling) if self.drawn is None else style_of_drawing(self.drawn)

    @property
    def grammar(self) -> Grammar:
        return self.found.grammar

    @property
    def warnings(self) -> list[str]:
        found = list(self.regularization.warnings)
        snapped = self.snapping.warning()
        if snapped:
            found.append(snapped)
        if (
            self.found.method == "adp"
            and self.found.iterations < self.options.iterations
            and not self.found.budget_spent
        ):
            found.append(
                f"time limit of {self.options.time_limit:g} s reached after "
                f"{self.found.iterations} of {self.options.iterations} iterations: the best "
                "grammar so far is kept, and it depends on the machine's speed"
            )
        if self.found.budget_spent:
            found.append(
                f"the search did the most work it may ({regions.WORK_MAX:,} units) "
                f"after {self.found.iterations} of {self.options.iterations} iterations: the "
                "best grammar so far is kept"
            )
        if self.found.repeats_stopped == "time":
            found.append(
                f"time limit of {self.options.time_limit:g} s: the search for repeated regions "
                f"stopped at {self.found.repeats} kinds; the grammar depends on the machine's "
                "speed"
            )
        if self.found.repeats_stopped == "work":
            found.append(
                "the search for repeated regions did the most work it may "
                f"({symmetry.WORK_SHARE * regions.WORK_MAX:,.0f} of the search's "
                f"{regions.WORK_MAX:,} units) and stopped at {self.found.repeats} kinds"
            )
        return found


def read_layout(path: Path) -> tuple[LabelledLayout, str]:
    """The labelled layout in a file, and its kind: cmp, report or plain."""
    if not path.is_file():
        raise SpecError.at(str(path), None, None, "no such file", "check the path")
    name = path.name
    if name.endswith(".xml"):
        return read_cmp(path), "cmp"
    if name.endswith(".layout.json"):
        return read_report(path), "report"
    return read_plain(path), "plain"


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


def check_cells(path: Path, layout: LabelledLayout, snap: float) -> None:
    """The tiling of the (snapped) layout has at most ``CELLS_MAX`` cells."""
    columns = len({0.0, layout.width, *(v for r in layout.rects for v in (r.x0, r.x1))}) - 1
    rows = len({0.0, layout.height, *(v for r in layout.rects for v in (r.y0, r.y1))}) - 1
    if columns * rows > CELLS_MAX:
        raise SpecError.at(
            str(path),
            None,
            None,
            f"the tiling would have {columns:,} x {rows:,} cells; at most {CELLS_MAX:,}",
            f"join nearby edges with a larger --snap (now {snap:g}), or give fewer rectangles",
        )


def resize(layout: LabelledLayout, width: float, height: float) -> LabelledLayout:
    """The layout stretched to a new size (CMP annotations are on a unit square)."""
    sx, sy = width / layout.width, height / layout.height
    rects = tuple(
        replace(r, x0=r.x0 * sx, x1=r.x1 * sx, y0=r.y0 * sy, y1=r.y1 * sy) for r in layout.rects
    )
    return LabelledLayout(width, height, rects)


def stem(path: Path) -> str:
    name = path.name.removesuffix(".layout.json")
    return name.rsplit(".", 1)[0] if "." in name else name


@dataclass(frozen=True)
class Tidied:
    """A labelled layout as read, resized, snapped and regularised, and what that changed."""

    layout: LabelledLayout
    snapping: Snapping
    regularization: Regularization
    snapped: LabelledLayout  # before regularising: its rectangles in the same order
    raw: LabelledLayout  # as read (stretched to the size): what fidelity is measured against


Progress = Callable[[str], None]  # told the name of each stage as it starts


def no_progress(stage: str) -> None:
    """The default ``progress``: stages told to no one."""


def tidy_layout(
    path: Path, options: Options, deadline: Deadline, progress: Progress = no_progress
) -> Tidied:
    """Read a labelled layout (``options`` checked first), stretch it to ``options.size``,
    snap it and regularise it, with the defaults of its kind (``TIDY``)."""
    check_options(options)
    progress("reading")
    layout, kind = read_layout(path)
    if not layout.rects:
        raise SpecError.at(str(path), None, None, "no rectangles", "label some elements")
    if options.size is not None:
        layout = resize(layout, *options.size)
    snap = options.snap if options.snap is not None else TIDY[kind][0]
    tolerance = options.tolerance if options.tolerance is not None else TIDY[kind][1]
    progress(f"snapping {len(layout.rects)} rectangles")
    snapped, snapping = snap_and_count(layout, snap, deadline)
    check_cells(path, snapped, snap)
    progress("regularising")
    regular, regularization = regularize(snapped, tolerance, deadline=deadline, drawn=layout)
    return Tidied(regular, snapping, regularization, snapped, layout)


def extract_grammar(
    path: Path, options: Options = Options(), progress: Progress = no_progress
) -> Extraction:
    """The grammar of a labelled layout; ``progress`` is told each stage as it starts."""
    deadline = Deadline(options.time_limit, str(path))
    tidied = tidy_layout(path, options, deadline, progress)
    regular, regularization, snapping = tidied.layout, tidied.regularization, tidied.snapping
    progress("tiling")
    tiling = tile(regular, tolerance=0.0, deadline=deadline)
    progress(
        f"searching ({options.method}, {options.iterations} iterations)"
        if options.method == "adp"
        else "searching (greedy)"
    )
    started = time.perf_counter()
    found = extract(
        tiling,
        options.method,
        options.iterations,
        options.seed,
        options.costs,
        options.extensions,
        deadline=deadline,
    )
    elapsed = (time.perf_counter() - started) * 1000
    extraction = Extraction(path.name, regular, tiling, found, regularization, options, elapsed)
    progress("checking the grammar derives the layout")
    extraction.problems = rederivation_problems(found.grammar, tiling)
    extraction.snapping = snapping
    extraction.drawn = tidied.snapped
    progress("measuring the derivation against the annotation")
    terminals = [Rect(*box) for box in derive(found.grammar, tiling.xs[-1], tiling.ys[-1])]
    extraction.fidelity = fidelity(tidied.raw, regular, terminals)
    return extraction


def rederivation_problems(grammar: Grammar, tiling: Tiling, limit: int = 5) -> list[str]:
    """Where the grammar's derivation differs from the tiling (empty when exact): every
    derived rectangle must cover cells of its own label only, and together they must cover
    the façade once. Each derived edge is taken to the nearest cut of the tiling, which must
    be within ``REDERIVE_TOLERANCE`` of the façade's size: regions that share a rule are
    equal to within the size quantum of ``regions``, and repeats add those differences up
    (cells may be thinner than that tolerance, so the nearest cut is the one meant)."""
    width, height = tiling.xs[-1], tiling.ys[-1]
    eps = REDERIVE_TOLERANCE * max(width, height)
    problems = []
    area = 0.0
    for label, x0, y0, x1, y1 in derive(grammar, width, height):
        area += (x1 - x0) * (y1 - y0)
        c0, c1 = _nearest(tiling.xs, x0), _nearest(tiling.xs, x1)
        r0, r1 = _nearest(tiling.ys, y0), _nearest(tiling.ys, y1)
        cells = {
            tiling.labels[r][c]
            for r in range(r0, max(r1, r0 + 1))
            for c in range(c0, max(c1, c0 + 1))
        }
        off = max(
            abs(tiling.xs[c0] - x0),
            abs(tiling.xs[c1] - x1),
            abs(tiling.ys[r0] - y0),
            abs(tiling.ys[r1] - y1),
        )
        if cells != {label} or off > eps:
            problems.append(
                f"{label} at ({x0:.4g}, {y0:.4g})-({x1:.4g}, {y1:.4g}) covers {sorted(cells)}"
            )
            if len(problems) >= limit:
                break
    if abs(area - width * height) > 1e-6 * width * height:
        problems.append(f"derived area {area:.6g} is not the façade's {width * height:.6g}")
    return problems


def _nearest(cuts: tuple[float, ...], value: float) -> int:
    """The index of the cut nearest to the value."""
    i = bisect.bisect_left(cuts, value)
    if i == len(cuts) or (i > 0 and value - cuts[i - 1] < cuts[i] - value):
        return i - 1
    return i


__all__ = [
    "CELLS_MAX",
    "Extraction",
    "Options",
    "check_options",
    "extract_grammar",
    "rederivation_problems",
]


def grammar_files(
    extraction: Extraction,
    name: str,
    timings: bool = False,
    derived: Sequence[DerivedSize] = (),
) -> dict[str, str]:
    """The grammar's own files by name: text, JSON, CityEngine CGA, the tiling as SVG and
    the report (with the style each derived layout keeps)."""
    from facadecli.grammar.cga import grammar_cga
    from facadecli.grammar.outputs import grammar_json, grammar_report, tiling_svg

    found = extraction.grammar
    tiling = extraction.tiling
    return {
        f"{name}.grammar.txt": found.text(),
        f"{name}.grammar.json": grammar_json(found),
        f"{name}.cga": grammar_cga(found, tiling.xs[-1], tiling.ys[-1], name),
        f"{name}.tiling.svg": tiling_svg(tiling, found, name),
        f"{name}.grammar-report.json": grammar_report(extraction, timings, derived),
    }


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


def derive_sizes(
    extraction: Extraction,
    name: str,
    sizes: list[tuple[float, float]],
    variations: int = 1,
    seed: int = 0,
    progress: Progress = no_progress,
) -> list[DerivedSize]:
    """The grammar derived at every size, with up to ``variations`` layouts each (raises
    :class:`~facadecli.grammar.variation.TooLarge` for a size too large to derive)."""
    from facadecli.grammar.variation import derive_variations

    derived = []
    style = extraction.style
    source = (extraction.tiling.xs[-1], extraction.tiling.ys[-1])
    for width, height in sizes:
        progress(f"deriving at {width:g}x{height:g}")
        drawn, notes = derive_variations(
            extraction.grammar, extraction.tiling, width, height, name, variations, seed, style
        )
        scale = max(width / source[0], height / source[1], source[0] / width, source[1] / height)
        if scale > SCALE_NOTED:
            notes = [
                f"the input is {source[0]:g} x {source[1]:g} and this size {scale:.0f} times it "
                "along an axis: its elements are that many times larger or smaller (a CMP "
                "annotation is a unit square: give --size WxH in metres)",
                *notes,
            ]
        derived.append(
            DerivedSize(
                width,
                height,
                [v.layout for v in drawn],
                notes,
                [v.kept for v in drawn],
                [v.retarget or "grammar" for v in drawn],
            )
        )
    return derived


def variations_sheet(derived: list[DerivedSize], name: str, seed: int) -> str:
    """A contact sheet of every size's layouts, a row a size (``<name>.variations.svg``)."""
    from facadecli.export.contact import Variant, contact_sheet

    rows = [
        [
            Variant(layout, (size.width, size.height), seed, k)
            for k, layout in enumerate(size.layouts)
        ]
        for size in derived
    ]
    return contact_sheet(rows, f"{name} (grammar variations)")
