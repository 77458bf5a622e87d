"""Fidelity (issue 34, item 1): outputs measured against the raw annotation, rasterised with
its z-order, label by label and element by element."""

from __future__ import annotations

from pathlib import Path

import pytest

from facadecli import parse_spec
from facadecli.grammar.extract import extract_grammar
from facadecli.grammar.fidelity import CELLS_MAX, fidelity, grid
from facadecli.grammar.inputs import LabelledLayout, Rect
from facadecli.grammar.model import Options
from facadecli.infer.run import check, infer


def _windows(gap: float = 1.0) -> list[Rect]:
    """Two floors of three 1 x 1.5 windows on a 10 x 8 wall, ``gap`` apart."""
    return [
        Rect("window", 1.0 + (1.0 + gap) * bay, y, 2.0 + (1.0 + gap) * bay, y + 1.5, 10)
        for bay in range(3)
        for y in (2.0, 5.0)
    ]


def test_an_exact_output_is_faithful() -> None:
    annotation = LabelledLayout(10.0, 8.0, tuple(_windows()))
    found = fidelity(annotation, annotation)
    assert found.iou_mean == 1.0 and found.iou_per_label() == {"facade": 1.0, "window": 1.0}
    assert (found.elements, found.lost, found.fused) == (6, 0, 0)
    assert found.warnings("it") == []
    summary = found.summary()
    assert summary["against"] == "annotation" and summary["raster"] == {
        "columns": 400,
        "rows": 320,
        "cell": 0.025,
    }


def test_two_windows_fused_into_one_are_found() -> None:
    windows = _windows()
    annotation = LabelledLayout(10.0, 8.0, tuple(windows))
    left, middle = windows[0], windows[2]  # the first two of the lower floor
    fused = Rect("window", left.x0, left.y0, middle.x1, middle.y1, 10)
    output = LabelledLayout(10.0, 8.0, (fused, *windows[1:2], *windows[3:]))
    found = fidelity(annotation, output)
    assert (found.elements, found.lost, found.fused, found.fused_elements) == (6, 0, 1, 2)
    assert found.iou_per_label()["window"] < 1.0 and found.iou_mean < 1.0
    (warning,) = found.warnings("the output")
    assert "fuses 2 into 1 of the annotation's 6 elements (window: 0 lost, 1 fused)" in warning


def test_windows_made_to_touch_are_fused_and_windows_drawn_touching_are_not() -> None:
    """The tidy-up sized the wall between two windows 0: two rectangles in the output, one
    region to whoever reads it (and one terminal to a grammar). A pillar drawn as base and
    shaft touching is one region in the annotation already: kept as drawn, not fused."""
    apart = (Rect("window", 0.5, 0.5, 1.5, 1.5, 10), Rect("window", 1.6, 0.5, 2.6, 1.5, 10))
    touching = (Rect("window", 0.5, 0.5, 1.55, 1.5, 10), Rect("window", 1.55, 0.5, 2.6, 1.5, 10))
    annotation = LabelledLayout(4.0, 2.0, apart)
    found = fidelity(annotation, LabelledLayout(4.0, 2.0, touching))
    assert (found.lost, found.fused, found.fused_elements) == (0, 1, 2)
    drawn = [Rect("window", 0.5, 0.5, 2.6, 1.5)]  # a grammar's terminal over both
    found = fidelity(annotation, LabelledLayout(4.0, 2.0, apart), drawn)
    assert (found.lost, found.fused) == (0, 1) and found.iou_per_label()["window"] < 1.0
    pillar = (Rect("pillar", 1.0, 0.0, 1.4, 0.5, 12), Rect("pillar", 1.0, 0.5, 1.4, 2.0, 12))
    whole = (Rect("pillar", 1.0, 0.0, 1.4, 2.0, 12),)
    found = fidelity(LabelledLayout(4.0, 2.0, pillar), LabelledLayout(4.0, 2.0, whole))
    assert (found.elements, found.lost, found.fused, found.iou_mean) == (2, 0, 0, 1.0)


def test_a_window_moved_off_its_place_is_lost() -> None:
    windows = _windows()
    annotation = LabelledLayout(10.0, 8.0, tuple(windows))
    moved = Rect("window", 1.6, 2.0, 2.6, 3.5, 10)  # 60% of its width off
    found = fidelity(annotation, LabelledLayout(10.0, 8.0, (moved, *windows[1:])))
    assert (found.lost, found.fused) == (1, 0)
    (warning,) = found.warnings("it")
    assert warning == "it loses 1 of the annotation's 6 elements (window: 1 lost, 0 fused)"


