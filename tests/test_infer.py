"""``facade infer`` (issue 15): a labelled layout back to a layered spec that solves to it."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from facadecli import parse_spec
from facadecli.grammar.tiling import LabelledLayout, Rect
from facadecli.infer.layers import grids
from facadecli.infer.run import Inference, check, infer
from facadecli.infer.spec_text import SQUEEZE

ROOT = Path(__file__).resolve().parent.parent


def _palazzo() -> list[dict[str, object]]:
    """Three floors of three windows over a door, on an 11.4 x 10 façade."""
    rects: list[dict[str, object]] = []
    for floor in range(3):
        y = 3.5 + 2.0 * floor
        for bay in range(3):
            x = 2.1 + 3.0 * bay
            rects.append({"label": "window", "x0": x, "y0": y, "x1": x + 1.2, "y1": y + 1.5})
            rects.append({"label": "sill", "x0": x - 0.1, "y0": y - 0.15, "x1": x + 1.3, "y1": y})
    rects.append({"label": "door", "x0": 5.1, "y0": 0.0, "x1": 6.3, "y1": 2.6})
    rects.append({"label": "shop", "x0": 1.6, "y0": 0.4, "x1": 3.8, "y1": 2.6})
    return rects


def _write(path: Path, rects: list[dict[str, object]], width: float = 11.4) -> Path:
    path.write_text(json.dumps({"canvas": {"width": width, "height": 10.0}, "rects": rects}))
    return path


def test_a_label_is_split_into_grids() -> None:
    rects = [Rect("window", x, y, x + 1, y + 1, 1) for x in (1, 3, 5) for y in (1, 4)]
    rects += [Rect("window", 1, 7, 2, 8, 1), Rect("window", 5, 7, 6, 8, 1)]  # a third row: 2
    rects += [Rect("window", 1.5, 1, 2.5, 2, 1)]  # overlaps a window of its row
    found = grids(LabelledLayout(7.0, 9.0, tuple(rects)))
    assert [(len(g.columns), len(g.rows)) for g in found] == [(3, 2), (2, 1), (1, 1)]
    assert found[2].columns == ((1.5, 2.5),)  # in a grid of its own, in front
    assert found[0].columns == ((1, 2), (3, 4), (5, 6)) and found[0].rows == ((1, 2), (4, 5))


def test_the_spec_solves_back_to_the_input(tmp_path: Path) -> None:
    inferred = infer(_write(tmp_path / "palazzo.json", _palazzo()), "palazzo")
    spec = parse_spec(inferred.text, "palazzo.yaml")
    assert [layer.name for layer in spec.layers] == ["wall", "sill", "door", "shop", "window"]
    checks = check(inferred, spec)
    assert checks["solves"] and checks["iou"] == {
        "door": 1.0,
        "facade": 1.0,
        "shop": 1.0,
        "sill": 1.0,
        "window": 1.0,
    }
    assert [r["solves"] for r in checks["retargets"]] == [True, True]  # type: ignore[index]
    assert "window_w1" in inferred.text and "window_w2" not in inferred.text  # one size


def test_the_check_sees_a_spec_that_does_not_match(tmp_path: Path) -> None:
    inferred = infer(_write(tmp_path / "palazzo.json", _palazzo()), "palazzo")
    wrong = Inference(
        inferred.source,
        inferred.layout,
        inferred.tiling,
        inferred.grids,
        # the door half as tall (its width is the bays': their gaps would size it back)
        re.sub(
            r"door_h1: \{size: 2.6,( max: [0-9.]+,)?",
            "door_h1: {size: 1.3, max: 1.3,",
            inferred.text,
        ),
    )
    checks = check(wrong, parse_spec(wrong.text, "wrong.yaml"))
    assert checks["solves"] and checks["iou"]["door"] < 0.9  # type: ignore[index]


def _infer(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "facadecli", "infer", *args], capture_output=True, text=True
    )


def test_facade_infer_writes_a_valid_spec_and_its_report(tmp_path: Path) -> None:
    source = _write(tmp_path / "palazzo.json", _palazzo())
    spec = tmp_path / "out" / "palazzo.yaml"
    done = _infer(str(source), "-o", str(spec))
    assert done.returncode == 0, done.stderr
    assert "IoU at least 1.000" in done.stdout
    report = json.loads((tmp_path / "out" / "palazzo.infer.json").read_text())
    assert report["rectangles"] == 20 and report["layers"] == 5 and report["iou_min"] == 1.0
    assert report["spec_lines"] == len(
        [line for line in spec.read_text().splitlines() if line.strip()[:1] not in ("", "#")]
    )
    validate = subprocess.run(
        [sys.executable, "-m", "facadecli", "validate", str(spec)], capture_output=True, text=True
    )
    assert validate.returncode == 0, validate.stderr
    quick = _infer(str(source), "-o", str(tmp_path / "quick.yaml"), "--no-check")
    assert quick.returncode == 0 and "iou" not in json.loads(
        (tmp_path / "quick.infer.json").read_text()
    )


def test_facade_infer_rejects_a_layout_without_elements(tmp_path: Path) -> None:
    empty = _write(
        tmp_path / "empty.json", [{"label": "facade", "x0": 0, "y0": 0, "x1": 1, "y1": 1}]
    )
    done = _infer(str(empty), "-o", str(tmp_path / "empty.yaml"))
    assert done.returncode == 2 and "no elements" in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "empty.yaml").exists()


def test_a_solved_example_infers_back(tmp_path: Path) -> None:
    solved = subprocess.run(
        [
            sys.executable,
            "-m",
            "facadecli",
            "solve",
            str(ROOT / "specs" / "residential-house.yaml"),
            "-o",
            str(tmp_path),
            "-f",
            "json",
        ],
        capture_output=True,
        text=True,
    )
    assert solved.returncode == 0, solved.stderr
    (layout,) = tmp_path.glob("*.layout.json")
    done = _infer(str(layout), "-o", str(tmp_path / "back.yaml"))
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "back.infer.json").read_text())
    assert report["solves"] and report["iou_min"] >= 0.9
    assert all(r["solves"] for r in report["retargets"])


def test_runs_become_counters_and_a_wider_facade_gains_bays(tmp_path: Path) -> None:
    from facadecli import solve
    from facadecli.solve import retarget

    inferred = infer(_write(tmp_path / "palazzo.json", _palazzo()), "palazzo")
    # mirrored, its end bays the only ones that could repeat: a word a layer (``bays``)
    assert "(window_w1 window_gx" in inferred.text and "counters:" in inferred.text
    spec = parse_spec(inferred.text, "palazzo.yaml")
    windows = {}
    for width in (11.4, 17.1):
        layout = solve(retarget(spec, width, 10.0))
        shown = [s for s in layout.shapes if s.layer == "window" and s.visible]
        windows[width] = (len(shown), {round(s.x1 - s.x0, 1) for s in shown})
    assert windows[11.4] == (9, {1.2})
    assert windows[17.1][0] == 15 and windows[17.1][1] <= {1.1, 1.2, 1.3}  # 5 bays, not wider


def test_layers_on_the_same_columns_stay_aligned_at_other_widths(tmp_path: Path) -> None:
    """Blinds over the windows' columns, in rows of their own: the two layers share their
    x gaps, so at other widths every blind is still over its window (with gaps of their
    own, the sizing QP spread the change differently over each, as the windows' width is
    held by a floor of windows on other columns too). Here the bays are each drawn once,
    so both layers follow one sequence of bays, each inner bay on a counter."""
    from facadecli import solve
    from facadecli.solve import retarget

    rects = []
    for x in (0.9, 2.9, 5.5, 8.3):  # uneven bays: no run, every gap a symbol of its own
        for y in (2.0, 5.0):
            rects.append({"label": "window", "x0": x, "y0": y, "x1": x + 1.2, "y1": y + 1.5})
            rects.append({"label": "blind", "x0": x, "y0": y + 1.6, "x1": x + 1.2, "y1": y + 2})
    for x in (2.0, 7.0):  # windows of the same size on other columns, without blinds
        rects.append({"label": "window", "x0": x, "y0": 8.0, "x1": x + 1.2, "y1": 9.5})
    rects.append({"label": "door", "x0": 4.4, "y0": 0.0, "x1": 5.3, "y1": 1.8})
    inferred = infer(_write(tmp_path / "blinds.json", rects), "blinds")
    # one set of gaps: the bays' (each bay drawn once, on counters), else one layer's
    one_set = ("blind_gx" in inferred.text) != ("window_gx" in inferred.text)
    assert "bays_m1" in inferred.text or one_set
    spec = parse_spec(inferred.text, "blinds.yaml")
    for width in (8.0, 17.1):
        layout = solve(retarget(spec, width, 10.0))
        spans = {
            label: sorted(
                {
                    (round(s.x0, 6), round(s.x1, 6))
                    for s in layout.shapes
                    if s.layer == label and s.visible
                }
            )
            for label in ("window", "blind")
        }
        # a narrower façade drops bays (windows and blinds alike), never all of them: at
        # 8 m (0.7x) the end bay, whose two columns the attic window over them made one
        # bay, 3.5 m, what the façade loses (before copies no denser than the façade,
        # ``bays._gains``, it dropped the attic bay too and copied a column at its drawn
        # pitch: three columns left)
        assert len(spans["blind"]) >= 2 and set(spans["blind"]) <= set(spans["window"])


def test_a_runs_jittered_elements_are_one_size_kept_at_every_size(tmp_path: Path) -> None:
    """Hand annotation jitters: windows of 1.16-1.24 m in a run are one size (their
    median, one symbol), and a run's elements keep it (``min`` = ``max``), so a retargeted
    façade gains or drops bays of windows at the input's size; the door, which does not
    repeat, keeps its size too (its bay is one, never repeated: a narrower façade drops
    window bays around it), and the ledge across the façade is not held (it stretches)."""
    from facadecli import solve
    from facadecli.solve import retarget

    rects: list[dict[str, object]] = [
        {"label": "window", "x0": 1.0 + 2.0 * k, "y0": 5.0, "x1": 1.0 + 2.0 * k + w, "y1": 6.5}
        for k, w in enumerate((1.2, 1.16, 1.24, 1.19, 1.21))
    ]
    rects.append({"label": "door", "x0": 4.5, "y0": 0.0, "x1": 5.7, "y1": 2.4})
    rects.append({"label": "cornice", "x0": 0.0, "y0": 8.0, "x1": 11.4, "y1": 8.4})
    inferred = infer(_write(tmp_path / "jitter.json", rects), "jitter")
    spec = parse_spec(inferred.text, "jitter.yaml")
    assert "window_w2" not in spec.symbols
    window = spec.symbols["window_w1"]
    assert window.size == pytest.approx(1.2, abs=2e-3)
    assert window.min == window.max == window.size
    assert spec.symbols["door_w1"].min == spec.symbols["door_w1"].max == pytest.approx(1.2)
    assert spec.symbols["cornice_w1"].min is None
    counts = []
    for width in (8.0, 11.4, 17.1):
        layout = solve(retarget(spec, width, 10.0))
        widths = [round(s.x1 - s.x0, 4) for s in layout.shapes if s.layer == "window" and s.visible]
        assert widths and all(w == pytest.approx(window.size, abs=1e-4) for w in widths)
        counts.append(len(widths))
    assert counts[0] < counts[1] == 5 < counts[2]  # bays dropped and gained


def test_a_mirrored_floor_is_written_reflected_and_stays_mirrored(tmp_path: Path) -> None:
    """Three windows either side of a centred door: the windows' word reads the same
    backwards, so it is written as its left half and that half reflected, each half with
    its run of windows under one counter; a wider façade gains as many windows on the
    right as on the left (written whole, only one of the two runs could repeat)."""
    from facadecli import solve
    from facadecli.solve import retarget

    lefts = [1.0, 2.8, 4.6]
    rects: list[dict[str, object]] = []
    for x in [*lefts, *(14.4 - a - 1.2 for a in reversed(lefts))]:
        for y in (5.0, 8.0):
            rects.append({"label": "window", "x0": x, "y0": y, "x1": x + 1.2, "y1": y + 1.5})
    rects.append({"label": "door", "x0": 6.6, "y0": 0.0, "x1": 7.8, "y1": 2.6})
    inferred = infer(_write(tmp_path / "mirrored.json", rects, width=14.4), "mirrored")
    (window,) = [line for line in inferred.text.splitlines() if "name: window" in line]
    assert ")^-1" in window and window.count("^bays1") == 2
    spec = parse_spec(inferred.text, "mirrored.yaml")
    assert check(inferred, spec)["iou_min"] == 1.0
    layout = solve(retarget(spec, 21.6, 10.0))
    row = sorted(
        (s.x0, s.x1)
        for s in layout.shapes
        if s.layer == "window"
        and s.visible
        and s.y0 == min(t.y0 for t in layout.shapes if t.layer == "window")
    )
    assert len(row) > 6 and len(row) % 2 == 0
    assert all(abs(a[0] + b[1] - 21.6) < 1e-6 for a, b in zip(row, reversed(row), strict=True))


def test_openings_nothing_covers_are_unoccludable(tmp_path: Path) -> None:
    """The door is clear in the input, so its symbols are unoccludable; a pillar in front
    of a window (CMP draws pillars over windows) covers it, so the windows' are not."""
    rects = [*_palazzo()]
    rects.append({"label": "pillar", "x0": 2.5, "y0": 3.0, "x1": 2.9, "y1": 9.0})
    inferred = infer(_write(tmp_path / "pillar.json", rects), "pillar")
    spec = parse_spec(inferred.text, "pillar.yaml")
    assert spec.qualifiers("door_w1").unoccludable and spec.qualifiers("door_h1").unoccludable
    assert not spec.qualifiers("window_w1").unoccludable
    assert check(inferred, spec)["iou_min"] == 1.0


