"""A layout made wider or taller by copying (or removing) whole bays, the rest taken up by
the wall: retargeting by slabs, after Lin et al. 2011 (the simple form of relayouting that
Bao et al. 2013 compare themselves with).

Along one axis the elements (the background and bands, elements at least ``BAND`` of the
extent long, left out) stand in *blocks*, the stretches that some element covers; the
*gaps* between blocks, and the margins, are wall only. A *unit* runs from the middle of
one gap to the middle of a later one, at most ``UNIT_BLOCKS`` blocks: a bay, everything
above and below it included (a window column from the plinth to the cornice). A unit
may also be cut through elements where its other end cuts the same elements one unit
along (:func:`cuttable`): the pilasters between the bays of a façade that has no wall
between them, which a copy puts together again. A *plan*
lays the source along the axis with some units copied beside themselves (a unit and its
mirror image together, so a symmetric façade stays symmetric) or one left out, and
scales what is left over: everything alike when that changes it by ``WIDEN_MOST`` at
most (spacing and symmetry stay exact), else the gaps alone (within ``GAPS_LEAST`` to
``GAPS_MOST`` of their size), else everything squeezed (to 1 / ``SQUEEZE_MOST`` at
most); otherwise there is no plan. Whole bays copied keep every column, alignment and
spacing of the source, and no element grows by more than ``WIDEN_MOST``: the copies,
not wider windows, fill a wider façade.

The module is one-dimensional: :func:`units` and :func:`shifted` find where a stretch of
façade can be cut, :func:`copied` and :func:`plans` make plans from the elements' spans,
and :func:`place` lays a source interval by a plan.
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from facadecli.grammar.style import BAND  # a longer element is a band: a copy lengthens it

UNIT_BLOCKS = 3  # blocks a unit holds at most
UNITS_TRIED = 6  # units made into plans, the most regular first
GAPS_LEAST = 0.5  # of their source size: gaps squeezed further squeeze everything instead
GAPS_MOST = 1.5  # ... and stretched further, the plan is no good (copies should fill it)
SQUEEZE_MOST = 1.5  # elements squeezed further (1 / this), the plan is no good
WIDEN_MOST = 1.1  # ... or stretched further: copies, not wider windows, fill a façade
NEAR = 1e-9  # of the extent: spans closer than this touch
SNAP = 1e-3  # of the extent: a cut this near an element's edge is moved onto it
ALIKE = 0.02  # of the extent: elements cut at both ends of a unit this near one unit apart
ALIKE_PART = 0.05  # ... and this near, of their length
SLIVER = 0.01  # of the extent: an element that goes on this little past a cut (and at most
SLIVER_PART = 0.25  # ... this much of its length) is trimmed to it (see :func:`levels`)


@dataclass(frozen=True)
class Segment:
    """A stretch of the source, ``lo`` to ``hi``, laid ``scale`` times its length."""

    lo: float
    hi: float
    scale: float


@dataclass(frozen=True)
class Plan:
    """The source laid along one axis: ``segments`` in their new order (a unit copied is
    there twice), and what was done, for people (empty: the source stretched)."""

    segments: tuple[Segment, ...]
    text: str = ""

    @property
    def stretch(self) -> float:
        """How far its most scaled segment is from its source size (0: none scaled)."""
        return max((abs(math.log(s.scale)) for s in self.segments), default=0.0)


def blocks_of(spans: Sequence[tuple[float, float]], extent: float) -> list[tuple[float, float]]:
    """The stretches that some element's span covers, in order (bands left out)."""
    near = NEAR * extent
    found: list[list[float]] = []
    for lo, hi in sorted(s for s in spans if s[1] - s[0] < BAND * extent):
        if found and lo < found[-1][1] - near:
            found[-1][1] = max(found[-1][1], hi)
        else:
            found.append([lo, hi])
    return [(lo, hi) for lo, hi in found]


