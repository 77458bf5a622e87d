"""A façade's style (Bao et al. 2013, issue 14): constraints found in a labelled layout, kept
or broken in layouts derived from it; periodic runs and line-ups in regularisation."""

from __future__ import annotations

import itertools
import json
import random
import subprocess
import sys
from pathlib import Path

import pytest

from facadecli.grammar.align import align
from facadecli.grammar.derive import derive_at
from facadecli.grammar.extract import extract_grammar
from facadecli.grammar.inputs import BACKGROUND
from facadecli.grammar.model import Options, Piece
from facadecli.grammar.regularize import regularize
from facadecli.grammar.style import (
    Box,
    check,
    facade_of,
    find_style,
    holds,
    shown_tiles,
    style_of_drawing,
)
from facadecli.grammar.tiling import LabelledLayout, Rect
from facadecli.grammar.variations import derive_variations

ROOT = Path(__file__).resolve().parent.parent


def _palazzo(jitter: float = 0.0, seed: int = 0) -> list[Box]:
    """Three floors of three windows 1.2 m wide, 3 m apart, over a centred door, on a
    11.4 x 10 façade, each window moved by up to ``jitter`` metres."""
    rng = random.Random(seed)
    boxes = []
    for floor in range(3):
        y = 3.5 + 2.5 * floor
        for bay in range(3):
            x = 2.1 + 3.0 * bay + rng.uniform(-jitter, jitter)
            boxes.append(Box("window", x, y, x + 1.2, y + 1.6))
    boxes.append(Box("door", 5.1, 0.0, 6.3, 2.6))
    return boxes


def _kinds(constraints: list) -> set[tuple[str, str]]:  # type: ignore[type-arg]
    return {(c.kind, c.label) for c in constraints}


def test_the_style_of_a_symmetric_facade() -> None:
    style = find_style(facade_of(_palazzo(), 11.4, 10.0, BACKGROUND))
    assert _kinds(style) == {
        ("symmetry", "*"),
        ("columns", "window"),
        ("spacing", "window"),
        ("axis", "door"),
        ("centre", "door"),
        ("centre", "window"),
        ("sizes", "window"),
        ("sizes", "door"),
        ("pitch", "window"),
    }
    sizes = next(c for c in style if c.kind == "sizes" and c.label == "window")
    assert sizes.text == "window 1.2 m wide, 1.6 m tall"
    pitch = next(c for c in style if c.kind == "pitch")
    assert pitch.text == "rows of window 2.5 m apart"
    columns = next(c for c in style if c.kind == "columns")
    assert columns.text == "3 of 3 rows of window on the same 3 columns"
    spacing = next(c for c in style if c.kind == "spacing")
    assert spacing.text == "3 of 3 rows of three or more window evenly spaced"


def test_a_moved_window_breaks_columns_spacing_and_symmetry() -> None:
    boxes = _palazzo()
    style = find_style(facade_of(boxes, 11.4, 10.0, BACKGROUND))
    moved = [b._replace(x0=b.x0 + 0.6, x1=b.x1 + 0.6) if b == boxes[5] else b for b in boxes]
    kept = check(style, facade_of(moved, 11.4, 10.0, BACKGROUND))
    broken = _kinds(list(kept.broken))
    assert {("columns", "window"), ("spacing", "window"), ("symmetry", "*")} <= broken
    assert ("axis", "door") not in broken and ("centre", "door") not in broken
    assert kept.warnings() and "3 of 3 rows of window on the same 3 columns" in kept.warnings()[0]


def test_a_row_on_one_pitch_with_an_empty_place_is_evenly_spaced() -> None:
    def row(*xs: float) -> list[Box]:
        return [Box("window", x - 0.5, 3.0, x + 0.5, 4.0) for x in xs]

    def even(boxes: list[Box]) -> bool:
        spacing = find_style(facade_of(boxes, 20.0, 10.0, BACKGROUND))
        return any(c.kind == "spacing" for c in spacing)

    assert even(row(2.0, 6.0, 10.0))
    assert even(row(2.0, 6.0, 14.0, 18.0))  # the middle place empty: still one pitch
    assert not even(row(2.0, 6.0, 14.0))  # one pitch and a double: no pitch twice
    assert not even(row(2.0, 6.0, 11.0, 15.0))  # 4, 5, 4: off the pitch
    assert not even(row(2.0, 3.0, 15.0, 16.0))  # 1, 12, 1: more than one place empty


