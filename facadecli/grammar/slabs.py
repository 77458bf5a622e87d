"""A façade at a new size made of the input's own terminals, whole bays and floors copied
(retargeting by slabs, after Lin et al. 2011): the two-dimensional use of the
one-dimensional plans of :mod:`facadecli.grammar.retarget`, beside the grammar's
derivations (:mod:`facadecli.grammar.derive`); :mod:`facadecli.grammar.variations`
compares them.
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from collections.abc import Sequence

from facadecli.grammar import retarget
from facadecli.grammar.bays import bay_plans
from facadecli.grammar.floors import floor_plans, levelled, unbanded
from facadecli.grammar.model import Constraint, Piece
from facadecli.grammar.pieces import boxes_of, elements_of, score
from facadecli.grammar.style import Box, Facade, check, shared_rows
from facadecli.grammar.tiling import BACKGROUND

RETARGETS_MAX = 5  # plans up the façade tried with each plan across it (stretched first)
PIECES_MOST = 20_000  # pieces a copied layout would have at most (more: none is made)
LAID_MOST = 60_000  # pieces laid over all the copied layouts (the rest are not made)
HALF = 0.6  # of its source's width: a part of a piece this narrow was cut (see _halves_joined)
BUILDINGS_TRIED = 64  # stretches of the width looked at for a building's floors, at most
WIDER_FIRST = 2  # wider layouts given floors building by building, at most

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
    pilasters where a copy puts their halves together again,
    :func:`~facadecli.grammar.bays.unit_cut`); a stratum that cannot be cut near it (a
    ground floor of shops) is stretched instead, so the floors above keep their columns
    whatever the ground floor does (where its wall cannot take the width, it is scaled
    alike, within :mod:`~facadecli.grammar.bays`' limits: staggered elements with no
    period). Plans across: :func:`~facadecli.grammar.bays.bay_plans`; up:
    :func:`~facadecli.grammar.floors.floor_plans`.
    The units tried first hold a column of the style's (one pitch of it, centred on a
    column, is a period by construction), then those that most strata can be cut at.
    Every stratum stretches the wall that is wall in all of them, so strata cut alike
    stay lined up. ``style`` gives the columns and whether the façade is mirrored (units
    are then copied with their mirror images).

    Taller, the floors are cut where hand-drawn floors overlap by a sliver, the sliver
    trimmed (:func:`~facadecli.grammar.floors.levelled`); where no floor can be cut
    across the whole width, each building of a row of them gains its own floors
    (:func:`_by_buildings`; wider too, on the façade made wider first:
    :func:`_taller_by_buildings`)."""
    grown = max(1.0, width / source[0]) * max(1.0, height / source[1])
    if (width, height) == source or len(pieces) * grown > PIECES_MOST:
        return []
    facade = elements_of(pieces, *source)
    if height != source[1]:  # floors cut where hand-drawn floors overlap by a sliver
        trimmed = levelled(pieces, facade.boxes, source)
        if trimmed is not pieces:
            pieces, facade = trimmed, elements_of(trimmed, *source)
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
    in_bays = unbanded(elements, joined, "x", source[0])
    clean = unbanded(elements, joined, "x", source[0], whole_labels=False)
    in_floors = unbanded(elements, joined, "y", source[1])
    rows = [sorted((r[0].y0 + r[0].y1) / 2 for r in group) for group in shared if group]
    # an element across several of a label's rows (a giant order of pilasters) is a band
    # too, for copying floors (taller only: at the source's height floors are stretched)
    in_storeys = in_floors
    if height != source[1]:
        in_storeys = unbanded(elements, joined, "y", source[1], rows=rows)
    floors = floor_plans(in_storeys, source[1], height, rows)
    bays = bay_plans(in_bays, in_floors, source, width, pairs, columns, clean)
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
    (see :func:`floor_plans`, with the style's rows in it); a layout of the k-th plan of each
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
        return [plan for plan in floor_plans(here, source[1], height, rows) if plan.text]

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
