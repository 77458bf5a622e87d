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
  window): a soft constraint, weighted, as one element may line up with two that cannot.

If the equalities cannot all hold, the runs' are dropped, then the strips', then the
elements'. What moved is returned for the report.
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from dataclasses import dataclass, field, replace

import numpy as np

from facadecli.grammar.deadline import Deadline
from facadecli.grammar.tiling import LabelledLayout, Rect, Tiling, snap, tile

DEFAULT_TOLERANCE = 0.01  # of the façade's extent along the axis
RELATIVE = 0.1  # and never sizes more than this fraction apart
LINED = 1e-3  # of the extent: line-ups the soft QP brings this near are then made exact
SOFT = 100.0  # weight of a line-up against moving edges (both squared)
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


def _centre_gap(line_up: list[Span], at: dict[float, float]) -> float:
    """How far apart the centres of a line-up's two elements are (twice, in fact), with
    the edges where ``at`` puts them."""
    (a0, b0), (a, b) = line_up
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
    soft: list[list[tuple[float, float]]],
) -> list[float] | None:
    """Edges as near as they can be to where they were, with the spans of each group
    equal, and those of each ``soft`` group as near to equal as they can be (weighted by
    ``SOFT``)."""
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
    objective = cp.sum_squares(v - np.array(edges))
    if kept:  # every element keeps at least half its size
        constraints.append(v[stops] - v[starts] >= drawn / 2)
        objective += cp.sum_squares(v[stops] - v[starts] - drawn)
    if len(equal):
        constraints.append(v[equal[:, 3]] - v[equal[:, 2]] == v[equal[:, 1]] - v[equal[:, 0]])
    near = _pairs(soft, index)
    if len(near):
        objective += SOFT * cp.sum_squares(
            v[near[:, 3]] - v[near[:, 2]] - v[near[:, 1]] + v[near[:, 0]]
        )
    problem = cp.Problem(cp.Minimize(objective), constraints)
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.error.SolverError:
        return None
    if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or v.value is None:
        return None
    return [float(x) for x in v.value]


def regularize(
    layout: LabelledLayout,
    tolerance: float = DEFAULT_TOLERANCE,
    background: str = "facade",
    deadline: Deadline | None = None,
) -> tuple[LabelledLayout, Regularization]:
    """The layout with repeated elements made equal (see the module); its edges must be
    snapped already (``tile`` snaps, ``snap_layout`` gives the snapped layout). The
    deadline is checked before each QP (a QP itself cannot be stopped)."""
    result = Regularization(tolerance)
    if tolerance <= 0:
        return layout, result
    deadline = deadline or Deadline()
    tiling = tile(layout, tolerance=0.0, background=background, deadline=deadline)
    rects = [r for r in layout.rects if r.label != background]
    mapping: dict[str, dict[float, float]] = {}
    for axis, extent in (("x", layout.width), ("y", layout.height)):
        edges = list(tiling.xs if axis == "x" else tiling.ys)
        elements, strips = _pairs_of(rects, tiling, axis, extent, tolerance)
        element_groups = [g for groups in elements.values() for g in groups]
        strip_groups = [g for groups in strips.values() for g in groups]
        runs = _runs(rects, axis, extent, tolerance)
        run_groups = [g for groups in runs.values() for g in groups]
        line_ups = _line_ups(rects, axis, extent, tolerance)
        spans = [(r.x0, r.x1) if axis == "x" else (r.y0, r.y1) for r in rects]
        cuts = set(edges)
        spans = [(a, b) for a, b in spans if a in cuts and b in cuts]
        solved = None
        attempts = (  # each one without what the one before could not hold
            (element_groups + strip_groups + run_groups, "runs", "equal pitches of runs"),
            (element_groups + strip_groups, "strips", "equal sizes of strips"),
            (element_groups, "elements", "equal sizes of elements"),
        )
        used = ""
        movable_line_ups = [g for g in line_ups if _movable(g, cuts)]
        for kept, dropped, what in attempts:
            deadline.check("regularising")
            movable = [g for g in kept if _movable(g, cuts)]
            solved = _solve_axis(edges, extent, movable, spans, movable_line_ups)
            if solved is not None:
                used = dropped
                # the line-ups the soft QP nearly met are made exact where they all can be
                at = dict(zip(edges, solved, strict=True))
                met = [g for g in movable_line_ups if _centre_gap(g, at) <= LINED * extent]
                if met:
                    exact = _solve_axis(edges, extent, movable + met, spans, [])
                    solved = exact or solved
                break
            result.warnings.append(f"{axis}: {what} do not all fit; left out")
        if solved is None:
            mapping[axis] = {e: e for e in edges}
            continue
        solved[0], solved[-1] = 0.0, extent
        merged = snap(solved, 1e-7 * extent, (0.0, extent))  # edges the QP joined are one
        solved = [merged[value] for value in solved]
        mapping[axis] = dict(zip(edges, solved, strict=True))
        for before, after in zip(edges, solved, strict=True):
            if abs(after - before) > 1e-6 * extent:
                result.moves.append(Move(axis, before, after))
        strips_kept = used in ("strips", "runs")
        runs_kept = used == "runs"
        for kind, named in (
            ("element", elements),
            ("strip", strips if strips_kept else {}),
            ("run", runs if runs_kept else {}),
        ):
            for label, groups in named.items():
                for group in groups:
                    a, b = group[0]
                    size = mapping[axis][b] - mapping[axis][a]
                    count = len(group) + (kind == "run")  # a run of n pitches has n + 1
                    result.groups.append(SizeGroup(axis, kind, label, count, size))
        lined = sum(_centre_gap(g, mapping[axis]) <= 1e-6 * extent for g in movable_line_ups)
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
