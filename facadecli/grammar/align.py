"""A derivation tidied with a QP per axis (cvxpy), after Bao et al. 2013: edges stay near
where the derivation put them, terminals that were one size in the source get one size,
their edges that nearly line up across the façade are lined up, elements the derivation
made longer than in the source (a split without repeats shares a wider façade among all
its parts) are pulled back towards their source size, the wall taking the rest, and the
source's style (:mod:`facadecli.grammar.style`) is made exact where the derivation nearly
keeps it. Constraints that cannot all hold are dropped (alignment first, then the style,
then equal sizes) with a warning; a tidying that breaks some of the style the derivation
keeps is not taken (:func:`tidy_derivation`).
"""

from __future__ import annotations

import itertools
import warnings as warnings_module
from collections import defaultdict
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from facadecli.grammar.model import Constraint, Kept, Piece
from facadecli.grammar.pieces import elements_of, score
from facadecli.grammar.split import Axis
from facadecli.grammar.style import Equation, equations
from facadecli.grammar.tiling import BACKGROUND, snap

STRETCHED = 1.05  # an element derived longer than this times its source size is pulled back
WIDTHS = 100.0  # ... with this weight against moving edges (bands are not: they stretch)
BAND = 0.25  # of the new extent: a longer element is a band across the façade
ALIGN = 0.02  # of the new extent: edges of equal terminals closer than this are lined up
STYLE_NEAR = 0.05  # of the new width: near misses of the style this close are made exact
KEPT_LEAST = 0.75  # of its size as derived: the alignment QP shrinks no element further
SOFT = 100.0  # weight of equal sizes and line-ups when they cannot all hold exactly


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


def tidy_derivation(
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
    if after.broken and not copies and any_stretched(pieces, width, height):
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


def any_stretched(pieces: list[Piece], width: float, height: float) -> bool:
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
