"""A grammar at a new size (Wu et al. 2014, section 5), and the result as a layout for the
layout writers.

Size independence: a part thinner than ``THIN`` of the façade's extent along its axis keeps
its absolute size (frames, sills, slivers of wall); the other parts are weights. A repeat
lays as many copies as fit best (the nearest whole number, at least one) and stretches them
slightly. Within a split, parts that hold a repeat along the split's axis are *elastic*: they
take up the change in size while the others keep theirs, so a wider façade gets more window
bays rather than wider windows; without elastic parts, the weights share the change.

The derivation is then tidied with a QP per axis (cvxpy), after Bao et al. 2013: edges stay
near where the derivation put them, terminals that were one size in the source get one size,
their edges that nearly line up across the façade are lined up, elements the derivation
made longer than in the source (a split without repeats shares a wider façade among all
its parts) are pulled back towards their source size, the wall taking the rest, and the
source's style (:mod:`facadecli.grammar.style`) is made exact where the derivation nearly
keeps it.
Constraints that cannot all hold are dropped (alignment first, then the style, then equal
sizes) with a warning. Of the derivations the repeat counts allow, and the layouts that
copy the source's whole bays and floors instead (:mod:`facadecli.grammar.slabs`), the
one written keeps the most of the source's style (after tidying), then is the nearest the
source's sizes, wall included; variations also vary counts, shuffle parts of one size and
draw new proportions.
"""

from __future__ import annotations

import itertools
import math
import random
import re
import warnings as warnings_module
from collections import defaultdict
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from facadecli import proportions
from facadecli.grammar.pieces import Piece, apart, elements_of, likeness, score
from facadecli.grammar.slabs import retargeted
from facadecli.grammar.split import Axis, Grammar, Part, Rule
from facadecli.grammar.style import (
    NOTHING_KEPT,
    Constraint,
    Equation,
    Kept,
    check,
    equations,
    style_of,
)
from facadecli.grammar.tiling import BACKGROUND, CMP_Z_ORDER, Tiling, snap

if TYPE_CHECKING:
    from facadecli.layout import Layout

THIN = 0.03  # of the source façade's extent: thinner parts keep their absolute size
STRETCHED = 1.05  # an element derived longer than this times its source size is pulled back
WIDTHS = 100.0  # ... with this weight against moving edges (bands are not: they stretch)
BAND = 0.25  # of the new extent: a longer element is a band across the façade
ALIGN = 0.02  # of the new extent: edges of equal terminals closer than this are lined up
STYLE_NEAR = 0.05  # of the new width: near misses of the style this close are made exact
KEPT_LEAST = 0.75  # of its size as derived: the alignment QP shrinks no element further
SOFT = 100.0  # weight of equal sizes and line-ups when they cannot all hold exactly
MAX_PIECES = 200_000  # a derivation making more terminals than this is refused
REPEATS = ("repeat", "repeatABA", "run")  # rules whose count the derivation chooses
RUN_BAYS = 3  # bays of one size and kind side by side that a derivation may add to
RUN_LEAST = 0.05  # of the source's extent: a narrower part is no bay (a slat, a frame)
STRETCH = 0.5  # a varied repeat's copies stay within 1/(1 + this) to 1 + this of their size
CANDIDATES_MAX = 729  # repeat-count choices tried per size (all of them when fewer: 3^6)
SHUFFLES_MAX = 6  # new orders of one split rule's parts tried as variations
STYLE_MAX = 81  # ... and for one layout, when the best fit breaks some of the style (3^4)
TEMPERATURE = 0.1  # of the score: how strongly variations near the source's sizes are preferred
APART = 0.01  # of the façade's smaller side: the least mean displacement between variations
NAME_MAX = 150  # characters of the source's name in a derived layout's name


class TooLarge(ValueError):
    """The new size would make too many pieces."""


def _elastic(grammar: Grammar) -> dict[tuple[str, str], bool]:
    memo: dict[tuple[str, str], bool] = {}

    def elastic(symbol: str, axis: str) -> bool:
        key = (symbol, axis)
        if key not in memo:
            rule = grammar.rules.get(symbol)
            memo[key] = (
                rule is not None
                and rule.axis == axis
                and rule.op != "gridsplit"
                and (rule.op in REPEATS or any(elastic(p.symbol, axis) for p in rule.parts))
            )
        return memo[key]

    for symbol in grammar.rules:
        for axis in ("x", "y"):
            elastic(symbol, axis)
    return memo


def distribute(
    sizes: list[float], absolute: list[bool], elastic: list[bool], extent: float
) -> list[float]:
    """New sizes of parts filling ``extent`` (see the module)."""
    total = sum(sizes)
    fixed = sum(s for s, a in zip(sizes, absolute, strict=True) if a)
    if fixed >= extent or fixed >= total:
        return [s * extent / total for s in sizes]
    free = [not a for a in absolute]
    stretch = [f and e for f, e in zip(free, elastic, strict=True)]
    rigid = sum(s for s, f, e in zip(sizes, free, stretch, strict=True) if f and not e)
    stretchy = sum(s for s, e in zip(sizes, stretch, strict=True) if e)
    if stretchy > 0 and extent - fixed - rigid >= stretchy / 2:
        scale = (extent - fixed - rigid) / stretchy
        return [s * scale if e else s for s, e in zip(sizes, stretch, strict=True)]
    scale = (extent - fixed) / (total - fixed)
    return [s * scale if f else s for s, f in zip(sizes, free, strict=True)]