def units(spans: Sequence[tuple[float, float]], extent: float) -> list[tuple[float, float, float]]:
    """The units of a stretch of façade whose elements span ``spans``, with how far each
    is from a period of the source (0: a copy looks like the next bay along), the most
    regular first; at most ``UNIT_BLOCKS`` blocks and half the extent long, never all of
    it."""
    blocks = blocks_of(spans, extent)
    gaps = _gaps(blocks, extent)
    middles = [(lo + hi) / 2 for lo, hi in gaps]
    found = sorted(
        (_irregularity(blocks, gaps, i, j, extent), j - i, middles[i], middles[j])
        for i in range(len(gaps))
        for j in range(i + 1, min(i + UNIT_BLOCKS, len(gaps) - 1) + 1)
        if j - i < len(blocks) and middles[j] - middles[i] <= extent / 2
    )
    return [(irregular, lo, hi) for irregular, _, lo, hi in found]


def _crossed(
    spans: Sequence[tuple[float, float]], extent: float, at: float
) -> list[tuple[float, float]]:
    """The elements a cut at ``at`` crosses (bands aside: a copy lengthens them)."""
    near = NEAR * extent
    return [(lo, hi) for lo, hi in spans if lo + near < at < hi - near and hi - lo < BAND * extent]


def cuttable(spans: Sequence[tuple[float, float]], extent: float, lo: float, hi: float) -> bool:
    """Whether a unit can be cut out from ``lo`` to ``hi``: both cuts cross no element, or
    what one crosses the other crosses too, one unit along (within ``ALIKE`` of the
    extent): a pilaster cut at each end of a bay, which a copy puts together again."""
    a, b = sorted(set(_crossed(spans, extent, lo))), sorted(set(_crossed(spans, extent, hi)))
    along = hi - lo

    def alike(x0: float, x1: float, y0: float, y1: float) -> bool:
        near = min(ALIKE * extent, ALIKE_PART * (x1 - x0))
        return abs(x0 + along - y0) <= near and abs(x1 + along - y1) <= near

    return len(a) == len(b) and all(alike(*x, *y) for x, y in zip(a, b, strict=True))


def _cut_points(spans: Sequence[tuple[float, float]], extent: float) -> list[float]:
    """Where a cut may go: the elements' edges and middles (bands aside)."""
    kept = [(lo, hi) for lo, hi in spans if hi - lo < BAND * extent]
    return sorted({v for lo, hi in kept for v in (lo, hi, (lo + hi) / 2)})


def levels(spans: Sequence[tuple[float, float]], extent: float) -> list[float]:
    """Where the façade can be cut across once the elements that go on a sliver past the
    cut are trimmed to it (a hand-drawn cornice that overlaps the next floor's molding by a
    hand's breadth): at most ``SLIVER`` of the extent and ``SLIVER_PART`` of their length
    past it; of such cuts near each other (within twice that), the one that trims least.
    Cuts that cross no element are not levels: they are there already."""
    kept = np.array([(lo, hi) for lo, hi in spans if hi - lo < BAND * extent]).reshape(-1, 2)
    lo, hi = kept[:, 0], kept[:, 1]
    trimmed = []
    for at in _cut_points(spans, extent):
        crossed = (lo + NEAR * extent < at) & (at < hi - NEAR * extent)
        past = np.minimum(at - lo, hi - at)[crossed]
        most = np.minimum(SLIVER * extent, SLIVER_PART * (hi - lo)[crossed])
        if past.size and bool(np.all(past <= most)):
            trimmed.append((float(past.sum()), at))
    clean = [v for block in blocks_of(spans, extent) for v in block]
    found: list[float] = []
    near = 2 * SLIVER * extent
    for _, at in sorted(trimmed):
        if all(abs(at - v) > near for v in [*found, *clean]):
            found.append(at)
    return sorted(found)


