"""``facade grammar --derive WxH --variations N --seed S``: several layouts per size, drawn
by varying repeat counts (Bao et al. 2013)."""

from __future__ import annotations

import itertools
import random
import warnings
from pathlib import Path

import pytest

from facadecli import load_spec
from facadecli.export.report import report_text
from facadecli.grammar import floors
from facadecli.grammar.align import KEPT_LEAST, align
from facadecli.grammar.derive import _run_of, derive_at
from facadecli.grammar.extract import extract_grammar
from facadecli.grammar.model import Extraction, Kept, Options, Piece, Variation
from facadecli.grammar.pieces import apart, displacement, likeness, pieces_key
from facadecli.grammar.slabs import retargeted
from facadecli.grammar.split import Part
from facadecli.grammar.style import Box as StyleBox
from facadecli.grammar.style import check, facade_of
from facadecli.grammar.tiling import LabelledLayout, Rect
from facadecli.grammar.variations import APART, derive_layout, derive_variations
from facadecli.grammar.vary import proportioned_copies
from facadecli.layout import Layout
from facadecli.solve import solve
from tests.benchmarks.annotated_family import cmp_xml, family
from tests.test_grammar import _facade, _floors, _write_plain

Box = tuple[str, float, float, float, float]
ROOT = Path(__file__).resolve().parent.parent


def _symmetric() -> LabelledLayout:
    """Three floors of a wide window at each end and three narrow ones each side of a
    door in the middle, mirrored about x = 10."""
    rects = [Rect("door", 9.25, 0.0, 10.75, 2.5, 1)]
    for j in range(3):
        y = 1.0 + 3 * j
        rects += [
            Rect("window", 0.5, y, 2.5, y + 1.5, 1),
            Rect("window", 17.5, y, 19.5, y + 1.5, 1),
        ]
        for x in (3.5, 5.5, 7.5):
            rects += [Rect("window", x, y, x + 1, y + 1.5, 1)]
            rects += [Rect("window", 20 - x - 1, y, 20 - x, y + 1.5, 1)]
    return LabelledLayout(20.0, 10.0, tuple(rects))


def _extract(tmp_path: Path, layout: LabelledLayout, *extensions: str) -> Extraction:
    source = tmp_path / "facade.json"
    _write_plain(source, layout)
    return extract_grammar(source, Options(iterations=50, extensions=extensions))


def _boxes(layout: Layout) -> list[Box]:
    labels = {name: symbol.label for name, symbol in layout.spec.symbols.items()}
    return sorted(
        (str(labels[s.x]), *(round(float(v), 6) for v in (s.x0, s.y0, s.x1, s.y1)))
        for s in layout.shapes
    )


def _draw(
    extraction: Extraction, size: tuple[float, float], count: int, seed: int = 0
) -> list[Variation]:
    variations, _ = derive_variations(
        extraction.grammar, extraction.tiling, *size, "facade", count, seed, extraction.style
    )
    return variations


def test_n_variations_are_distinct_and_the_first_is_the_single_derivation(
    tmp_path: Path,
) -> None:
    extraction = _extract(tmp_path, _floors(6, 4))
    variations = _draw(extraction, (16.0, 17.0), 3)
    assert len(variations) == 3
    boxes = [_boxes(v.layout) for v in variations]
    assert all(a != b for a, b in itertools.combinations(boxes, 2))
    single = derive_layout(extraction.grammar, extraction.tiling, 16.0, 17.0, "facade")
    assert variations[0].offsets == ()
    assert variations[0].layout.shapes == single.shapes
    assert [v.layout.spec.name for v in variations] == [f"facade-16x17-v{k}" for k in range(3)]
    (one,) = _draw(extraction, (16.0, 17.0), 1)
    assert one.layout == single  # N = 1 is today's derivation, name and all
    assert [v.score for v in variations[1:]] == sorted(v.score for v in variations[1:])


