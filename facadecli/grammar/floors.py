"""Ways to lay a façade up a new height, for copying whole floors
(:mod:`facadecli.grammar.slabs`): the one-dimensional plans of
:mod:`facadecli.grammar.retarget` over the façade's elements, bands along the axis left
out (:func:`unbanded`), with units one pitch of the style's rows (:func:`pitched`), and
elements that go a sliver past a level trimmed to it (:func:`levelled`)."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

from facadecli.grammar import retarget
from facadecli.grammar.model import Piece
from facadecli.grammar.pieces import boxes_of
from facadecli.grammar.style import BAND, Box
from facadecli.grammar.tiling import BACKGROUND

SPANNED_ROWS = 3  # rows of a label an element runs across, up the façade, to be a band there

Span = tuple[float, float]


def levelled(
    pieces: list[Piece], joined: Sequence[Box], source: tuple[float, float]
) -> list[Piece]:
    """The pieces with the elements that go on a sliver past a level
    (:func:`~facadecli.grammar.retarget.levels`) trimmed to it, the sliver made wall: a
    floor whose cornice overlaps the next floor's molding by a hand's breadth can then be
    copied, and the wall stays whole (``joined``: the pieces' elements; the pieces
    themselves where nothing is trimmed)."""
    elements = [*joined, *(b for b in boxes_of(pieces) if b.label != BACKGROUND)]
    crossing = unbanded(elements, joined, "y", source[1])
    levels = retarget.levels([(b.y0, b.y1) for b in crossing], source[1])
    near = retarget.NEAR * source[1]
    # the elements (and pieces of them) each level crosses, and whether they keep their
    # part below it
    crossed = [
        (b, at, at - b.y0 > b.y1 - at)
        for at in levels
        for b in crossing
        if b.y0 + near < at < b.y1 - near
    ]
    if not crossed:
        return pieces
    found = []
    for p in pieces:
        lo, hi = p.y0, p.y1
        for b, at, below in crossed:
            if p.label == b.label and inside(p, b, near):
                lo, hi = (lo, min(hi, at)) if below else (max(lo, at), hi)
        if (lo, hi) == (p.y0, p.y1):
            found.append(p)
            continue
        if hi <= lo:  # all of it a sliver
            lo = hi = p.y1
        else:
            found.append(Piece(p.label, p.x0, lo, p.x1, hi, p.source_w, p.source_h))
        found += [
            Piece(BACKGROUND, p.x0, y0, p.x1, y1, p.x1 - p.x0, y1 - y0)
            for y0, y1 in ((p.y0, lo), (hi, p.y1))
            if y1 > y0
        ]
    return found


def inside(p: Piece | Box, b: Box, near: float) -> bool:
    """Whether ``p`` lies within ``b`` (``near`` either way)."""
    return (
        b.x0 - near <= p.x0 and p.x1 <= b.x1 + near and b.y0 - near <= p.y0 and p.y1 <= b.y1 + near
    )


def floor_plans(
    elements: Sequence[Box], extent: float, height: float, rows: Sequence[Sequence[float]]
) -> list[retarget.Plan]:
    """Ways to lay the façade up its height: the façade stretched, then floors copied
    across the whole width: a unit one pitch of ``rows`` (the style's rows, of windows
    say), centred on one of them, holding no lowest or highest row of a label with three
    rows or more, so that a copy is the next floor up (a strip of a ground floor, an attic
    or a frieze copied would stack shop fronts, doors or bands); then a unit between the
    gaps of wall between floors, holding one of those rows and none of those ends, and
    neither the lowest floor nor the highest (a façade of two floors and an attic, whose
    rows make no pitch)."""
    spans = [(b.y0, b.y1) for b in elements]
    found: list[retarget.Plan | None] = [retarget.copied(spans, extent, height, (), 0)]
    ends = [c for centres in rows if len(centres) > 2 for c in (centres[0], centres[-1])]
    units = [  # holding no end
        unit
        for unit in pitched(rows, extent, False)
        if not any(unit[0][0] < c < unit[0][1] for c in ends)
    ]
    blocks = retarget.blocks_of(spans, extent)
    centres = [c for row in rows for c in row]
    if len(blocks) > 2:
        units += [
            ((lo, hi),)
            for _, lo, hi in retarget.units(spans, extent)
            if lo >= blocks[0][1]
            and hi <= blocks[-1][0]
            and any(lo < c < hi for c in centres)
            and not any(lo < c < hi for c in ends)
        ]
    for unit in units:
        cut = retarget.shifted(spans, extent, unit)
        if cut is not None:
            found += retarget.copying(spans, extent, height, cut)
    return [plan for plan in found if plan is not None]


def unbanded(
    elements: list[Box],
    joined: Sequence[Box],
    axis: str,
    extent: float,
    whole_labels: bool = True,
    rows: Sequence[Sequence[float]] = (),
) -> list[Box]:
    """The elements but bands along the axis (a cornice, a balcony across the façade) and
    the pieces they are made of; with ``whole_labels``, but every element of a label that
    makes a band somewhere (the molding around a floor's windows, beside the molding
    across the façade). Given ``rows`` (centres of a label's rows, up the façade), an
    element across ``SPANNED_ROWS`` of one label's rows or more is a band too (a giant order of
    pilasters)."""

    def length(b: Box) -> float:
        return (b.x1 - b.x0) if axis == "x" else (b.y1 - b.y0)

    def spans_rows(b: Box) -> bool:  # a giant order: across SPANNED_ROWS of a label's rows
        return any(sum(b.y0 < c < b.y1 for c in centres) >= SPANNED_ROWS for centres in rows)

    bands = [b for b in joined if length(b) >= BAND * extent or spans_rows(b)]
    if whole_labels:
        labels = {b.label for b in bands}
        return [e for e in elements if e.label not in labels]
    near = 1e-9 * extent
    return [
        e for e in elements if not any(e.label == b.label and inside(e, b, near) for b in bands)
    ]


def pitched(
    columns: Sequence[Sequence[float]], extent: float, mirrored: bool
) -> list[tuple[Span, ...]]:
    """Units one pitch of a label's columns long (of the style's ``columns``), centred on
    one of them (a window column and half the wall each side: its copy is the next bay
    along), with their mirror images when ``mirrored``."""
    near = 1e-3 * extent
    centred = 0.01 * extent  # the style's tolerance
    found: list[tuple[Span, ...]] = []
    pairs = [pair for centres in columns for pair in itertools.pairwise(centres)]
    for a, b in pairs:
        half = (b - a) / 2
        for centre in (a, b):
            lo, hi = max(0.0, centre - half), min(extent, centre + half)
            unit: tuple[Span, ...] = ((lo, hi),)
            if mirrored and abs(lo + hi - extent) > centred:
                if extent - hi < hi - near:
                    continue  # the unit and its mirror image overlap
                unit = ((lo, hi), (extent - hi, extent - lo))
            if unit not in found:
                found.append(unit)
    return found


def holds_column(unit: Sequence[Span], columns: Sequence[Sequence[float]]) -> bool:
    return any(lo < c < hi for lo, hi in unit for centres in columns for c in centres)