def mirror(
    spans: Sequence[tuple[float, float]], extent: float, unit: tuple[float, float]
) -> tuple[float, float] | None:
    """The unit's mirror image about the centre, when that is a unit too and apart from it
    (its ends moved onto an element's edge or middle within ``SNAP`` of the extent: see
    :func:`snapped`), cut where :func:`cuttable` lets it be."""
    lo, hi = unit
    points = _cut_points(spans, extent)
    mirrored = (snapped(points, extent - hi, extent), snapped(points, extent - lo, extent))
    if mirrored[0] < hi - NEAR * extent and mirrored[1] > lo + NEAR * extent:
        return None
    return mirrored if cuttable(spans, extent, *mirrored) else None


def snapped(points: Sequence[float], at: float, extent: float) -> float:
    """A cut moved onto the nearest of ``points`` (elements' edges and middles, sorted) within
    ``SNAP`` of the extent (so that a hand-drawn façade's bays and mirror images are
    found, and no element is cut a sliver off); else where it is."""
    i = bisect.bisect_left(points, at)
    beside = points[max(0, i - 1) : i + 1]  # sorted: the nearest is one of these two
    near = min(beside, key=lambda e: abs(e - at), default=None)
    return near if near is not None and abs(near - at) <= SNAP * extent else at


def copied(
    spans: Sequence[tuple[float, float]],
    extent: float,
    new_extent: float,
    laid: Sequence[tuple[float, float]],
    copies: int,
) -> Plan | None:
    """The plan that copies the units ``laid`` ``copies`` times each (-1: leaves them out;
    0: stretches the source) and scales what is left over to fill ``new_extent`` (None
    when that is no good: see :func:`_laid`)."""
    blocks = blocks_of(spans, extent)
    stretches = _stretches(sorted(laid), extent, copies)
    if sum(b - a for a, b, times in stretches if times) < extent / 2:
        return None  # not the source any more
    return _laid(blocks, extent, new_extent, stretches, describe(laid, copies))


def scaled(extent: float, new_extent: float, most: float = SQUEEZE_MOST) -> Plan | None:
    """The source scaled alike to ``new_extent``, its elements too (None beyond what an
    element may be squeezed or stretched by: ``most`` either way, ``SQUEEZE_MOST`` unless
    said)."""
    alike = new_extent / extent
    if not 1 / most <= alike <= most:
        return None
    return Plan((Segment(0.0, extent, alike),), "scaled")


def describe(laid: Sequence[tuple[float, float]], copies: int) -> str:
    """What copying the units ``laid`` does, for people (empty: nothing)."""
    where = " and ".join(f"{round(a, 6):.3g}-{round(b, 6):.3g}" for a, b in sorted(laid))
    return "" if copies == 0 else f"{'left out' if copies < 0 else f'copied {copies}x'}: {where}"


def shifted(
    spans: Sequence[tuple[float, float]],
    extent: float,
    laid: Sequence[tuple[float, float]],
    through: bool = True,
) -> tuple[tuple[float, float], ...] | None:
    """The units ``laid`` (a unit, or a unit and its mirror image) moved by the least
    distance, at most half the unit's length, that lets a stretch of façade be cut at
    their ends (a unit and its mirror image by mirrored moves where they can be, else
    each by its own); themselves when it can be already; None when no move does. On a
    periodic façade a bay cut a little to one side copies the same bay. Without
    ``through``, the cuts cross no element (see :func:`cuttable`)."""
    points = _cut_points(spans, extent)

    def moves(lo: float, hi: float) -> list[float]:
        found = {0.0, *(e - v for e in points for v in (lo, hi))}
        return sorted((d for d in found if abs(d) <= (hi - lo) / 2), key=lambda d: (abs(d), d))

    def cut(lo: float, hi: float) -> tuple[float, float] | None:
        lo, hi = snapped(points, lo, extent), snapped(points, hi, extent)
        inside = lo >= 0.0 and hi <= extent
        if through:
            return (lo, hi) if inside and cuttable(spans, extent, lo, hi) else None
        free = not _crossed(spans, extent, lo) and not _crossed(spans, extent, hi)
        return (lo, hi) if inside and free else None

    (lo, hi), *rest = laid
    for move in moves(lo, hi):  # mirrored moves keep a mirrored pair mirrored
        units = [cut(lo + move, hi + move), *(cut(a - move, b - move) for a, b in rest)]
        if all(units):
            return tuple(u for u in units if u is not None)
    found = []
    for a, b in laid:
        own = next((u for d in moves(a, b) if (u := cut(a + d, b + d)) is not None), None)
        if own is None:
            return None
        found.append(own)
    return tuple(found)


