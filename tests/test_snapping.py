"""Snapping nearby edges of a labelled layout (``tiling.snap``, ``snap_layout``): clusters
of bounded width, never chains; no rectangle is ever removed; the report counts what moved.

Every fixture is made here by hand (small CMP-like annotations and JSON lists)."""

from __future__ import annotations

import itertools
import json
import random
import statistics
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from facadecli.errors import SearchLimitError
from facadecli.grammar import tiling
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.extract import extract_grammar
from facadecli.grammar.inputs import LabelledLayout, Rect
from facadecli.grammar.model import Options
from facadecli.grammar.read import read_layout
from facadecli.grammar.tiling import snap, snap_and_count, snap_layout, tile
from tests.running import facade

# -- fixtures ------------------------------------------------------------------------------


def cmp_text(rects: list[tuple[str, float, float, float, float]]) -> str:
    """CMP XML of (label, x0, y0, x1, y1) on the unit square, y up (CMP rows count down)."""
    return "\n".join(
        f"<object><points><x>{1 - y1:.6f}</x><x>{1 - y0:.6f}</x><y>{x0:.6f}</y>"
        f"<y>{x1:.6f}</y></points><label>3</label><labelname>{label}</labelname>"
        "<flag>1</flag></object>"
        for label, x0, y0, x1, y1 in rects
    )


def pilasters() -> list[tuple[str, float, float, float, float]]:
    """Like CMP's cmp_b0008: pilasters drawn as stacked pieces (base, shaft, capital) whose
    sides drift by 0.0024 from piece to piece, so their x edges make chains each within
    0.005 of the next over more than 0.03; windows with sills between them, a little off."""
    rects = [("facade", 0.0, 0.0, 1.0, 1.0)]
    for c in (0.1, 0.4, 0.7):
        y = 0.1
        for k in range(8):
            x0 = c + 0.0024 * (k % 5)
            width = (0.0121, 0.0169, 0.0218)[k % 3]
            height = 0.006 if k % 2 else 0.09
            rects.append(("pillar", x0, y, x0 + width, y + height))
            y += height
    for floor in range(3):
        for c in (0.15, 0.45, 0.75):
            off = 0.002 * ((floor + int(c * 10)) % 3 - 1)
            y0 = 0.15 + 0.22 * floor + off
            rects.append(("window", c + off, y0, c + 0.15 - off, y0 + 0.12))
            rects.append(("sill", c - 0.01, y0 - 0.006, c + 0.16, y0))
    return rects


def frieze() -> list[tuple[str, float, float, float, float]]:
    """A row of deco pieces 0.004 wide side by side (each edge 0.004 from the next): one
    chain from 0.3 to 0.34 at the default snap of 0.005."""
    pieces = [("deco", 0.3 + 0.004 * i, 0.8, 0.304 + 0.004 * i, 0.85) for i in range(10)]
    return [("facade", 0.0, 0.0, 1.0, 1.0), *pieces, ("cornice", 0.0, 0.85, 1.0, 0.87)]


def staircase() -> list[tuple[str, float, float, float, float]]:
    """A column of windows each drawn 0.004 right of the one below, and thin pillars
    (mullions 0.003 wide, thinner than the snap, drawn over the windows) in their middles."""
    rects = [("facade", 0.0, 0.0, 1.0, 1.0)]
    for floor in range(6):
        x0, y0 = 0.2 + 0.004 * floor, 0.05 + 0.15 * floor
        rects.append(("window", x0, y0, x0 + 0.1, y0 + 0.1))
        rects.append(("pillar", x0 + 0.0485, y0, x0 + 0.0515, y0 + 0.1))
    return rects


def small() -> list[tuple[str, float, float, float, float]]:
    """The annotation of tests/test_grammar_input.py's CMP fixture."""
    return [
        ("facade", 0, 0, 1, 1),
        ("window", 0.2, 0.7, 0.4, 0.9),
        ("balcony", 0.1, 0.65, 0.5, 0.75),
        ("door", 0.451, 0.0, 0.6, 0.2),
    ]


CMP_LIKE = {"pilasters": pilasters, "frieze": frieze, "staircase": staircase, "small": small}


def write_cmp(folder: Path, name: str) -> Path:
    path = folder / f"{name}.xml"
    path.write_text(cmp_text(CMP_LIKE[name]()))
    return path


def write_plain(path: Path, width: float, height: float, rects: list[Rect]) -> Path:
    data = [{"label": r.label, "x0": r.x0, "y0": r.y0, "x1": r.x1, "y1": r.y1} for r in rects]
    path.write_text(json.dumps({"canvas": {"width": width, "height": height}, "rects": data}))
    return path