def test_fewer_variations_than_asked_come_with_a_warning(tmp_path: Path) -> None:
    """A window 1 m square in the middle of a 3 x 3 m façade: every part is 1 m long, so
    drawn proportions scale them all alike, which the façade's size takes back; nothing
    repeats and nothing can change places: one layout exists."""
    rects = (Rect("window", 1.0, 1.0, 2.0, 2.0, 1),)
    extraction = _extract(tmp_path, LabelledLayout(3.0, 3.0, rects))
    variations, notes = derive_variations(
        extraction.grammar, extraction.tiling, 4.5, 3.0, "facade", 4, 0
    )
    assert len(variations) == 1
    assert notes and "only 1 of 4 variations" in notes[0]
    assert derive_variations(extraction.grammar, extraction.tiling, 4.5, 3.0, "f", 1, 0)[1] == []


def test_drawn_proportions_give_variations_that_differ_visibly_and_keep_the_style(
    tmp_path: Path,
) -> None:
    """Bao et al. 2013 draw each region's size near its size in the input: with repeat
    counts and shuffles alone, six floors of four windows gave 9 of 64 layouts at
    16 x 17 m; drawn proportions give many more, but most of them a few millimetres from
    another. Each variation given is a mean ``APART`` of the façade's smaller side or more
    from every other (its elements' edges, to the nearest of their label), and keeps every
    constraint of the input's style (one factor for parts of one size: the windows stay in
    columns); the rest are said to be missing."""
    extraction = _extract(tmp_path, _floors(6, 4))
    assert extraction.style
    variations, notes = derive_variations(
        extraction.grammar, extraction.tiling, 16.0, 17.0, "facade", 64, 0, extraction.style
    )
    assert 6 <= len(variations) < 64 and "variations exist" in notes[0]
    for a, b in itertools.combinations(variations, 2):
        assert apart(a.pieces, b.pieces, APART * 16.0)
    assert any(v.proportions for v in variations) and not variations[0].proportions
    assert all(not v.kept.broken for v in variations)


def test_displacement_is_how_far_elements_moved_and_counts_those_added() -> None:
    def piece(label: str, x0: float, y0: float, x1: float, y1: float) -> Piece:
        return Piece(label, x0, y0, x1, y1, x1 - x0, y1 - y0)

    one = [piece("window", 1.0, 1.0, 2.0, 2.0), piece("facade", 0.0, 0.0, 10.0, 10.0)]
    assert displacement(one, one) == 0.0
    moved = [piece("window", 1.005, 1.0, 2.005, 2.0)]  # 5 mm: not visibly different
    assert displacement(one, moved) == pytest.approx(0.005)
    assert displacement(one, moved) < APART * 10.0
    more = [*one, piece("window", 5.0, 1.0, 6.0, 2.0)]  # a bay gained, 4 m on
    assert displacement(one, more) == pytest.approx(4.0 / 2)  # the wall is no element
    assert displacement(one, [*one, piece("door", 4.0, 0.0, 5.0, 2.0)]) == pytest.approx(1.0)
    assert not apart(one, moved, APART * 10.0) and apart(one, more, APART * 10.0)


def test_variations_are_deterministic_per_seed_and_seeds_differ(tmp_path: Path) -> None:
    extraction = _extract(tmp_path, _floors(6, 4))

    def drawn(seed: int) -> list[list[Box]]:
        return [_boxes(v.layout) for v in _draw(extraction, (16.0, 17.0), 3, seed)]

    first = drawn(1)
    assert drawn(1) == first
    seeds = [first if seed == 1 else drawn(seed) for seed in range(6)]  # each drawn once
    assert len({str(boxes) for boxes in seeds}) > 1
    assert all(boxes[0] == seeds[0][0] for boxes in seeds[:3])  # the best fit is fixed


def test_symmetric_input_stays_symmetric_in_every_variation(tmp_path: Path) -> None:
    extraction = _extract(tmp_path, _symmetric(), "symsplit")
    assert any(rule.op == "symsplit" for rule in extraction.grammar.rules.values())
    width = 26.0
    variations = _draw(extraction, (width, 14.0), 5)
    assert len(variations) >= 2
    for variation in variations:
        boxes = _boxes(variation.layout)
        mirrored = sorted(
            (b[0], round(width - b[3], 6), b[2], round(width - b[1], 6), b[4]) for b in boxes
        )
        assert [b[0] for b in boxes] == [m[0] for m in mirrored]
        for b, m in zip(boxes, mirrored, strict=True):
            assert b[1:] == pytest.approx(m[1:], abs=1e-4)