def test_a_band_a_sliver_short_of_the_edge_stretches_with_the_facade(tmp_path: Path) -> None:
    """A cornice drawn 4 cm short of the façade's left edge: the sliver is not kept as a
    gap, which the sizing would grow as much as the cornice (a wider façade left the
    cornice metres short of its edge); the cornice spans every width."""
    from facadecli import solve
    from facadecli.solve import retarget

    rects = [*_palazzo()]
    rects.append({"label": "cornice", "x0": 0.04, "y0": 9.4, "x1": 11.4, "y1": 9.8})
    inferred = infer(_write(tmp_path / "cornice.json", rects), "cornice")
    spec = parse_spec(inferred.text, "cornice.yaml")
    assert check(inferred, spec)["iou"]["cornice"] >= 0.99  # type: ignore[index]
    for width in (8.0, 17.1):
        layout = solve(retarget(spec, width, 10.0))
        (cornice,) = [s for s in layout.shapes if s.layer == "cornice" and s.visible]
        assert (cornice.x0, cornice.x1) == (0.0, pytest.approx(width))


def _widths(spec_text: str, name: str, width: float, layer: str) -> list[float]:
    from facadecli import solve
    from facadecli.solve import retarget

    layout = solve(retarget(parse_spec(spec_text, f"{name}.yaml"), width, 10.0))
    return [round(s.x1 - s.x0, 6) for s in layout.shapes if s.layer == layer and s.visible]