def thin_pillars() -> list[Rect]:
    """On a 10 x 10 façade: three pillars 0.03 wide (the snap 0.005 is 0.05 here), each
    between two windows whose sides are drawn 0.005 or 0.01 off the pillar's."""
    rects = []
    for i, x in enumerate((2.0, 5.0, 8.0)):
        rects.append(Rect("window", x - 1.5, 2.0, x - 0.01, 8.0))
        rects.append(Rect("window", x + 0.035 + 0.005 * (i % 2), 2.0, x + 1.0, 8.0))
        rects.append(Rect("pillar", x, 1.0, x + 0.03, 9.0))
    return rects


def labels(layout: LabelledLayout) -> Counter[str]:
    return Counter(r.label for r in layout.rects)


def clusters(mapping: dict[float, float]) -> list[list[float]]:
    """The values of a snap mapping grouped by target, in order."""
    groups: dict[float, list[float]] = {}
    for value in sorted(mapping):
        groups.setdefault(mapping[value], []).append(value)
    return list(groups.values())


# -- no chains -----------------------------------------------------------------------------


def test_a_chain_of_near_edges_is_not_joined_end_to_end() -> None:
    values = [0.100, 0.104, 0.108, 0.112, 0.116, 0.120]  # each 0.004 from the next
    mapping = snap(values, 0.005)
    assert mapping[0.100] != mapping[0.120]
    assert all(c[-1] - c[0] <= 0.005 for c in clusters(mapping))
    assert clusters(mapping) == [[0.100, 0.104], [0.108, 0.112], [0.116, 0.120]]  # fewest
    assert all(abs(mapping[v] - v) <= 0.005 for v in values)


def test_a_chain_is_cut_where_edges_move_least() -> None:
    # gaps 0.4, 0.6, 0.1 of the tolerance: a sweep from the left would part the last two
    mapping = snap([1.0, 1.4, 2.0, 2.1], 1.0)
    assert clusters(mapping) == [[1.0, 1.4], [2.0, 2.1]]
    assert mapping[1.0] == mapping[1.4] == 1.2 and mapping[2.0] == mapping[2.1] == 2.05


def test_a_cluster_goes_where_most_of_its_edges_are() -> None:
    # nine edges at 0.5 and one at 0.503: the nine stay, the one moves (a weighted median)
    assert snap([0.5] * 9 + [0.503], 0.005)[0.503] == 0.5
    mapping = snap([0.0, 0.5, 0.503], 0.005, (0.0, 1.0))  # one edge each: the middle
    assert mapping[0.5] == mapping[0.503] == pytest.approx(0.5015)
    assert (mapping[0.0], mapping[1.0]) == (0.0, 1.0)


def test_the_facades_edges_stay_put() -> None:
    mapping = snap([0.002, 0.004, 0.997], 0.005, (0.0, 1.0))
    assert mapping[0.002] == mapping[0.004] == 0.0 and mapping[0.997] == 1.0


def test_a_staircase_column_stays_a_staircase(tmp_path: Path) -> None:
    layout = read_layout(write_cmp(tmp_path, "staircase"))[0]
    snapped, snapping = snap_and_count(layout, 0.005)
    lefts = sorted(r.x0 for r in snapped.rects if r.label == "window")
    assert lefts[-1] - lefts[0] > 0.015  # drawn 0.02 apart in steps of 0.004
    assert snapping.max_move_share <= 0.005


def _best(values: list[float], tolerance: float) -> tuple[int, float]:
    """The fewest clusters at most ``tolerance`` wide, and the least total move to their
    medians among those, by trying every way to cut the sorted values."""
    found = []
    for cuts in itertools.product((False, True), repeat=len(values) - 1):
        groups, group = [], [values[0]]
        for value, cut in zip(values[1:], cuts, strict=True):
            if cut:
                groups.append(group)
                group = []
            group.append(value)
        groups.append(group)
        if all(g[-1] - g[0] <= tolerance for g in groups):
            moved = sum(abs(v - statistics.median_low(g)) for g in groups for v in g)
            found.append((len(groups), moved))
    return min(found)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.integers(0, 400), min_size=1, max_size=60),  # integers: many equal gaps
    st.integers(0, 60),
    st.booleans(),
)
def test_clusters_are_never_wider_than_the_tolerance_and_keep_the_order(
    ints: list[int], tolerance: int, scaled: bool
) -> None:
    values = [n / 397 if scaled else float(n) for n in ints]
    tol = tolerance / 397 if scaled else float(tolerance)
    mapping = snap(values, tol)
    assert all(group[-1] - group[0] <= tol for group in clusters(mapping))
    targets = [mapping[v] for v in sorted(mapping)]
    assert targets == sorted(targets)  # order kept: distinct clusters, distinct targets
    assert all(abs(mapping[v] - v) <= tol for v in values)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.integers(0, 60), min_size=1, max_size=11, unique=True), st.integers(0, 20))
