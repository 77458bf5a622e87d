"""A façade at a new size made of the input's own terminals, whole bays and floors copied
(retargeting by slabs, after Lin et al. 2011): the two-dimensional use of the
one-dimensional plans of :mod:`facadecli.grammar.retarget`, beside the grammar's
derivations (:mod:`facadecli.grammar.derive`); :mod:`facadecli.grammar.variations`
compares them.
"""

from __future__ import annotations

import functools
import itertools
from collections import defaultdict
from collections.abc import Sequence

from facadecli.grammar import retarget
from facadecli.grammar.model import Piece
from facadecli.grammar.pieces import boxes_of, elements_of, score
from facadecli.grammar.style import Box, Constraint, Facade, check, shared_rows
from facadecli.grammar.tiling import BACKGROUND

RETARGETS_MAX = 5  # plans up the façade tried with each plan across it (stretched first)
PIECES_MOST = 20_000  # pieces a copied layout would have at most (more: none is made)
SCALED_MOST = 0.25  # of the height: strata a unit cannot be cut out of, scaled alike instead
SCALED_ACROSS = 2.0  # ... by this at most, either way (an attic of ornaments at twice the width)
LAID_MOST = 60_000  # pieces laid over all the copied layouts (the rest are not made)
HALF = 0.6  # of its source's width: a part of a piece this narrow was cut (see _halves_joined)
BUILDINGS_TRIED = 64  # stretches of the width looked at for a building's floors, at most
WIDER_FIRST = 2  # wider layouts given floors building by building, at most
GIANT = 3  # rows of a label an element runs across, up the façade, to be a band there

Span = tuple[float, float]
Part = tuple[float, float, float, float, float, float]  # x0, x1, y0, y1, source across, up


