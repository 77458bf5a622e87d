"""Hostile and broken layouts for ``facade grammar``: every one ends in exit 2 with its place
(file:line:col, and the JSON path), no traceback, and nothing written; the work is bounded
(rectangles, cells, the time limit over every stage)."""

from __future__ import annotations

import json
import random
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from facadecli.errors import SearchLimitError, SpecError
from facadecli.grammar import deadline as deadlines
from facadecli.grammar.cmp_xml import read_cmp
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.extract import rederivation_problems
from facadecli.grammar.inputs import RECTS_MAX, LabelledLayout, Rect
from facadecli.grammar.json_layouts import read_plain
from facadecli.grammar.model import Options, check_options
from facadecli.grammar.outputs import tiling_svg
from facadecli.grammar.regions import Grid
from facadecli.grammar.regularize import regularize
from facadecli.grammar.search import extract
from facadecli.grammar.symmetry import find_repeats
from facadecli.grammar.tidy import CELLS_MAX
from facadecli.grammar.tiling import tile
from tests.running import facade as run_facade


def facade(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str]:
    """(exit code, stderr) of one command run in this process; never a traceback."""
    code, _, err = run_facade(capsys, *args)
    return code, err


def refused(capsys: pytest.CaptureFixture[str], path: Path, *args: str) -> str:
    """The command's errors for a layout it must refuse: exit 2, nothing written."""
    out = path.parent / "out"
    code, err = facade(capsys, "grammar", str(path), "-o", str(out), *args)
    assert code == 2, err
    assert not out.exists()
    return err


def cmp_object(top: str, bottom: str, left: str, right: str, label: str = "window") -> str:
    return (
        f"<object><points><x>{top}</x><x>{bottom}</x><y>{left}</y><y>{right}</y></points>"
        f"<label>3</label><labelname>{label}</labelname><flag>1</flag></object>"
    )


GOOD = cmp_object("0.1", "0.3", "0.2", "0.4")  # one line; its second <x> is at column 27


# -- CMP XML -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "place", "message"),
    [
        (f"{GOOD}\n{GOOD[:-20]}", "2:1", "<object> is not closed before the file ends"),
        (f"{GOOD}\n{GOOD}</object>", "2:136", "not XML: mismatched tag"),
        (cmp_object("0.1", "0.3", "0.2", "0.4", "&lt;window&gt;"), "1:82", "unknown label"),
        (cmp_object("0.1", "0.3", "0.2", "0.4", "roof"), "1:82", "use one of background"),
        (cmp_object("0.1", "0.3", "0.2", "0.4", "&xxe;"), "1:93", "undefined entity"),
        (cmp_object("0.1", "0.3", "0.2", "0.4", "&#0;"), "1:93", "invalid character number"),
        (cmp_object("0.1", "0.3", "0.2", "0.4", "win\x01dow"), "1:96", "U+0001 cannot be in XML"),
        (cmp_object("0.1", "0.3", "0.2", "0.4", " "), "1:82", "the label is empty"),
        (cmp_object("0.1", "nan", "0.2", "0.4"), "1:27", "<x> 'nan' is not a number"),
        (cmp_object("0.1", "inf", "0.2", "0.4"), "1:27", "<x> 'inf' is not a number"),
        (cmp_object("0.1", "1e308", "0.2", "0.4"), "1:27", "outside the image"),
        (cmp_object("-1e308", "0.3", "0.2", "0.4"), "1:17", "outside the image"),
        (cmp_object("0.1", "1.5", "0.2", "0.4"), "1:27", "outside the image"),
        (cmp_object("0.1", "0.3", "0.2", "1_0"), "1:47", "'1_0' is not a number"),
        (cmp_object("0.3", "0.1", "0.2", "0.4"), "1:27", "no area: its second <x> (0.1)"),
        (cmp_object("0.1", "0.3", "0.4", "0.4"), "1:47", "give the columns in increasing order"),
        (GOOD.replace("<x>0.1</x>", ""), "1:9", "<points> has 1 <x>, not 2"),
        (GOOD.replace("<labelname>window</labelname>", ""), "1:1", "has 0 <labelname>"),
        (GOOD.replace("<flag>", "<colour/><flag>"), "1:111", "<colour> inside <object>"),
        (f"{GOOD} windows {GOOD}", "1:134", "text 'windows' between objects"),
        (
            '<!DOCTYPE l [<!ENTITY a "aa"><!ENTITY b "&a;&a;">]>' + GOOD.replace("window", "&b;"),
            "1:1",
            "a DTD is not read",
        ),
        (
            f'{GOOD}\n<!DOCTYPE x [<!ENTITY e SYSTEM "file:///etc/passwd">]>',
            "2:1",
            "a DTD is not read",
        ),
    ],
)
def test_a_broken_cmp_annotation_is_refused_at_its_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, text: str, place: str, message: str
) -> None:
    path = tmp_path / "f.xml"
    path.write_text(text, encoding="utf-8")
    err = refused(capsys, path)
    assert f"f.xml:{place}: error: " in err and message in err, err


