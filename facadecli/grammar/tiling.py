"""Labelled layouts in, a tiling of terminal regions out (issue 6, step 1).

A labelled layout (``inputs``) is a set of rectangles with labels and a z-order; they
overlap and do not tile. The tiling cuts the façade at every rectangle edge, gives each cell
the label of the top-most rectangle covering it (later ones win among equals) or the
background, after snapping nearly equal edges together so that hand-drawn annotations line
up.

The readers live in ``cmp_xml`` (CMP Facade Database XML) and ``json_layouts`` (a plain
JSON list of ``{label, x0, y0, x1, y1}``, and facadecli's own ``<name>.layout.json``),
``read`` picks one by the file's name: this stage comes after them and imports none.
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, replace

import numpy as np

from facadecli.grammar.deadline import Deadline
from facadecli.grammar.inputs import BACKGROUND, CMP_Z_ORDER, LabelledLayout, Rect

__all__ = [
    "BACKGROUND",
    "CMP_Z_ORDER",
    "NO_SNAPPING",
    "LabelledLayout",
    "Rect",
    "Snapping",
    "Tiling",
    "snap",
    "snap_and_count",
    "snap_layout",
    "tile",
]


@dataclass(frozen=True)
class Tiling:
    """Cuts on each axis and the label of every cell: ``labels[row][column]``, bottom up."""

    xs: tuple[float, ...]
    ys: tuple[float, ...]
    labels: tuple[tuple[str, ...], ...]

    def label_at(self, x: float, y: float) -> str:
        column = min(max(bisect.bisect_right(self.xs, x) - 1, 0), len(self.xs) - 2)
        row = min(max(bisect.bisect_right(self.ys, y) - 1, 0), len(self.ys) - 2)
        return self.labels[row][column]


MOVE_SHARE = 0.125  # an edge moves at most this share of the narrowest element or gap it bounds
WIDE = 24  # candidate starts of a cluster above which numpy weighs them, not a loop


def _chain_starts(
    values: list[float],
    weights: list[int],
    tolerance: float,
    pairs: list[tuple[int, int]],
    deadline: Deadline,
) -> list[int]:
    """The first index of each cluster of one chain of sorted distinct values (each within
    the tolerance of the next), clustered into the fewest clusters that are each at most
    ``tolerance`` wide and hold no ``pairs`` (index pairs kept apart), and among those the
    clustering that moves edges least: the sum of each value's weight times its distance
    to its cluster's weighted median. A dynamic programme over the chain: the best
    clustering of the first ``e`` values ends in a cluster from some ``s`` to ``e - 1``,
    which must start at or after the first value within the tolerance of value ``e - 1``
    and after the first end of every pair that ends by ``e - 1``; the fewest clusters
    before ``e`` never fall as ``e`` grows, so the candidates are a run from that first
    start. The first of equal choices (the longest last cluster) is kept: deterministic.
    Widths are of the values as given; sums of moves are from the chain's first value."""
    n = len(values)
    shifted = [v - values[0] for v in values]
    after = [0] * n
    for i, j in pairs:
        after[j] = max(after[j], i + 1)
    total = [0, *itertools.accumulate(weights)]  # the weight before each index
    moment = [0.0, *itertools.accumulate(w * v for w, v in zip(weights, shifted, strict=True))]
    double = [2 * t for t in total]
    arrays = None
    count = [0] * (n + 1)  # clusters of the best clustering of the first e values
    cost = [0.0] * (n + 1)
    back = [0] * (n + 1)
    first = barrier = 0
    for e in range(1, n + 1):
        if e % 1024 == 0:
            deadline.check("snapping edges")
        t = e - 1
        while values[t] - values[first] > tolerance:
            first += 1
        barrier = max(barrier, after[t])
        lo = max(first, barrier)
        hi = bisect.bisect_right(count, count[lo], lo, e)
        if hi - lo <= WIDE:
            best, least = lo, math.inf
            for s in range(lo, hi):
                q = bisect.bisect_left(double, total[e] + total[s], s + 1, e + 1) - 1
                m = shifted[q]
                spread = (
                    m * (total[q + 1] - total[s])
                    - (moment[q + 1] - moment[s])
                    + (moment[e] - moment[q + 1])
                    - m * (total[e] - total[q + 1])
                )
                if cost[s] + spread < least:
                    best, least = s, cost[s] + spread
        else:
            if arrays is None:
                arrays = [np.array(a) for a in (shifted, total, moment, double)]
            v, tot, mom, dbl = arrays
            s_ = np.arange(lo, hi)
            q_ = np.searchsorted(dbl, tot[e] + tot[s_], side="left") - 1
            m_ = v[q_]
            spreads = (
                m_ * (tot[q_ + 1] - tot[s_])
                - (mom[q_ + 1] - mom[s_])
                + (mom[e] - mom[q_ + 1])
                - m_ * (tot[e] - tot[q_ + 1])
            )
            k = int(np.argmin(np.array(cost[lo:hi]) + spreads))
            best, least = lo + k, cost[lo + k] + float(spreads[k])
        back[e], count[e], cost[e] = best, count[best] + 1, least
    starts = []
    e = n
    while e > 0:
        e = back[e]
        starts.append(e)
    return starts[::-1]