def test_a_band_across_the_facade_is_on_no_column() -> None:
    bands = [Box("cornice", 0.2, y, 11.2, y + 0.3) for y in (3.1, 5.6, 8.1)]
    style = find_style(facade_of(_palazzo() + bands, 11.4, 10.0, BACKGROUND))
    assert ("columns", "cornice") not in _kinds(style)  # three rows, each one band
    assert all(c.other != "cornice" for c in style)  # and no axis of anything


def test_an_ornament_across_bays_is_on_no_column_with_the_awnings_under_it() -> None:
    """cmp_b0007: two awnings over the middle window column and an attic ornament 47%
    of the width centred over them made "3 rows of deco on the same column"; copying a
    bay adds awnings but not the attic's ornament, so every copy broke it. An element
    wider than 40% of the façade spans bays: it is on no column (the centre line keeps
    it centred)."""
    awnings = [Box("deco", 4.8, y, 6.6, y + 0.4) for y in (5.2, 7.7)]
    ornament = [Box("deco", 3.0, 9.6, 8.4, 9.9)]  # 5.4 of 11.4 m
    style = find_style(facade_of(_palazzo() + awnings + ornament, 11.4, 10.0, BACKGROUND))
    (columns,) = [c for c in style if c.kind == "columns" and c.label == "deco"]
    assert columns.rows == 2  # the awnings alone
    assert ("centre", "deco") in _kinds(style)


def test_a_window_stretched_across_bays_in_a_derived_layout_is_still_checked() -> None:
    """A derived layout whose top floor is one window 5 m wide (44% of the façade, wider
    than the input's bands) does not keep the windows' columns: in a derived layout
    only elements of half the width or more are bands."""
    palazzo = _palazzo()
    style = find_style(facade_of(palazzo, 11.4, 10.0, BACKGROUND))
    assert ("columns", "window") in _kinds(style)
    top = [b for b in palazzo if b.label == "window" and b.y0 == 8.5]
    stretched = [b for b in palazzo if b not in top] + [Box("window", 1.5, 8.5, 6.5, 10.1)]
    kept = check(style, facade_of(stretched, 11.4, 10.2, BACKGROUND))
    assert ("columns", "window") in {(c.kind, c.label) for c in kept.broken}


def test_spacing_is_of_elements_as_wide_as_each_other() -> None:
    def balconies(*boxes: tuple[float, float]) -> list[Box]:
        return [Box("balcony", x0, 3.0, x1, 3.5) for x0, x1 in boxes]

    # two wide end balconies and three narrow ones between, the narrow ones 3 m apart
    row = balconies((0.5, 2.5), (3.5, 4.5), (6.5, 7.5), (9.5, 10.5), (11.5, 13.5))
    spacing = [c for c in find_style(facade_of(row, 14.0, 10.0, BACKGROUND)) if c.kind == "spacing"]
    assert [c.text for c in spacing] == ["1 of 1 rows of three or more balcony evenly spaced"]
    uneven = balconies((0.5, 2.5), (3.5, 4.5), (6.5, 7.5), (8.5, 9.5), (11.5, 13.5))
    assert not any(
        c.kind == "spacing" for c in find_style(facade_of(uneven, 14.0, 10.0, BACKGROUND))
    )


def test_floors_copied_that_were_never_even_leave_the_even_one_even() -> None:
    def row(y: float, *xs: float) -> list[Box]:
        return [Box("window", x - 0.5, y, x + 0.5, y + 1.0) for x in xs]

    source = row(1.0, 2.0, 5.0, 8.0) + row(4.0, 2.0, 5.0, 9.0) + row(7.0, 2.0, 5.0, 9.0)
    style = [
        c for c in find_style(facade_of(source, 11.0, 10.0, BACKGROUND)) if c.kind == "spacing"
    ]
    assert [c.text for c in style] == ["1 of 3 rows of three or more window evenly spaced"]
    taller = source + row(10.0, 2.0, 5.0, 9.0) + row(13.0, 2.0, 5.0, 9.0)  # 1 of 5 even
    assert not check(style, facade_of(taller, 11.0, 16.0, BACKGROUND)).broken
    uneven = row(1.0, 2.0, 5.0, 9.0) + taller[3:]  # the even floor made uneven: none is
    assert check(style, facade_of(uneven, 11.0, 16.0, BACKGROUND)).broken