def retargeted(
    pieces: list[Piece],
    source: tuple[float, float],
    width: float,
    height: float,
    style: Sequence[Constraint],
) -> list[tuple[list[Piece], float, str]]:
    """The source's pieces laid out at a new size by :mod:`~facadecli.grammar.retarget`:
    each layout, how far its wall stretched (the squares of the log-ratios, a term of its
    score) and what was done; none at the source's size, nor where a layout would have
    more than ``PIECES_MOST`` pieces, and no more once ``LAID_MOST`` pieces are laid
    (budgets counted in work: a façade many times its source's size is the grammar's).

    Floors are copied across the whole width. Bays are copied floor by floor (a floor, or
    the wall between floors, is a stratum): one unit, where a stratum lets it be cut out
    there or a little to one side (:func:`~facadecli.grammar.retarget.shifted`; through
    pilasters where a copy puts their halves together again, :func:`_cut`); a stratum
    that cannot be cut near it (a ground floor of shops) is stretched instead, so
    the floors above keep their columns whatever the ground floor does (where its wall
    cannot take the width, it is scaled alike, by ``SCALED_ACROSS`` at most, if such
    strata are at most ``SCALED_MOST`` of the height: an attic of staggered ornaments).
    The units tried first hold a column of the style's (one pitch of it, centred on a
    column, is a period by construction), then those that most strata can be cut at.
    Every stratum stretches the wall that is wall in all of them, so strata cut alike
    stay lined up. ``style`` gives the columns and whether the façade is mirrored (units
    are then copied with their mirror images).

    Taller, the floors are cut where hand-drawn floors overlap by a sliver, the sliver
    trimmed (:func:`_levelled`); where no floor can be cut across the whole width, each
    building of a row of them gains its own floors (:func:`_by_buildings`; wider too, on
    the façade made wider first: :func:`_taller_by_buildings`)."""
    grown = max(1.0, width / source[0]) * max(1.0, height / source[1])
    if (width, height) == source or len(pieces) * grown > PIECES_MOST:
        return []
    facade = elements_of(pieces, *source)
    if height != source[1]:  # floors cut where hand-drawn floors overlap by a sliver
        levelled = _levelled(pieces, facade.boxes, source)
        if levelled is not pieces:
            pieces, facade = levelled, elements_of(levelled, *source)
    boxes = boxes_of(pieces)
    joined = facade.boxes
    # a mirrored façade copies a unit with its mirror image; one with an element on the
    # centre line may (so it stays there) or may not (the centred unit itself copied)
    symmetric = any(c.kind == "symmetry" for c in style)
    centred = any(c.kind == "centre" for c in style)
    pairs = (True,) if symmetric else (False, True) if centred else (False,)
    shared = [shared_rows(facade, c.label) for c in style if c.kind == "columns"]
    columns = [[(b.x0 + b.x1) / 2 for b in group[0]] for group in shared if group]
    # no cut may cross an element, nor a piece of one (an L-shaped molding), but for
    # labels that make bands along the axis (a cornice, pilasters): a copy lengthens them
    elements = [*joined, *(b for b in boxes if b.label != BACKGROUND)]
    in_bays = _unbanded(elements, joined, "x", source[0])
    clean = _unbanded(elements, joined, "x", source[0], whole_labels=False)
    in_floors = _unbanded(elements, joined, "y", source[1])
    rows = [sorted((r[0].y0 + r[0].y1) / 2 for r in group) for group in shared if group]
    # a giant order of pilasters across several floors is a band too, for copying floors
    # (taller only: at the source's height the floors are stretched, as before)
    in_giant = in_floors
    if height != source[1]:
        in_giant = _unbanded(elements, joined, "y", source[1], rows=rows)
    floors = _floors(in_giant, source[1], height, rows)
    bays = _bays(in_bays, in_floors, source, width, pairs, columns, clean)
    laid = []
    # where the wall alone cannot stretch up the façade, everything is scaled alike, so
    # that bays copied across still make a layout (never the layout unchanged across)
    along = floors[:RETARGETS_MAX]
    scaled_up = retarget.scaled(source[1], height)
    if scaled_up is not None and not any(plan.text == "" for plan in along):
        along.append(scaled_up)
    budget = LAID_MOST
    if height != source[1] and not any(plan.text for plan in floors):
        # no floor across the whole width: each building of a row of them its own floors
        # (wider too: on the façade made wider first, bays copied across)
        for layout in _taller_by_buildings(
            pieces, facade, (in_floors, in_bays), source, (width, height), style
        ):
            budget -= len(layout[0])
            laid.append(layout)
    for (text_x, strata, across), along_y in itertools.product(bays, along):
        if along_y is scaled_up and not text_x:
            continue
        if budget <= 0:
            break
        parts: dict[int, list[Part]] = defaultdict(list)
        for k, p in enumerate(pieces):
            for (lo, hi), plan in zip(strata, across, strict=True):
                if p.y0 < hi and p.y1 > lo:
                    for x0, x1, along_x in retarget.laid(plan, p.x0, p.x1):
                        for y0, y1, up in retarget.laid(along_y, max(p.y0, lo), min(p.y1, hi)):
                            parts[k].append((x0, x1, y0, y1, along_x, up))
        moved = _halves_joined(
            [_moved(pieces[k], part) for k in sorted(parts) for part in _stacked(parts[k])],
            1e-9 * width,
        )
        budget -= len(moved)
        stretch = max(plan.stretch for plan in across) ** 2 + along_y.stretch**2
        texts = [t for t in (text_x, f"y {along_y.text}" if along_y.text else "") if t]
        laid.append((moved, stretch, "; ".join(texts) or "stretched"))
    return laid


def _taller_by_buildings(
    pieces: list[Piece],
    facade: Facade,
    elements: tuple[Sequence[Box], Sequence[Box]],
    source: tuple[float, float],
    size: tuple[float, float],
    style: Sequence[Constraint],
) -> list[tuple[list[Piece], float, str]]:
    """:func:`_by_buildings` at the source's width; at a new width too, on the
    ``WIDER_FIRST`` layouts at the source's height (bays copied across) that keep the most
    of the style, then are nearest the source's sizes."""
    width, height = size
    if width == source[0]:
        return _by_buildings(pieces, facade, *elements, source, height, style)

    def rank(layout: tuple[list[Piece], float, str]) -> tuple[int, float]:
        kept = check(style, elements_of(layout[0], width, source[1]))
        return -len(kept.kept), score(layout[0]) + layout[1]

    wider = sorted(retargeted(pieces, source, width, source[1], style), key=rank)[:WIDER_FIRST]
    return [
        (taller, stretch + more, f"{text_x}; {text_y}")
        for moved, stretch, text_x in wider
        for taller, more, text_y in retargeted(moved, (width, source[1]), width, height, style)
        if text_y.startswith("by buildings")
    ]


