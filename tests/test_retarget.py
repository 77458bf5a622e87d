"""Retargeting by slabs (:mod:`facadecli.grammar.retarget`): whole bays copied or left out
along one axis, the wall taking up the rest."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from facadecli.grammar import floors, retarget, slabs
from facadecli.grammar.model import Piece
from facadecli.grammar.pieces import elements_of, likeness
from facadecli.grammar.slabs import retargeted
from facadecli.grammar.style import BAND, Box, facade_of, find_style
from facadecli.grammar.tiling import BACKGROUND

ROW = [(1.0, 2.0), (3.0, 4.0), (5.0, 6.0)]  # three windows 1 m wide, 1 m apart, in 7 m


def _length(plan: retarget.Plan) -> float:
    return sum((s.hi - s.lo) * s.scale for s in plan.segments)


def test_a_copied_unit_lays_its_elements_twice_and_lengthens_a_band_across_it() -> None:
    plan = retarget.copied(ROW, 7.0, 9.0, [(2.5, 4.5)], 1)
    assert plan is not None
    assert plan.stretch == pytest.approx(0.0)  # the copy fills the new length exactly
    assert retarget.place(plan, 3.0, 4.0) == [(3.0, 4.0), (5.0, 6.0)]
    assert retarget.place(plan, 5.0, 6.0) == [(7.0, 8.0)]
    assert retarget.place(plan, 0.0, 7.0) == [(0.0, 9.0)]  # a band: one, longer


def test_an_element_across_bays_is_a_band_that_a_cut_may_cross() -> None:
    """cmp_b0003's attic molding runs 44% of the width, over one building and half the
    next: at 40% of the width or longer an element is a band (as the style counts it),
    so a unit may be cut through it and the copy lengthens it; the attic then gains the
    bays the floors gain instead of being scaled."""
    spans = [(1.0, 2.0), (3.0, 4.0), (5.0, 6.0), (2.2, 8.8)]  # the last: 6.6 of 15
    assert retarget.cuttable(spans, 15.0, 2.5, 4.5)  # through the molding at both ends
    plan = retarget.copied(spans, 15.0, 17.0, [(2.5, 4.5)], 1)
    assert plan is not None
    assert retarget.place(plan, 2.2, 8.8) == [(2.2, 10.8)]  # one, 2 m longer
    assert retarget.place(plan, 3.0, 4.0) == [(3.0, 4.0), (5.0, 6.0)]


def test_a_unit_left_out_takes_its_elements_with_it() -> None:
    plan = retarget.copied(ROW, 7.0, 5.0, [(2.5, 4.5)], -1)
    assert plan is not None
    assert retarget.place(plan, 3.0, 4.0) == []
    assert retarget.place(plan, 5.0, 6.0) == [(3.0, 4.0)]


def test_the_gaps_take_up_the_rest_and_elements_keep_their_size() -> None:
    plan = retarget.copied(ROW, 7.0, 10.0, [(2.5, 4.5)], 1)
    assert plan is not None and _length(plan) == pytest.approx(10.0)
    laid = [retarget.place(plan, lo, hi) for lo, hi in ROW]
    assert all(b - a == pytest.approx(1.0) for spans in laid for a, b in spans)


def test_a_unit_is_cut_through_pilasters_that_a_copy_puts_together_again() -> None:
    # pilasters 1 m wide every 3 m, windows between them, no wall between: 9 m
    row = [(0.0, 1.0), (1.0, 2.0), (2.0, 4.0), (4.0, 5.0), (5.0, 7.0), (7.0, 8.0), (8.0, 9.0)]
    row = [(lo, hi) for lo, hi in row if (lo, hi) not in ((2.0, 4.0), (5.0, 7.0))]
    row += [(1.8, 4.2), (4.8, 7.2)]  # windows overlapping the pilasters: no cut between
    assert retarget.cuttable(row, 9.0, 1.5, 4.5)  # each end halves a pilaster
    assert not retarget.cuttable(row, 9.0, 1.5, 4.6)  # not one unit along
    assert not retarget.cuttable(row, 9.0, 1.9, 4.5)  # a window at one end only
    assert retarget.shifted(row, 9.0, [(1.4, 4.4)]) == ((1.4, 4.4),)  # a period: as it is
    assert retarget.shifted(row, 9.0, [(1.4, 4.4)], through=False) is None  # no wall
    plan = retarget.copied(row, 9.0, 12.0, [(1.5, 4.5)], 1)
    assert plan is not None
    halves = retarget.place(plan, 4.0, 5.0)[:1] + retarget.place(plan, 1.0, 2.0)[1:]
    assert halves == [(4.0, 4.5), (4.5, 5.0)]  # one pilaster between the bay and its copy


def test_a_scaled_plan_lays_everything_alike() -> None:
    plan = retarget.scaled(7.0, 8.4)
    assert plan is not None
    assert plan.text == "scaled" and _length(plan) == pytest.approx(8.4)
    assert retarget.place(plan, 1.0, 2.0) == [(pytest.approx(1.2), pytest.approx(2.4))]


def test_gaps_stretched_too_far_or_elements_widened_make_no_plan() -> None:
    assert retarget.copied(ROW, 7.0, 14.0, [], 0) is None  # the wall alone: 4 m -> 11 m
    assert retarget.copied(ROW, 7.0, 7.5, [], 0) is not None


def test_the_units_nearest_a_period_come_first() -> None:
    irregular, lo, hi = retarget.units(ROW, 7.0)[0]
    assert irregular == pytest.approx(0.0)
    assert hi - lo == pytest.approx(2.0)  # a window and a gap: the row's period


def test_a_mirrored_facade_copies_a_unit_and_its_mirror_image_together() -> None:
    row = [(1.0, 2.0), (3.0, 4.0), (5.0, 6.0), (7.0, 8.0), (9.0, 10.0)]  # 11 m, symmetric
    for _, unit in retarget.laid_units(row, 11.0, mirrored=True):
        centred = len(unit) == 1 and unit[0][0] + unit[0][1] == pytest.approx(11.0)
        mirrored = len(unit) == 2 and unit[0][0] + unit[1][1] == pytest.approx(11.0)
        assert centred or mirrored
    for plan in retarget.plans(row, 11.0, 15.0, mirrored=True):
        assert _length(plan) == pytest.approx(15.0)
        centres = sorted((a + b) / 2 for lo, hi in row for a, b in retarget.place(plan, lo, hi))
        assert centres == pytest.approx([15.0 - c for c in reversed(centres)])


def test_strata_are_the_floors_and_the_wall_between_them() -> None:
    floors = [(1.0, 2.5), (3.5, 5.0), (1.2, 2.0)]
    assert retarget.strata(floors, 6.0) == [
        (0.0, 1.0),
        (1.0, 2.5),
        (2.5, 3.5),
        (3.5, 5.0),
        (5.0, 6.0),
    ]


def test_a_unit_that_a_stratum_cannot_be_cut_at_moves_by_the_least_distance() -> None:
    with_ornament = [*ROW, (4.3, 4.7)]  # an ornament where the unit 2.5-4.5 ends
    assert retarget.shifted(ROW, 7.0, [(2.5, 4.5)]) == ((2.5, 4.5),)
    assert retarget.shifted(with_ornament, 7.0, [(2.5, 4.5)]) == ((2.3, 4.3),)
    chained = [(0.5, 3.0), (2.9, 5.5)]  # one block 5 m wide: no cut near the unit
    assert retarget.shifted(chained, 7.0, [(2.5, 4.5)]) is None


def test_what_a_plan_does_is_said_for_people() -> None:
    assert retarget.describe([(2.5, 4.5)], 2) == "copied 2x: 2.5-4.5"
    assert retarget.describe([(9.0, 11.0), (1.0, 3.0)], -1) == "left out: 1-3 and 9-11"
    assert retarget.describe([(2.5, 4.5)], 0) == ""


@st.composite
def _rows(draw: st.DrawFn) -> tuple[list[tuple[float, float]], float]:
    """Elements along one axis: widths and gaps drawn, in whole centimetres."""
    at, spans = draw(st.integers(0, 300)) / 100, []
    for _ in range(draw(st.integers(1, 8))):
        width = draw(st.integers(20, 300)) / 100
        spans.append((at, at + width))
        at += width + draw(st.integers(0, 300)) / 100
    return spans, at + draw(st.integers(0, 300)) / 100


@settings(max_examples=150, deadline=None)
@given(_rows(), st.floats(0.5, 3.0), st.booleans())
def test_every_plan_fills_the_new_extent_and_keeps_elements_whole(
    row: tuple[list[tuple[float, float]], float], factor: float, mirrored: bool
) -> None:
    """Whatever the elements and the new extent: a plan lays the source end to end over
    exactly the new extent, every element but a band is laid whole (or cut in two at the
    ends of a copied unit and put together again there) and at most ``WIDEN_MOST`` longer
    or ``SQUEEZE_MOST`` shorter, and a copied element never overlaps another."""
    spans, extent = row
    new = extent * factor
    least, most = 1 / retarget.SQUEEZE_MOST, retarget.WIDEN_MOST
    for plan in retarget.plans(spans, extent, new, mirrored):
        assert _length(plan) == pytest.approx(new)
        laid = sorted(part for lo, hi in spans for part in retarget.place(plan, lo, hi))
        assert all(0.0 <= a < b <= new + 1e-9 for a, b in laid)
        for (_, end), (start, _) in itertools.pairwise(laid):
            assert start >= end - 1e-9
        parts = sorted(  # a band may be lengthened
            (a, b, hi - lo)
            for lo, hi in spans
            if hi - lo < BAND * extent
            for a, b in retarget.place(plan, lo, hi)
        )
        off = retarget.ALIKE_PART  # two parts of cut elements, one unit along, nearly

        def fits(a: float, b: float, length: float, slack: float = 0.0) -> bool:
            ratio = (b - a) / length
            return least * (1 - slack) - 1e-9 <= ratio <= most * (1 + slack) + 1e-9

        for a, b, length in parts:  # whole, or cut and put together with another part
            assert fits(a, b, length) or any(
                fits(min(a, c), max(b, d), length, off)
                for c, d, _ in parts
                if abs(c - b) < 1e-9 or abs(d - a) < 1e-9
            )


@st.composite
def _grids(draw: st.DrawFn) -> tuple[list[Piece], tuple[float, float]]:
    """A façade tiled by a grid of cells, whole metres or halves, each wall or an element
    (a run of cells of one label in a row or a column makes a longer element)."""
    widths = draw(st.lists(st.integers(1, 6), min_size=2, max_size=9))
    heights = draw(st.lists(st.integers(1, 6), min_size=2, max_size=6))
    labels = st.sampled_from([BACKGROUND, BACKGROUND, "window", "pillar", "ledge"])
    xs = list(itertools.accumulate([0.0, *(w / 2 for w in widths)]))
    ys = list(itertools.accumulate([0.0, *(h / 2 for h in heights)]))
    pieces = [
        Piece(draw(labels), x0, y0, x1, y1, x1 - x0, y1 - y0)
        for x0, x1 in itertools.pairwise(xs)
        for y0, y1 in itertools.pairwise(ys)
    ]
    return pieces, (xs[-1], ys[-1])


@settings(max_examples=60, deadline=None)
@given(_grids(), st.sampled_from([(0.7, 1.0), (1.5, 1.0), (2.0, 1.0), (1.0, 1.5), (1.6, 1.4)]))
def test_every_facade_laid_out_anew_tiles_its_new_size(
    grid: tuple[list[Piece], tuple[float, float]], factors: tuple[float, float]
) -> None:
    """Whatever the façade and the new size, every layout made by copying bays and floors
    (and halves of elements put together again) tiles the new façade: its pieces lie on
    it, overlap nowhere and cover it."""
    pieces, source = grid
    width, height = source[0] * factors[0], source[1] * factors[1]
    boxes = [Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in pieces]
    style = find_style(facade_of(boxes, *source, BACKGROUND))
    for moved, _, text in retargeted(pieces, source, width, height, style):
        area = 0.0
        for p in moved:
            assert -1e-9 <= p.x0 < p.x1 <= width + 1e-9 and -1e-9 <= p.y0 < p.y1 <= height + 1e-9
            area += (p.x1 - p.x0) * (p.y1 - p.y0)
        assert area == pytest.approx(width * height), text
        cells = sorted(moved, key=lambda p: (p.x0, p.y0))
        for a, b in itertools.combinations(cells, 2):
            overlap_x = min(a.x1, b.x1) - max(a.x0, b.x0)
            overlap_y = min(a.y1, b.y1) - max(a.y0, b.y0)
            assert overlap_x <= 1e-9 or overlap_y <= 1e-9, text


def test_no_facade_is_laid_out_anew_many_times_its_size() -> None:
    """A work budget: a layout of more than ``PIECES_MOST`` pieces is not made (a façade
    many times its source's size is the grammar's alone)."""
    pieces = [
        Piece("window" if (i + j) % 2 else BACKGROUND, i, j, i + 1.0, j + 1.0, 1.0, 1.0)
        for i in range(5)
        for j in range(4)
    ]
    style = find_style(
        facade_of([Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in pieces], 5, 4, BACKGROUND)
    )
    assert retargeted(pieces, (5.0, 4.0), 10.0, 4.0, style)
    grown = slabs.PIECES_MOST / len(pieces) + 1  # times the area
    assert retargeted(pieces, (5.0, 4.0), 5.0 * grown, 4.0, style) == []


def test_a_level_is_where_hand_drawn_floors_overlap_by_a_sliver() -> None:
    """cmp_b0010's cornice runs 10 cm into the next floor's molding, so every cut across
    the façade crosses something; a cut that only trims slivers (at most ``SLIVER`` of the
    extent and ``SLIVER_PART`` of the element: 8 cm here) is a level, the one that trims
    least."""
    cornice_in_two = [(1.0, 2.88), (2.8, 3.3), (2.8, 3.3), (3.3, 5.2)]
    assert retarget.levels(cornice_in_two, 10.0) == [pytest.approx(2.8)]  # the window trimmed
    assert retarget.levels([(1.0, 2.9), (2.6, 3.3)], 10.0) == []  # 30 cm: no sliver
    assert retarget.levels([(1.0, 2.8), (2.8, 3.3)], 10.0) == []  # cut there already


def _floor(x0: float, x1: float, y: float, ledge: float, window: float) -> list[Piece]:
    """A floor of one bay: a ledge across it, then a window between wall, up to ``window``."""
    pieces = [Piece("ledge", x0, y, x1, y + ledge, x1 - x0, ledge)]
    top, middle = y + ledge, (x0 + x1) / 2
    for a, b, label in (
        (x0, middle - 0.8, BACKGROUND),
        (middle - 0.8, middle + 0.8, "window"),
        (middle + 0.8, x1, BACKGROUND),
    ):
        pieces.append(Piece(label, a, top, b, window, b - a, window - top))
    return pieces


def _two_buildings() -> list[Piece]:
    """Two buildings side by side, 8 x 11 m: floors 2.5 m apart on the left, 3 m on the
    right, each floor a ledge and a window up to the next (no floor can be cut across
    both, nor through one where the other's windows would come apart)."""
    pieces = [
        Piece(BACKGROUND, 0.0, 0.0, 4.0, 2.5, 4.0, 2.5),
        Piece(BACKGROUND, 4.0, 0.0, 8.0, 2.0, 4.0, 2.0),
    ]
    for y in (2.5, 5.0, 7.5):
        pieces += _floor(0.0, 4.0, y, 0.3, y + 2.5)
    pieces.append(Piece(BACKGROUND, 0.0, 10.0, 4.0, 11.0, 4.0, 1.0))
    for y in (2.0, 5.0, 8.0):
        pieces += _floor(4.0, 8.0, y, 0.3, y + 3.0)
    return pieces


def test_a_row_of_buildings_whose_floors_differ_gains_floors_building_by_building() -> None:
    """cmp_b0003 is three buildings whose floors are at different heights: taller, each
    copies its own middle floor (the ends of a label's rows are a ground floor or an
    attic), and the two stay side by side."""
    pieces = _two_buildings()
    boxes = [Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in pieces]
    style = find_style(facade_of(boxes, 8.0, 11.0, BACKGROUND))
    laid = retargeted(pieces, (8.0, 11.0), 8.0, 16.5, style)
    by_buildings = [(moved, text) for moved, _, text in laid if text.startswith("by buildings")]
    assert by_buildings, [text for _, _, text in laid]
    moved, text = by_buildings[0]
    windows = [p for p in moved if p.label == "window"]
    assert sum(p.x1 <= 4.0 for p in windows) == 5 and sum(p.x0 >= 4.0 for p in windows) == 5, text
    for p in windows:  # copies, not taller windows, fill the height
        own = 2.2 if p.x1 <= 4.0 else 2.7
        assert own / retarget.WIDEN_MOST <= p.y1 - p.y0 <= own * retarget.WIDEN_MOST, text
    assert not any(text.startswith("y ") for _, _, text in laid)  # none across both
    # wider too: bays copied across first, then the floors building by building
    both = [text for _, _, text in retargeted(pieces, (8.0, 11.0), 12.0, 16.5, style)]
    assert any(
        "copied" in text.split("; by buildings")[0] for text in both if "; by buildings" in text
    ), both


def test_what_goes_on_a_sliver_past_a_level_is_trimmed_and_made_wall() -> None:
    """The window on the left runs 8 cm past the floor the cornice on the right starts: it
    is trimmed to that level and the 8 cm become wall, so the façade stays tiled."""
    pieces = [
        Piece("window", 0.0, 0.0, 1.0, 2.08, 1.0, 2.08),
        Piece("cornice", 0.0, 2.08, 1.0, 2.5, 1.0, 0.42),
        Piece("window", 1.0, 0.0, 2.0, 2.0, 1.0, 2.0),
        Piece("cornice", 1.0, 2.0, 2.0, 2.5, 1.0, 0.5),
        Piece(BACKGROUND, 0.0, 2.5, 2.0, 10.0, 2.0, 7.5),
    ]
    joined = elements_of(pieces, 2.0, 10.0).boxes  # the same at either height
    levelled = floors.levelled(pieces, joined, (2.0, 10.0))
    assert Piece("window", 0.0, 0.0, 1.0, 2.0, 1.0, 2.08) in levelled
    assert Piece(BACKGROUND, 0.0, 2.0, 1.0, 2.08, 1.0, pytest.approx(0.08)) in levelled
    assert sum((p.x1 - p.x0) * (p.y1 - p.y0) for p in levelled) == pytest.approx(20.0)
    assert floors.levelled(pieces, joined, (2.0, 2.5)) == pieces  # 8 cm is no sliver of 2.5 m


def test_a_band_laid_across_copies_of_a_unit_is_made_of_that_much_source() -> None:
    plan = retarget.copied(ROW, 7.0, 9.0, [(2.5, 4.5)], 1)
    assert plan is not None
    assert retarget.laid(plan, 0.0, 7.0) == [(0.0, 9.0, pytest.approx(9.0))]
    assert retarget.laid(plan, 3.0, 4.0) == [(3.0, 4.0, 1.0), (5.0, 6.0, 1.0)]


def test_the_wall_beside_copied_floors_is_as_long_as_they_are_not_stretched() -> None:
    """cmp_b0008 at twice the height: the wall beside its frame runs up across the copied
    floors; laid one floor taller by copying one, nothing is stretched, so the layout is
    as near the input's sizes as can be (the wall once counted as stretched, and the
    grammar's layout, with blank wall, was taken instead)."""
    pieces = [Piece(BACKGROUND, 0.0, 0.0, 1.0, 9.0, 1.0, 9.0)]
    for y in (0.0, 3.0, 6.0):
        pieces += _floor(1.0, 3.0, y, 0.3, y + 3.0) + _floor(3.0, 5.0, y, 0.3, y + 3.0)
    boxes = [Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in pieces]
    style = find_style(facade_of(boxes, 5.0, 9.0, BACKGROUND))
    laid = {text: moved for moved, _, text in retargeted(pieces, (5.0, 9.0), 5.0, 12.0, style)}
    assert "y copied 1x: 3-6" in laid, list(laid)
    moved = laid["y copied 1x: 3-6"]
    assert [p.y1 - p.y0 for p in moved if p.x1 <= 1.0] == [pytest.approx(12.0)]
    assert likeness(moved) == pytest.approx(0.0, abs=1e-12)


def _tiled(
    rects: list[tuple[str, float, float, float, float]], size: tuple[float, float]
) -> list[Piece]:
    """The façade cut at every edge of ``rects`` into cells, each of the label of the rect
    it lies in (the wall elsewhere)."""
    xs = sorted({0.0, size[0], *(v for _, x0, _, x1, _ in rects for v in (x0, x1))})
    ys = sorted({0.0, size[1], *(v for _, _, y0, _, y1 in rects for v in (y0, y1))})
    return [
        Piece(
            next(
                (
                    label
                    for label, a, b, c, d in rects
                    if a <= x0 and x1 <= c and b <= y0 and y1 <= d
                ),
                BACKGROUND,
            ),
            x0,
            y0,
            x1,
            y1,
            x1 - x0,
            y1 - y0,
        )
        for x0, x1 in itertools.pairwise(xs)
        for y0, y1 in itertools.pairwise(ys)
    ]


def test_a_giant_order_of_pilasters_is_a_band_that_floors_are_copied_across() -> None:
    """cmp_b0009's pilasters run up four floors of windows, 39% of the height (under the
    40% of a band): across three rows of a label or more they are a band for copying
    floors, which lengthens them, so a taller façade gains floors between them."""
    rects = [("door", 2.5, 0.0, 3.5, 2.5)]
    rects += [("pillar", x, 4.0, x + 0.2, 9.8) for x in (1.9, 3.9)]
    rects += [
        ("window", x, 4.2 + 1.4 * k, x + 1.0, 5.2 + 1.4 * k)
        for x in (0.5, 2.5, 4.5)
        for k in range(4)
    ]
    pieces = _tiled(rects, (6.0, 15.0))
    boxes = [Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in pieces]
    style = find_style(facade_of(boxes, 6.0, 15.0, BACKGROUND))
    laid = {text: moved for moved, _, text in retargeted(pieces, (6.0, 15.0), 6.0, 21.0, style)}
    floors = [text for text in laid if text.startswith("y copied")]
    assert floors, list(laid)
    moved = laid[floors[0]]
    windows = [p for p in moved if p.label == "window"]
    assert len(windows) > 12 and all(p.y1 - p.y0 <= 1.0 * retarget.WIDEN_MOST for p in windows)
    pillars = facade_of(
        [Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in moved if p.label == "pillar"],
        6.0,
        21.0,
        BACKGROUND,
    ).boxes
    assert len(pillars) == 2 and all(b.y1 - b.y0 > 5.8 for b in pillars)  # whole, longer