def test_tiles_of_one_element_are_joined_back() -> None:
    window = [Box("window", 1.0, 1.0, 1.5, 2.0), Box("window", 1.5, 1.0, 2.0, 2.0)]
    window += [Box("window", 1.0, 2.0, 2.0, 2.5)]
    wall = [Box(BACKGROUND, 0.0, 0.0, 3.0, 1.0), Box(BACKGROUND, 0.0, 2.5, 3.0, 3.0)]
    facade = facade_of([*window, *wall], 3.0, 3.0, BACKGROUND)
    assert facade.boxes == (Box("window", 1.0, 1.0, 2.0, 2.5),)


def test_a_wider_facade_keeps_what_it_can_and_the_report_says_which() -> None:
    style = find_style(facade_of(_palazzo(), 11.4, 10.0, BACKGROUND))
    wider = facade_of([b for b in _palazzo() if b.label != "door"], 17.1, 10.0, BACKGROUND)
    assert not holds(next(c for c in style if c.kind == "axis"), wider)  # no door
    assert holds(next(c for c in style if c.kind == "columns"), wider)


def _layout(boxes: list[Box], width: float, height: float) -> LabelledLayout:
    return LabelledLayout(
        width, height, tuple(Rect(b.label, b.x0, b.y0, b.x1, b.y1, 2) for b in boxes)
    )


def test_regularisation_evens_out_hand_drawn_runs() -> None:
    layout = _layout(_palazzo(jitter=0.03, seed=3), 11.4, 10.0)
    regular, report = regularize(layout, tolerance=0.01)
    for floor in range(3):
        row = sorted(
            r.x0
            for r in regular.rects
            if r.label == "window" and abs(r.y0 - 3.5 - 2.5 * floor) < 0.01
        )
        pitches = [b - a for a, b in itertools.pairwise(row)]
        assert max(pitches) - min(pitches) < 1e-6, pitches
    assert any(g.kind == "run" and g.label == "window" for g in report.groups)
    drawn = sorted(b.x0 for b in _palazzo(jitter=0.03, seed=3) if b.y0 == 3.5)
    assert abs((drawn[1] - drawn[0]) - (drawn[2] - drawn[1])) > 0.01  # the run was uneven


def test_regularisation_lines_up_a_door_under_a_window_column() -> None:
    door = Box("door", 5.13, 0.0, 6.33, 2.6)  # 3 cm off: within FAITHFUL of its width
    boxes = [b for b in _palazzo() if b.label != "door"] + [door]
    regular, report = regularize(_layout(boxes, 11.4, 10.0), tolerance=0.01)
    door = next(r for r in regular.rects if r.label == "door")
    middle = next(r for r in regular.rects if r.label == "window" and 4 < r.x0 < 6)
    assert abs((door.x0 + door.x1) - (middle.x0 + middle.x1)) < 1e-6
    assert any(g.kind == "line-up" and g.count >= 1 for g in report.groups)


def _extracted(tmp_path: Path, boxes: list[Box], width: float, height: float):  # type: ignore[no-untyped-def]
    path = tmp_path / "palazzo.json"
    rects = [{"label": b.label, "x0": b.x0, "y0": b.y0, "x1": b.x1, "y1": b.y1} for b in boxes]
    path.write_text(json.dumps({"canvas": {"width": width, "height": height}, "rects": rects}))
    return extract_grammar(path, Options(iterations=200))


def test_derived_layouts_keep_the_style_at_new_widths(tmp_path: Path) -> None:
    extraction = _extracted(tmp_path, _palazzo(), 11.4, 10.0)
    style = extraction.style
    assert ("columns", "window") in _kinds(style) and ("axis", "door") in _kinds(style)
    for width, height in ((7.98, 10.0), (17.1, 10.0), (22.8, 10.0), (11.4, 15.0)):
        found, _ = derive_variations(
            extraction.grammar, extraction.tiling, width, height, "p", 1, 0, style
        )
        assert not found[0].kept.broken, (width, [c.text for c in found[0].kept.broken])