def derive_at(
    grammar: Grammar,
    source: tuple[float, float],
    width: float,
    height: float,
    offsets: dict[str, int] | None = None,
    used: set[str] | None = None,
) -> list[Piece]:
    """The grammar applied to a façade of a new size (see the module). ``offsets`` adds to
    the best-fitting count of each repeat rule named (every region the rule makes gets the
    same offset, except where the count would be below one or stretch its copies beyond
    ``STRETCH``: there it keeps the best fit); ``used`` collects the repeat rules the
    derivation applies."""
    elastic = _elastic(grammar)
    thin = {"x": THIN * source[0], "y": THIN * source[1]}
    out: list[Piece] = []

    def expand(
        symbol: str, box: tuple[float, float, float, float], src: tuple[float, float]
    ) -> None:
        x0, y0, x1, y1 = box
        rule = grammar.rules.get(symbol)
        if rule is None:
            out.append(Piece(symbol, x0, y0, x1, y1, src[0], src[1]))
            if len(out) > MAX_PIECES:
                raise TooLarge(
                    f"{width:g}x{height:g} makes more than {MAX_PIECES:,} pieces; "
                    "choose a smaller size"
                )
            return
        if rule.op == "gridsplit":
            _grid(rule, box, expand)
            return
        axis = rule.axis
        extent = (x1 - x0) if axis == "x" else (y1 - y0)
        if used is not None and rule.op in REPEATS:
            used.add(symbol)
        sequence = _fit(rule, extent, (offsets or {}).get(symbol, 0))
        sizes = distribute(
            [p.size for p in sequence],
            [p.size < thin[axis] for p in sequence],
            [elastic.get((p.symbol, axis), False) for p in sequence],
            extent,
        )
        cursor = x0 if axis == "x" else y0
        for part, size in zip(sequence, sizes, strict=True):
            end = cursor + size
            if axis == "x":
                expand(part.symbol, (cursor, y0, end, y1), (part.size, src[1]))
            else:
                expand(part.symbol, (x0, cursor, x1, end), (src[0], part.size))
            cursor = end

    expand(grammar.start, (0.0, 0.0, width, height), source)
    return out


