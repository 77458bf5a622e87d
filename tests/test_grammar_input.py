"""Labelled layouts in (CMP XML, plain JSON, facadecli reports), tilings out (issue 6)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from facadecli import load_spec, solve
from facadecli.export.report import report_text
from facadecli.grammar.cmp_xml import read_cmp
from facadecli.grammar.json_layouts import read_plain, read_report
from facadecli.grammar.tiling import tile

ROOT = Path(__file__).resolve().parent.parent

# our own fixture in the CMP format: rows are <x> (from the top), columns are <y>
CMP = "\n".join(
    f"<object><points><x>{top}</x><x>{bottom}</x><y>{left}</y><y>{right}</y></points>"
    f"<label>{label}</label><labelname>{name}</labelname><flag>1</flag></object>"
    for top, bottom, left, right, label, name in [
        (0, 1, 0, 1, 2, "facade"),
        (0.1, 0.3, 0.2, 0.4, 3, "window"),
        (0.25, 0.35, 0.1, 0.5, 7, "balcony"),
        (0.8, 1, 0.451, 0.6, 4, "door"),
    ]
)


def test_cmp_rows_and_columns_and_z_order(tmp_path: Path) -> None:
    path = tmp_path / "f.xml"
    path.write_text(CMP)
    layout = read_cmp(path)
    window = next(r for r in layout.rects if r.label == "window")
    assert (window.x0, window.y0, window.x1, window.y1) == pytest.approx((0.2, 0.7, 0.4, 0.9))
    tiling = tile(layout)
    assert tiling.label_at(0.3, 0.8) == "window"
    # window (z 10) is drawn over balcony (z 4) where they overlap, balcony shows elsewhere
    assert tiling.label_at(0.3, 0.72) == "window"
    assert tiling.label_at(0.15, 0.7) == "balcony"
    assert tiling.label_at(0.5, 0.1) == "door"  # at the bottom: rows count from the top
    assert tiling.label_at(0.9, 0.5) == "facade"


def test_nearly_equal_edges_snap_together(tmp_path: Path) -> None:
    path = tmp_path / "f.json"
    rects = [
        {"label": "window", "x0": 1.0, "y0": 1.0, "x1": 2.0, "y1": 2.0},
        {"label": "window", "x0": 3.0, "y0": 1.02, "x1": 4.0, "y1": 2.0},  # 2 cm off: snapped
    ]
    path.write_text(json.dumps({"canvas": {"width": 5, "height": 3}, "rects": rects}))
    tiling = tile(read_plain(path), tolerance=0.01)
    assert tiling.ys == pytest.approx((0.0, 1.01, 2.0, 3.0))
    assert tiling.xs == (0.0, 1.0, 2.0, 3.0, 4.0, 5.0)
    assert [row.count("window") for row in tiling.labels] == [0, 2, 0]


def test_a_solved_layout_tiles_back_into_its_shapes(tmp_path: Path) -> None:
    layout = solve(load_spec(ROOT / "specs" / "residential-house.yaml"))
    path = tmp_path / "r.layout.json"
    path.write_text(report_text(layout, timings=False))
    tiling = tile(read_report(path), tolerance=0.0)
    for shape in layout.shapes:
        if shape.visible and shape.layer == "columns":
            centre = ((shape.x0 + shape.x1) / 2, (shape.y0 + shape.y1) / 2)
            assert tiling.label_at(*centre) == f"{shape.x}.{shape.y}"
    assert tiling.xs[0] == 0.0 and tiling.xs[-1] == layout.width


def _rederives(tiling: object, grammar: object) -> bool:
    from facadecli.grammar.split import derive

    width, height = tiling.xs[-1], tiling.ys[-1]  # type: ignore[attr-defined]
    for label, x0, y0, x1, y1 in derive(grammar, width, height):  # type: ignore[arg-type]
        if tiling.label_at((x0 + x1) / 2, (y0 + y1) / 2) != label:  # type: ignore[attr-defined]
            return False
    return True


def test_the_greedy_grammar_rederives_its_tiling_exactly(tmp_path: Path) -> None:
    from facadecli.grammar.search import greedy_grammar

    path = tmp_path / "f.xml"
    path.write_text(CMP)
    tiling = tile(read_cmp(path))
    grammar = greedy_grammar(tiling)
    assert _rederives(tiling, grammar)
    # every cell is covered exactly once
    from facadecli.grammar.split import derive

    area = sum((x1 - x0) * (y1 - y0) for _, x0, y0, x1, y1 in derive(grammar, 1.0, 1.0))
    assert area == pytest.approx(1.0)


def test_repeated_floors_become_a_repeat_rule(tmp_path: Path) -> None:
    from facadecli.grammar.search import extract, greedy_grammar

    rects = [
        {"label": "window", "x0": x, "y0": y, "x1": x + 1, "y1": y + 1.5}
        for y in (0.5, 3.5, 6.5)
        for x in (1.0, 3.0, 5.0)
    ]
    path = tmp_path / "f.json"
    path.write_text(json.dumps({"canvas": {"width": 7, "height": 9.5}, "rects": rects}))
    tiling = tile(read_plain(path), tolerance=0.0)
    grammar = extract(tiling, iterations=300, seed=1).grammar
    assert _rederives(tiling, grammar)
    text = grammar.text()
    # three floors and three windows a floor, whichever way round
    assert "repeat(y)" in text and "repeat(x)" in text and text.count("}*3") == 2
    assert len(grammar.rules) <= 5
    assert grammar.cost <= 10.3 + 1e-9
    assert greedy_grammar(tiling).cost > 20  # the heuristic alone splits in two each time