@pytest.mark.parametrize(
    ("layout", "size", "extensions"),
    [
        (_floors(6, 4), (16.0, 17.0), ()),
        (_floors(3, 3), (11.0, 14.0), ()),
        (_symmetric(), (26.0, 14.0), ("symsplit",)),
        (_symmetric(), (15.0, 8.0), ("symsplit", "repeatABA")),
    ],
)
def test_every_variation_tiles_the_canvas_with_the_grammars_labels(
    tmp_path: Path, layout: LabelledLayout, size: tuple[float, float], extensions: tuple[str, ...]
) -> None:
    extraction = _extract(tmp_path, layout, *extensions)
    width, height = size
    for variation in _draw(extraction, size, 6):
        boxes = _boxes(variation.layout)
        assert {b[0] for b in boxes} <= extraction.grammar.terminals
        assert all(0 <= b[1] < b[3] <= width and 0 <= b[2] < b[4] <= height for b in boxes)
        area = sum((b[3] - b[1]) * (b[4] - b[2]) for b in boxes)
        assert area == pytest.approx(width * height, rel=1e-6)
        for a, b in itertools.combinations(boxes, 2):  # no overlaps: together, exactly once
            overlap_w = min(a[3], b[3]) - max(a[1], b[1])
            overlap_h = min(a[4], b[4]) - max(a[2], b[2])
            assert overlap_w <= 1e-5 or overlap_h <= 1e-5


def test_the_command_writes_each_variation_and_a_contact_sheet(tmp_path: Path) -> None:
    source = tmp_path / "floors.json"
    _write_plain(source, _floors(6, 4))
    # --seed seeds the grammar's search too: today's run takes the same one
    base = (
        "grammar",
        str(source),
        "-n",
        "50",
        "--seed",
        "4",
        "--derive",
        "16x17",
        "-f",
        "svg,json",
    )
    today, single, many = tmp_path / "today", tmp_path / "single", tmp_path / "many"
    assert _facade(*base, "-o", str(today)).returncode == 0
    assert _facade(*base, "-o", str(single), "--variations", "1").returncode == 0
    read = {p.name: p.read_bytes() for p in today.iterdir()}
    assert {p.name: p.read_bytes() for p in single.iterdir()} == read  # N = 1 is today's
    assert "floors.variations.svg" not in read
    args = (*base, "-o", str(many), "--variations", "3", "--derive", "8x7")
    result = _facade(*args)
    assert result.returncode == 0, result.stderr
    names = {p.name for p in many.iterdir()}
    assert {f"floors-16x17-v{k}.svg" for k in range(3)} <= names
    assert "floors-16x17.svg" not in names and "floors.variations.svg" in names
    for suffix in (".svg", ".layout.json"):  # variation 0 is today's, but for its name
        v0 = (many / f"floors-16x17-v0{suffix}").read_text().replace("16x17-v0", "16x17")
        assert v0 == (today / f"floors-16x17{suffix}").read_text()
    sheet = (many / "floors.variations.svg").read_text()
    assert sheet.count("<svg x=") == len([n for n in names if n.endswith(".svg") and "-v" in n])
    assert "seed 4, #2" in sheet
    first = {p.name: p.read_bytes() for p in many.iterdir()}
    assert _facade(*args).returncode == 0
    assert {p.name: p.read_bytes() for p in many.iterdir()} == first  # same seed, same bytes
    if "8x7-v1.svg" not in " ".join(names):
        assert "only" in result.stderr and "8x7" in result.stderr