def test_every_bad_value_of_a_cmp_file_is_reported_at_once(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "f.xml"
    lines = [
        GOOD,
        cmp_object("0.1", "inf", "0.2", "0.4"),
        cmp_object("0.1", "0.3", "0.5", "0.4", "roof"),
    ]
    path.write_text("\n".join(lines))
    err = refused(capsys, path)
    errors = [line for line in err.splitlines() if ": error" in line]  # not the progress
    assert [line.split(": error")[0] for line in errors] == [
        f"{path}:2:27",
        f"{path}:3:47",
        f"{path}:3:82",
    ]


def test_500_kb_of_unclosed_objects_end_at_once(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "f.xml"
    path.write_text("<object>" * 64_000)  # 512 KB: the regular expressions took minutes
    err = refused(capsys, path)
    assert "f.xml:1:9: error: <object> inside <object>" in err


def test_text_that_once_took_quadratic_time_ends_at_once(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "f.xml"  # a coordinate of 200,000 digits and a letter
    path.write_text(cmp_object("0.1", "0." + "1" * 200_000 + "x", "0.2", "0.4"))
    assert "f.xml:1:27: error: <x> '0.1111" in refused(capsys, path)
    plain = tmp_path / "f.json"  # 500 KB of quotes and escapes: one string, never closed
    plain.write_text('"\\' * 250_000)
    assert "f.json:1:1: error: not JSON: Unterminated string" in refused(capsys, plain)


def test_a_truncated_file_and_bad_bytes_are_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "f.xml"
    path.write_text(GOOD + "\n" + GOOD[:40])  # cut inside the second <x>
    assert "f.xml:2:37: error: <y> is not closed" in refused(capsys, path)
    path.write_bytes(GOOD.encode() + b"\n<object>\xff</object>")
    assert "f.xml:2:9: error: not UTF-8 text" in refused(capsys, path)


def test_cmp_lines_end_in_carriage_returns_and_edges_may_overshoot_a_little(
    tmp_path: Path,
) -> None:
    path = tmp_path / "f.xml"  # the database's files end lines in CR alone
    body = "\r".join([GOOD, cmp_object("-0.004", "1.005", "0.5", "0.6", "door")])
    path.write_bytes(("\ufeff" + '<?xml version="1.0" encoding="UTF-8"?>\r' + body).encode())
    door = read_cmp(path).rects[1]
    assert (door.x0, door.y0, door.x1, door.y1) == (0.5, 0.0, 0.6, 1.0)  # clipped to 0..1
    path.write_bytes(body.replace("0.6", "0.4").encode())
    with pytest.raises(SpecError, match=r"f\.xml:2:52: error: the object has no area"):
        read_cmp(path)


def test_more_rectangles_than_the_limit_are_refused_before_the_work(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "f.xml"
    path.write_text("\n".join([GOOD] * (RECTS_MAX + 1)))
    assert f"f.xml:{RECTS_MAX + 1}:1: error: more than 20,000 rectangles" in refused(capsys, path)
    plain = tmp_path / "f.json"
    plain.write_text("[" + ",".join(["{}"] * (RECTS_MAX + 1)) + "]")
    assert "f.json:1:1: error: more than 20,000 rectangles" in refused(capsys, plain)


# -- JSON ----------------------------------------------------------------------------------

RECT = '{"label": "window", "x0": 1, "y0": 1, "x1": 2, "y1": 2}'


@pytest.mark.parametrize(
    ("text", "place", "message"),
    [
        ('{"canvas": {"width": NaN, "height": 3},\n "rects": []}', "1:22", "NaN is not a number"),
        ('[{"label": "w", "x0": 1, "y0": -Infinity, "x1": 2, "y1": 2}]', "1:32", "-Infinity"),
        ("[" * 100_000 + "]" * 100_000, "1:65", "nested deeper than 64"),
        ('{"canvas": {"width": 0, "height": 3},\n "rects": [' + RECT + "]}", "1:22", "width: 0"),
        ('{"canvas": {"width": 5, "height": -3}, "rects": []}', "1:35", "canvas.height: -3"),
        ('{"canvas": {"width": 5}, "rects": []}', "1:12", "canvas has no 'height'"),
        ('{"canvas": [5, 3], "rects": []}', "1:12", "canvas is a list, not an object"),
        (
            '[\n  {"label": "w", "x0": "1", "y0": 1, "x1": 2, "y1": 2}]',
            "2:24",
            "[0].x0 is a string",
        ),
        ('[{"label": "w", "x0": 1, "y0": 1, "x1": 2}]', "1:2", "[0] has no 'y1'"),
        ('[{"label": "w", "x0": 1, "y0": true, "x1": 2, "y1": 2}]', "1:32", "true or false"),
        ('[{"label": "w", "x0": 1, "y0": 1e400, "x1": 2, "y1": 2}]', "1:32", "[0].y0: inf is too"),
        ('[{"label": "w", "x0": 1, "y0": 1' + "0" * 5000 + ', "x1": 2, "y1": 2}]', "1:32", "large"),
        ('[{"label": "w", "x0": 1, "y0": 1, "x1": 2, "y1": 2e7}]', "1:50", "at most 1e+06"),
        ('[{"label": "w\\u0000", "x0": 1, "y0": 1, "x1": 2, "y1": 2}]', "1:12", "U+0000"),
        ('[{"label": "\\ud800", "x0": 1, "y0": 1, "x1": 2, "y1": 2}]', "1:12", "U+D800"),
        ('[{"label": "", "x0": 1, "y0": 1, "x1": 2, "y1": 2}]', "1:12", "the label is empty"),
        ('[{"label": 3, "x0": 1, "y0": 1, "x1": 2, "y1": 2}]', "1:12", "[0].label is a number"),
        ('[{"label": "w", "x0": 3, "y0": 1, "x1": 2, "y1": 2}]', "1:2", "has no area"),
        ('[{"label": "w", "x0": 1, "y0": 1, "x1": 2, "y1": 2, "Z": 1}]', "1:58", "unknown key"),
        (
            '{"rects": [' + RECT + '], "canvas": {"width": 1.5, "height": 3}}',
            "1:56",
            "x1 is 2, outside",
        ),
        ('[{"label": "w", "x0": -3, "y0": 1, "x1": 2, "y1": 2}]', "1:23", "x0 is -3, outside"),
        ('{"rects": {"a": 1}}', "1:11", "rects is an object, not a list"),
        ('"rectangles"', "1:1", "the top level is a string"),
        ('{"rects": [' + RECT + "],}", "1:69", "not JSON"),
    ],
)
def test_a_broken_json_layout_is_refused_at_its_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, text: str, place: str, message: str
) -> None:
    path = tmp_path / "f.json"
    path.write_text(text)
    err = refused(capsys, path)
    assert f"f.json:{place}: error: " in err and message in err, err


def test_json_problems_name_the_path_and_the_line_of_the_value(tmp_path: Path) -> None:
    path = tmp_path / "f.json"
    rects = [json.loads(RECT) for _ in range(4)]
    rects[3]["x0"] = "left"
    rects[1]["y1"] = None
    path.write_text(json.dumps({"canvas": {"width": 9, "height": 9}, "rects": rects}, indent=1))
    with pytest.raises(SpecError) as caught:
        read_plain(path)
    lines = path.read_text().splitlines()
    found = [(p.line, p.message) for p in caught.value.problems]
    assert [message for _, message in found] == [
        "rects[1].y1 is null, not a number",
        "rects[3].x0 is a string, not a number",
    ]
    assert lines[found[0][0] - 1].strip() == '"y1": null'  # type: ignore[operator]
    assert lines[found[1][0] - 1].strip() == '"x0": "left",'  # type: ignore[operator]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"shapes": {"x": 1}}, "shapes is an object, not a list of shapes"),
        ({"canvas": {"width": 6, "height": 0}}, "canvas.height: 0 is not a façade size"),
        ({"layers": [{"name": "other"}]}, "shapes[0].layer: no layer 'base'"),
        ({"shape": {"visible": "yes"}}, "shapes[0].visible is a string, not true or false"),
        ({"shape": {"x0": 4, "x1": 2}}, "shape 1 is inverted"),
        ({"shape": {"y": "P\u0007"}}, "shapes[0].y: the label holds the character U+0007"),
        ({"shape": {"x1": 60}}, "shapes[0].x1 is 60, outside the façade"),
    ],
)
def test_a_broken_layout_report_is_refused_at_its_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, change: dict[str, object], message: str
) -> None:
    shape = {"layer": "base", "x": "A", "y": "P", "x0": 0, "x1": 2, "y0": 0, "y1": 1}
    shape |= {"visible": True, **change.pop("shape", {})}  # type: ignore[dict-item]
    report = {"canvas": {"width": 6, "height": 3}, "layers": [{"name": "base"}]}
    report |= {"shapes": [shape], **change}
    path = tmp_path / "f.layout.json"
    path.write_text(json.dumps(report))
    err = refused(capsys, path)
    assert "f.layout.json:1:" in err and message in err, err


