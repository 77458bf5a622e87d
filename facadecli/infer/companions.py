"""Companions placed from their openings (issue 34): a sill under its window, a blind
beside it, a balcony slab under it, a lintel over it.

The tidy-up keeps what was drawn within a hand's jitter, so a sill drawn two centimetres
under its window stays two centimetres under it, the next one a centimetre over it, and
each floor's sills read as rows and sizes of their own: a spec writes each such set as a
layer with its own gaps and sizes, though the façade means one sill under every window.
So, once the structure has put the openings on shared sizes and lines
(``infer.structure``), each companion (an element of another label touching an opening,
``touching``: within ``TOUCH``, overlapping it along the other axis; of several, the one
it shares most with) is placed from its opening.

Along each axis, each of a companion's two edges is measured from the nearer edge of its
opening (a sill's top from its window's bottom, its ends from the window's sides). The
offsets of one kind (the companion's label and edge, the opening's label and edge) are
clustered across the façade, each within twice its reach (below) of the cluster's least;
a cluster's offset is its median, or none where that is within ``FLUSH`` (drawn flush).
A companion takes its two offsets along an axis where neither edge moves further than
its reach, ``share`` of what shows of it (its size less what its opening hides of it)
and ``NEAR`` of the façade, else it stays as it is along that axis. An edge behind its
opening both before and after (hidden by it: CMP's z-order) moves freely, but what
shows of the companion beside the openings in front of it never shrinks by more than
``share``: a blind drawn behind its window but for a sliver is never hidden whole.
Sills on their windows' rows at one offset are one grid, one size and one set of gaps,
written once.
"""

from __future__ import annotations

import statistics
from collections import defaultdict
from itertools import pairwise

from facadecli.grammar.inputs import BACKGROUND, CMP_Z_ORDER, Rect
from facadecli.infer.layers import BAND, OPENINGS

TOUCH = 0.05  # m: a companion this close to an opening (overlapping it along the other axis)
ATTACHED = 0.2  # of a companion's size: the most an edge of it moves onto its offset
REACHES = (ATTACHED, ATTACHED / 2, 0.0)  # tried in turn while the layout stays faithful
FLUSH = 0.01  # m: an offset this small is none (edges drawn as one, as ``bays.COLUMN``)
NEAR = 0.01  # of the façade: the most an edge moves, whatever the companion's size

Key = tuple[str, str, int, int]  # companion label, opening label, its edge, the opening's


def companions_placed(
    rects: list[Rect], width: float, height: float, share: float = ATTACHED
) -> list[Rect]:
    """``rects`` with each companion placed from its opening (see the module; ``share``:
    of a companion's size, the most an edge moves); the rest as they are."""
    pairs = _pairs(rects, width, height)
    openings = [r for r in rects if r.label in OPENINGS]
    out = list(rects)
    for axis, extent in (("x", width), ("y", height)):
        offsets: dict[Key, list[tuple[int, float]]] = defaultdict(list)
        nearer: dict[tuple[int, int], int] = {}  # (companion, its edge): the opening's edge
        for k, j in pairs.items():
            edges, frame = _span(rects[k], axis), _span(rects[j], axis)
            for side in (0, 1):
                ref = min((0, 1), key=lambda s: (abs(edges[side] - frame[s]), s))
                nearer[k, side] = ref
                key = (rects[k].label, rects[j].label, side, ref)
                offsets[key].append((k, edges[side] - frame[ref]))
        target: dict[tuple[int, int], float] = {}
        for (_, _, side, _), members in offsets.items():
            for cluster in _clusters(members, rects, pairs, axis, extent, share):
                value = statistics.median(offset for _, offset in cluster)
                for k, _ in cluster:
                    target[k, side] = 0.0 if abs(value) <= FLUSH else value
        for k, j in pairs.items():
            frame = _span(rects[j], axis)
            low = frame[nearer[k, 0]] + target[k, 0]
            high = frame[nearer[k, 1]] + target[k, 1]
            if high - low <= 0 or not _near(rects[k], (low, high), rects[j], axis, extent, share):
                continue
            r = out[k]
            moved = (
                Rect(r.label, low, r.y0, high, r.y1, r.z)
                if axis == "x"
                else Rect(r.label, r.x0, low, r.x1, high, r.z)
            )
            fronts = [o for o in openings if _order(o) > _order(r)]
            if _shown(moved, fronts) >= (1 - share) * _shown(r, fronts):
                out[k] = moved
    return out


def _order(rect: Rect) -> tuple[int, float]:
    return (CMP_Z_ORDER.get(rect.label, 99), rect.z)