def copies_near(length: float, extent: float, new_extent: float) -> list[int]:
    """Copies of units ``length`` long to try: as many as fit best, one more and one fewer
    (-1 leaves them out, 0 is the source stretched)."""
    if new_extent == extent:
        return [0]
    best = round((new_extent - extent) / length)
    return [c for c in sorted({best - 1, best, best + 1}) if c >= -1]


def plans(
    spans: Sequence[tuple[float, float]], extent: float, new_extent: float, mirrored: bool
) -> list[Plan]:
    """Plans that lay a stretch of façade ``extent`` long (elements spanning ``spans``)
    along ``new_extent``: the source stretched, and the first ``UNITS_TRIED`` units copied
    as often as fit best, one more and one fewer (or left out), in mirrored pairs when
    ``mirrored`` (a unit without a mirror image must then be centred)."""
    found = [copied(spans, extent, new_extent, [], 0)]
    for _, unit in laid_units(spans, extent, mirrored)[:UNITS_TRIED]:
        found += copying(spans, extent, new_extent, unit)
    return [plan for plan in found if plan is not None]


def copying(
    spans: Sequence[tuple[float, float]],
    extent: float,
    new_extent: float,
    laid: Sequence[tuple[float, float]],
) -> list[Plan | None]:
    """The plans that copy the units ``laid`` as many times as fit best, one more and one
    fewer, or leave them out (see :func:`copies_near`; None where :func:`copied` is)."""
    length = sum(hi - lo for lo, hi in laid)
    return [
        copied(spans, extent, new_extent, laid, copies)
        for copies in copies_near(length, extent, new_extent)
        if copies
    ]


def laid_units(
    spans: Sequence[tuple[float, float]], extent: float, mirrored: bool
) -> list[tuple[float, tuple[tuple[float, float], ...]]]:
    """The units (see :func:`units`) as they are copied, with how irregular they are:
    alone, or when ``mirrored`` with their mirror image (alone only when centred)."""
    found = []
    for irregular, lo, hi in units(spans, extent):
        pair = mirror(spans, extent, (lo, hi)) if mirrored else None
        if mirrored and pair is None and abs(lo + hi - extent) > 1e-3 * extent:
            continue  # an unmirrored unit off the centre would break the symmetry
        found.append((irregular, ((lo, hi),) if pair is None else tuple(sorted([(lo, hi), pair]))))
    return found


def strata(spans: Sequence[tuple[float, float]], extent: float) -> list[tuple[float, float]]:
    """The façade across the axis cut where no element crosses (bands aside): each block
    of elements and each gap between them (a floor and the wall between floors)."""
    blocks = blocks_of(spans, extent)
    ends = sorted({0.0, extent, *(v for b in blocks for v in b)})
    return [(a, b) for a, b in itertools.pairwise(ends) if b > a]


def _gaps(blocks: list[tuple[float, float]], extent: float) -> list[tuple[float, float]]:
    """The wall between blocks, the margins included (as long as there are blocks, + 1)."""
    ends = [0.0, *(v for b in blocks for v in b), extent]
    return [(ends[k], ends[k + 1]) for k in range(0, len(ends), 2)]


def _irregularity(
    blocks: list[tuple[float, float]],
    gaps: list[tuple[float, float]],
    i: int,
    j: int,
    extent: float,
) -> float:
    """How far copying the unit from gap ``i`` to gap ``j`` is from repeating a period:
    the gap it starts in against the one it ends in, and its first block against the block
    after it (0: a copy looks like the next bay along)."""
    length = [hi - lo for lo, hi in gaps]
    width = [hi - lo for lo, hi in blocks]
    after = width[j] if j < len(blocks) else 0.0
    margin = i == 0 or j == len(gaps) - 1
    return (abs(length[i] - length[j]) + abs(width[i] - after)) / extent + margin


