"""Regularising a labelled layout (Wu et al. 2014, section 3.3): repeated elements get one
size, so that their regions hash alike and a grammar can share their rules.

Per axis, every distinct edge of the (snapped) layout is a variable of a small QP (cvxpy):
edges stay as near as they can to where they were drawn, the façade's own edges stay put,
edges keep their order, and

- elements of one label whose sizes differ by less than ``tolerance`` x the façade's extent
  (and less than a tenth) get one size;
- strips of the tiling between neighbouring edges that show the same labels across the
  whole façade (the wall between two window columns, say) and differ as little get one size.

If the equalities cannot all hold, the strips' are dropped, then the elements'. What moved is
returned for the report.
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


@dataclass(frozen=True)
class Move:
    axis: str
    before: float
    after: float


@dataclass(frozen=True)
class SizeGroup:
    axis: str
    kind: str  # "element" (one label) or "strip" (a band of the tiling)
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


def _solve_axis(
    edges: list[float],
    extent: float,
    groups: list[list[tuple[float, float]]],
    elements: list[tuple[float, float]],
) -> list[float] | None:
    import cvxpy as cp  # imported here: it takes half a second

    index = {value: i for i, value in enumerate(edges)}
    kept = sorted(set(elements))  # elements keep their sizes as well as they can
    starts = np.array([index[a] for a, _ in kept], dtype=int)
    stops = np.array([index[b] for _, b in kept], dtype=int)
    drawn = np.array([b - a for a, b in kept])
    equal = np.array(  # (a0, b0, a, b): b - a == b0 - a0
        [
            (index[group[0][0]], index[group[0][1]], index[a], index[b])
            for group in groups
            for a, b in group[1:]
        ],
        dtype=int,
    ).reshape(-1, 4)
    v = cp.Variable(len(edges))
    # constraints as a few vector expressions: building one per pair is slow in cvxpy
    constraints = [v[0] == 0.0, v[len(edges) - 1] == extent, cp.diff(v) >= 0]
    objective = cp.sum_squares(v - np.array(edges))
    if kept:  # every element keeps at least half its size
        constraints.append(v[stops] - v[starts] >= drawn / 2)
        objective += cp.sum_squares(v[stops] - v[starts] - drawn)
    if len(equal):
        constraints.append(v[equal[:, 3]] - v[equal[:, 2]] == v[equal[:, 1]] - v[equal[:, 0]])
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
        spans = [(r.x0, r.x1) if axis == "x" else (r.y0, r.y1) for r in rects]
        cuts = set(edges)
        spans = [(a, b) for a, b in spans if a in cuts and b in cuts]
        solved = None
        for kept, used in (
            (element_groups + strip_groups, True),
            (element_groups, False),
        ):
            deadline.check("regularising")
            solved = _solve_axis(edges, extent, kept, spans)
            if solved is not None:
                break
            result.warnings.append(
                f"{axis}: equal sizes of {'strips' if used else 'elements'} do not all fit; "
                "left out"
            )
        else:
            used = False
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
        for kind, named in (("element", elements), ("strip", strips if used else {})):
            for label, groups in named.items():
                for group in groups:
                    a, b = group[0]
                    size = mapping[axis][b] - mapping[axis][a]
                    result.groups.append(SizeGroup(axis, kind, label, len(group), size))
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