def _two_doors() -> list[dict[str, object]]:
    """Two doors under their columns of windows between two narrow window columns, on a
    9.6 x 11 façade: the doors' bays (unique) span 0.72 of it, so the bays cannot narrow
    to 0.7 and each layer keeps a word of its own."""
    rects: list[dict[str, object]] = [
        {"label": "window", "x0": x, "y0": y, "x1": x + w, "y1": y + 1.5}
        for x, w in ((0.3, 0.4), (2.0, 1.2), (6.4, 1.2), (8.9, 0.4))
        for y in (3.0, 5.5, 8.0)
    ]
    rects += [{"label": "door", "x0": x, "y0": 0.0, "x1": x + 1.2, "y1": 2.6} for x in (2.0, 6.4)]
    return rects


def test_an_element_that_does_not_repeat_never_grows_beyond_what_the_input_shows(
    tmp_path: Path,
) -> None:
    """The palazzo's door and shop front appear once: a wider façade widens the wall
    around them, not them (without a bound, the sizing spread the extra width over every
    letter of the word, and a 1.2 m door became 3.1 m at 1.5x). Where each layer keeps a
    word of its own (the palazzo, mirrored, its end bays the only ones that could repeat;
    two doors' bays too wide to narrow), a narrower façade may shrink an opening to fit,
    to ``SQUEEZE`` of its size at most."""
    inferred = infer(_write(tmp_path / "palazzo.json", _palazzo()), "palazzo")
    spec = parse_spec(inferred.text, "palazzo.yaml")
    assert spec.symbols["door_w1"].max == pytest.approx(1.2)
    assert spec.symbols["door_w1"].min == pytest.approx(SQUEEZE * 1.2)  # it may shrink
    assert _widths(inferred.text, "palazzo", 17.1, "door") == [pytest.approx(1.2)]
    assert _widths(inferred.text, "palazzo", 17.1, "shop") == [pytest.approx(2.2)]
    assert all(w <= 1.2 + 1e-6 for w in _widths(inferred.text, "palazzo", 6.0, "door"))
    inferred = infer(_write(tmp_path / "doors.json", _two_doors(), 9.6), "doors")
    assert inferred.bays.startswith("not shared"), inferred.bays
    spec = parse_spec(inferred.text, "doors.yaml")
    assert spec.symbols["door_w1"].max == pytest.approx(1.2)
    assert spec.symbols["door_w1"].min == pytest.approx(SQUEEZE * 1.2)  # it may shrink
    assert _widths(inferred.text, "doors", 14.4, "door") == [pytest.approx(1.2)] * 2
    narrow = _widths(inferred.text, "doors", 6.72, "door")
    assert narrow and all(SQUEEZE * 1.2 - 1e-6 <= w <= 1.2 + 1e-6 for w in narrow)


def test_elements_that_fill_their_word_without_gaps_stretch_with_the_facade(
    tmp_path: Path,
) -> None:
    """Two shop fronts side by side across the whole width leave no gap to take a
    wider façade's extra width: they get no bound and grow with it (with one, the façade
    would have no layout at 1.5x)."""
    rects: list[dict[str, object]] = [
        {"label": "shop", "x0": a, "y0": 0.0, "x1": b, "y1": 2.6}
        for a, b in ((0.0, 5.0), (5.0, 11.4))
    ]
    rects.append({"label": "window", "x0": 5.1, "y0": 5.0, "x1": 6.3, "y1": 6.5})
    inferred = infer(_write(tmp_path / "shops.json", rects), "shops")
    spec = parse_spec(inferred.text, "shops.yaml")
    assert spec.symbols["shop_w1"].max is None and spec.symbols["window_w1"].max is not None
    shops = _widths(inferred.text, "shops", 17.1, "shop")
    assert len(shops) == 2 and sum(shops) == pytest.approx(17.1) and min(shops) > 5.0
