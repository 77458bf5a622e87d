"""The layers of a labelled layout: each label's elements as grids, back to front.

The layered model draws a layer as the outer product of a horizontal and a vertical word
(Ilčík et al. 2015), so a layer's elements are a *grid*: every row holds an element in
every column. A label's elements are split into grids: rows (one height span) that hold the
same columns (width spans) form one, bottom up; elements that overlap one of their label
already taken in a row, and rows that overlap a row already in the grid, go to the next
grid. Labels stack in the input's z-order (the CMP order: what is drawn over what); the
background becomes the wall behind them all.
"""

from __future__ import annotations

import itertools
import math
import statistics
from collections import defaultdict
from dataclasses import dataclass
from itertools import pairwise

from facadecli.grammar.inputs import BACKGROUND, CMP_Z_ORDER, LabelledLayout, Rect

Span = tuple[float, float]
BAND = 0.25  # an element longer than this share of the façade is a band across it
EDGE = 0.01  # a band this share of the façade or less from an edge reaches the edge
FLOOR = 0.15  # rows of a label this close in height (a share of it) are floors alike
STOREY = 0.4  # of the façade's height: the most a floor's pitch is (two floors and a base)
FLOOR_PITCH = 0.05  # pitches this close (a share) are the openings' floors'
NEAR = 0.05  # m: an element this close beside an opening's column stands with it (a blind)


@dataclass(frozen=True)
class Grid:
    """One layer: a label's elements at every crossing of ``columns`` and ``rows``."""

    label: str
    columns: tuple[Span, ...]  # along x, left to right
    rows: tuple[Span, ...]  # along y, bottom up
    apart: bool = False  # of elements left where drawn, off the façade's bays (``infer.bays``)

    @property
    def elements(self) -> int:
        return len(self.columns) * len(self.rows)


def _z(label: str, rects: list[Rect]) -> tuple[int, float, str]:
    """Back to front: the CMP order, then the z the input gives, then the label."""
    return (CMP_Z_ORDER.get(label, 99), min(r.z for r in rects), label)


def grids(
    layout: LabelledLayout, background: str = BACKGROUND, apart: frozenset[int] = frozenset()
) -> list[Grid]:
    """Every label's elements as grids, back to front (see the module); the rectangles
    ``apart`` (by index) in grids of their own, after the label's others."""
    by_label: dict[str, list[Rect]] = defaultdict(list)
    for rect in layout.rects:
        if rect.label != background:
            by_label[rect.label].append(rect)
    found: list[Grid] = []
    for label in sorted(by_label, key=lambda name: _z(name, by_label[name])):
        for own in (False, True):
            spans = sorted(
                {
                    ((r.y0, r.y1), (r.x0, r.x1))
                    for k, r in enumerate(layout.rects)
                    if r.label == label and (k in apart) == own
                }
            )
            found.extend(cut(label, spans, own))
    return found


def cut(label: str, spans: list[tuple[Span, Span]], apart: bool = False) -> list[Grid]:
    """A label's elements (``(row, column)`` spans, sorted) as grids (see the module)."""
    found: list[Grid] = []
    while spans:
        taken, spans = _grid_rows(spans)
        found.extend(_by_columns(label, taken, apart))
    return found


def _grid_rows(
    spans: list[tuple[Span, Span]],
) -> tuple[dict[Span, tuple[Span, ...]], list[tuple[Span, Span]]]:
    """Rows of disjoint elements (the rest for later grids)."""
    rows: dict[Span, list[Span]] = defaultdict(list)
    rest: list[tuple[Span, Span]] = []
    for row, column in spans:
        held = rows[row]
        if held and held[-1][1] > column[0]:  # overlaps the last one taken in its row
            rest.append((row, column))
        else:
            held.append(column)
    return {row: tuple(columns) for row, columns in rows.items()}, rest


def _by_columns(label: str, rows: dict[Span, tuple[Span, ...]], apart: bool) -> list[Grid]:
    """Rows that hold the same columns, as grids whose rows do not overlap."""
    same: dict[tuple[Span, ...], list[Span]] = defaultdict(list)
    for row in sorted(rows):
        same[rows[row]].append(row)
    found: list[Grid] = []
    for columns, members in same.items():
        stacks: list[list[Span]] = []
        for row in members:  # bottom up; a row overlapping the last of a stack starts another
            stack = next((s for s in stacks if s[-1][1] <= row[0]), None)
            if stack is None:
                stacks.append([row])
            else:
                stack.append(row)
        found.extend(Grid(label, columns, tuple(stack), apart) for stack in stacks)
    return sorted(found, key=lambda g: (g.rows[0], g.columns[0]))