def test_a_wider_facade_without_repeats_does_not_widen_its_windows(
    tmp_path: Path,
) -> None:
    """Windows on three unevenly spaced columns and a door: nothing repeats along x, so
    the grammar shares a wider façade among all parts (windows 1.2 m became 1.8 m at 1.5x
    and 2.4 m at 2x). The tidying QP pulls them back, the wall taking the rest; copying a
    window bay fills the width with bays instead of blank wall. Either way no window nor
    the door grows by more than 5%, and the style holds."""
    rects = [Rect("window", x, y, x + 1.2, y + 1.5, 1) for x in (1.0, 4.1, 8.3) for y in (1.0, 4.0)]
    rects.append(Rect("door", 5.9, 0.0, 7.0, 2.2, 1))
    extraction = _extract(tmp_path, LabelledLayout(11.0, 7.0, tuple(rects)))
    assert not any(rule.op == "repeat" for rule in extraction.grammar.rules.values())
    for width in (16.5, 22.0):
        (variation,) = _draw(extraction, (width, 7.0), 1)
        boxes = _boxes(variation.layout)
        windows = [b[3] - b[1] for b in boxes if b[0] == "window"]
        doors = [b[3] - b[1] for b in boxes if b[0] == "door"]
        assert len(windows) > 6 and len(windows) % 2 == 0  # bays gained, both floors alike
        assert all(w <= 1.05 * 1.2 for w in windows)
        assert len(doors) == 1 and doors[0] <= 1.05 * 1.1
        assert not variation.kept.broken


def test_each_variation_carries_its_terminals_with_their_sizes_in_the_source(
    tmp_path: Path,
) -> None:
    """The pieces of a variation are its layout's rectangles (the background aside), each
    with the size its part has in the source grammar: at the source's own size a window
    is as wide as its source piece; a façade twice as wide has windows no wider than that
    where the grammar repeats them (the bench counts those that grew)."""
    extraction = _extract(tmp_path, _floors(6, 4))
    source = (extraction.tiling.xs[-1], extraction.tiling.ys[-1])
    for width in (source[0], 2 * source[0]):
        for variation in _draw(extraction, (width, source[1]), 2):
            drawn = sorted(
                (p.label, *(round(v, 6) for v in (p.x0, p.y0, p.x1, p.y1)))
                for p in variation.pieces
                if p.label != "facade"
            )
            assert drawn == [b for b in _boxes(variation.layout) if b[0] != "facade"]
            windows = [p for p in variation.pieces if p.label == "window"]
            assert windows
            assert all(p.x1 - p.x0 <= 1.15 * p.source_w for p in windows)


def _bays_drawn_apart() -> LabelledLayout:
    """Three floors of three window bays, the middle bay's window with a sill the others
    lack (drawn a little differently, as a hand annotation is): no rule repeats the bays."""
    rects = []
    for j in range(3):
        y = 0.5 + 3 * j
        for i in range(3):
            x = 1.0 + 2 * i
            rects.append(Rect("window", x, y + 0.2, x + 1, y + 1.7, 1))
            if i == 1:
                rects.append(Rect("sill", x, y, x + 1, y + 0.2, 1))
    return LabelledLayout(7.0, 9.5, tuple(rects))


def test_bays_alike_but_not_identical_are_laid_more_often_on_a_wider_facade(
    tmp_path: Path,
) -> None:
    """Bays of one size holding the same kinds of element, between equal gaps, make a run:
    twice as wide, the façade gets more of them, not wider windows; its own size and a
    narrower one keep the source's bays."""
    extraction = _extract(tmp_path, _bays_drawn_apart())
    rules = extraction.grammar.rules.values()
    assert not any(r.op in ("repeat", "repeatABA") for r in rules if r.axis == "x")

    def windows(width: float) -> list[Piece]:
        (variation,) = _draw(extraction, (width, 9.5), 1)
        return [p for p in variation.pieces if p.label == "window"]

    assert len(windows(7.0)) == len(windows(5.0)) == 9
    wide = windows(14.0)
    assert len(wide) > 9 and len(wide) % 3 == 0  # each floor alike
    assert all(p.x1 - p.x0 <= 1.15 * p.source_w for p in wide)


def test_a_run_gains_copies_of_its_middle_bay_and_never_loses_one() -> None:
    a, b, c, gap = (Part(1.0, s) for s in ("A", "B", "C", "g"))
    run = (a, gap, b, gap, c)
    assert _run_of(run, 3) == run
    assert [p.symbol for p in _run_of(run, 5)] == ["A", "g", "B", "g", "B", "g", "B", "g", "C"]
    assert _run_of(run, 5)[::2] == (a, b, b, b, c)