def _starts(
    values: list[float],
    weights: list[int],
    tolerance: float,
    pairs: list[tuple[int, int]],
    deadline: Deadline,
) -> list[int]:
    """``_chain_starts`` over every chain of the sorted distinct values (a chain ends
    where the next value is further than the tolerance: no cluster reaches across)."""
    bounds = [0]
    bounds += [k + 1 for k, (a, b) in enumerate(itertools.pairwise(values)) if b - a > tolerance]
    inside: dict[int, list[tuple[int, int]]] = {}
    for i, j in pairs:
        chain = bisect.bisect_right(bounds, i) - 1
        if j < (bounds[chain + 1] if chain + 1 < len(bounds) else len(values)):
            inside.setdefault(chain, []).append((i - bounds[chain], j - bounds[chain]))
    bounds.append(len(values))
    starts = []
    for chain, (lo, hi) in enumerate(itertools.pairwise(bounds)):
        deadline.check("snapping edges")
        pairs = inside.get(chain, [])
        found = _chain_starts(values[lo:hi], weights[lo:hi], tolerance, pairs, deadline)
        starts += [lo + s for s in found]
    return starts


def _representative(cluster: list[float], weights: Counter[float]) -> float:
    """The weighted median of a cluster's values (each weighs the number of edges on it):
    the value with half the edges on either side, or the middle of the two values where
    the edges split exactly in half. Most edges stay where they are."""
    total = sum(weights[value] for value in cluster)
    below = 0
    for k, value in enumerate(cluster):
        below += weights[value]
        if 2 * below == total and k + 1 < len(cluster):
            return (value + cluster[k + 1]) / 2
        if 2 * below >= total:
            return value
    return cluster[-1]


def _snap_axis(
    values: list[float],
    tolerance: float,
    anchors: tuple[float, ...] = (),
    apart: Iterable[tuple[float, float]] = (),
    deadline: Deadline | None = None,
    limits: dict[float, float] | None = None,
) -> tuple[dict[float, float], set[tuple[float, float]]]:
    """``snap``, and the pairs of ``apart`` (the two edges of one element) that the
    clustering would have joined and that were kept in different clusters instead.

    An anchor weighs as much as every value together (a cluster's median is its anchor,
    and moving it costs most); two anchors are never joined. A value of ``limits`` moves
    at most its limit (``_limited``)."""
    deadline = deadline or Deadline()
    weights = Counter(values)
    ordered = sorted(set(values) | set(anchors))
    index = {value: i for i, value in enumerate(ordered)}
    heavy = len(values) + 1
    limits = {v: limit for v, limit in (limits or {}).items() if limit < tolerance}
    mass = [weights[v] + (heavy if v in anchors or v in limits else 0) for v in ordered]
    held = sorted({index[a] for a in anchors})
    pinned = list(itertools.pairwise(held))
    starts = _starts(ordered, mass, tolerance, pinned, deadline)
    firsts = set(starts)
    cluster = list(itertools.accumulate(int(k in firsts) for k in range(len(ordered))))
    pairs = sorted({(index[a], index[b]) for a, b in apart if index[a] < index[b]})
    joined = [(i, j) for i, j in pairs if cluster[i] == cluster[j]]
    limited = _limited(ordered, limits, anchors, tolerance)
    if joined or limited:  # cluster again, keeping every pair apart and within the limits
        starts = _starts(ordered, mass, tolerance, pinned + pairs + limited, deadline)
    kept = {(ordered[i], ordered[j]) for i, j in joined}
    mapping = {}
    for lo, hi in itertools.pairwise([*starts, len(ordered)]):
        members = ordered[lo:hi]
        anchored = [a for a in anchors if a in members]
        target = anchored[0] if anchored else _representative(members, weights)
        for value in members:
            mapping[value] = target
    return mapping, kept