OPENINGS = ("window", "door", "shop")  # labels that may be unoccludable (SPEC 2.4)


def uncovered(found: list[Grid]) -> set[str]:
    """The opening labels none of whose elements an element of a grid in front of it
    overlaps: what the input shows nothing over (``unoccludable`` in the spec)."""
    covered: set[str] = set()
    for k, grid in enumerate(found):
        if grid.label not in OPENINGS or grid.label in covered:
            continue
        mine = [(c, r) for c in grid.columns for r in grid.rows]
        for front in found[k + 1 :]:
            if any(
                _overlap(c, fc) and _overlap(r, fr)
                for c, r in mine
                for fc in front.columns
                for fr in front.rows
            ):
                covered.add(grid.label)
                break
    return {grid.label for grid in found if grid.label in OPENINGS} - covered


def _overlap(a: Span, b: Span) -> bool:
    return min(a[1], b[1]) - max(a[0], b[0]) > 1e-9


def to_edges(grid: Grid, width: float, height: float) -> Grid:
    """The grid with its bands (elements across a good share of the façade) reaching the
    façade's edges where they stop a sliver short of them (hand annotation: 0.04 m short
    on a 15 m façade). Left in, the sliver is a gap as costly to stretch as the band, so a
    wider façade would grow it as much as the band and leave the band metres short."""
    return Grid(grid.label, _reach(grid.columns, width), _reach(grid.rows, height), grid.apart)


def _reach(spans: tuple[Span, ...], extent: float) -> tuple[Span, ...]:
    reached = list(spans)
    first, last = reached[0], reached[-1]
    if first[1] - first[0] > BAND * extent and 0 < first[0] <= EDGE * extent:
        reached[0] = first = (0.0, first[1])
    if last[1] - last[0] > BAND * extent and 0 < extent - last[1] <= EDGE * extent:
        reached[-1] = (last[0] if len(reached) > 1 else first[0], extent)
    return tuple(reached)


Frame = tuple[tuple[Span, str], ...]  # columns left to right, each with its label


def frames(found: list[Grid]) -> list[Frame | None]:
    """For each grid, the columns its layer's x word is written over: its own and those of
    the opening grids that stand beside it on a floor (rows overlapping along y, columns
    apart along x: a door between the ground floor's windows, or one floor's windows drawn
    in two grids, a few centimetres off each other's rows), so that the layers of one floor
    share one word, each showing its own elements (its mask), and solved at another width
    keep their order and spacing together instead of moving over one another. None where a
    grid has no such neighbour.

    Grids of a label on the same columns (floors apart, or one drawn over the other) are
    one unit: they keep one word, as their columns are one. Units join one at a time, in
    pairs in the order found, and only where the floor's columns stay apart (no two
    overlapping, no span of two units): a unit that cannot join (its column over one of
    another floor's, on a grid of several floors) keeps its own word, and the floor's
    others still share theirs. Two units of one label in one word show their elements by
    symbols of their own where their widths meet (``spec_text``: a mask names sizes)."""
    units: dict[tuple[str, tuple[Span, ...]], list[int]] = defaultdict(list)
    for k, grid in enumerate(found):  # grids of a label on the same columns: one unit
        if grid.label in OPENINGS:
            units[grid.label, grid.columns].append(k)
    order = list(units)
    rows = {u: [r for k in units[u] for r in found[k].rows] for u in order}
    members = {u: [u] for u in order}  # by the group's first unit
    root = {u: u for u in order}
    for n, a in enumerate(order):
        for b in order[n + 1 :]:
            if root[a] == root[b] or not any(_overlap(r, s) for r in rows[a] for s in rows[b]):
                continue
            joined = members[root[a]] + members[root[b]]
            if _one_word([columns for _, columns in joined]):
                first, other = sorted((root[a], root[b]), key=order.index)
                members[first] = sorted(joined, key=order.index)
                del members[other]
                for u in joined:
                    root[u] = first
    out: list[Frame | None] = [None] * len(found)
    for group in members.values():
        if len(group) < 2:
            continue
        frame = tuple(sorted((c, label) for label, columns in group for c in columns))
        for unit in group:
            for k in units[unit]:
                out[k] = frame
    return out