def test_the_z_order_hides_what_is_behind() -> None:
    """A window over a wall: the wall's IoU counts its visible part only, and the window
    is drawn over it whatever their order in the file (CMP's z-order by label)."""
    wall = Rect("molding", 0.0, 0.0, 4.0, 4.0, 7)
    window = Rect("window", 1.0, 1.0, 3.0, 3.0, 10)
    for order in ((wall, window), (window, wall)):
        annotation = LabelledLayout(4.0, 4.0, order)
        found = fidelity(annotation, LabelledLayout(4.0, 4.0, (wall, window)))
        assert found.iou_per_label() == {"molding": 1.0, "window": 1.0}
    # an output that drops the window: molding covers 16 m², the annotation shows 12 of them
    annotation = LabelledLayout(4.0, 4.0, (wall, window))
    found = fidelity(annotation, LabelledLayout(4.0, 4.0, (wall,)))
    assert found.iou_per_label()["molding"] == pytest.approx(12 / 16)
    assert found.iou_per_label()["window"] == 0.0 and found.lost == 1
    # within one label, the later rectangle is over the earlier one
    first = Rect("window", 0.0, 0.0, 2.0, 2.0, 10.0)
    later = Rect("window", 1.0, 0.0, 3.0, 2.0, 10.000001)
    found = fidelity(LabelledLayout(4.0, 4.0, (first, later)), LabelledLayout(4.0, 4.0, (later,)))
    assert found.elements == 2 and found.lost == 1  # the first shows only its left half


def test_a_hidden_element_is_not_counted() -> None:
    cornice = Rect("cornice", 0.0, 1.0, 4.0, 2.0, 11)
    window = Rect("window", 1.0, 1.2, 2.0, 1.8, 10)  # wholly behind the cornice
    annotation = LabelledLayout(4.0, 4.0, (window, cornice))
    found = fidelity(annotation, LabelledLayout(4.0, 4.0, (cornice,)))
    assert found.elements == 1 and found.lost == 0 and found.iou_mean == 1.0


def test_the_raster_is_capped() -> None:
    """2.5 cm cells unless that passes the cell limit: a huge façade is coarser; a small
    one (a CMP unit square) has at least 400 cells along its longer side."""
    assert (grid(15.0, 15.0).columns, grid(15.0, 15.0).rows) == (600, 600)
    assert (grid(1.0, 1.0).columns, grid(1.0, 1.0).rows) == (400, 400)
    huge = grid(1000.0, 500.0)
    assert huge.columns * huge.rows <= CELLS_MAX and huge.columns == pytest.approx(2828, abs=2)
    tiny = grid(1000.0, 500.0, cells_max=1000)
    assert tiny.columns * tiny.rows <= 1000 and tiny.cell_w == pytest.approx(tiny.cell_h, rel=0.05)
    sliver = grid(1e-6, 1e6)  # one column: the rows alone are capped
    assert sliver.columns == 1 and sliver.rows <= CELLS_MAX
    annotation = LabelledLayout(1000.0, 500.0, (Rect("window", 100, 100, 300, 200, 10),))
    found = fidelity(annotation, annotation, cells_max=1000)
    assert found.columns * found.rows <= 1000 and found.iou_mean == 1.0


def _cmp(path: Path, rects: list[tuple[str, float, float, float, float]]) -> Path:
    """A CMP annotation: rects (label, left, top, right, bottom) as fractions of the image."""
    objects = [
        f"<object><points><x>{top}</x><x>{bottom}</x><y>{left}</y><y>{right}</y></points>"
        f"<labelname>{label}</labelname></object>"
        for label, left, top, right, bottom in rects
    ]
    path.write_text("\n".join(objects) + "\n")
    return path


def test_infer_and_grammar_report_fidelity_against_the_annotation(tmp_path: Path) -> None:
    """Eleven windows 1% of the façade apart in a CMP annotation: the tidy-up (snapping at
    0.5%, then regularising) is measured against what was drawn, not against itself."""
    rects = [("facade", 0.0, 0.0, 1.0, 1.0)]
    rects += [("window", 0.05 + 0.06 * k, 0.3, 0.1 + 0.06 * k, 0.4) for k in range(11)]
    rects.append(("window", 0.05, 0.6, 0.1, 0.7))
    source = _cmp(tmp_path / "row.xml", rects)
    inferred = infer(source, "row", Options(size=(10.0, 10.0)))
    checks = check(inferred, parse_spec(inferred.text, "row.yaml"))
    faithful = checks["fidelity"]
    assert isinstance(faithful, dict) and faithful["against"] == "annotation"
    assert faithful["elements"] == 12 and faithful["lost"] == 0 and faithful["fused"] == 0
    assert faithful["iou_mean"] >= 0.9 and checks["iou_min"] == 1.0
    extraction = extract_grammar(source, Options(size=(10.0, 10.0), iterations=20))
    assert extraction.fidelity is not None and extraction.fidelity.elements == 12
    assert extraction.fidelity.iou_mean >= 0.9