def _by_buildings(
    pieces: list[Piece],
    facade: Facade,
    in_floors: Sequence[Box],
    in_bays: Sequence[Box],
    source: tuple[float, float],
    height: float,
    style: Sequence[Constraint],
) -> list[tuple[list[Piece], float, str]]:
    """The façade made ``height`` tall with floors copied building by building, for a row
    of buildings whose floors are at different heights (no floor can be cut across the
    whole width): cut up the façade where no element crosses (``in_bays``: bands across
    aside), into buildings from the left, each as wide as lets it copy a floor of its own
    (see :func:`_floors`, with the style's rows in it); a layout of the k-th plan of each
    (its last where it has fewer), for the first ``RETARGETS_MAX``. None where some
    building has no floor to copy, or the whole width is one building, or more than
    ``BUILDINGS_TRIED`` stretches were looked at (a budget counted in work)."""
    strata = retarget.strata([(b.x0, b.x1) for b in in_bays], source[0])
    ends = [0.0, *(hi for _, hi in strata)]
    labels = [c.label for c in style if c.kind == "columns"]

    def floors_of(lo: float, hi: float) -> list[retarget.Plan]:
        here = [b for b in in_floors if b.x0 < hi and b.x1 > lo]
        part = Facade(tuple(b for b in facade.boxes if lo <= (b.x0 + b.x1) / 2 <= hi), *source)
        rows = [
            sorted((r[0].y0 + r[0].y1) / 2 for r in group)
            for group in (shared_rows(part, label) for label in labels)
            if group
        ]
        return [plan for plan in _floors(here, source[1], height, rows) if plan.text]

    buildings: list[tuple[float, float, list[retarget.Plan]]] = []
    tried, i = 0, 0
    while i < len(ends) - 1:
        for j in range(len(ends) - 1, i, -1):
            tried += 1
            if tried > BUILDINGS_TRIED:
                return []
            plans = floors_of(ends[i], ends[j])
            if plans:
                buildings.append((ends[i], ends[j], plans))
                break
        else:
            return []
        i = j
    if len(buildings) < 2:
        return []
    laid = []
    for k in range(RETARGETS_MAX):
        if k and all(k >= len(plans) for _, _, plans in buildings):
            break
        chosen = [(lo, hi, plans[min(k, len(plans) - 1)]) for lo, hi, plans in buildings]
        moved = [
            _moved(p, (max(p.x0, lo), min(p.x1, hi), y0, y1, min(p.x1, hi) - max(p.x0, lo), up))
            for p in pieces
            for lo, hi, plan in chosen
            if p.x0 < hi and p.x1 > lo
            for y0, y1, up in retarget.laid(plan, p.y0, p.y1)
        ]
        stretch = max(plan.stretch for _, _, plan in chosen) ** 2
        text = "; ".join(f"{lo:.3g}-{hi:.3g}: y {plan.text}" for lo, hi, plan in chosen)
        laid.append((moved, stretch, f"by buildings: {text}"))
    return laid


def _levelled(
    pieces: list[Piece], joined: Sequence[Box], source: tuple[float, float]
) -> list[Piece]:
    """The pieces with the elements that go on a sliver past a level
    (:func:`~facadecli.grammar.retarget.levels`) trimmed to it, the sliver made wall: a
    floor whose cornice overlaps the next floor's molding by a hand's breadth can then be
    copied, and the wall stays whole (``joined``: the pieces' elements; the pieces
    themselves where nothing is trimmed)."""
    elements = [*joined, *(b for b in boxes_of(pieces) if b.label != BACKGROUND)]
    unbanded = _unbanded(elements, joined, "y", source[1])
    levels = retarget.levels([(b.y0, b.y1) for b in unbanded], source[1])
    near = retarget.NEAR * source[1]
    # the elements (and pieces of them) each level crosses, and whether they keep their
    # part below it
    crossed = [
        (b, at, at - b.y0 > b.y1 - at)
        for at in levels
        for b in unbanded
        if b.y0 + near < at < b.y1 - near
    ]
    if not crossed:
        return pieces
    found = []
    for p in pieces:
        lo, hi = p.y0, p.y1
        for b, at, below in crossed:
            if p.label == b.label and _inside(p, b, near):
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


def _inside(p: Piece | Box, b: Box, near: float) -> bool:
    """Whether ``p`` lies within ``b`` (``near`` either way)."""
    return (
        b.x0 - near <= p.x0 and p.x1 <= b.x1 + near and b.y0 - near <= p.y0 and p.y1 <= b.y1 + near
    )