def _stretches(
    units: list[tuple[float, float]], extent: float, copies: int
) -> list[tuple[float, float, int]]:
    """The source as stretches laid once, ``1 + copies`` times (a unit) or not at all."""
    found: list[tuple[float, float, int]] = []
    at = 0.0
    for lo, hi in units:
        found.append((at, lo, 1))
        found.append((lo, hi, 1 + copies))
        at = hi
    found.append((at, extent, 1))
    return [s for s in found if s[1] > s[0]]


def _laid(
    blocks: list[tuple[float, float]],
    extent: float,
    new_extent: float,
    stretches: list[tuple[float, float, int]],
    text: str,
) -> Plan | None:
    """The stretches cut where blocks meet gaps and scaled to fill ``new_extent``: all
    alike where that changes them by ``WIDEN_MOST`` at most (every spacing and symmetry
    kept), else the gaps alone where they stay within ``GAPS_LEAST`` to ``GAPS_MOST`` of
    their size, else all alike squeezed down to 1 / ``SQUEEZE_MOST``; None otherwise."""
    cuts = sorted({v for b in blocks for v in b})
    pieces: list[tuple[float, float, bool]] = []  # lo, hi, wall
    for lo, hi, times in stretches:
        edges = [lo, *(c for c in cuts if lo < c < hi), hi]
        laid = [
            (a, b, not any(p < (a + b) / 2 < q for p, q in blocks))
            for a, b in itertools.pairwise(edges)
        ]
        pieces += laid * times
    wall = sum(b - a for a, b, is_wall in pieces if is_wall)
    rest = sum(b - a for a, b, is_wall in pieces if not is_wall)
    alike = new_extent / (wall + rest)
    gaps = (new_extent - rest) / wall if wall > 0 else 0.0
    if 1 / WIDEN_MOST <= alike <= WIDEN_MOST:
        gap_scale = block_scale = alike
    elif GAPS_LEAST <= gaps <= GAPS_MOST:
        gap_scale, block_scale = gaps, 1.0
    elif 1 / SQUEEZE_MOST <= alike <= 1.0:
        gap_scale = block_scale = alike
    else:
        return None
    return Plan(
        tuple(Segment(a, b, gap_scale if w else block_scale) for a, b, w in pieces),
        text,
    )


def place(plan: Plan, lo: float, hi: float, near: float = 1e-9) -> list[tuple[float, float]]:
    """Where the source interval ``lo``-``hi`` lies after a plan: once, or once per copy
    of a unit it lies in. Where the interval goes on across the end of a segment and the
    next segment starts inside it (a band across a copied unit), the two parts are one;
    an interval exactly as long as a unit is laid once per copy. Overlaps of ``near`` or
    less are none (rounding in the source's coordinates)."""
    return [(start, end) for start, end, _ in laid(plan, lo, hi, near)]


def laid(plan: Plan, lo: float, hi: float, near: float = 1e-9) -> list[tuple[float, float, float]]:
    """:func:`place`, each part with the length of source it is made of (longer than the
    interval where a band goes on across copies of a unit: its length as copied, which a
    copy does not stretch)."""
    found: list[tuple[float, float, float]] = []
    at = 0.0
    going_on = False  # the last part was cut where its segment ends, the interval going on
    for segment in plan.segments:
        length = (segment.hi - segment.lo) * segment.scale
        a, b = max(lo, segment.lo), min(hi, segment.hi)
        if b - a > near:
            start = at + (a - segment.lo) * segment.scale
            end = at + (b - segment.lo) * segment.scale
            cut_here = a - segment.lo <= near and lo < segment.lo - near
            if going_on and cut_here and found:
                found[-1] = (found[-1][0], end, found[-1][2] + b - a)
            else:
                found.append((start, end, b - a))
            going_on = segment.hi - b <= near and hi > segment.hi + near
        else:
            going_on = False
        at += length
    return found