def test_clusters_are_the_fewest_and_move_edges_least(ints: list[int], tolerance: int) -> None:
    values = sorted(float(n) for n in ints)
    groups = clusters(snap(values, float(tolerance)))
    moved = sum(abs(v - statistics.median_low(g)) for g in groups for v in g)
    count, least = _best(values, float(tolerance))
    assert len(groups) == count and moved == pytest.approx(least)


def test_the_loop_and_numpy_weigh_candidates_alike(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = random.Random(1)
    for _ in range(40):
        values = [rng.randrange(2000) / 1000 for _ in range(rng.randrange(1, 300))]
        tolerance = rng.choice([0.01, 0.05, 0.2])
        found = []
        for wide in (0, 10**9):  # numpy always, the loop always
            monkeypatch.setattr(tiling, "WIDE", wide)
            found.append(snap(values, tolerance, (0.0, 2.0)))
        assert found[0] == found[1]


def test_snapping_ends_at_the_hard_time_limit() -> None:
    late = Deadline(0.0, "f.json")
    late.hard = -1.0
    layout = LabelledLayout(1.0, 1.0, (Rect("window", 0.1, 0.1, 0.2, 0.2),))
    with pytest.raises(SearchLimitError, match="while snapping edges"):
        snap_and_count(layout, 0.005, late)


# -- no rectangle removed --------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(CMP_LIKE))
@pytest.mark.parametrize("share", [None, 0.02, 0.1])
def test_every_rectangle_comes_out_with_its_label(
    tmp_path: Path, name: str, share: float | None
) -> None:
    path = write_cmp(tmp_path, name)
    layout = read_layout(path)[0]
    extraction = extract_grammar(path, Options(iterations=20, snap=share))
    assert labels(extraction.layout) == labels(layout)
    assert all(r.x1 > r.x0 and r.y1 > r.y0 for r in extraction.layout.rects)
    assert extraction.snapping.rectangles == len(layout.rects)
    assert extraction.problems == []
    if share is None:  # at the default snap every label still shows (a snap of 10% may
        # leave an element wholly under another: it is in the layout, not in the tiling)
        shown = {label for row in extraction.tiling.labels for label in row}
        hidden = {"facade", "sill"} if name == "pilasters" else {"facade"}  # drawn over
        assert shown >= set(labels(layout)) - hidden


def test_the_frieze_keeps_every_piece(tmp_path: Path) -> None:
    layout = read_layout(write_cmp(tmp_path, "frieze"))[0]
    snapped, snapping = snap_and_count(layout, 0.005)
    pieces = sorted((r.x0, r.x1) for r in snapped.rects if r.label == "deco")
    assert len(pieces) == 10 and all(x1 > x0 for x0, x1 in pieces)
    assert all(a[1] <= b[0] for a, b in itertools.pairwise(pieces))  # still a row
    tiling = tile(snapped, tolerance=0.0)
    assert [tiling.label_at((x0 + x1) / 2, 0.82) for x0, x1 in pieces] == ["deco"] * 10
    assert snapping.summary()["kept_from_collapsing"] >= 1


def test_thin_pillars_survive_with_their_labels(tmp_path: Path) -> None:
    path = write_plain(tmp_path / "pillars.json", 10.0, 10.0, thin_pillars())
    extraction = extract_grammar(path, Options(iterations=20, snap=0.005))
    pillars = [r for r in extraction.layout.rects if r.label == "pillar"]
    assert len(pillars) == 3 and len(extraction.layout.rects) == 9
    for pillar in pillars:
        assert pillar.x1 - pillar.x0 >= 0.02  # drawn 0.03 wide, the snap is 0.05
        assert extraction.tiling.label_at((pillar.x0 + pillar.x1) / 2, 5.0) == "pillar"
    summary = extraction.snapping.summary()
    assert summary["kept_from_collapsing"] == 3 and summary["kept_by_label"] == {"pillar": 3}
    assert any("kept 3 of 9 rectangles" in w and "pillar 3" in w for w in extraction.warnings)


def test_a_thin_element_on_the_facades_edge_keeps_an_area() -> None:
    layout = LabelledLayout(1.0, 1.0, (Rect("pillar", 0.0, 0.0, 0.002, 1.0),))
    (pillar,) = snap_layout(layout, 0.005).rects
    assert (pillar.x0, pillar.x1) == (0.0, 0.002)


def test_a_rectangle_off_the_facade_stays_as_drawn() -> None:
    off = Rect("deco", -0.009, 0.2, -0.002, 0.3)  # within the readers' 1% slack
    layout = LabelledLayout(1.0, 1.0, (off, Rect("window", 0.1, 0.2, 0.3, 0.302)))
    deco, window = snap_layout(layout, 0.005).rects
    assert (deco.label, deco.x0, deco.x1) == ("deco", -0.009, -0.002)  # x as drawn
    assert deco.y1 > deco.y0 and window.y1 > window.y0


@settings(max_examples=150, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from(["window", "pillar", "sill"]),
            st.integers(0, 999),
            st.integers(0, 999),
            st.integers(1, 40),
            st.integers(1, 40),
        ),
        min_size=1,
        max_size=40,
    ),
    st.sampled_from([0.001, 0.005, 0.02, 0.1]),
)
def test_snapping_removes_nothing_and_moves_edges_at_most_the_snap(
    drawn: list[tuple[str, int, int, int, int]], share: float
) -> None:
    rects = tuple(
        Rect(label, x / 1000, y / 1000, min(x + w, 1000) / 1000, min(y + h, 1000) / 1000, i)
        for i, (label, x, y, w, h) in enumerate(drawn)
        if x + 1 <= 999 and y + 1 <= 999
    )
    layout = LabelledLayout(
        1.0, 2.0, tuple(Rect(r.label, r.x0, 2 * r.y0, r.x1, 2 * r.y1, r.z) for r in rects)
    )
    snapped, snapping = snap_and_count(layout, share)
    assert [(r.label, r.z) for r in snapped.rects] == [(r.label, r.z) for r in layout.rects]
    assert all(r.x1 > r.x0 and r.y1 > r.y0 for r in snapped.rects)
    for before, after in zip(layout.rects, snapped.rects, strict=True):
        assert abs(after.x0 - before.x0) <= share and abs(after.x1 - before.x1) <= share
        assert abs(after.y0 - before.y0) <= 2 * share and abs(after.y1 - before.y1) <= 2 * share
    assert snapping.max_move_share <= share and snapping.rectangles == len(layout.rects)