def test_a_much_wider_facade_gains_whole_bays_on_every_floor_and_keeps_its_style(
    tmp_path: Path,
) -> None:
    """Twice as wide, the symmetric façade's window bays are copied (a bay and its mirror
    image together) through every floor: each floor has the same, larger, number of
    windows, none wider than in the source, and every constraint of the style holds."""
    extraction = _extract(tmp_path, _symmetric())
    (variation,) = _draw(extraction, (40.0, 10.0), 1)
    windows = [p for p in variation.pieces if p.label == "window"]
    per_floor = {y: sum(round(p.y0, 6) == y for p in windows) for y in (1.0, 4.0, 7.0)}
    assert len(set(per_floor.values())) == 1 and per_floor[1.0] > 8
    assert all(p.x1 - p.x0 <= 1.0001 * p.source_w for p in windows)
    assert not variation.kept.broken and len(variation.kept.kept) == len(extraction.style)


def _pilasters() -> list[Rect]:
    """Pilasters 1 m wide every 4 m on a 13 x 10 façade, three floors of windows between
    them, ledges from the middle of one pilaster to the middle of the next."""
    rects = [Rect("pillar", x, 0.0, x + 1.0, 10.0, 1) for x in (0.0, 4.0, 8.0, 12.0)]
    for y in (1.0, 4.0, 7.0):
        rects += [Rect("window", x, y, x + 2.0, y + 1.5, 1) for x in (1.5, 5.5, 9.5)]
        rects += [Rect("ledge", x, y - 0.5, x + 4.0, y, 1) for x in (0.5, 4.5, 8.5)]
    return rects


def test_bays_between_pilasters_with_no_wall_between_are_copied_whole(
    tmp_path: Path,
) -> None:
    """Pilasters 1 m wide every 4 m, ledges running from the middle of one to the middle of
    the next (no wall to cut at between bays): 8 m wider, the bay is copied twice, cut
    through the middles of the pilasters and put together again, every pilaster whole."""
    extraction = _extract(tmp_path, LabelledLayout(13.0, 10.0, tuple(_pilasters())))
    source = (13.0, 10.0)
    pieces = derive_at(extraction.grammar, source, *source)
    laid = retargeted(pieces, source, 21.0, 10.0, extraction.style)
    moved = next(moved for moved, _, text in laid if text == "x copied 2x: 4.5-8.5")
    assert sum(p.label == "window" for p in moved) == 15
    pillars = {(round(p.x0, 3), round(p.x1, 3)) for p in moved if p.label == "pillar"}
    whole = [(x, x + 1.0) for x in (0.0, 4.0, 8.0, 12.0, 16.0, 20.0)]
    assert pillars - set(whole) == {(0.0, 0.5), (20.5, 21.0)}  # under the end ledges
    assert set(whole) <= pillars


def test_bays_copied_across_a_facade_whose_wall_cannot_stretch_up_are_scaled_alike(
    tmp_path: Path,
) -> None:
    """1.2 times as tall, the pilastered façade's wall between floors cannot take the
    height alone: with bays copied across, everything is scaled alike up it (never the
    layout unchanged across: that is the grammar's)."""
    source = (13.0, 10.0)
    extraction = _extract(tmp_path, LabelledLayout(*source, tuple(_pilasters())))
    pieces = derive_at(extraction.grammar, source, *source)
    texts = [text for _, _, text in retargeted(pieces, source, 21.0, 12.0, extraction.style)]
    assert "x copied 2x: 4.5-8.5; y scaled" in texts
    assert not any(text.startswith("y") or text == "stretched" for text in texts)


def test_bays_copied_on_a_symmetric_facade_keep_it_symmetric(tmp_path: Path) -> None:
    """Every layout made by copying whole bays of the symmetric façade (a bay with its
    mirror image) is mirror-symmetric and has as many windows on each floor."""
    extraction = _extract(tmp_path, _symmetric())
    source = (20.0, 10.0)
    pieces = derive_at(extraction.grammar, source, *source)
    laid = retargeted(pieces, source, 33.0, 10.0, extraction.style)
    copied = [(moved, text) for moved, _, text in laid if text.startswith("x copied")]
    assert copied
    for moved, text in copied:
        windows = sorted(
            (round(p.y0, 4), round(p.x0, 4), round(p.x1, 4)) for p in moved if p.label == "window"
        )
        mirrored = sorted((y, round(33.0 - x1, 4), round(33.0 - x0, 4)) for y, x0, x1 in windows)
        assert windows == mirrored, text
        assert len({sum(w[0] == y for w in windows) for y in (1.0, 4.0, 7.0)}) == 1