def _limited(
    ordered: list[float], limits: dict[float, float], anchors: tuple[float, ...], tolerance: float
) -> list[tuple[int, int]]:
    """Index pairs kept in different clusters so that a value with a limit shares its
    cluster with no other limited value, nor anchor, further from it than its limit: for
    each, the nearest such one beyond its limit on either side (a cluster holding both
    would hold every value between). Limited values weigh as much as anchors, so a
    cluster's representative lies among them (``_snap_axis``) and none moves further
    than its limit. Values further apart than the tolerance never share a cluster."""
    held = {v: limit for v, limit in limits.items() if limit < tolerance}
    heavy = sorted({*held, *anchors})
    index = {value: i for i, value in enumerate(ordered)}
    pairs = []
    for value, limit in held.items():
        below = bisect.bisect_left(heavy, value - limit) - 1
        above = bisect.bisect_right(heavy, value + limit)
        if below >= 0 and value - heavy[below] <= tolerance:
            pairs.append((index[heavy[below]], index[value]))
        if above < len(heavy) and heavy[above] - value <= tolerance:
            pairs.append((index[value], index[heavy[above]]))
    return sorted(pairs)


def snap(
    values: list[float], tolerance: float, anchors: tuple[float, ...] = ()
) -> dict[float, float]:
    """Each value mapped to the representative of its cluster: values are clustered so
    that no two in a cluster are further apart than ``tolerance`` (never a chain of values
    each near the next joined end to end), into as few clusters as that allows, moving
    values least (``_chain_starts``); a cluster goes to the anchor it holds (the façade's
    edges stay put), else to its weighted median (``_representative``)."""
    return _snap_axis(values, tolerance, anchors)[0]


@dataclass(frozen=True)
class Snapping:
    """What snapping changed (the report's ``snapping``). Snapping removes no rectangle:
    ``rectangles`` went in and came out."""

    snap: float  # the tolerance, a share of the façade's size along each axis (0: none)
    rectangles: int
    edges: int  # distinct edge coordinates of the rectangles, x and y together
    edges_moved: int
    max_move: float  # in the layout's units
    max_move_share: float  # of the façade's size along the edge's axis: at most ``snap``
    kept: tuple[str, ...] = ()  # labels of the rectangles kept from collapsing, in order

    def summary(self) -> dict[str, object]:
        return {
            "snap": self.snap,
            "rectangles": self.rectangles,
            "edges": self.edges,
            "edges_moved": self.edges_moved,
            "max_move": round(self.max_move, 6),
            "max_move_share": round(self.max_move_share, 6),
            "kept_from_collapsing": len(self.kept),
            "kept_by_label": dict(sorted(Counter(self.kept).items())),
        }

    def warning(self) -> str | None:
        """What users are told when snapping kept elements from collapsing, else None."""
        if not self.kept:
            return None
        labels = ", ".join(f"{label} {n}" for label, n in sorted(Counter(self.kept).items()))
        return (
            f"snapping edges closer than {self.snap:g} of the façade moved {self.edges_moved} "
            f"of {self.edges} edges (by at most {self.max_move_share:.2g} of the façade) and "
            f"kept {len(self.kept)} of {self.rectangles} rectangles thinner than that from "
            f"collapsing ({labels}): their own two edges stay apart; a smaller --snap "
            "joins fewer edges"
        )