SIZE_KEY = 6  # decimals: sizes of a label's elements this alike are one symbol in a spec


def _one_word(group: list[tuple[Span, ...]]) -> bool:
    """Whether grids on these columns can share one x word: their columns apart."""
    spans = sorted(c for columns in group for c in columns)
    return all(b[0] >= a[1] - 1e-9 for a, b in pairwise(spans))


def top_floors(found: list[Grid], width: float, height: float) -> dict[int, float]:
    """The grids whose top row is their label's top floor, by index, each with the pitch
    its copies stand at: elements, not bands across the façade (``BAND`` of its
    ``width``: a balcony or a cornice along a floor stretches with the façade and is not a
    bay's), no element of its label like it (a height within ``FLOOR`` of its own) starts
    above that row, and below it stands a row of its label like it (of the grid, or of
    another in columns overlapping its own), at most ``STOREY`` of the façade's ``height``
    lower (the floor below); the pitch is the distance from the start of the nearest such
    row to the start of the top one. So the top floor is the last floor like one under
    it: a floor of lower windows over it (cmp_b0007's, an attic's) is no floor like it,
    and keeps its margin to the roof over the copies (``spec_text``). A façade of one
    floor over another has no run of floors, nor one whose top floor is drawn apart from
    the rest (its windows a few centimetres off the others' rows): written as a top floor
    that repeats upwards from none more, a taller façade still gains floors at its
    pitch.

    Copies stand at the façade's floor pitches (``_pitches``): the openings' top floors'
    pitches within ``FLOOR_PITCH`` of one another (a hand's jitter) are one, the middle
    one, on one counter (at pitches a hand's jitter apart a window's copies and its
    blind's drift apart floor by floor, and layers on the same rows, which share their
    margin to the roof, admit no copy at all: the family with defects' seed 24 gained no
    floor); a part of the façade whose floors are taller (two houses side by side,
    cmp_b0003) keeps its own pitch and counter. Only grids at their pitch (within
    ``FLOOR_PITCH``: a floor of lower windows over the last like those under it finds its
    like floors under them, a pitch too far, and does not repeat), whose top row is lower
    than it; and labels other than the openings' only on the top floor of an opening
    grid that repeats, over or beside its columns (``NEAR``: a sill under its window, a
    blind beside it, never a sill of another column whose window does not repeat), with
    a row of their label that pitch under it, of any height (sills drawn 1-2 cm tall
    differ in height by more than ``FLOOR``: the family with defects' seed 24 gained
    floors without them); for those, "like it above" means in their own columns (the
    other house's top sills stand higher)."""
    out: dict[int, float] = {}
    under: dict[int, list[float]] = {}  # each candidate's rows under it: where they start
    for k, grid in enumerate(found):
        low, high = grid.rows[-1]
        if any(b - a > BAND * width for a, b in grid.columns):
            continue
        mine = [g for g in found if g.label == grid.label]
        size = high - low
        if any(
            row[0] >= high - 1e-9 and abs(row[1] - row[0] - size) <= FLOOR * size
            for g in mine
            if g is grid or over(g, grid)
            for row in g.rows
        ):
            continue  # not the top floor: one of its label like it stands above it
        rows = [
            row
            for g in mine
            if g is grid or over(g, grid)
            for row in g.rows
            if row[1] <= low + 1e-9
        ]
        under[k] = [row[0] for row in rows]
        below = [row[0] for row in rows if abs(row[1] - row[0] - size) <= FLOOR * size]
        if grid.label in OPENINGS and not _like_under(mine, grid):
            continue  # a column of it over no floor like it: a row of its own (an attic's)
        if below and low - max(below) <= STOREY * height:
            out[k] = low - max(below)
    measured = [out[k] for k in out if found[k].label in OPENINGS]
    if not measured:
        return {}
    main = statistics.median_low(measured)
    pitches = [main, *_pitches(sorted(p for p in measured if abs(p - main) > FLOOR_PITCH * main))]
    copied = {
        k: pitch
        for k in out
        if found[k].label in OPENINGS
        for pitch in [_nearest(out[k], pitches)]
        if found[k].rows[-1][1] - found[k].rows[-1][0] < pitch
        and abs(out[k] - pitch) <= FLOOR_PITCH * pitch
        and (pitch == main or _clear_above(found, found[k]))
    }

    def stands_on(k: int) -> float | None:
        """The pitch of an opening grid that repeats whose top floor another label's
        row stands on, beside or over its columns (``NEAR``), with a row of its label
        that pitch under it (a sill of the floor below, whatever the jitter of its
        height); None where it stands on none."""
        low, high = found[k].rows[-1]
        return next(
            (
                pitch
                for o, pitch in copied.items()
                if high - low < pitch
                and found[o].rows[-1][0] - pitch / 2 <= low <= found[o].rows[-1][1]
                and over(found[o], found[k], NEAR)
                and any(abs(low - start - pitch) <= FLOOR * pitch for start in under[k])
            ),
            None,
        )

    others = {k: stands_on(k) for k in under if found[k].label not in OPENINGS}
    return {**copied, **{k: pitch for k, pitch in others.items() if pitch is not None}}


