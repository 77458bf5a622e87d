"""Regularising a labelled layout (Wu et al. 2014, section 3.3): repeated elements get one
size, so that their regions hash alike and a grammar can share their rules.

Per axis, every distinct edge of the (snapped) layout is a variable of a small QP (cvxpy):
edges stay as near as they can to where they were drawn, the façade's own edges stay put,
edges keep their order, and

- elements of one label whose sizes differ by less than ``tolerance`` x the façade's extent
  (and less than a tenth) get one size;
- strips of the tiling between neighbouring edges that show the same labels across the
  whole façade (the wall between two window columns, say) and differ as little get one size;
- *periodic runs* (Bao et al. 2013's equal spacing): three or more elements of one label
  and size side by side in a row (or stacked in a column) whose pitches differ by less than
  ``PITCH`` x the tolerance x the extent (and less than a tenth of the pitch) get one pitch,
  so hand-drawn bays become a run a grammar can repeat;
- *line-ups* (Bao's alignment): elements whose centres are nearer than the tolerance x the
  extent get one centre where they can (a door under a window column, a balcony under a
  window).

Fidelity comes first (issue 34): no edge goes further from where it was drawn than the
tolerance, nor than ``FAITHFUL`` (a thirty-second) of the narrowest element, gap between
two elements of one label, or visible part of an element it bounds (``tiling.move_limits``;
``bounds_of``), so an equal size changes no member's size by more than a sixteenth and
nothing is lost, shrunk away or fused. Within those bounds every equality is first asked
for softly (weighted by kind, ``WEIGHTS``: elements, then strips, runs and line-ups);
those the soft QP meets are then made exact together (where they cannot all be, an exact
penalty keeps the most), and the rest stay exactly as drawn, never moved part of the way
(the report counts them). What moved is returned for the report.
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from dataclasses import dataclass, field, replace

import numpy as np

from facadecli.grammar.deadline import Deadline
from facadecli.grammar.tiling import LabelledLayout, Rect, Tiling, move_limits, snap, tile

DEFAULT_TOLERANCE = 0.01  # of the façade's extent along the axis
RELATIVE = 0.1  # and never sizes more than this fraction apart
MET = 1e-4  # of the extent: equal sizes and line-ups the soft QP brings this near are made exact
EQUAL = 1e-6  # of the extent: sizes this near are equal
# weights of equal sizes against moving edges (both squared), the weightiest kept first
WEIGHTS = {"element": 1e4, "strip": 3e3, "run": 1e3, "line-up": 1e2}
FAITHFUL = 1 / 32  # an edge moves at most this share of the narrowest element or gap it bounds
YIELD = 10.0  # an equality made exact costs this many times the objective's steepest slope
PITCH = 2.0  # pitches of a run may differ by this many tolerances (hand drawing jitters)


@dataclass(frozen=True)
class Move:
    axis: str
    before: float
    after: float


@dataclass(frozen=True)
class SizeGroup:
    axis: str
    kind: str  # "element" (one label), "strip" (a band of the tiling), "run" or "line-up"
    label: str
    count: int
    size: float


@dataclass
class Regularization:
    tolerance: float
    moves: list[Move] = field(default_factory=list)
    groups: list[SizeGroup] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    @property
    def max_move(self) -> float:
        return max((abs(m.after - m.before) for m in self.moves), default=0.0)

    def summary(self) -> dict[str, object]:
        return {
            "tolerance": self.tolerance,
            "edges_moved": len(self.moves),
            "max_move": round(self.max_move, 6),
            "moves": [
                {"axis": m.axis, "from": round(m.before, 6), "to": round(m.after, 6)}
                for m in self.moves
            ],
            "equal_sizes": [
                {
                    "axis": g.axis,
                    "kind": g.kind,
                    "label": g.label,
                    "count": g.count,
                    "size": round(g.size, 6),
                }
                for g in self.groups
            ],
            "warnings": self.warnings,
        }


def _clusters(items: list[tuple[float, int]], tolerance: float) -> list[list[int]]:
    """Indices grouped by nearly equal value: sorted, a new group where the value is further
    from the group's first than the tolerance or than ``RELATIVE`` of itself. Groups of one
    are left out."""
    groups: list[list[tuple[float, int]]] = []
    for value, index in sorted(items):
        if groups and value - groups[-1][0][0] <= min(tolerance, RELATIVE * value):
            groups[-1].append((value, index))
        else:
            groups.append([(value, index)])
    return [[index for _, index in group] for group in groups if len(group) > 1]


def _movable(group: list[Span], cuts: set[float]) -> bool:
    """Whether every edge of a group is an edge of the tiling (a QP variable)."""
    return all(a in cuts and b in cuts for a, b in group)


def _pairs_of(
    rects: list[Rect], tiling: Tiling, axis: str, extent: float, tolerance: float
) -> tuple[dict[str, list[list[tuple[float, float]]]], dict[str, list[list[tuple[float, float]]]]]:
    """Spans (start, end) to be equal along an axis: element groups and strip groups."""
    elements: dict[str, list[list[tuple[float, float]]]] = {}
    by_label: dict[str, dict[tuple[float, float], None]] = defaultdict(dict)
    for rect in rects:  # each label's distinct spans, in order (a dict as an ordered set)
        by_label[rect.label][(rect.x0, rect.x1) if axis == "x" else (rect.y0, rect.y1)] = None
    for label, distinct in sorted(by_label.items()):
        spans = list(distinct)
        sizes = [(b - a, i) for i, (a, b) in enumerate(spans)]
        elements[label] = [
            [spans[i] for i in group] for group in _clusters(sizes, tolerance * extent)
        ]
    cuts = tiling.xs if axis == "x" else tiling.ys
    bands: dict[tuple[str, ...], list[tuple[float, float]]] = defaultdict(list)
    for k, (a, b) in enumerate(itertools.pairwise(cuts)):
        column = tuple(row[k] for row in tiling.labels) if axis == "x" else tiling.labels[k]
        bands[column].append((a, b))
    strips: dict[str, list[list[tuple[float, float]]]] = {}
    for column, spans in bands.items():
        sizes = [(b - a, i) for i, (a, b) in enumerate(spans)]
        groups = [[spans[i] for i in group] for group in _clusters(sizes, tolerance * extent)]
        if groups:
            name = "/".join(dict.fromkeys(column))
            strips.setdefault(name, []).extend(groups)
    return elements, strips


Span = tuple[float, float]


def _runs(
    rects: list[Rect], axis: str, extent: float, tolerance: float
) -> dict[str, list[list[Span]]]:
    """Equal pitches of periodic runs (see the module), as groups of spans from one
    element's start to the next one's, by label."""
    rows: dict[tuple[str, float, float], set[Span]] = defaultdict(set)
    for rect in rects:
        start, end = (rect.x0, rect.x1) if axis == "x" else (rect.y0, rect.y1)
        across = (rect.y0, rect.y1) if axis == "x" else (rect.x0, rect.x1)
        rows[(rect.label, *across)].add((start, end - start))
    runs: dict[str, list[list[Span]]] = defaultdict(list)
    for (label, *_), members in sorted(rows.items()):
        ordered = sorted(members)
        run: list[Span] = []
        for (a, size_a), (b, size_b) in itertools.pairwise(ordered):
            pitch = b - a
            near = min(PITCH * tolerance * extent, RELATIVE * pitch)
            if (
                run
                and abs(pitch - (run[0][1] - run[0][0])) <= near
                and abs(size_b - size_a) <= min(tolerance * extent, RELATIVE * size_a)
            ):
                run.append((a, b))
                continue
            if len(run) >= 2:
                runs[label].append(run)
            run = (
                [(a, b)]
                if abs(size_b - size_a) <= min(tolerance * extent, RELATIVE * size_a)
                else []
            )
        if len(run) >= 2:
            runs[label].append(run)
    return runs


def _line_ups(rects: list[Rect], axis: str, extent: float, tolerance: float) -> list[list[Span]]:
    """Line-ups (see the module), each as pairs that keep the sum of their edges: the
    centre of ``(a, b)`` equals that of ``(a0, b0)`` when ``b - a0 == b0 - a``, so each
    member after the first is the group ``[(b0, a), (a0, b)]`` read as equal spans."""
    spans = sorted(
        {((r.x0, r.x1) if axis == "x" else (r.y0, r.y1)) for r in rects},
        key=lambda span: (span[0] + span[1], span),
    )
    centres = [((a + b) / 2, i) for i, (a, b) in enumerate(spans)]
    groups = []
    for members in _clusters(centres, tolerance * extent):
        (a0, b0), rest = spans[members[0]], [spans[i] for i in members[1:]]
        groups += [[(a, b0), (a0, b)] for a, b in rest if (a, b) != (a0, b0)]
    return groups


def _size_gap(pair: list[Span], at: dict[float, float]) -> float:
    """How far apart the sizes of a pair's two spans are, with the edges where ``at`` puts
    them (a line-up is such a pair: see ``_line_ups``)."""
    (a0, b0), (a, b) = pair
    return abs(at[b] - at[a] - at[b0] + at[a0])


def _pairs(groups: list[list[Span]], index: dict[float, int]) -> np.ndarray:
    """Rows (a0, b0, a, b) of edge indices, one per member after a group's first: the
    span (a, b) is to be as long as (a0, b0)."""
    return np.array(
        [
            (index[group[0][0]], index[group[0][1]], index[a], index[b])
            for group in groups
            for a, b in group[1:]
        ],
        dtype=int,
    ).reshape(-1, 4)


def _solve_axis(
    edges: list[float],
    extent: float,
    groups: list[list[tuple[float, float]]],
    elements: list[tuple[float, float]],
    soft: list[tuple[float, list[list[tuple[float, float]]]]],
    bounds: tuple[np.ndarray, np.ndarray],
    yielding: bool = False,
) -> list[float] | None:
    """Edges as near as they can be to where they were and within their ``bounds`` (low,
    high), with the spans of each group equal, and those of each ``soft`` group as near to
    equal as they can be (its weight times the square of the difference). ``yielding``:
    the groups' equalities are an exact penalty (``YIELD`` times the absolute difference)
    instead of constraints, so groups that cannot all be equal together leave the fewest
    apart and the rest exactly equal."""
    import cvxpy as cp  # imported here: it takes half a second

    index = {value: i for i, value in enumerate(edges)}
    kept = sorted(set(elements))  # elements keep their sizes as well as they can
    starts = np.array([index[a] for a, _ in kept], dtype=int)
    stops = np.array([index[b] for _, b in kept], dtype=int)
    drawn = np.array([b - a for a, b in kept])
    equal = _pairs(groups, index)
    v = cp.Variable(len(edges))
    # constraints as a few vector expressions: building one per pair is slow in cvxpy
    constraints = [v[0] == 0.0, v[len(edges) - 1] == extent, cp.diff(v) >= 0]
    constraints += [v >= bounds[0], v <= bounds[1]]
    # moving an edge costs more the less it may move (the edge of a sill more than of a
    # wall): the same share of its bound costs the same, so small elements move least
    reach = np.maximum((bounds[1] - bounds[0]) / 2, 1e-9 * extent)
    objective = cp.sum_squares(cp.multiply(reach.max() / reach, v - np.array(edges)))
    if kept:  # every element keeps at least half its size
        constraints.append(v[stops] - v[starts] >= drawn / 2)
        objective += cp.sum_squares(v[stops] - v[starts] - drawn)
    if len(equal):
        difference = v[equal[:, 3]] - v[equal[:, 2]] - v[equal[:, 1]] + v[equal[:, 0]]
        if yielding:
            # above the steepest the rest of the objective can be within the bounds
            free = reach[1:-1] if len(reach) > 2 else reach  # the façade's edges stay
            steepest = 2 * extent * (1 + (reach.max() / free.min()) ** 2)
            objective += YIELD * steepest * cp.norm1(difference)
        else:
            constraints.append(difference == 0)
    near = _pairs([group for _, groups in soft for group in groups], index)
    if len(near):
        weights = np.sqrt(np.array([w for w, g in soft for _ in g]))
        objective += cp.sum_squares(
            cp.multiply(weights, v[near[:, 3]] - v[near[:, 2]] - v[near[:, 1]] + v[near[:, 0]])
        )
    problem = cp.Problem(cp.Minimize(objective), constraints)
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.error.SolverError:
        return None
    if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or v.value is None:
        return None
    return [float(x) for x in v.value]


def _made_equal(
    edges: list[float],
    extent: float,
    met: list[list[Span]],
    spans: list[Span],
    bounds: tuple[np.ndarray, np.ndarray],
    deadline: Deadline,
) -> list[float]:
    """The edges with the pairs the soft QP ``met`` exactly equal, all at once where they
    can be. Where they cannot (near equalities chained over many edges add up past the
    bounds), those the exact penalty leaves apart stay apart. Never the soft solution: it
    moves every edge part of the way, equal or not. As drawn where nothing is met."""
    if not met:
        return list(edges)
    deadline.check("regularising")
    exact = _solve_axis(edges, extent, met, spans, [], bounds)
    if exact is not None:
        return exact
    deadline.check("regularising")
    yielded = _solve_axis(edges, extent, met, spans, [], bounds, yielding=True)
    if yielded is None:
        return list(edges)
    at = dict(zip(edges, yielded, strict=True))
    held = [pair for pair in met if _size_gap(pair, at) <= EQUAL * extent]
    if not held:
        return list(edges)
    deadline.check("regularising")
    return _solve_axis(edges, extent, held, spans, [], bounds) or list(edges)


def bounds_of(
    layout: LabelledLayout,
    drawn: LabelledLayout,
    axis: str,
    edges: list[float],
    tolerance: float,
    background: str,
    share: float = FAITHFUL,
) -> tuple[np.ndarray, np.ndarray]:
    """How far each edge of ``layout`` (snapped from ``drawn``: the same rectangles in the
    same order) may go: within ``move_limits`` (the tolerance, and a share of the narrowest
    element, gap or visible part it bounds as drawn) of every drawn coordinate snapped to
    it, and never further from where it is now than to there. The façade's edges stay."""
    extent = layout.width if axis == "x" else layout.height

    def span(r: Rect) -> tuple[float, float]:  # clipped to the façade, as snapped
        a, b = (r.x0, r.x1) if axis == "x" else (r.y0, r.y1)
        return min(max(a, 0.0), extent), min(max(b, 0.0), extent)

    pairs = [
        (r, q)
        for r, q in zip(drawn.rects, layout.rects, strict=True)
        if r.label != background and span(r)[0] < span(r)[1]
    ]
    limits = move_limits(
        [r for r, _ in pairs],
        [span(r) for r, _ in pairs],
        [(r.y0, r.y1) if axis == "x" else (r.x0, r.x1) for r, _ in pairs],
        tolerance * extent,
        share,
    )
    index = {value: i for i, value in enumerate(edges)}
    low = np.array(edges) - tolerance * extent
    high = np.array(edges) + tolerance * extent
    for r, q in pairs:
        for was, now in zip(span(r), span(q), strict=True):
            k = index.get(now)
            if k is not None:
                reach = limits.get(was, tolerance * extent)
                low[k] = max(low[k], was - reach)
                high[k] = min(high[k], was + reach)
    current = np.array(edges)
    low, high = np.minimum(low, current), np.maximum(high, current)
    low[0] = high[0] = 0.0
    low[-1] = high[-1] = extent
    return low, high