def move_limits(
    rects: list[Rect],
    spans: list[tuple[float, float]],
    across: list[tuple[float, float]],
    tolerance: float,
    share: float = MOVE_SHARE,
) -> dict[float, float]:
    """How far each edge coordinate along an axis may move, where that is less than the
    ``tolerance``: ``share`` of the narrowest span it bounds of

    - an element (``spans``, of ``rects``; ``across``: the other axis);
    - the gap between two elements of one label that face each other (overlapping
      across): the wall between two windows never closes, they stay two;
    - each part of an element left visible beside or between elements in front of it
      that cover most of it across (a blind's strip beside its window, a balcony's
      strip between the moulding under it and its window): it never goes behind.

    So tidying keeps what was drawn: every element most of its size and what shows of
    it. Only spans shorter than ``tolerance / share`` limit anything; each element is
    looked up against the elements starting or ending inside it or just past its end."""
    limits: dict[float, float] = {}
    reach = tolerance / share

    def limit(a: float, b: float) -> None:
        for value in (a, b):
            if share * (b - a) < min(tolerance, limits.get(value, tolerance)):
                limits[value] = share * (b - a)

    by_start = sorted(range(len(spans)), key=lambda i: spans[i][0])
    starts = [spans[i][0] for i in by_start]
    by_end = sorted(range(len(spans)), key=lambda i: spans[i][1])
    ends = [spans[i][1] for i in by_end]

    def covers(front: int, back: int) -> bool:  # front hides most of back across
        (a, b), (c, d) = across[front], across[back]
        in_front = (rects[front].z, front) > (rects[back].z, back)
        return in_front and min(b, d) - max(a, c) >= (d - c) / 2

    for i, (a, b) in enumerate(spans):
        limit(a, b)
        lo, hi = across[i]
        # elements of its label starting just past this one's end: the gap between them
        for j in by_start[bisect.bisect_left(starts, b) : bisect.bisect_right(starts, b + reach)]:
            start, facing = spans[j][0], across[j][0] < hi and lo < across[j][1]
            if rects[j].label == rects[i].label and start > b and facing:
                limit(b, start)
        # what shows of it between the elements in front that start or end inside it
        inside = {
            *by_start[bisect.bisect_right(starts, a) : bisect.bisect_left(starts, b)],
            *by_end[bisect.bisect_right(ends, a) : bisect.bisect_left(ends, b)],
        }
        fronts = sorted(spans[j] for j in inside if covers(j, i))
        shown = a  # the start of the part shown now
        for start, end in fronts:
            if start > shown:  # a part shown before a front (after another, or from a)
                limit(shown, start)
            shown = max(shown, end)
        if fronts and a < shown < b:
            limit(shown, b)
    return limits


NO_SNAPPING = Snapping(0.0, 0, 0, 0, 0.0, 0.0)  # before anything was snapped


