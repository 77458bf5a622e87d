"""Ways to lay a façade's strata across a new width, for copying whole bays
(:mod:`facadecli.grammar.slabs`): per stratum (a floor, or the wall between floors), a
unit cut out there or a little to one side (:func:`~facadecli.grammar.retarget.shifted`),
through elements only where a copy puts their halves together again (:func:`unit_cut`);
a stratum no unit can be cut out of is stretched, or scaled alike."""

from __future__ import annotations

import functools
from collections.abc import Sequence

from facadecli.grammar import retarget
from facadecli.grammar.floors import Span, holds_column, pitched
from facadecli.grammar.style import BAND, Box

SCALED_MOST = 0.25  # of the height: strata a unit cannot be cut out of, scaled alike instead
SCALED_ACROSS = 2.0  # ... by this at most, either way


def bay_plans(
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
    on_columns = [u for mirrored in pairs for u in pitched(columns, extent, mirrored)]
    # where each unit is cut in each stratum (None: nowhere near)
    cuts = {
        unit: [
            unit_cut(here, stratum, extent, unit)
            for here, stratum in zip(stratum_elements, strata, strict=True)
        ]
        for unit in [*on_columns, *(u for here in listed for u in here)]
    }
    worth = {
        unit: sum(
            (hi - lo) * (1 - min(1.0, 0.0 if unit in on_columns else here.get(unit, 0.5)))
            for (lo, hi), cut, here in zip(strata, cuts[unit], listed, strict=True)
            if cut is not None
        )
        for unit in cuts
    }
    # units that hold one of the style's columns (of windows, say) first: a bay, not a
    # slab of wall with an ornament in it
    ranked = sorted(worth, key=lambda u: (not holds_column(u, columns), -worth[u], u))[
        : retarget.UNITS_TRIED
    ]
    # a cut that crosses no piece of an element if there is one near, else one that
    # crosses only pieces of labels that make bands
    best_cuts = {
        unit: [
            unit_cut(whole, stratum, extent, unit) or cut
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


def unit_cut(
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
            if b.x0 + near < at < b.x1 - near and b.x1 - b.x0 < BAND * extent
        }

    return crossed(lo) == crossed(hi)
