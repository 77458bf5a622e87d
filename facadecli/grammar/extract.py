"""Extracting, the third stage of ``facade grammar``: the tidied layout tiled, a grammar
found (:mod:`facadecli.grammar.search`), checked to derive the tiling exactly, and its
derivation at the input's size measured against the annotation.

Every number reaching the stages is finite: the readers check the file's,
``check_options`` the options'. The work is bounded before it starts (``RECTS_MAX``
rectangles when reading, ``CELLS_MAX`` cells of the snapped tiling) and while it runs (one
``Deadline`` for all stages, from ``--time-limit``)."""

from __future__ import annotations

import bisect
import time
from pathlib import Path

from facadecli.grammar import regions, symmetry
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.fidelity import fidelity
from facadecli.grammar.inputs import Rect
from facadecli.grammar.model import DEFAULT_OPTIONS, Extraction, Options, Progress, no_progress
from facadecli.grammar.search import extract
from facadecli.grammar.split import Grammar, derive
from facadecli.grammar.style import style_of_drawing
from facadecli.grammar.tidy import tidy_layout
from facadecli.grammar.tiling import Tiling, tile

REDERIVE_TOLERANCE = 1e-4  # x the façade's size: a derived edge this near a tiling edge is on it


def extract_grammar(
    path: Path, options: Options = DEFAULT_OPTIONS, progress: Progress = no_progress
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
    extraction.style = style_of_drawing(tidied.snapped)
    extraction.warnings = [*tidied.warnings, *extraction_warnings(extraction)]
    progress("measuring the derivation against the annotation")
    terminals = [Rect(*box) for box in derive(found.grammar, tiling.xs[-1], tiling.ys[-1])]
    extraction.fidelity = fidelity(tidied.raw, regular, terminals)
    return extraction


def extraction_warnings(extraction: Extraction) -> list[str]:
    """What the tidy-up changed and where the search stopped short of its iterations."""
    found = list(extraction.regularization.warnings)
    snapped = extraction.snapping.warning()
    if snapped:
        found.append(snapped)
    search, options = extraction.found, extraction.options
    if (
        search.method == "adp"
        and search.iterations < options.iterations
        and not search.budget_spent
    ):
        found.append(
            f"time limit of {options.time_limit:g} s reached after "
            f"{search.iterations} of {options.iterations} iterations: the best "
            "grammar so far is kept, and it depends on the machine's speed"
        )
    if search.budget_spent:
        found.append(
            f"the search did the most work it may ({regions.WORK_MAX:,} units) "
            f"after {search.iterations} of {options.iterations} iterations: the "
            "best grammar so far is kept"
        )
    if search.repeats_stopped == "time":
        found.append(
            f"time limit of {options.time_limit:g} s: the search for repeated regions "
            f"stopped at {search.repeats} kinds; the grammar depends on the machine's "
            "speed"
        )
    if search.repeats_stopped == "work":
        found.append(
            "the search for repeated regions did the most work it may "
            f"({symmetry.WORK_SHARE * regions.WORK_MAX:,.0f} of the search's "
            f"{regions.WORK_MAX:,} units) and stopped at {search.repeats} kinds"
        )
    return found


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