def snap_and_count(
    layout: LabelledLayout, tolerance: float = 0.005, deadline: Deadline | None = None
) -> tuple[LabelledLayout, Snapping]:
    """``snap_layout``, and what it changed. The deadline is checked as the clustering
    goes (a dense layout at a large snap takes seconds)."""
    rects = layout.rects
    extents = {"x": layout.width, "y": layout.height}
    spans = {"x": [(r.x0, r.x1) for r in rects], "y": [(r.y0, r.y1) for r in rects]}
    edges = sum(len({v for span in spans[axis] for v in span}) for axis in spans)
    if tolerance <= 0:
        return layout, Snapping(0.0, len(rects), edges, 0, 0.0, 0.0)
    moves: dict[tuple[str, float], tuple[float, float]] = {}  # (axis, from): (by, share)
    kept: set[int] = set()
    for axis, extent in extents.items():

        def clip(value: float, extent: float = extent) -> float:
            return min(max(value, 0.0), extent)

        # a span wholly off the façade (within the readers' slack) stays as drawn
        on = [i for i, (a, b) in enumerate(spans[axis]) if clip(a) < clip(b)]
        clipped = [(clip(a), clip(b)) for a, b in (spans[axis][i] for i in on)]
        thin = {(a, b) for a, b in clipped if b - a <= tolerance * extent}
        values = [v for span in clipped for v in span]
        across = "y" if axis == "x" else "x"
        limits = move_limits(
            [rects[i] for i in on], clipped, [spans[across][i] for i in on], tolerance * extent
        )
        mapping, joined = _snap_axis(
            values, tolerance * extent, (0.0, extent), thin, deadline, limits
        )
        for i, (a, b) in zip(on, clipped, strict=True):
            if (a, b) in joined:
                kept.add(i)
            for value in spans[axis][i]:
                to = mapping[clip(value)]
                if to != value:
                    moves[axis, value] = (abs(to - value), abs(to - value) / extent)
            spans[axis][i] = (mapping[a], mapping[b])
    snapped = tuple(
        replace(r, x0=x0, x1=x1, y0=y0, y1=y1)
        for r, (x0, x1), (y0, y1) in zip(rects, spans["x"], spans["y"], strict=True)
    )
    snapping = Snapping(
        tolerance,
        len(rects),
        edges,
        len(moves),
        max((move for move, _ in moves.values()), default=0.0),
        max((share for _, share in moves.values()), default=0.0),
        tuple(rects[i].label for i in sorted(kept)),
    )
    return replace(layout, rects=snapped), snapping


def snap_layout(layout: LabelledLayout, tolerance: float = 0.005) -> LabelledLayout:
    """The layout with nearby edges joined: per axis, edge coordinates are clustered so
    that no two in a cluster lie further apart than ``tolerance`` x the façade's size
    (edges in a row each near the next are never joined end to end), into the fewest
    clusters, moving edges least, and each cluster is moved to one value (``snap``: the
    façade's edge if it holds one, else its weighted median). The two edges of an element
    never share a cluster (an element thinner than the tolerance is clustered again with
    its edges kept apart), so every rectangle keeps its label and an area, and no edge
    moves further than the tolerance. Edges are clipped to the façade first; a rectangle
    wholly off it (within the readers' slack) stays as drawn on that axis."""
    return snap_and_count(layout, tolerance)[0]


def tile(
    layout: LabelledLayout,
    tolerance: float = 0.005,
    background: str = BACKGROUND,
    deadline: Deadline | None = None,
) -> Tiling:
    """The tiling of a labelled layout, snapped first (``snap_layout``): cuts at every edge,
    and each cell the label of the top-most rectangle covering it, else the background.
    Rectangles are painted bottom up over the cells they cover (numpy), so the work is the
    cells covered, not the cells times the rectangles."""
    deadline = deadline or Deadline()
    layout = snap_and_count(layout, tolerance, deadline)[0] if tolerance > 0 else layout
    w, h = layout.width, layout.height
    clip = [
        Rect(r.label, max(r.x0, 0.0), max(r.y0, 0.0), min(r.x1, w), min(r.y1, h), r.z)
        for r in layout.rects
    ]
    rects = [r for r in clip if r.x1 > r.x0 and r.y1 > r.y0]
    xs = sorted({0.0, w, *(v for r in rects for v in (r.x0, r.x1))})
    ys = sorted({0.0, h, *(v for r in rects for v in (r.y0, r.y1))})
    column = {x: i for i, x in enumerate(xs)}
    row = {y: i for i, y in enumerate(ys)}
    names = [background, *sorted({r.label for r in rects} - {background})]
    code = {name: i for i, name in enumerate(names)}
    cells = np.zeros((len(ys) - 1, len(xs) - 1), dtype=np.int32)
    for r in sorted(rects, key=lambda r: r.z):  # stable: among equals the later wins
        deadline.check("tiling")
        cells[row[r.y0] : row[r.y1], column[r.x0] : column[r.x1]] = code[r.label]
    labels = np.array(names, dtype=object)[cells].tolist()
    return Tiling(tuple(xs), tuple(ys), tuple(tuple(line) for line in labels))