def _floors(
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
        for unit in _pitched(rows, extent, False)
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


def _unbanded(
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
    element across ``GIANT`` of one label's rows or more is a band too (a giant order of
    pilasters)."""

    def length(b: Box) -> float:
        return (b.x1 - b.x0) if axis == "x" else (b.y1 - b.y0)

    def spans_rows(b: Box) -> bool:  # a giant order: across GIANT of a label's rows
        return any(sum(b.y0 < c < b.y1 for c in centres) >= GIANT for centres in rows)

    bands = [b for b in joined if length(b) >= retarget.BAND * extent or spans_rows(b)]
    if whole_labels:
        labels = {b.label for b in bands}
        return [e for e in elements if e.label not in labels]
    near = 1e-9 * extent
    return [
        e for e in elements if not any(e.label == b.label and _inside(e, b, near) for b in bands)
    ]


def _bays(
    elements: Sequence[Box],
    floors: Sequence[Box],
    source: tuple[float, float],
    width: float,
    pairs: Sequence[bool] = (False,),
    columns: Sequence[Sequence[float]] = (),
    clean: Sequence[Box] = (),
) -> list[tuple[str, list[Span], list[retarget.Plan]]]:
    """Ways to lay the façade's strata across (see :func:`retargeted`): what was done,
    the strata and a plan for each; the source stretched first. The strata are cut where
    none of ``floors`` crosses (a balcony across the façade is in one stratum), a stratum
    where none of ``elements`` crosses."""
    extent = source[0]
    strata = retarget.strata([(b.y0, b.y1) for b in floors], source[1])
    stratum_elements = [[b for b in elements if b.y0 < hi and b.y1 > lo] for lo, hi in strata]
    stratum_clean = [[b for b in clean if b.y0 < hi and b.y1 > lo] for lo, hi in strata]
    spans = [[(b.x0, b.x1) for b in here] for here in stratum_elements]
    # a unit's worth: the height of the strata it can be cut out of, less their height
    # times how far it is from a period there
    listed = [
        {
            u: irregular
            for mirrored in pairs
            for irregular, u in retarget.laid_units(here, extent, mirrored)
        }
        for here in spans
    ]
    every = [span for here in spans for span in here]
    pitched = [u for mirrored in pairs for u in _pitched(columns, extent, mirrored)]
    # where each unit is cut in each stratum (None: nowhere near)
    cuts = {
        unit: [
            _cut(here, stratum, extent, unit)
            for here, stratum in zip(stratum_elements, strata, strict=True)
        ]
        for unit in [*pitched, *(u for here in listed for u in here)]
    }
    worth = {
        unit: sum(
            (hi - lo) * (1 - min(1.0, 0.0 if unit in pitched else here.get(unit, 0.5)))
            for (lo, hi), cut, here in zip(strata, cuts[unit], listed, strict=True)
            if cut is not None
        )
        for unit in cuts
    }
    # units that hold one of the style's columns (of windows, say) first: a bay, not a
    # slab of wall with an ornament in it
    ranked = sorted(worth, key=lambda u: (not _holds_column(u, columns), -worth[u], u))[
        : retarget.UNITS_TRIED
    ]
    # a cut that crosses no piece of an element if there is one near, else one that
    # crosses only pieces of labels that make bands
    best_cuts = {
        unit: [
            _cut(whole, stratum, extent, unit) or cut
            for whole, stratum, cut in zip(stratum_clean, strata, cuts[unit], strict=True)
        ]
        for unit in ranked
    }
    # the wall that stretches is the wall of every stratum, so that the strata cut alike
    # stay lined up; strata cut alike share their plan
    plans: dict[tuple[tuple[Span, ...], int], retarget.Plan | None] = {}

    def plan_of(cut: tuple[Span, ...], copies: int) -> retarget.Plan | None:
        if (cut, copies) not in plans:
            plans[(cut, copies)] = retarget.copied(every, extent, width, cut, copies)
        return plans[(cut, copies)]

    # a stratum no unit can be cut out of
    scaled_across = retarget.scaled(extent, width, SCALED_ACROSS)
    found = []
    for unit, copies in [((), 0)] + [
        (u, c)
        for u in ranked
        for c in retarget.copies_near(sum(b - a for a, b in u), extent, width)
        if c
    ]:
        across = []
        scaled = 0.0  # the height of the strata scaled alike
        for k, (lo, hi) in enumerate(strata):
            cut = best_cuts[unit][k] if unit else ()
            plan = None if cut is None else plan_of(cut, copies)
            if plan is None:  # the stratum stretched (its own bays copied would not line up)
                plan = plan_of((), 0)
            if plan is None and unit and scaled_across is not None:
                plan = scaled_across
                scaled += hi - lo
            if plan is None or scaled > SCALED_MOST * source[1]:
                break
            across.append(plan)
        else:
            text = retarget.describe(unit, copies)
            found.append((f"x {text}" if text else "", strata, across))
    return found


def _cut(
    boxes: Sequence[Box], stratum: Span, extent: float, unit: tuple[Span, ...]
) -> tuple[Span, ...] | None:
    """Where a stratum holding ``boxes`` is cut for a unit (see
    :func:`~facadecli.grammar.retarget.shifted`): through elements only where what is cut
    at one end is cut at the other, one unit along, of the same label and height there
    (so a copy puts the halves together again); else between elements."""
    spans = tuple(sorted((b.x0, b.x1) for b in boxes))
    cut = _shifted(spans, extent, unit, True)
    if cut is None or all(_rejoined(boxes, stratum, extent, lo, hi) for lo, hi in cut):
        return cut
    return _shifted(spans, extent, unit, False)


@functools.lru_cache(maxsize=4096)
def _shifted(
    spans: tuple[Span, ...], extent: float, unit: tuple[Span, ...], through: bool
) -> tuple[Span, ...] | None:
    """:func:`~facadecli.grammar.retarget.shifted`, once for the strata with the same
    elements across (floors alike): a pure function of its arguments."""
    return retarget.shifted(spans, extent, unit, through)


def _rejoined(boxes: Sequence[Box], stratum: Span, extent: float, lo: float, hi: float) -> bool:
    """Whether each element a cut at ``lo`` crosses has one of its label and height (in the
    stratum) that a cut at ``hi`` crosses."""
    near = retarget.NEAR * extent

    def crossed(at: float) -> set[tuple[str, float, float]]:
        return {
            (b.label, round(max(b.y0, stratum[0]), 6), round(min(b.y1, stratum[1]), 6))
            for b in boxes
            if b.x0 + near < at < b.x1 - near and b.x1 - b.x0 < retarget.BAND * extent
        }

    return crossed(lo) == crossed(hi)


def _pitched(
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


def _holds_column(unit: Sequence[Span], columns: Sequence[Sequence[float]]) -> bool:
    return any(lo < c < hi for lo, hi in unit for centres in columns for c in centres)


def _halves_joined(pieces: list[Piece], near: float) -> list[Piece]:
    """The pieces, each part of an element cut at the end of a copied unit (much narrower
    than its source) joined to the part of its label and height that it touches (the two
    halves of a pilaster make one), in the order of the first."""

    def cut(p: Piece) -> bool:
        return p.label != BACKGROUND and p.x1 - p.x0 < HALF * p.source_w

    joined: dict[int, Piece] = {}
    order = sorted(range(len(pieces)), key=lambda k: (pieces[k].label, pieces[k].y0, pieces[k].x0))
    last = None
    for k in order:
        p = pieces[k]
        q = joined.get(last) if last is not None else None
        if (
            q is not None
            and q.label == p.label
            and abs(q.x1 - p.x0) <= near
            and abs(q.y0 - p.y0) <= near
            and abs(q.y1 - p.y1) <= near
            and (cut(q) or cut(p))
        ):
            joined[last] = Piece(
                q.label, q.x0, q.y0, p.x1, q.y1, max(q.source_w, p.source_w), q.source_h
            )
            continue
        joined[k] = p
        last = k
    return [joined[k] for k in sorted(joined)]


def _stacked(parts: list[Part]) -> list[Part]:
    """A piece's parts, those one above the other across the same span joined."""
    joined: list[Part] = []
    for x0, x1, y0, y1, along, up in sorted(parts):
        last = joined[-1] if joined else None
        if last is not None and (last[0], last[1]) == (x0, x1) and abs(last[3] - y0) < 1e-12:
            joined[-1] = (x0, x1, last[2], y1, along, last[5] + up)
        else:
            joined.append((x0, x1, y0, y1, along, up))
    return joined


def _moved(p: Piece, part: Part) -> Piece:
    """A part of a piece as laid; a piece of wall made of more source than itself (across
    copies of a unit) has that as its source size: the wall beside copied floors is as
    long as they are, not stretched (an element's band lengthened still counts against
    the layout's fit, which keeps strips of ornament from being copied for bays)."""
    x0, x1, y0, y1, along, up = part
    if p.label != BACKGROUND or p.x1 <= p.x0 or p.y1 <= p.y0:
        return Piece(p.label, x0, y0, x1, y1, p.source_w, p.source_h)
    lengthened_x, lengthened_y = max(1.0, along / (p.x1 - p.x0)), max(1.0, up / (p.y1 - p.y0))
    return Piece(p.label, x0, y0, x1, y1, p.source_w * lengthened_x, p.source_h * lengthened_y)
