"""``facade grammar``'s pipeline, without the writing: read a labelled layout, snap and
regularise it, tile it, find a grammar, and check that it derives the tiling exactly."""

from __future__ import annotations

import bisect
import json
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

from facadecli.errors import SpecError
from facadecli.grammar.regularize import Regularization, regularize
from facadecli.grammar.search import SearchResult, extract
from facadecli.grammar.split import DEFAULT_COSTS, Costs, Grammar, derive
from facadecli.grammar.tiling import (
    LabelledLayout,
    Tiling,
    read_cmp,
    read_plain,
    read_report,
    snap_layout,
    tile,
)

# How much each kind of input is tidied, as fractions of the façade's size: edges closer
# than ``snap`` become one, and repeated elements closer in size than ``tolerance`` get one
# size. CMP annotations are drawn by hand on photographs (a few pixels off); plain lists may
# be measured or detected; facadecli layouts are exact.
TIDY = {"cmp": (0.005, 0.01), "plain": (0.001, 0.005), "report": (0.0, 0.0)}
REDERIVE_TOLERANCE = 1e-4  # x the façade's size: a derived edge this near a tiling edge is on it


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
    time_limit: float = 120.0  # seconds of ADP; the best grammar so far is kept


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

    @property
    def grammar(self) -> Grammar:
        return self.found.grammar

    @property
    def warnings(self) -> list[str]:
        found = list(self.regularization.warnings)
        if self.found.method == "adp" and self.found.iterations < self.options.iterations:
            found.append(
                f"time limit of {self.options.time_limit:g} s reached after "
                f"{self.found.iterations} of {self.options.iterations} iterations: the best "
                "grammar so far is kept, and it depends on the machine's speed"
            )
        return found


def read_layout(path: Path) -> tuple[LabelledLayout, str]:
    """The labelled layout in a file, and its kind: cmp, report or plain."""
    if not path.is_file():
        raise SpecError.at(str(path), None, None, "no such file", "check the path")
    name = path.name
    try:
        if name.endswith(".xml"):
            return read_cmp(path), "cmp"
        if name.endswith(".layout.json"):
            return read_report(path), "report"
        return read_plain(path), "plain"
    except json.JSONDecodeError as error:
        raise SpecError.at(
            str(path), error.lineno, error.colno, f"not JSON: {error.msg}", "fix the JSON syntax"
        ) from None
    except (ValueError, KeyError, TypeError) as error:
        raise SpecError.at(
            str(path),
            None,
            None,
            f"not a labelled layout: {error}",
            "give a CMP .xml, a .layout.json, or [{label, x0, y0, x1, y1}, ...]",
        ) from None


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


def extract_grammar(path: Path, options: Options = Options()) -> Extraction:
    layout, kind = read_layout(path)
    if not layout.rects:
        raise SpecError.at(str(path), None, None, "no rectangles", "label some elements")
    if options.size is not None:
        layout = resize(layout, *options.size)
    snap = options.snap if options.snap is not None else TIDY[kind][0]
    tolerance = options.tolerance if options.tolerance is not None else TIDY[kind][1]
    snapped = snap_layout(layout, snap) if snap > 0 else layout
    regular, regularization = regularize(snapped, tolerance)
    tiling = tile(regular, tolerance=0.0)
    started = time.perf_counter()
    found = extract(
        tiling,
        options.method,
        options.iterations,
        options.seed,
        options.costs,
        options.extensions,
        time_limit=options.time_limit,
    )
    elapsed = (time.perf_counter() - started) * 1000
    extraction = Extraction(path.name, regular, tiling, found, regularization, options, elapsed)
    extraction.problems = rederivation_problems(found.grammar, tiling)
    return extraction


def rederivation_problems(grammar: Grammar, tiling: Tiling, limit: int = 5) -> list[str]:
    """Where the grammar's derivation differs from the tiling (empty when exact): every
    derived rectangle must cover cells of its own label only, and together they must cover
    the façade once. Positions are compared to ``REDERIVE_TOLERANCE`` of the façade's
    size: regions that share a rule are equal to within the size quantum of ``regions``, and
    repeats add those differences up."""
    width, height = tiling.xs[-1], tiling.ys[-1]
    eps = REDERIVE_TOLERANCE * max(width, height)
    problems = []
    area = 0.0
    for label, x0, y0, x1, y1 in derive(grammar, width, height):
        area += (x1 - x0) * (y1 - y0)
        c0 = bisect.bisect_left(tiling.xs, x0 - eps)
        c1 = bisect.bisect_left(tiling.xs, x1 - eps)
        r0 = bisect.bisect_left(tiling.ys, y0 - eps)
        r1 = bisect.bisect_left(tiling.ys, y1 - eps)
        cells = {
            tiling.labels[r][c]
            for r in range(r0, max(r1, r0 + 1))
            for c in range(c0, max(c1, c0 + 1))
        }
        if cells != {label}:
            problems.append(
                f"{label} at ({x0:.4g}, {y0:.4g})-({x1:.4g}, {y1:.4g}) covers {sorted(cells)}"
            )
            if len(problems) >= limit:
                break
    if abs(area - width * height) > 1e-6 * width * height:
        problems.append(f"derived area {area:.6g} is not the façade's {width * height:.6g}")
    return problems


__all__ = ["Extraction", "Options", "extract_grammar", "rederivation_problems"]