def _fit(rule: Rule, extent: float, offset: int = 0) -> tuple[Part, ...]:
    """The rule's parts in order, with as many repeats as fit best (plus ``offset``)."""
    period = sum(p.size for p in rule.parts)
    if rule.op == "repeat":
        count = _count(extent, period, offset)
        return rule.parts * count
    if rule.op == "repeatABA":
        a, b = rule.parts
        count = _count(extent - a.size, period, offset)
        return (a, *((b, a) * count))
    if rule.op == "run":
        a, b = rule.parts[:2]
        count = _count(extent - a.size, a.size + b.size, offset) + 1
        return _run_of(rule.parts, max(count, (len(rule.parts) + 1) // 2))
    return rule.sequence()


def _run_of(parts: tuple[Part, ...], count: int) -> tuple[Part, ...]:
    """A run's bays A B A B A made ``count`` bays long (never fewer than the source's):
    the source's bays as they are, and copies of the middle bay beside it (a symmetric run
    stays symmetric)."""
    bays, gap = list(parts[::2]), parts[1]
    middle = (len(bays) - 1) // 2
    bays = [*bays[: middle + 1], *[bays[middle]] * (count - len(bays)), *bays[middle + 1 :]]
    sequence: list[Part] = []
    for bay in bays:
        sequence += [gap, bay] if sequence else [bay]
    return tuple(sequence)


def _with_runs(grammar: Grammar, source: tuple[float, float]) -> Grammar:
    """The grammar with every run of bays in a split (see :func:`_run_end`) made a rule of
    its own, a ``run``, that the derivation lays as many bays of as fit: windows of one size
    and kind drawn a little differently from bay to bay (a sill missing, a pillar thinner)
    are not one rule a repeat could copy, yet a wider façade should get more of them."""
    kinds: dict[str, frozenset[str]] = {}

    def kind(symbol: str) -> frozenset[str]:
        """The labels a symbol's region holds."""
        if symbol not in kinds:
            rule = grammar.rules.get(symbol)
            kinds[symbol] = (
                frozenset([symbol])
                if rule is None
                else frozenset().union(*(kind(p.symbol) for p in rule.parts))
            )
        return kinds[symbol]

    rules = dict(grammar.rules)
    for name, rule in grammar.rules.items():
        if rule.op != "split":
            continue
        least = RUN_LEAST * (source[0] if rule.axis == "x" else source[1])
        parts: list[Part] = []
        at = 0
        while at < len(rule.parts):
            end = _run_end(rule.parts, at, kind) if rule.parts[at].size >= least else at + 1
            if end - at < RUN_BAYS * 2 - 1:
                parts.append(rule.parts[at])
                at += 1
                continue
            symbol = f"{name}~run{at}"
            run = rule.parts[at:end]
            rules[symbol] = Rule("run", rule.axis, run)
            parts.append(Part(sum(p.size for p in run), symbol))
            at = end
        if len(parts) < len(rule.parts):
            rules[name] = replace(rule, parts=tuple(parts))
    return replace(grammar, rules=rules)


def _run_end(parts: Sequence[Part], at: int, kind: Callable[[str], frozenset[str]]) -> int:
    """Where a run of bays that starts at ``at`` ends (``at`` + 1 when none): bays of one
    size and the same kinds of element, not plain wall, between gaps of one symbol and size,
    A B A B A."""
    first = parts[at]
    if kind(first.symbol) <= {BACKGROUND}:
        return at + 1
    end = at + 1
    while end + 1 < len(parts):
        gap, bay = parts[end], parts[end + 1]
        same_gap = end == at + 1 or (
            gap.symbol == parts[at + 1].symbol and _alike(gap.size, parts[at + 1].size)
        )
        if not (
            same_gap
            and gap.symbol != first.symbol
            and _alike(bay.size, first.size)
            and kind(bay.symbol) == kind(first.symbol)
        ):
            break
        end += 2
    return end


def _alike(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-6 * max(abs(a), abs(b), 1e-12)


def _count(length: float, period: float, offset: int) -> int:
    best = max(1, round(length / period))
    if offset == 0:
        return best
    count = best + offset
    stretch = length / (count * period) if count >= 1 else 0.0
    if count < 1 or not 1 / (1 + STRETCH) <= stretch <= 1 + STRETCH:
        return best
    return count


def _grid(rule: Rule, box: tuple[float, float, float, float], expand: object) -> None:
    x0, y0, x1, y1 = box
    columns = len(rule.across)
    rows = [rule.parts[i * columns].size for i in range(len(rule.parts) // columns)]
    widths = [w * (x1 - x0) / sum(rule.across) for w in rule.across]
    heights = [h * (y1 - y0) / sum(rows) for h in rows]
    y = y0
    for i, h in enumerate(heights):
        x = x0
        for j, w in enumerate(widths):
            part = rule.parts[i * columns + j]
            expand(part.symbol, (x, y, x + w, y + h), (rule.across[j], rows[i]))  # type: ignore[operator]
            x += w
        y += h


# -- the alignment QP -------------------------------------------------------------------


def align(
    pieces: list[Piece],
    width: float,
    height: float,
    background: str = BACKGROUND,
    style: Sequence[Constraint] = (),
    pull: bool = True,
    hold: bool = False,
) -> tuple[list[Piece], list[str]]:
    """Equal terminals one size and lined up, and the style's near misses made exact (see
    the module and :func:`~facadecli.grammar.style.equations`); with ``pull``, elements
    derived longer than in the source pulled back towards their source size; with
    ``hold``, every element (bands aside) keeps its size as derived instead, only moved
    (bays copied: their elements have the source's sizes already)."""
    warnings: list[str] = []
    mapping = {}
    kept: list[Equation] = []
    if style:
        kept = equations(style, elements_of(pieces, width, height, background), STYLE_NEAR * width)
    axes: tuple[tuple[Axis, float, list[Equation]], ...] = (("x", width, kept), ("y", height, []))
    for axis, extent, extra in axes:
        mapping[axis], axis_warnings = _align_axis(
            pieces, axis, extent, background, extra, pull, hold
        )
        warnings += axis_warnings
    moved = [
        Piece(
            p.label,
            mapping["x"][p.x0],
            mapping["y"][p.y0],
            mapping["x"][p.x1],
            mapping["y"][p.y1],
            p.source_w,
            p.source_h,
        )
        for p in pieces
    ]
    return [p for p in moved if p.x1 > p.x0 and p.y1 > p.y0], warnings


def _align_axis(
    pieces: list[Piece],
    axis: Axis,
    extent: float,
    background: str,
    extra: list[Equation],
    pull: bool = True,
    hold: bool = False,
) -> tuple[dict[float, float], list[str]]:
    import cvxpy as cp  # imported here: it takes half a second

    values = [v for p in pieces for v in ((p.x0, p.x1) if axis == "x" else (p.y0, p.y1))]
    joined = snap(values, 1e-9 * extent, (0.0, extent))
    edges = sorted(set(joined.values()))
    index = {v: i for i, v in enumerate(edges)}
    spans = []
    stretched: dict[tuple[int, int], float] = {}  # elements derived longer than their source
    held: dict[tuple[int, int], float] = {}  # elements that keep their size as derived
    groups: dict[tuple[str, int], list[tuple[int, int]]] = defaultdict(list)
    for p in pieces:
        a, b = (p.x0, p.x1) if axis == "x" else (p.y0, p.y1)
        span = (index[joined[a]], index[joined[b]])
        if p.label != background:  # elements keep KEPT_LEAST of their size; wall may vanish
            spans.append((span, edges[span[1]] - edges[span[0]]))
            source = p.source_w if axis == "x" else p.source_h
            groups[(p.label, round(source / (1e-6 * extent)))].append(span)
            if hold and b - a <= BAND * extent:
                held[span] = b - a
            elif pull and _stretched(b - a, source, extent):
                stretched[span] = source
    equal = []
    lined = []
    for members in groups.values():
        unique = sorted(set(members))
        equal += [(unique[0], other) for other in unique[1:]]
        for side in (0, 1):
            ends = sorted({span[side] for span in unique}, key=lambda i: edges[i])
            lined += [
                (a, b) for a, b in itertools.pairwise(ends) if edges[b] - edges[a] < ALIGN * extent
            ]
    v = cp.Variable(len(edges))
    n = len(edges)
    base = [v[0] == 0.0, v[n - 1] == extent]
    if n > 1:
        base.append(v[1:] >= v[:-1])
    floors = sorted(set(spans))  # elements keep KEPT_LEAST of their size
    if floors:
        base.append(_lengths(cp, v, n, [(span, size * KEPT_LEAST) for span, size in floors]) >= 0)
    if held:
        base.append(_lengths(cp, v, n, sorted(held.items())) == 0)
    # every gap below one vector (a matrix times the edges): one expression each, however
    # many terminals a large derivation makes
    size_gaps = _combination(
        cp,
        v,
        n,
        [_terms((b1, 1.0), (a1, -1.0), (b0, -1.0), (a0, 1.0)) for (a0, b0), (a1, b1) in equal],
    )
    line_gaps = _combination(cp, v, n, [_terms((a, 1.0), (b, -1.0)) for a, b in lined])
    styled = [(terms, rhs) for terms, rhs in extra if all(value in joined for value, _ in terms)]
    style_gaps = _combination(
        cp,
        v,
        n,
        [_terms(*((index[joined[value]], c) for value, c in terms)) for terms, _ in styled],
        [rhs for _, rhs in styled],
    )
    moves = cp.sum_squares(v - edges)
    if stretched:  # back towards their source size, the wall around them taking the rest
        moves = moves + WIDTHS * cp.sum_squares(_lengths(cp, v, n, sorted(stretched.items())))
    hard_sizes = [] if size_gaps is None else [size_gaps == 0]
    hard_style = [] if style_gaps is None else [style_gaps == 0]
    hard_lines = [] if line_gaps is None else [line_gaps == 0]
    soft_sizes = 0.0 if size_gaps is None else cp.sum_squares(size_gaps)
    soft_lines = 0.0 if line_gaps is None else cp.sum_squares(line_gaps)
    soft_style = 0.0 if style_gaps is None else SOFT * cp.sum_squares(style_gaps)
    attempts = [  # hard where they fit, else as near as they can be (weighted), else neither
        (moves, hard_sizes + hard_style + hard_lines, None),
        (moves + SOFT * soft_lines, hard_sizes + hard_style, None),
        (moves + SOFT * soft_lines + soft_style, hard_sizes, None),
        (
            moves + SOFT * (soft_sizes + soft_lines) + soft_style,
            [],
            "made as near as they can be",
        ),
        (moves, [], "left out"),
    ]
    warnings = []
    for objective, constraints, fallback in attempts:
        if fallback:
            warnings.append(f"{axis}: equal sizes of equal terminals {fallback}")
        problem = cp.Problem(cp.Minimize(objective), base + constraints)
        try:
            with warnings_module.catch_warnings():  # "may be inaccurate": the style is checked
                warnings_module.simplefilter("ignore", UserWarning)
                # overflow evaluating the objective of an attempt that failed: its status says
                warnings_module.simplefilter("ignore", RuntimeWarning)
                problem.solve(solver=cp.CLARABEL)
        except cp.error.SolverError:
            continue
        if problem.status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) and v.value is not None:
            solved = [float(x) for x in v.value]
            solved[0], solved[-1] = 0.0, extent
            apart = sum(abs(solved[a] - solved[b]) > 1e-3 * extent for a, b in lined)
            if apart:
                warnings.append(
                    f"{axis}: {apart} of {len(lined)} near line-ups of equal terminals left "
                    "apart (lining them up would squeeze other elements)"
                )
            merged = snap(solved, 1e-7 * extent, (0.0, extent))
            return {value: merged[solved[index[joined[value]]]] for value in joined}, warnings
    return {value: joined[value] for value in joined}, warnings


def _lengths(cp: Any, v: Any, n: int, spans: list[tuple[tuple[int, int], float]]) -> Any:
    """The vector of each span's length (its end edge less its start edge) less a size."""
    return _combination(
        cp, v, n, [_terms((b, 1.0), (a, -1.0)) for (a, b), _ in spans], [s for _, s in spans]
    )


def _terms(*pairs: tuple[int, float]) -> dict[int, float]:
    """Coefficients by edge, those of one edge added up."""
    found: dict[int, float] = {}
    for i, c in pairs:
        found[i] = found.get(i, 0.0) + c
    return found


def _combination(
    cp: Any, v: Any, n: int, rows: list[dict[int, float]], rhs: list[float] | None = None
) -> Any:
    """The vector of ``row @ v - rhs`` over the rows (None when there are none), as one
    sparse matrix times the edges."""
    if not rows:
        return None
    import scipy.sparse as sparse

    entries = [(r, i, c) for r, row in enumerate(rows) for i, c in row.items()]
    matrix = sparse.csr_matrix(
        ([c for _, _, c in entries], ([r for r, _, _ in entries], [i for _, i, _ in entries])),
        shape=(len(rows), n),
    )
    made = matrix @ v
    return made if rhs is None else made - np.array(rhs)


# -- the result as a layout ---------------------------------------------------------------


@dataclass(frozen=True)
class Look:
    mesh: str
    depth: float  # front face out from the wall, in fifteenths of the façade's shorter side
    thickness: float  # in the same units


LOOKS = {  # CMP labels; anything else is a shallow box
    BACKGROUND: Look("box", 0.0, 0.3),
    "window": Look("frame", 0.0, 0.3),
    "door": Look("frame", 0.0, 0.3),
    "shop": Look("frame", 0.0, 0.3),
    "balcony": Look("box", 0.4, 0.7),
    "cornice": Look("ledge", 0.15, 0.45),
    "molding": Look("ledge", 0.1, 0.4),
    "sill": Look("ledge", 0.1, 0.4),
    "pillar": Look("box", 0.1, 0.4),
    "blind": Look("box", 0.02, 0.32),
}
DEFAULT_LOOK = Look("box", 0.05, 0.35)


def _ident(label: str, taken: set[str]) -> str:
    name = re.sub(r"[^A-Za-z0-9_]", "_", label) or "label"
    if not name[0].isalpha():
        name = "L" + name
    base, n = name, 2
    while name in taken:
        name, n = f"{base}_{n}", n + 1
    taken.add(name)
    return name


def pieces_layout(
    pieces: list[Piece], width: float, height: float, name: str, warnings: list[str]
) -> Layout:
    """A ``Layout`` of the pieces, one layer per label, for the layout writers."""
    from facadecli.grammar.palette import label_colour
    from facadecli.layout import Appearance, Layout, Shape
    from facadecli.solver.axis import AxisLayout
    from facadecli.spec.model import Spec

    unit = min(width, height) / 15  # looks are in metres for a façade 15 m on its shorter side
    labels = sorted(
        {p.label for p in pieces}, key=lambda label: (CMP_Z_ORDER.get(label, 99), label)
    )
    taken: set[str] = set()
    idents = {label: _ident(label, taken) for label in labels}
    spec = Spec.model_validate(
        {
            "version": 1,
            "name": name,
            "canvas": {"width": width, "height": height},
            "symbols": {idents[label]: {"label": label} for label in labels},
            "patterns": {idents[label]: idents[label] for label in labels},
            "layers": [
                {"name": idents[label], "x": idents[label], "y": idents[label]} for label in labels
            ],
            "materials": {idents[label]: {"color": label_colour(label)} for label in labels},
        }
    )
    shapes = []
    for p in sorted(pieces, key=lambda p: (labels.index(p.label), p.y0, p.x0)):
        look = LOOKS.get(p.label, DEFAULT_LOOK)
        ident = idents[p.label]
        shapes.append(
            Shape(
                layer=ident,
                x=ident,
                y=ident,
                x0=p.x0,
                x1=p.x1,
                y0=p.y0,
                y1=p.y1,
                z0=round((look.depth - look.thickness) * unit, 6),
                z1=round(look.depth * unit, 6),
                material=ident,
                mesh=look.mesh,
                reflected_x=False,
                reflected_y=False,
                opaque=True,
                look=Appearance(ident, look.mesh, look.depth * unit, look.thickness * unit),
            )
        )
    extents: tuple[tuple[Axis, float], ...] = (("x", width), ("y", height))
    axes = [
        AxisLayout(
            axis,
            extent,
            {},
            {},
            {},
            {},
            {},
            0.0,
            0.0,
            0,
            tuple(w for w in warnings if w.startswith(axis)),
        )
        for axis, extent in extents
    ]
    return Layout(spec, width, height, axes[0], axes[1], tuple(shapes), 0.0)


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)[:NAME_MAX] or "layout"


def derive_layout(
    grammar: Grammar, tiling: Tiling, width: float, height: float, name: str
) -> Layout:
    """The grammar at a new size as a layout named ``<name>-<W>x<H>`` (the name with every
    character a layout name cannot hold made ``_``): :func:`derive_variations`' first, with
    the style of the tiling the grammar comes from."""
    drawn, _ = derive_variations(grammar, tiling, width, height, name, 1, 0, style_of(tiling))
    return drawn[0].layout


# -- variations (Bao et al. 2013) ---------------------------------------------------------


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


Shuffle = tuple[str, tuple[str, ...]]  # a split rule, its parts' symbols in a new order
Proportions = tuple[tuple[str, str, float], ...]  # (axis, part size, factor on that size)


@dataclass(frozen=True)
class _Candidate:
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


def _key(pieces: list[Piece]) -> tuple[tuple[str, float, float, float, float], ...]:
    """The pieces as they would be written (to tell two derivations apart)."""
    return tuple(
        sorted(
            (p.label, round(p.x0, 9), round(p.y0, 9), round(p.x1, 9), round(p.y1, 9))
            for p in pieces
        )
    )


def derive_variations(
    grammar: Grammar,
    tiling: Tiling,
    width: float,
    height: float,
    name: str,
    count: int,
    seed: int,
    style: Sequence[Constraint] = (),
) -> tuple[list[Variation], list[str]]:
    """Up to ``count`` different layouts of the grammar at a size, and warnings (fewer than
    asked). Candidates vary the best-fitting count of each repeat rule by -1, 0 or +1 (one
    offset per rule, so a rule's copies stay equal and the two halves of a mirrored split
    stay alike; one offset for all repeats of one period along one axis, so columns of
    windows and of their sills stay lined up), where the copies stretch by at most
    ``STRETCH`` (elsewhere the best fit stays); shuffle the parts of a split that are as
    long as each other (``_shuffles``); or draw new proportions near the source's
    (``_proportions``, ``proportions.DRAWS`` per variation asked for; never variation 0).

    Variation 0 keeps the most of the source's ``style`` (Bao et al. 2013's constraints),
    and among those it is the nearest the source's sizes (the best fit, when it keeps as
    much as any). The others are drawn at random (``seed``) among the candidates that keep
    as much, then among the rest, favouring low scores, and ordered by what they keep and
    their score; each differs visibly from every one before it (``pieces.apart``: more
    or fewer elements of a label, or its elements a mean ``APART`` of the façade's smaller
    side or more from theirs) and
    keeps as much of the style as variation 0, so fewer than ``count`` may exist. Named
    ``<name>-<W>x<H>`` when ``count`` is 1, else ``<name>-<W>x<H>-v<K>``."""
    source = (tiling.xs[-1], tiling.ys[-1])
    stem = f"{_safe(name)}-{width:g}x{height:g}"
    grammar = _with_runs(grammar, source)

    def named(k: int) -> str:
        return stem if count == 1 else f"{stem}-v{k}"

    def kept(pieces: list[Piece]) -> Kept:
        return check(style, elements_of(pieces, width, height))

    def candidate(
        offsets: dict[str, int], shuffle: Shuffle | None = None, drawn: Proportions = ()
    ) -> _Candidate | None:
        rules = grammar
        if shuffle is not None:
            rule = grammar.rules[shuffle[0]]
            parts = tuple(Part(p.size, s) for p, s in zip(rule.parts, shuffle[1], strict=True))
            rules = replace(
                grammar, rules={**grammar.rules, shuffle[0]: replace(rule, parts=parts)}
            )
        if drawn:
            rules = _proportioned(rules, drawn, source)
        try:
            pieces = derive_at(rules, source, width, height, offsets)
        except TooLarge:
            return None
        changes = tuple(sorted(offsets.items()))
        return _Candidate(score(pieces), changes, shuffle, pieces, kept(pieces), drawn)

    used: set[str] = set()
    best = derive_at(grammar, source, width, height, used=used)
    best_kept = kept(best)
    candidates: list[_Candidate | None] = [_Candidate(score(best), (), None, best, best_kept)]
    if (width, height) != source:  # whole bays copied from the source's own terminals
        at_source = derive_at(grammar, source, *source)
        for pieces, stretch, text in retargeted(at_source, source, width, height, style):
            candidates.append(
                _Candidate(score(pieces) + stretch, (), None, pieces, kept(pieces), (), text)
            )
    if count > 1 or best_kept.broken:
        rng = random.Random(seed)
        most = CANDIDATES_MAX if count > 1 else STYLE_MAX
        candidates += [candidate(offsets) for offsets in _offsets(grammar, used, rng, most)]
    if count > 1:
        candidates += [candidate({}, shuffle) for shuffle in _shuffles(grammar)]
        rng = random.Random(seed)
        draws = _proportions(grammar, source, rng, proportions.DRAWS * count)
        candidates += [candidate({}, None, factors) for factors in draws]
        if (width, height) != source:  # until enough keep the most of the style
            size = (width, height)
            made = [c for c in candidates if c is not None]
            most = max(len(c.kept.kept) for c in made)
            good = {_key(c.pieces) for c in made if len(c.kept.kept) >= most}
            candidates += _proportioned_copies(
                at_source, source, size, style, random.Random(seed), kept, (most, count, good)
            )
    # most constraints kept, then the best fit, then nearest the source; the same pieces once
    seen: set[tuple[tuple[str, float, float, float, float], ...]] = set()
    ranked = []
    for found_one in sorted((c for c in candidates if c is not None), key=lambda c: c.rank):
        key = _key(found_one.pieces)
        if key not in seen:
            seen.add(key)
            ranked.append(found_one)
    # drawn proportions only vary a layout: the layout of a size is the grammar's own
    # the best of the grammar's and the best of whole bays copied, as each is written:
    # tidying makes a near miss of the style exact, so either may keep more in the end
    finalists = [
        next((c for c in ranked if not c.proportions and bool(c.retarget) is copied), None)
        for copied in (False, True)
    ]
    # at the input's own size the best fit is the input itself: nothing to tidy (the QP
    # once halved cmp_b0001's windows there, keeping as much of the style)
    tidied = [
        (c, c.pieces, [], c.kept)
        if (width, height) == source and not c.offsets and c.shuffle is None
        else (c, *_tidied(c.pieces, c.kept, kept, width, height, style, bool(c.retarget)))
        for c in finalists
        if c is not None
    ]
    first, aligned, warnings, keeps = min(tidied, key=lambda t: (-len(t[3].kept), likeness(t[1])))
    layout = pieces_layout(aligned, width, height, named(0), warnings)
    found = [
        Variation(
            layout,
            first.offsets,
            first.score,
            keeps,
            first.shuffle,
            (),
            tuple(aligned),
            first.retarget,
        )
    ]
    if count == 1:
        return found, []
    # a weighted draw without replacement (Efraimidis and Spirakis): keys u^(1/w), drawn
    # first among the candidates that keep as much of the style as variation 0
    rng = random.Random(seed)
    drawn = sorted(
        (c for c in ranked if c is not first),
        key=lambda c: (
            -len(c.kept.kept),
            -math.log(rng.random() or 1e-300)
            * math.exp(min((c.score - first.score) / TEMPERATURE, 700.0)),
        ),
    )
    chosen: list[tuple[_Candidate, list[Piece], list[str], Kept]] = []
    aligned_seen = {_key(aligned)}
    shown = [aligned]  # the variations so far: another differs visibly from each
    least = APART * min(width, height)
    for other in drawn:  # aligned, two could still coincide
        if len(chosen) == count - 1:
            break
        if not all(apart(other.pieces, p, least) for p in shown):
            continue  # too near one as derived: not tidied (tidying moves edges a little)
        moved, moved_warnings, keeps = _tidied(
            other.pieces, other.kept, kept, width, height, style, bool(other.retarget)
        )
        key = _key(moved)
        if (
            key not in aligned_seen
            and len(keeps.kept) >= len(found[0].kept.kept)  # the style, as variation 0 keeps it
            and all(apart(moved, p, least) for p in shown)
        ):
            aligned_seen.add(key)
            shown.append(moved)
            chosen.append((other, moved, moved_warnings, keeps))
    chosen.sort(key=lambda c: (-len(c[3].kept), c[0].rank[2:]))
    for k, (other, moved, moved_warnings, keeps) in enumerate(chosen, start=1):
        layout = pieces_layout(moved, width, height, named(k), moved_warnings)
        found.append(
            Variation(
                layout,
                other.offsets,
                other.score,
                keeps,
                other.shuffle,
                other.proportions,
                tuple(moved),
                other.retarget,
            )
        )
    notes = []
    if len(found) < count:
        notes.append(
            f"only {len(found)} of {count} variations exist (repeat counts within 1 of the "
            f"best fit whose copies stretch by at most {STRETCH:.0%}, parts of a split "
            "that are as long as each other in a new order, and parts' proportions drawn "
            "near the source's; each keeping as much of the style as the first, with more "
            f"or fewer elements, or its elements a mean {APART:.0%} of the façade's smaller "
            "side or more from every other's)"
        )
    return found, notes


def _proportions(
    grammar: Grammar, source: tuple[float, float], rng: random.Random, draws: int
) -> list[Proportions]:
    """``draws`` sets of new proportions (:mod:`facadecli.proportions`): a factor per class
    of part sizes along an axis (sizes within ``ALIGN`` of the façade's extent), so parts
    of one size, in whatever rule, stay alike."""
    keys: list[tuple[str, str, int]] = []  # axis, size, class
    for axis, extent in zip(("x", "y"), source, strict=True):
        sizes = {
            part.size
            for rule in grammar.rules.values()
            if rule.op != "gridsplit" and rule.axis == axis
            for part in rule.parts
        }
        classes = proportions.size_classes(sizes, ALIGN * extent)
        keys += [(axis, _size_key(size), number) for size, number in sorted(classes.items())]
    found = []
    for _ in range(draws if keys else 0):
        factors: dict[tuple[str, int], float] = {}
        for axis, _, number in keys:
            if (axis, number) not in factors:
                factors[(axis, number)] = proportions.factor(rng)
        found.append(tuple((axis, size, factors[(axis, number)]) for axis, size, number in keys))
    return found


def _proportioned_copies(
    source_pieces: list[Piece],
    source: tuple[float, float],
    size: tuple[float, float],
    style: Sequence[Constraint],
    rng: random.Random,
    kept: Callable[[list[Piece]], Kept],
    wanted: tuple[int, int, set[tuple[tuple[str, float, float, float, float], ...]]],
) -> list[_Candidate]:
    """Whole bays and floors copied (:func:`~facadecli.grammar.slabs.retargeted`) from the
    source's terminals with new proportions (:func:`facadecli.proportions.warp` along
    each axis): variations of a copied layout that keep its style, where a façade has
    one good way to be copied. A draw that keeps less of the style at the source's size
    is skipped; the pieces keep their sizes in the source, so the score says how far the
    draw moved them. ``wanted`` = (most, count, good): draws stop once ``count``
    different layouts keep ``most`` of the style (``good`` holds those found already,
    :func:`_key`), and after ``count`` copied or ``proportions.DRAWS`` times as many
    drawn (the work counted in draws, not time)."""

    def kept_at_source(pieces: list[Piece]) -> int:
        return len(check(style, elements_of(pieces, *source)).kept)

    whole = kept_at_source(source_pieces)
    found: list[_Candidate] = []
    most, count, good = wanted
    good = set(good)
    copied = 0
    for _ in range(proportions.DRAWS * count):
        if copied == count or len(good) >= count:
            break
        xs, drawn_x = proportions.warp(
            [(p.x0, p.x1, p.label) for p in source_pieces],
            source[0],
            ALIGN * source[0],
            rng,
            mirrored=any(c.kind in ("symmetry", "centre") for c in style),
        )
        ys, drawn_y = proportions.warp(
            [(p.y0, p.y1, p.label) for p in source_pieces], source[1], ALIGN * source[1], rng
        )
        moved = [
            replace(p, x0=xs[p.x0], x1=xs[p.x1], y0=ys[p.y0], y1=ys[p.y1]) for p in source_pieces
        ]
        if kept_at_source(moved) < whole:
            continue
        copied += 1
        drawn: Proportions = (
            *(("x", kind, f) for kind, f in drawn_x),
            *(("y", kind, f) for kind, f in drawn_y),
        )
        for pieces, stretch, text in retargeted(moved, source, *size, style):
            made = f"{text}; proportions drawn"
            found.append(
                _Candidate(score(pieces) + stretch, (), None, pieces, kept(pieces), drawn, made)
            )
            if len(found[-1].kept.kept) >= most:
                good.add(_key(pieces))
    return found


def _size_key(size: float) -> str:
    return f"{size:.6g}"


def _proportioned(grammar: Grammar, drawn: Proportions, source: tuple[float, float]) -> Grammar:
    """The grammar with its parts' sizes multiplied by their factors; parts thinner than
    ``THIN`` keep their size (frames and sills keep their absolute size anyway)."""
    factor = {(axis, size): f for axis, size, f in drawn}
    thin = {"x": THIN * source[0], "y": THIN * source[1]}
    rules = {}
    for name, rule in grammar.rules.items():
        if rule.op == "gridsplit":
            rules[name] = rule
            continue
        parts = tuple(
            p
            if p.size < thin[rule.axis]
            else Part(p.size * factor[(rule.axis, _size_key(p.size))], p.symbol)
            for p in rule.parts
        )
        rules[name] = replace(rule, parts=parts)
    return replace(grammar, rules=rules)


def _shuffles(grammar: Grammar) -> list[Shuffle]:
    """New orders of split rules' parts (Bao et al. 2013's shuffles, ABB -> BAB): parts as
    long as each other (and not plain wall) change places; a mirrored split's centre stays,
    and its halves stay mirrored (the rule lays them). At most ``SHUFFLES_MAX`` a rule."""
    found: list[Shuffle] = []
    for name in sorted(grammar.rules):
        rule = grammar.rules[name]
        if rule.op not in ("split", "symsplit"):
            continue
        movable = len(rule.parts) - (1 if rule.op == "symsplit" and rule.centre else 0)
        by_size: dict[float, list[int]] = defaultdict(list)
        for i, part in enumerate(rule.parts[:movable]):
            if part.symbol != BACKGROUND:
                by_size[round(part.size, 6)].append(i)
        symbols = [p.symbol for p in rule.parts]
        for places in by_size.values():
            here = [symbols[i] for i in places]
            if len(set(here)) < 2:
                continue
            orders = sorted(set(itertools.permutations(here)) - {tuple(here)})
            for order in orders[:SHUFFLES_MAX]:
                new = list(symbols)
                for i, symbol in zip(places, order, strict=True):
                    new[i] = symbol
                found.append((name, tuple(new)))
    return found


def _tidied(
    pieces: list[Piece],
    keeps: Kept,
    kept: Callable[[list[Piece]], Kept],
    width: float,
    height: float,
    style: Sequence[Constraint],
    copies: bool = False,
) -> tuple[list[Piece], list[str], Kept]:
    """A derivation through the alignment QP (:func:`align`), unless that breaks some of
    the style the derivation keeps: then as derived, with a warning. Where pulling
    stretched elements back breaks some of the style, the QP without the pull is tried
    too, and the one that keeps more is taken (the pulled one on a tie). Of ``copies``
    (whole bays copied: already aligned) the QP's is taken only where it keeps more of
    the style, or as much and its sizes are no further from the source's."""
    aligned, warnings = align(pieces, width, height, style=style, hold=copies)
    after = kept(aligned)
    if after.broken and not copies and _any_stretched(pieces, width, height):
        plain, plain_warnings = align(pieces, width, height, style=style, pull=False)
        plain_after = kept(plain)
        if len(plain_after.kept) > len(after.kept):
            aligned, warnings, after = plain, plain_warnings, plain_after
    if copies and len(after.kept) == len(keeps.kept) and score(aligned) > score(pieces) + 1e-9:
        return pieces, [], keeps
    if len(after.kept) >= len(keeps.kept):
        return aligned, warnings, after
    lost = len(keeps.kept) - len(after.kept)
    return pieces, [f"not tidied: lining up equal terminals would break {lost} of its style"], keeps


def _any_stretched(pieces: list[Piece], width: float, height: float) -> bool:
    """Whether the alignment QP pulls some element back towards its source size."""
    return any(
        p.label != BACKGROUND
        and (
            _stretched(p.x1 - p.x0, p.source_w, width)
            or _stretched(p.y1 - p.y0, p.source_h, height)
        )
        for p in pieces
    )


def _stretched(size: float, source: float, extent: float) -> bool:
    """An element derived longer than its source, and not a band across the façade."""
    return STRETCHED * source < size <= BAND * extent


def _offsets(
    grammar: Grammar, used: set[str], rng: random.Random, most: int
) -> Iterator[dict[str, int]]:
    """Changes to the best-fitting repeat counts (see :func:`derive_variations`): every
    choice of -1, 0 or +1 per group of repeats when there are at most ``most``, else
    ``most`` drawn at random."""
    linked: dict[tuple[str, float], list[str]] = defaultdict(list)
    for symbol in sorted(used):  # repeats of one period along one axis vary together
        rule = grammar.rules[symbol]
        period = rule.parts[:2] if rule.op == "run" else rule.parts
        linked[(rule.axis, round(sum(p.size for p in period), 6))].append(symbol)
    groups = [linked[k] for k in sorted(linked)]
    if 3 ** len(groups) <= most:
        choices = list(itertools.product((-1, 0, 1), repeat=len(groups)))
    else:
        choices = sorted({tuple(rng.choice((-1, 0, 1)) for _ in groups) for _ in range(most)})
    for choice in choices:
        offsets = {s: o for g, o in zip(groups, choice, strict=True) if o for s in g}
        if offsets:
            yield offsets