# -- the report ----------------------------------------------------------------------------


def test_the_report_counts_the_edges_snapping_moved(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    rects = [Rect("window", 1.0, 1.0, 2.0, 2.0), Rect("window", 3.0, 1.02, 4.0, 2.0)]
    path = write_plain(tmp_path / "two.json", 5.0, 3.0, rects)
    code, _, err = facade(capsys, "grammar", path, "-o", tmp_path / "out", "--snap", "0.01")
    assert code == 0, err
    report = json.loads((tmp_path / "out" / "two.grammar-report.json").read_text())
    assert report["snapping"] == {
        "snap": 0.01,
        "rectangles": 2,
        "edges": 7,  # x 1, 2, 3, 4 and y 1, 1.02, 2
        "edges_moved": 2,  # 1 and 1.02 to 1.01
        "max_move": 0.01,
        "max_move_share": round(0.01 / 3, 6),
        "kept_from_collapsing": 0,
        "kept_by_label": {},
    }
    assert not any("snapping" in w for w in report["warnings"]) and "warning" not in err


def test_the_warning_and_the_report_say_which_elements_were_kept(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = write_plain(tmp_path / "pillars.json", 10.0, 10.0, thin_pillars())
    out = tmp_path / "out"
    code, _, err = facade(capsys, "grammar", path, "-o", out, "--snap", "0.005", "-n", "20")
    assert code == 0, err
    report = json.loads((out / "pillars.grammar-report.json").read_text())
    snapping = report["snapping"]
    assert snapping["kept_from_collapsing"] == 3 and snapping["kept_by_label"] == {"pillar": 3}
    # the windows either side of a pillar face each other across it: their edges keep to
    # within an eighth of that gap (tiling.move_limits), so none reaches the pillar
    assert 0 <= snapping["max_move_share"] <= 0.005
    assert "warning: snapping edges closer than 0.005 of the façade moved" in err
    assert "kept 3 of 9 rectangles thinner than that from collapsing (pillar 3)" in err
    assert report["warnings"][0] in err


def test_snap_zero_changes_nothing(tmp_path: Path) -> None:
    path = write_cmp(tmp_path, "pilasters")
    layout = read_layout(path)[0]
    extraction = extract_grammar(path, Options(iterations=5, snap=0.0, tolerance=0.0))
    assert extraction.layout == layout
    assert extraction.snapping.summary()["edges_moved"] == 0
    assert extraction.snapping.summary()["snap"] == 0.0


def test_same_input_same_bytes(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = write_cmp(tmp_path, "pilasters")
    written = []
    for run in ("a", "b"):
        code, _, err = facade(capsys, "grammar", path, "-o", tmp_path / run, "-n", "50")
        assert code == 0, err
        written.append({p.name: p.read_bytes() for p in sorted((tmp_path / run).iterdir())})
    assert written[0] == written[1] and "pilasters.grammar-report.json" in written[0]