# -- labels in the outputs -----------------------------------------------------------------


def test_the_svg_is_well_formed_whatever_the_labels_and_the_name(tmp_path: Path) -> None:
    layout = LabelledLayout(4, 3, (Rect("<a & b>", 1, 1, 2, 2), Rect("c]]>", 2, 1, 3, 2)))
    tiling = tile(layout, 0)
    grammar = extract(tiling, "greedy").grammar
    svg = tiling_svg(tiling, grammar, "name\x00with\ud800odd\x1bcharacters")
    texts = [e.text for e in ET.fromstring(svg.encode()).iter() if e.text]
    assert "<a & b>" in texts and "c]]>" in texts
    assert any(t.startswith("name\ufffdwith\ufffdodd\ufffdcharacters") for t in texts)


def test_a_derived_layout_of_a_file_with_spaces_in_its_name(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "my house.json"
    path.write_text(f"[{RECT}]")
    out = tmp_path / "out"
    code, err = facade(capsys, "grammar", str(path), "-o", str(out), "--derive", "6x4")
    assert code == 0, err
    assert (out / "my house.grammar.txt").exists() and (out / "my_house-6x4.layout.json").exists()


# -- numbers of the options ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (("--split-cost", "inf"), "--split-cost"),
        (("--repeat-cost", "1e300"), "--repeat-cost"),
        (("--snap", "nan"), "--snap"),
        (("--time-limit", "nan"), "--time-limit"),
        (("--size", "infx3"), "--size"),
        (("--derive", "nanx3"), "--derive"),
    ],
)
def test_options_that_are_not_finite_are_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, args: tuple[str, ...], option: str
) -> None:
    path = tmp_path / "f.json"
    path.write_text(f"[{RECT}]")
    assert option in refused(capsys, path, *args)