def test_tidying_copied_bays_moves_their_elements_but_keeps_their_sizes() -> None:
    """Two windows nearly lined up with a third: the QP lines them up; holding, it only
    moves them, never widening one to meet the other's edge."""
    pieces = [
        Piece("window", 1.0, 1.0, 2.0, 2.0, 1.0, 1.0),
        Piece("window", 1.05, 3.0, 2.1, 4.0, 1.0, 1.0),
        Piece("facade", 0.0, 0.0, 6.0, 5.0, 6.0, 5.0),
    ]
    held, _ = align(pieces, 6.0, 5.0, hold=True)
    windows = [p for p in held if p.label == "window"]
    assert [round(p.x1 - p.x0, 6) for p in windows] == [1.0, 1.05]
    free, _ = align(pieces, 6.0, 5.0)
    assert len({round(p.x1 - p.x0, 6) for p in free if p.label == "window"}) == 1


def test_tidying_shrinks_no_element_below_three_quarters_of_its_size() -> None:
    """Two windows of one source size, derived 1 m and 40 cm wide, are made one size, but
    not by shrinking the wider below 75 cm (``KEPT_LEAST``): with half allowed, the QP
    halved cmp_b0001's windows in its variations at the input's own size, pairing them
    with sills under half a window."""
    pieces = [
        Piece("window", 1.0, 1.0, 2.0, 2.0, 1.0, 1.0),
        Piece("window", 4.0, 1.0, 4.4, 2.0, 1.0, 1.0),
        Piece("facade", 0.0, 0.0, 6.0, 5.0, 6.0, 5.0),
    ]
    tidied, _ = align(pieces, 6.0, 5.0)
    widths = [round(p.x1 - p.x0, 6) for p in tidied if p.label == "window"]
    assert widths == [pytest.approx(KEPT_LEAST)] * 2


def test_likeness_counts_the_wall_a_derivation_widens() -> None:
    window = Piece("window", 1.0, 1.0, 2.0, 2.0, 1.0, 1.0)
    same = [window, Piece("facade", 0.0, 0.0, 3.0, 3.0, 3.0, 3.0)]
    blank = [window, Piece("facade", 0.0, 0.0, 9.0, 3.0, 3.0, 3.0)]
    assert likeness(same) == 0.0
    assert likeness(blank) > 0.5


def _floors_drawn_apart() -> LabelledLayout:
    """Three floors of three windows, the middle floor's with sills: the floors are not
    one rule a repeat could copy."""
    rects = []
    for j, y in enumerate((1.0, 4.0, 7.0)):
        for x in (1.0, 4.0, 7.0):
            rects.append(Rect("window", x, y + 0.2, x + 1.0, y + 1.7, 1))
            if j == 1:
                rects.append(Rect("sill", x, y, x + 1.0, y + 0.2, 1))
    return LabelledLayout(9.0, 9.5, tuple(rects))


def test_a_taller_facade_gains_floors_copied_whole(tmp_path: Path) -> None:
    """The grammar has no repeat up the façade; twice as tall, whole floors are copied
    (one pitch of the rows of windows): more floors of three windows, none taller than
    in the source, every constraint of the style kept."""
    extraction = _extract(tmp_path, _floors_drawn_apart())
    assert not any(r.op in ("repeat", "repeatABA") for r in extraction.grammar.rules.values())
    (variation,) = _draw(extraction, (9.0, 19.0), 1)
    windows = [p for p in variation.pieces if p.label == "window"]
    floors = {round(p.y0, 6) for p in windows}
    assert len(floors) > 3 and len(windows) == 3 * len(floors)
    assert all(p.y1 - p.y0 <= 1.1 * p.source_h for p in windows)
    assert not variation.kept.broken
    assert variation.retarget.startswith("y copied")