def _shown(rect: Rect, fronts: list[Rect]) -> float:
    """The area of ``rect`` that none of ``fronts`` covers."""
    over = [
        (max(rect.x0, f.x0), max(rect.y0, f.y0), min(rect.x1, f.x1), min(rect.y1, f.y1))
        for f in fronts
    ]
    over = [o for o in over if o[2] > o[0] and o[3] > o[1]]
    xs = sorted({rect.x0, rect.x1, *(v for o in over for v in (o[0], o[2]))})
    ys = sorted({rect.y0, rect.y1, *(v for o in over for v in (o[1], o[3]))})
    return sum(
        (x1 - x0) * (y1 - y0)
        for x0, x1 in pairwise(xs)
        for y0, y1 in pairwise(ys)
        if not any(o[0] <= x0 and x1 <= o[2] and o[1] <= y0 and y1 <= o[3] for o in over)
    )


def _pairs(rects: list[Rect], width: float, height: float) -> dict[int, int]:
    """Each companion (not an opening, the background or a band across the façade,
    ``layers.BAND``) and the opening it touches that it shares most with, by index."""
    openings = [j for j, r in enumerate(rects) if r.label in OPENINGS]
    found: dict[int, int] = {}
    for k, r in enumerate(rects):
        if r.label == BACKGROUND or r.label in OPENINGS:
            continue
        if r.x1 - r.x0 > BAND * width or r.y1 - r.y0 > BAND * height:
            continue
        near = [j for j in openings if touching(r, rects[j])]
        if near:
            found[k] = max(near, key=lambda j: (_shared(r, rects[j]), -j))
    return found


def _clusters(
    members: list[tuple[int, float]],
    rects: list[Rect],
    pairs: dict[int, int],
    axis: str,
    extent: float,
    share: float,
) -> list[list[tuple[int, float]]]:
    """Offsets, sorted, cut into runs each within twice its reach (``_reach``) of the
    run's least: each within reach of the run's middle."""
    runs: list[list[tuple[int, float]]] = []
    for k, offset in sorted(members, key=lambda m: (m[1], m[0])):
        reach = _reach(rects[k], rects[pairs[k]], axis, extent, share)
        if runs and offset - runs[-1][0][1] <= 2 * reach:
            runs[-1].append((k, offset))
        else:
            runs.append([(k, offset)])
    return runs


def _near(
    was: Rect, to: tuple[float, float], opening: Rect, axis: str, extent: float, share: float
) -> bool:
    """Each edge of ``was`` along ``axis`` within reach of where it goes in ``to``
    (``_reach``), or behind ``opening`` both where it was and where it goes."""
    frame = _span(opening, axis)
    covered = _covered(was, opening, axis)

    def hidden(edge: float) -> bool:
        return covered and frame[0] <= edge <= frame[1]

    reach = _reach(was, opening, axis, extent, share)
    return all(
        abs(now - edge) <= reach or (hidden(now) and hidden(edge))
        for edge, now in zip(_span(was, axis), to, strict=True)
    )


def _covered(rect: Rect, opening: Rect, axis: str) -> bool:
    """``rect`` is behind ``opening`` (CMP's z-order) and within its span across
    ``axis``: the opening hides what of it stands within its span along ``axis``."""
    across = "y" if axis == "x" else "x"
    (a, b), (c, d) = _span(opening, across), _span(rect, across)
    behind = CMP_Z_ORDER.get(rect.label, 99) < CMP_Z_ORDER.get(opening.label, 99)
    return behind and a - 1e-9 <= c and d <= b + 1e-9


def _reach(rect: Rect, opening: Rect, axis: str, extent: float, share: float) -> float:
    """How far an edge of ``rect`` may move along ``axis``: ``share`` of what shows of
    it beside ``opening`` (of a blind drawn behind its window but for a sliver: of the
    sliver), and ``NEAR`` of the façade."""
    low, high = _span(rect, axis)
    shown = high - low
    if _covered(rect, opening, axis):
        a, b = _span(opening, axis)
        shown -= max(0.0, min(high, b) - max(low, a))
    return min(share * shown, NEAR * extent)


def _span(rect: Rect, axis: str) -> tuple[float, float]:
    return (rect.x0, rect.x1) if axis == "x" else (rect.y0, rect.y1)


def _shared(a: Rect, b: Rect) -> float:
    """How much two rectangles share: their overlaps along x and y, summed (a gap
    counts against)."""
    return min(a.x1, b.x1) - max(a.x0, b.x0) + min(a.y1, b.y1) - max(a.y0, b.y0)


def touching(a: Rect, b: Rect) -> bool:
    """Overlapping along one axis, at most ``TOUCH`` apart (or overlapping) along the other."""
    over_x = min(a.x1, b.x1) - max(a.x0, b.x0)
    over_y = min(a.y1, b.y1) - max(a.y0, b.y0)
    return (over_x > 0 and over_y >= -TOUCH) or (over_y > 0 and over_x >= -TOUCH)