def regularize(
    layout: LabelledLayout,
    tolerance: float = DEFAULT_TOLERANCE,
    background: str = "facade",
    deadline: Deadline | None = None,
    drawn: LabelledLayout | None = None,
) -> tuple[LabelledLayout, Regularization]:
    """The layout with repeated elements made equal (see the module); its edges must be
    snapped already (``tile`` snaps, ``snap_layout`` gives the snapped layout), from
    ``drawn`` (the same rectangles as drawn; the layout itself when not given): no edge
    goes further from where it was drawn than ``bounds_of`` allows. The deadline is
    checked before each QP (a QP itself cannot be stopped)."""
    result = Regularization(tolerance)
    if tolerance <= 0:
        return layout, result
    deadline = deadline or Deadline()
    tiling = tile(layout, tolerance=0.0, background=background, deadline=deadline)
    rects = [r for r in layout.rects if r.label != background]
    mapping: dict[str, dict[float, float]] = {}
    for axis, extent in (("x", layout.width), ("y", layout.height)):
        edges = list(tiling.xs if axis == "x" else tiling.ys)
        bounds = bounds_of(layout, drawn or layout, axis, edges, tolerance, background)
        elements, strips = _pairs_of(rects, tiling, axis, extent, tolerance)
        runs = _runs(rects, axis, extent, tolerance)
        line_ups = _line_ups(rects, axis, extent, tolerance)
        spans = [(r.x0, r.x1) if axis == "x" else (r.y0, r.y1) for r in rects]
        cuts = set(edges)
        spans = [(a, b) for a, b in spans if a in cuts and b in cuts]
        movable_line_ups = [g for g in line_ups if _movable(g, cuts)]
        wanted = [  # (weight, kind, label, group): the equal sizes the QP is asked for
            (weight, kind, label, group)
            for weight, kind, named in (
                (WEIGHTS["element"], "element", elements),
                (WEIGHTS["strip"], "strip", strips),
                (WEIGHTS["run"], "run", runs),
            )
            for label, groups in named.items()
            for group in groups
            if _movable(group, cuts)
        ]
        soft = [(w, [[g[0], member]]) for w, _, _, g in wanted for member in g[1:]]
        soft += [(WEIGHTS["line-up"], [g]) for g in movable_line_ups]
        deadline.check("regularising")
        solved = _solve_axis(edges, extent, [], spans, soft, bounds)
        if solved is None:
            result.warnings.append(f"{axis}: the edges could not be regularised; left as drawn")
            mapping[axis] = {e: e for e in edges}
            continue
        # what the soft QP met is made exact, all at once where it can be
        at = dict(zip(edges, solved, strict=True))
        met = [pair for _, (pair,) in soft if _size_gap(pair, at) <= MET * extent]
        solved = _made_equal(edges, extent, met, spans, bounds, deadline)
        solved[0], solved[-1] = 0.0, extent
        merged = snap(solved, 1e-7 * extent, (0.0, extent))  # edges the QP joined are one
        solved = [merged[value] for value in solved]
        mapping[axis] = dict(zip(edges, solved, strict=True))
        for before, after in zip(edges, solved, strict=True):
            if abs(after - before) > 1e-6 * extent:
                result.moves.append(Move(axis, before, after))
        apart = 0
        for _, kind, label, group in wanted:
            kept = [
                m for m in group[1:] if _size_gap([group[0], m], mapping[axis]) <= EQUAL * extent
            ]
            apart += len(group) - 1 - len(kept)
            if kept:
                a, b = group[0]
                size = mapping[axis][b] - mapping[axis][a]
                count = len(kept) + 1 + (kind == "run")  # a run of n pitches has n + 1
                result.groups.append(SizeGroup(axis, kind, label, count, size))
        if apart:
            result.warnings.append(
                f"{axis}: {apart} of {len(soft) - len(movable_line_ups)} nearly equal sizes "
                "left apart (making them equal would move edges further than the drawing "
                "allows)"
            )
        lined = sum(_size_gap(g, mapping[axis]) <= EQUAL * extent for g in movable_line_ups)
        if movable_line_ups:
            result.groups.append(SizeGroup(axis, "line-up", "*", lined, 0.0))
            if lined < len(movable_line_ups):
                result.warnings.append(
                    f"{axis}: {len(movable_line_ups) - lined} of {len(movable_line_ups)} near "
                    "line-ups of element centres left apart (lining them up would move "
                    "other edges)"
                )
    moved = tuple(
        replace(
            r,
            x0=mapping["x"].get(r.x0, r.x0),
            x1=mapping["x"].get(r.x1, r.x1),
            y0=mapping["y"].get(r.y0, r.y0),
            y1=mapping["y"].get(r.y1, r.y1),
        )
        for r in layout.rects
    )
    return replace(layout, rects=moved), result