def test_floors_whose_rows_make_no_pitch_are_copied_between_the_gaps() -> None:
    """A shop floor, two floors and an attic, the style's rows too close to make a floor
    (a pitch of 0.5 m): a floor is still copied, one that runs between the gaps of wall
    and holds a row, never the shop floor or the attic."""
    spans = [(0.0, 3.0), (4.0, 5.5), (6.5, 8.0), (9.0, 10.0)]
    elements = [StyleBox("window", 1.0, lo, 2.0, hi) for lo, hi in spans]
    plans = floors.floor_plans(elements, 10.0, 15.0, [[4.75, 5.25]])
    copied = [plan.text for plan in plans if plan.text]
    assert "copied 2x: 3.5-6" in copied  # one floor, with the wall half way to the next
    assert all(text.endswith((": 3.5-6", ": 3.5-8.5")) for text in copied)  # never 0-3, 9-10


def _under_an_attic() -> LabelledLayout:
    """Three floors of four windows, 12.5 x 10 m, under an attic of staggered ornaments
    that leave no cut (nor one a bay along)."""
    rects = []
    for y in (1.0, 4.0, 7.0):
        rects += [Rect("window", x, y, x + 1.5, y + 1.5, 1) for x in (1.0, 4.0, 7.0, 10.0)]
    rects += [Rect("deco", x, 9.0, x + 2.6, 9.7, 1) for x in (0.2, 3.4, 6.6, 9.8)]
    rects += [Rect("sign", x, 9.4, x + 1.5, 10.0, 2) for x in (2.4, 5.6, 8.8)]
    return LabelledLayout(12.5, 10.0, tuple(rects))


def test_a_stratum_no_unit_can_be_cut_out_of_is_scaled_alike(tmp_path: Path) -> None:
    """Three floors of four windows under an attic of staggered ornaments that leave no
    cut (nor one a bay along): a bay is still copied through the floors, and the attic,
    a tenth of the height, is scaled alike across instead."""
    source = (12.5, 10.0)
    extraction = _extract(tmp_path, _under_an_attic())
    pieces = derive_at(extraction.grammar, source, *source)
    laid = {
        text: moved for moved, _, text in retargeted(pieces, source, 15.0, 10.0, extraction.style)
    }
    moved = laid["x copied 1x: 3.25-6.25"]  # the exact pitch: nothing drawn exactly moves
    assert sum(p.label == "window" for p in moved) == 15
    windows = [p.x1 - p.x0 for p in moved if p.label == "window"]
    assert all(1.5 / 1.1 <= w <= 1.5 * 1.1 for w in windows)  # copied, not stretched
    signs = [p for p in moved if p.label == "sign"]
    assert len(signs) == 3 and all(
        p.x1 - p.x0 == pytest.approx(1.2 * p.source_w) for p in signs
    )  # 15 / 12.5


def _three_bays() -> LabelledLayout:
    """A mirrored façade 15 x 9 m of three bays: windows 1.5 m wide each side, a door
    under wide windows in the middle."""
    rects = [Rect("door", 6.75, 0.0, 8.25, 2.4, 1)]
    for j in range(3):
        y = 0.8 + 3 * j
        rects += [Rect("window", 1.75, y, 3.25, y + 1.6, 1)]
        rects += [Rect("window", 11.75, y, 13.25, y + 1.6, 1)]
        if j:
            rects += [Rect("window", 6.25, y, 8.75, y + 1.6, 1)]
    return LabelledLayout(15.0, 9.0, tuple(rects))