def _like_under(mine: list[Grid], grid: Grid) -> bool:
    """Whether under ``grid``'s top row, and under every element of its label on that row
    (like it, starting within ``FLOOR`` of its height: one floor drawn in several grids),
    the elements of its label in that element's column are like it, or one of them is:
    a floor that repeats across the façade (a column over a door, with none of its label
    under it, stands on none). A row of small windows over columns of taller ones
    (cmp_b0008's inner part: an attic's row) is no top floor, in any of its grids, and
    the taller windows' own top floor under it repeats instead."""
    low, high = grid.rows[-1]
    size = high - low

    def like(row: Span) -> bool:
        return abs(row[1] - row[0] - size) <= FLOOR * size

    on_row = [
        column
        for g in mine
        if any(like(row) and abs(row[0] - low) <= FLOOR * size for row in g.rows)
        for column in g.columns
    ]
    under = [
        [
            row
            for g in mine
            if any(_overlap(column, c) for c in g.columns)
            for row in g.rows
            if row[1] <= low + 1e-9
        ]
        for column in on_row
    ]
    return all(not rows or any(like(row) for row in rows) for rows in under)


def _clear_above(found: list[Grid], grid: Grid) -> bool:
    """Whether no opening stands above ``grid``'s top row in its columns: a part of the
    façade with floors of its own pitch (``top_floors``) copies its top floor upwards
    only there (a window over it, of a pitch of the others', would stay where drawn
    and the copies would run into it: cmp_b0006's windows 2 m apart under floors 1.8 m
    apart)."""
    top = grid.rows[-1][1]
    return not any(
        g.label in OPENINGS and g is not grid and over(g, grid) and g.rows[-1][1] > top + 1e-9
        for g in found
    )


def _pitches(measured: list[float]) -> list[float]:
    """The floor pitches of the façade's parts from their top floors' (sorted, those
    apart from the main one): the middle one of each run of pitches within
    ``FLOOR_PITCH`` of the run's first (a hand's jitter), so that every copy of one
    part stands at one pitch, and a part whose floors are taller (cmp_b0003: two
    houses side by side) keeps its own."""
    runs: list[list[float]] = []
    for pitch in measured:
        if runs and pitch - runs[-1][0] <= FLOOR_PITCH * runs[-1][0]:
            runs[-1].append(pitch)
        else:
            runs.append([pitch])
    return [statistics.median_low(run) for run in runs]


def _nearest(pitch: float, pitches: list[float]) -> float:
    return min(pitches, key=lambda p: abs(p - pitch))


def over(a: Grid, b: Grid, reach: float = 0.0) -> bool:
    """Whether a column of ``a`` overlaps one of ``b`` (grown by ``reach`` either side)."""
    return any(_overlap(c, (d[0] - reach, d[1] + reach)) for c in a.columns for d in b.columns)


@dataclass(frozen=True)
class Stack:
    """A top floor that repeats upwards (``top_floors``) with the floors like it under it
    (``stacks``), as one layer sees them: ``floors`` slots of ``pitch``, the lowest
    starting at ``bottom``, numbered from the top (0, the top floor's, where the copies
    stand over); ``rows`` the layer's rows on them, each with its slot. The layer's other
    rows stand under ``bottom``."""

    top: bool  # the layer of the top floor (its copies are shown)
    pitch: float
    bottom: float
    floors: int
    rows: tuple[tuple[Span, int], ...]