def test_the_grammar_report_lists_the_style_and_what_each_derived_layout_keeps(
    tmp_path: Path,
) -> None:
    path = tmp_path / "palazzo.json"
    rects = [{"label": b.label, "x0": b.x0, "y0": b.y0, "x1": b.x1, "y1": b.y1} for b in _palazzo()]
    path.write_text(json.dumps({"canvas": {"width": 11.4, "height": 10.0}, "rects": rects}))
    out = tmp_path / "out"
    args = [str(path), "-o", str(out), "-n", "100", "--derive", "17.1x10", "--variations", "2"]
    done = subprocess.run(
        [sys.executable, "-m", "facadecli", "grammar", *args], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    report = json.loads((out / "palazzo.grammar-report.json").read_text())
    columns = "3 of 3 rows of window on the same 3 columns"
    assert {"kind": "columns", "label": "window", "text": columns} in report["style"]
    derived = report["derived"]
    assert [d["variation"] for d in derived] == list(range(len(derived)))
    assert derived[0]["size"] == {"width": 17.1, "height": 10.0}
    assert derived[0]["style_kept"] == {"kept": len(report["style"]), "broken": []}
    made = [d["made"] for d in derived]  # the grammar's derivation, or bays copied
    assert all(m in ("grammar", "stretched") or m.startswith(("x ", "y ")) for m in made)


def test_the_alignment_qp_makes_near_misses_of_the_style_exact() -> None:
    style = find_style(facade_of(_palazzo(), 11.4, 10.0, BACKGROUND))
    off = [
        b._replace(x0=b.x0 + 0.3, x1=b.x1 + 0.3) if b.label == "door" or b == _palazzo()[4] else b
        for b in _palazzo()
    ]
    pieces = [Piece(b.label, b.x0, b.y0, b.x1, b.y1, b.x1 - b.x0, b.y1 - b.y0) for b in off]
    before = check(style, facade_of(off, 11.4, 10.0, BACKGROUND))
    assert {c.kind for c in before.broken} >= {"centre", "columns", "symmetry"}
    plain, _ = align(pieces, 11.4, 10.0)
    tidied, _ = align(pieces, 11.4, 10.0, style=style)
    boxes = [Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in tidied]
    assert not check(style, facade_of(boxes, 11.4, 10.0, BACKGROUND)).broken
    door = next(p for p in tidied if p.label == "door")
    assert abs(door.x0 + door.x1 - 11.4) < 1e-6  # on the centre line again
    plain_door = next(p for p in plain if p.label == "door")
    assert abs(plain_door.x0 + plain_door.x1 - 11.4) > 0.1  # without the style it stays off


def test_a_shuffle_that_breaks_the_style_is_no_variation(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Shuffling parts of one size moves the door to where a shop was, off the centre
    line: that breaks the style, so it is not given as a variation (issue 34: every
    variation keeps the style as variation 0 does); the first keeps it."""
    # no drawn proportions: they keep the centre line, so they would come before shuffles
    monkeypatch.setattr("facadecli.proportions.DRAWS", 0)
    shops = [Box("shop", 2.1, 0.0, 3.3, 2.6), Box("shop", 8.1, 0.0, 9.3, 2.6)]
    extraction = _extracted(tmp_path, _palazzo() + shops, 11.4, 10.0)
    found, notes = derive_variations(
        extraction.grammar, extraction.tiling, 11.4, 10.0, "p", 6, 0, extraction.style
    )
    assert found[0].shuffle is None and not found[0].kept.broken
    assert all(len(v.kept.kept) >= len(found[0].kept.kept) for v in found)
    assert all(v.shuffle is None for v in found) and notes  # fewer than asked, said so


def test_a_layout_derived_at_its_own_size_is_the_input(tmp_path: Path) -> None:
    """At the input's size the best fit re-derives the input; the tidying QP is not run
    there (on cmp_b0001 it halved every window, keeping as much of the style): a door
    drawn a little off the centre line stays where it was drawn."""
    boxes = [b for b in _palazzo() if b.label != "door"] + [Box("door", 5.2, 0.0, 6.4, 2.6)]
    extraction = _extracted(tmp_path, boxes, 11.4, 10.0)
    assert ("centre", "door") in _kinds(extraction.style)  # 0.05 m off: near enough
    source = derive_at(extraction.grammar, (11.4, 10.0), 11.4, 10.0)
    found, _ = derive_variations(
        extraction.grammar, extraction.tiling, 11.4, 10.0, "p", 1, 0, extraction.style
    )
    assert sorted(found[0].pieces, key=str) == sorted(source, key=str)
    door = next(p for p in found[0].pieces if p.label == "door")
    assert (door.x0, door.x1) == pytest.approx((5.2, 6.4))


def _broken(style: list, boxes: list[Box], width: float, height: float) -> set[tuple[str, str]]:  # type: ignore[type-arg]
    return _kinds(list(check(style, facade_of(boxes, width, height, BACKGROUND)).broken))


def test_squeezed_windows_break_their_sizes_dropped_bays_do_not() -> None:
    """The style measures sizes: a narrower façade whose windows shrink by a fifth breaks
    ``sizes``; one that drops a bay and keeps its windows keeps it."""
    style = find_style(facade_of(_palazzo(), 11.4, 10.0, BACKGROUND))
    squeezed = [
        Box(b.label, b.x0 * 0.8, b.y0, b.x0 * 0.8 + (b.x1 - b.x0) * 0.8, b.y1)
        if b.label == "window"
        else b
        for b in _palazzo()
    ]
    assert ("sizes", "window") in _broken(style, squeezed, 9.1, 10.0)
    dropped = [b for b in _palazzo() if b.label != "window" or b.x0 < 8.0]
    assert ("sizes", "window") not in _broken(style, dropped, 8.4, 10.0)
    assert ("sizes", "door") not in _broken(style, dropped, 8.4, 10.0)


def test_stretched_floors_break_the_pitch_a_whole_floor_more_does_not() -> None:
    style = find_style(facade_of(_palazzo(), 11.4, 10.0, BACKGROUND))
    stretched = [
        Box(b.label, b.x0, 3.5 + (b.y0 - 3.5) * 1.4, b.x1, 3.5 + (b.y0 - 3.5) * 1.4 + 1.6)
        if b.label == "window"
        else b
        for b in _palazzo()
    ]
    assert ("pitch", "window") in _broken(style, stretched, 11.4, 12.0)
    taller = _palazzo() + [Box("window", x, 11.0, x + 1.2, 12.6) for x in (2.1, 5.1, 8.1)]
    assert ("pitch", "window") not in _broken(style, taller, 11.4, 12.5)


def test_the_style_is_found_on_what_the_drawing_shows() -> None:
    """A blind drawn whole behind a window shows as two strips beside it, as derived
    layouts show it; a window drawn over by a pillar is the pillar there."""
    rects = (
        Rect("blind", 1.0, 3.0, 3.0, 4.0, z=1),
        Rect("window", 1.5, 3.0, 2.5, 4.0, z=2),
        Rect("pillar", 5.0, 0.0, 5.5, 10.0, z=3),
        Rect("window", 4.5, 3.0, 6.0, 4.0, z=2),
    )
    tiles = shown_tiles(rects, 10.0, 10.0)
    assert sorted(t for t in tiles if t.label == "blind") == [
        Box("blind", 1.0, 3.0, 1.5, 4.0),
        Box("blind", 2.5, 3.0, 3.0, 4.0),
    ]
    assert sorted(t for t in tiles if t.label == "window") == [
        Box("window", 1.5, 3.0, 2.5, 4.0),
        Box("window", 4.5, 3.0, 5.0, 4.0),
        Box("window", 5.5, 3.0, 6.0, 4.0),
    ]
    assert sum((t.x1 - t.x0) * (t.y1 - t.y0) for t in tiles if t.label == "pillar") == 5.0
    style = style_of_drawing(LabelledLayout(10.0, 10.0, rects))
    sizes = next(c for c in style if c.kind == "sizes" and c.label == "window")
    assert sizes.sizes == ((0.5, 1.0), (1.0, 1.0))  # what shows, not what was drawn


def test_the_grammar_finds_its_style_on_the_annotation_not_its_tidied_tiling(
    tmp_path: Path,
) -> None:
    """Two windows drawn 3 cm apart: the style found has both, at their drawn sizes."""
    layout = {
        "canvas": {"width": 10.0, "height": 6.0},
        "rects": [
            {"label": "window", "x0": 1.0, "y0": 2.0, "x1": 2.2, "y1": 3.6},
            {"label": "window", "x0": 2.23, "y0": 2.0, "x1": 3.43, "y1": 3.6},
            {"label": "window", "x0": 6.0, "y0": 2.0, "x1": 7.2, "y1": 3.6},
        ],
    }
    path = tmp_path / "two.json"
    path.write_text(json.dumps(layout))
    extraction = extract_grammar(path, Options(iterations=20))
    sizes = next(c for c in extraction.style if c.kind == "sizes" and c.label == "window")
    assert sizes.sizes == ((1.2, 1.6),)