def test_copied_bays_with_drawn_proportions_keep_the_style(tmp_path: Path) -> None:
    """Bao et al. 2013 vary a layout's sizes as well as its counts: the source's
    terminals are given new proportions (a mirrored warp of each axis) and copied again,
    so a façade with one good way to be copied still has variations that keep its style.
    At most ``count`` draws are copied, and none once ``count`` layouts keep it."""
    extraction = _extract(tmp_path, _three_bays())
    style = extraction.style
    assert {c.kind for c in style} >= {"symmetry", "centre", "columns"}
    source, size = (15.0, 9.0), (22.5, 9.0)
    pieces = derive_at(extraction.grammar, source, *source)

    def kept(found: list[Piece]) -> Kept:
        boxes = [StyleBox(p.label, p.x0, p.y0, p.x1, p.y1) for p in found]
        return check(style, facade_of(boxes, *size, "wall"))

    plain = {pieces_key(moved) for moved, _, _ in retargeted(pieces, source, *size, style)}
    drawn = proportioned_copies(
        pieces, source, size, style, random.Random(0), kept, (len(style), 3, set())
    )
    assert drawn and all(c.retarget.endswith("; proportions drawn") for c in drawn)
    assert 1 <= len({c.proportions for c in drawn}) <= 3
    good = [c for c in drawn if not c.kept.broken]
    assert any(c.retarget.startswith("x copied") for c in good)
    assert not {pieces_key(c.pieces) for c in good} & plain  # new layouts, not the plain copies
    for candidate in good:  # the source's sizes kept for the score
        assert candidate.score > 0 and all(p.source_w > 0 for p in candidate.pieces)
    enough = {pieces_key(c.pieces) for c in good[:3]}
    assert len(enough) < 3 or not proportioned_copies(
        pieces, source, size, style, random.Random(0), kept, (len(style), 3, enough)
    )


def test_a_stratum_no_unit_can_be_cut_out_of_is_scaled_by_two_at_most(tmp_path: Path) -> None:
    """The attic of staggered ornaments at twice the width is scaled by 2 while the bays
    below are copied (cmp_b0010 at 30 m had blank margins instead); wider, it is not."""
    source = (12.5, 10.0)
    extraction = _extract(tmp_path, _under_an_attic())
    pieces = derive_at(extraction.grammar, source, *source)

    def copied(width: float) -> list[list[Piece]]:
        laid = retargeted(pieces, source, width, 10.0, extraction.style)
        return [moved for moved, _, text in laid if text.startswith("x copied")]

    wide = copied(25.0)
    assert wide
    for moved in wide:
        signs = [p for p in moved if p.label == "sign"]
        assert len(signs) == 3 and all(p.x1 - p.x0 == pytest.approx(2 * p.source_w) for p in signs)
        windows = [p.x1 - p.x0 for p in moved if p.label == "window"]
        assert len(windows) > 12 and all(w <= 1.5 * 1.1 for w in windows)
    assert not copied(26.0)  # the attic would be scaled by 2.08


def test_variations_print_no_solver_warnings(tmp_path: Path) -> None:
    """The townhouse derived at 30 x 12 m (3.2 times its width): an alignment attempt that
    fails made cvxpy warn of an overflow evaluating its objective, on the user's terminal;
    the attempt's status says it failed, and nothing is printed."""
    layout = solve(load_spec(ROOT / "specs" / "townhouse.yaml"))
    path = tmp_path / "house.layout.json"
    path.write_text(report_text(layout, timings=False))
    extraction = extract_grammar(path, Options(iterations=150))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        variations = _draw(extraction, (30.0, 12.0), 6)
    assert len(variations) >= 4  # (those a visible step apart that keep the style)


def test_variations_of_generated_facades_keep_every_constraint_the_first_keeps(
    tmp_path: Path,
) -> None:
    """Generated annotations (``annotated_family``) at 0.7 times their width: variation 0
    keeps the door's size, and every other variation keeps every constraint it keeps, not
    merely as many (seed 1's variations 1 and 2 squeezed the door, keeping as many
    constraints by others); fewer are written when fewer exist."""
    for seed in (1, 2):
        path = tmp_path / f"family-{seed}.xml"
        path.write_text(cmp_xml(family(seed)[0]))
        extraction = extract_grammar(path, Options(size=(15.0, 15.0)))
        variations, notes = derive_variations(
            extraction.grammar, extraction.tiling, 10.5, 15.0, "f", 3, 0, extraction.style
        )
        first = set(variations[0].kept.kept)
        assert any(c.kind == "sizes" and c.label == "door" for c in first)
        for variation in variations[1:]:
            assert first <= set(variation.kept.kept), (seed, first - set(variation.kept.kept))
        assert (len(variations) < 3) == bool(notes)