def test_options_are_checked_for_callers_of_the_library_too() -> None:
    with pytest.raises(SpecError, match="--time-limit: error: inf"):
        check_options(Options(time_limit=float("inf")))
    with pytest.raises(SpecError, match="--size: error: a size must be above 0"):
        check_options(Options(size=(0.0, 3.0)))


# -- bounded work --------------------------------------------------------------------------


def _random_rects(n: int, seed: int = 0) -> list[dict[str, object]]:
    rng = random.Random(seed)
    rects: list[dict[str, object]] = []
    for _ in range(n):
        x0, x1 = sorted((rng.random(), rng.random()))
        y0, y1 = sorted((rng.random(), rng.random()))
        rects.append({"label": rng.choice("abc"), "x0": x0, "y0": y0, "x1": x1, "y1": y1})
    return rects


def test_a_tiling_of_too_many_cells_is_refused_before_the_work(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "f.json"
    path.write_text(json.dumps(_random_rects(600)))  # 1,201 x 1,201 cells without snapping
    err = refused(capsys, path, "--snap", "0")
    assert f"at most {CELLS_MAX:,}" in err and "--snap (now 0)" in err


def test_snapping_removes_no_rectangle(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "f.json"
    rects = [{"label": "w", "x0": 0.5, "y0": 0.5, "x1": 0.5 + i * 1e-4, "y1": 1} for i in (1, 2)]
    path.write_text(json.dumps({"canvas": {"width": 1, "height": 1}, "rects": rects}))
    code, err = facade(capsys, "grammar", str(path), "-o", str(tmp_path / "out"), "--snap", "0.01")
    assert code == 0 and "kept 2 of 2 rectangles" in err  # thinner than the snap: kept


def test_cells_thinner_than_the_rederivation_tolerance_rederive_exactly() -> None:
    layout = LabelledLayout(
        10,
        10,
        (
            Rect("b", 2.0497884699533806, 1.8142236519530908, 9.870492712990124, 4.36313082209),
            Rect("c", 3.221736100147395, 1.8150776407371494, 4.12835441535112, 2.96775123266, 1),
        ),
    )  # a row of b 0.00085 high under c: the check once took c to cover it
    tiling = tile(layout, 0)
    assert rederivation_problems(extract(tiling, "greedy").grammar, tiling) == []


def _passed() -> Deadline:
    """A deadline whose hard limit has passed already."""
    late = Deadline(0.0, "f.json")
    late.hard = -1.0
    return late


def test_every_stage_before_the_first_grammar_ends_at_the_hard_time_limit() -> None:
    layout = LabelledLayout(4, 3, (Rect("w", 1, 1, 2, 2), Rect("w", 2.5, 1, 3.5, 2)))
    for stage, work in [
        ("tiling", lambda: tile(layout, 0, deadline=_passed())),
        ("tiling", lambda: regularize(layout, 0.01, deadline=_passed())),
        ("building the greedy grammar", lambda: extract(tile(layout, 0), deadline=_passed())),
    ]:
        with pytest.raises(SearchLimitError, match=f"f.json: error: time limit .* while {stage}"):
            work()


def test_the_time_limit_ends_the_command_with_exit_4_and_nothing_written(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(deadlines, "GRACE", -100.0)  # the hard limit passed at the start
    path = tmp_path / "f.json"
    path.write_text(f"[{RECT}]")
    out = tmp_path / "out"
    code, err = facade(capsys, "grammar", str(path), "-o", str(out), "--time-limit", "1")
    assert code == 4 and "time limit of 1 s passed" in err and "before any grammar" in err
    assert not out.exists()


def test_the_search_for_repeats_stops_at_its_share_of_the_time_and_says_so() -> None:
    rects = tuple(Rect("w", 1 + 2 * i, 1, 2 + 2 * i, 2) for i in range(4))
    tiling = tile(LabelledLayout(9, 3, rects), 0)
    assert find_repeats(Grid(tiling)).complete
    stopped = find_repeats(Grid(tiling), deadline=Deadline(0.0))
    assert not stopped.complete and stopped.kinds >= 1  # the seeds are kept
    found = extract(tiling, "adp", 50, deadline=Deadline(0.0))
    assert found.repeats_stopped == "time" and found.iterations == 1