def _slot(found: list[Grid], tops: dict[int, float], k: int) -> float:
    """Where the top floor's slot of top layer ``k`` starts: the middle of the wall under
    the top row of the openings' top layer at its pitch nearest it (its own, for an
    opening), moved by whole pitches to the floor ``k``'s top row stands on (a sill
    under its window shares the window's slot)."""
    pitch, start = tops[k], found[k].rows[-1][0]
    openings = [o for o, p in tops.items() if p == pitch and found[o].label in OPENINGS]
    o = min(openings, key=lambda o: abs(found[o].rows[-1][0] - start), default=k)
    low, high = found[o].rows[-1]
    first = low - (pitch - (high - low)) / 2
    return first + math.floor((start - first) / pitch) * pitch


def stacks(found: list[Grid], tops: dict[int, float], height: float) -> dict[int, Stack]:
    """The layers standing on the floors of a top floor that repeats upwards, and the top
    floor's own layer, each with its ``Stack``, so that a shorter façade drops whole
    floors from the top, with what stands on them, in every column alike, as a taller
    one gains copies of the top floor (``spec_text._stack_word``). A top floor's stack
    is the floors a pitch, two pitches, ... under its row (each within ``FLOOR_PITCH``
    of the pitch) holding a row of its label in columns overlapping its own, like it in
    height for the openings (``FLOOR``; sills drawn 1-2 cm tall are not), down to the
    first floor without one; a layer of one row joins the first stack it stands on.
    Each floor is a slot of the pitch, from the middle of the wall under it to the
    middle of the wall over it (as ``floors.Floors`` cuts the openings' run: a top floor
    closer to the roof than a floor's wall, or a lowest one closer to the ground, still
    has its slot), the top one's from the top row's, the others a pitch apart, lowered by
    the most any row of the stack starts under its slot (a hand's jitter), so each row
    stands in its slot. A stack whose rows do not fit in their slots, whose slots reach
    the ground or the roof, or whose top layer has rows between its slots is none:
    that top floor repeats upwards as it did, and a shorter façade has no layout."""
    out: dict[int, Stack] = {}
    for k, pitch in sorted(tops.items()):
        grid = found[k]
        start, end = grid.rows[-1]
        size = end - start
        like = grid.label in OPENINGS
        found_rows: dict[int, list[tuple[int, Span]]] = {0: [(k, grid.rows[-1])]}
        for depth in itertools.count(1):
            at = start - depth * pitch
            hits = [
                (m, row)
                for m, other in enumerate(found)
                if m not in out
                and (m == k or (m not in tops and len(other.rows) == 1 and over(other, grid)))
                and other.label == grid.label
                for row in other.rows
                if abs(row[0] - at) <= FLOOR_PITCH * pitch
                and (not like or abs(row[1] - row[0] - size) <= FLOOR * size)
            ]
            if at < 0 or not hits:
                break
            found_rows[depth] = hits
        floors = len(found_rows)
        first = _slot(found, tops, k)
        under = max(
            (first - d * pitch) - row[0] for d, hits in found_rows.items() for _, row in hits
        )
        bottom = first - (floors - 1) * pitch - max(under, 0.0)
        slots = {d: bottom + (floors - 1 - d) * pitch for d in found_rows}
        if any(
            row[1] > slots[d] + pitch + 1e-9 for d, hits in found_rows.items() for _, row in hits
        ):
            continue  # a row beyond its slot
        if bottom < 0 or bottom + floors * pitch >= height - 1e-6:
            continue  # the slots reach the ground or the roof: no margin
        own = [row for hits in found_rows.values() for m, row in hits if m == k]
        if any(row[1] > bottom + 1e-9 for row in grid.rows if row not in own):
            continue  # the top layer's rows between the slots
        members: dict[int, list[tuple[Span, int]]] = {}
        for d, hits in found_rows.items():
            for m, row in hits:
                members.setdefault(m, []).append((row, d))
        if any(m != k and m in out for m in members):
            continue
        for m, rows in members.items():
            out[m] = Stack(m == k, pitch, bottom, floors, tuple(sorted(rows)))
    return out
