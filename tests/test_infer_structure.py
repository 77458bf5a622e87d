"""``facade infer``: one structure per façade, right at every size (issue 34, items 2, 3).

Generated annotations only (jittered grids of windows with sills, drawn as a hand draws
them, and the generated family of ``tests/benchmarks/annotated_family``), never the CMP
samples: the spec has one window symbol and counters, and solved at other sizes it gains
or drops whole bays and floors at the input's size and pitch, with the sills under their
windows and mirrored façades mirrored.
"""

from __future__ import annotations

import itertools
import json
import math
import random
from collections.abc import Callable
from pathlib import Path

import pytest

from facadecli import parse_spec, solve
from facadecli.errors import InfeasibleError
from facadecli.grammar.inputs import LabelledLayout, Rect
from facadecli.grammar.model import Options
from facadecli.infer import run
from facadecli.infer.floors import Floors, by_floors, follows
from facadecli.infer.layers import Grid, frames, grids, top_floors
from facadecli.infer.run import RECUT_KEEP, at_input_size, infer, solved_layout
from facadecli.infer.structure import NEAR, structured
from facadecli.solve import retarget
from tests.benchmarks.annotated_family import cmp_xml, family

WIDTH, HEIGHT = 15.0, 12.0
PITCH_Y = 2.6


def _grid(path: Path, seed: int, bays: int = 5, floors: int = 4) -> Path:
    """Windows (1.2 x 1.5 m) with sills (0.2 m) under them on ``bays`` x ``floors``, every
    size jittered by up to 1% and every position by up to 1 cm (an edge moves at most an
    eighth of the narrowest thing it bounds: the sill under the window)."""
    rng = random.Random(seed)
    pitch_x = (WIDTH - 2.0) / bays
    rects = []
    for f in range(floors):
        for k in range(bays):
            cx = 1.0 + (k + 0.5) * pitch_x + rng.uniform(-0.01, 0.01)
            y0 = 1.5 + f * PITCH_Y + rng.uniform(-0.01, 0.01)
            w, h = 1.2 * (1 + rng.uniform(-0.01, 0.01)), 1.5 * (1 + rng.uniform(-0.01, 0.01))
            rects.append(
                {"label": "window", "x0": cx - w / 2, "y0": y0, "x1": cx + w / 2, "y1": y0 + h}
            )
            rects.append(
                {"label": "sill", "x0": cx - 0.7, "y0": y0 - 0.2, "x1": cx + 0.7, "y1": y0}
            )
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": HEIGHT}, "rects": rects}))
    return path


def _solved(path: Path, width: float, height: float) -> list[Rect]:
    inference = infer(path, path.stem)
    spec = parse_spec(inference.text, path.stem)
    layout = solve(retarget(spec, width, height))
    return list(solved_layout(layout, spec, inference).rects)


def _of(rects: list[Rect], label: str) -> list[Rect]:
    return [r for r in rects if r.label == label]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_jittered_grid_is_one_window_symbol_and_counters(tmp_path: Path, seed: int) -> None:
    inference = infer(_grid(tmp_path / "grid.json", seed), "grid")
    spec = parse_spec(inference.text, "grid")
    windows = [name for name in spec.symbols if name.startswith(("window_w", "window_h"))]
    assert sorted(windows) == ["window_h1", "window_w1"]
    window_layers = [layer for layer in spec.layers if layer.name.startswith("window")]
    assert len(window_layers) == 1
    assert len(spec.counters) == 2  # bays and floors, shared by the windows and their sills


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("share", [0.7, 1.5, 2.0])
def test_other_widths_gain_or_drop_bays_of_windows_at_their_size(
    tmp_path: Path, seed: int, share: float
) -> None:
    path = _grid(tmp_path / "grid.json", seed)
    spec = parse_spec(infer(path, "grid").text, "grid")
    size = spec.symbols["window_w1"].size
    rects = _solved(path, WIDTH * share, HEIGHT)
    windows = _of(rects, "window")
    assert all(r.x1 - r.x0 == pytest.approx(size, abs=1e-4) for r in windows)
    bays = len(windows) / 4
    assert bays == int(bays)  # every floor alike
    assert 0.85 <= bays / (5 * share) <= 1.15 or abs(bays - 5 * share) < 1  # density kept
    assert (bays > 5) if share > 1 else (bays < 5)
    for sill in _of(rects, "sill"):  # each sill under a window, centred as drawn
        centre = (sill.x0 + sill.x1) / 2
        assert any(
            abs((w.x0 + w.x1) / 2 - centre) < 0.01 and abs(w.y0 - sill.y1) < 0.01 for w in windows
        )


def test_a_taller_facade_gains_floors_at_the_inputs_pitch(tmp_path: Path) -> None:
    path = _grid(tmp_path / "grid.json", 4)
    windows = _of(_solved(path, WIDTH, HEIGHT * 1.5), "window")
    floors = sorted({round(r.y0, 4) for r in windows})
    assert len(floors) > 4
    pitches = [b - a for a, b in itertools.pairwise(floors)]
    assert all(p == pytest.approx(PITCH_Y, abs=0.05) for p in pitches)


@pytest.mark.parametrize(
    "seed", [s for s in range(1, 40) if family(s)[1].mirrored and family(s)[1].bays % 2][:3]
)
def test_a_mirrored_family_facade_stays_mirrored_and_the_door_single(
    tmp_path: Path, seed: int
) -> None:
    """Mirrored halves with the door in the middle bay (an odd number of bays: with an
    even one the family's door is off the middle, and the façade is not mirrored)."""
    path = tmp_path / f"family-{seed}.xml"
    path.write_text(cmp_xml(family(seed)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    width = inference.layout.width * 1.5
    layout = solve(retarget(spec, width, inference.layout.height))
    rects = list(solved_layout(layout, spec, inference).rects)
    assert len(_of(rects, "door")) == 1
    windows = _of(rects, "window")
    mirrored = [
        any(
            abs((q.x0 + q.x1) / 2 - (width - (r.x0 + r.x1) / 2)) < 0.15 and abs(q.y0 - r.y0) < 0.15
            for q in windows
        )
        for r in windows
    ]
    # as the bench counts it: 90% of the windows have their mirror image (a window whose
    # edge the tidy-up may not move as far as the structure asks stays as drawn)
    assert sum(mirrored) >= 0.9 * len(windows)


def test_structure_shares_sizes_and_lines_but_keeps_small_neighbours_apart() -> None:
    rects = [
        Rect("window", 1.0, 1.0, 2.2, 2.5),
        Rect("window", 1.03, 4.0, 2.21, 5.52),  # the same column and size, drawn 3 cm off
        Rect("deco", 5.0, 1.0, 5.1, 1.1),  # two small neighbours 12 cm apart: not merged
        Rect("deco", 5.12, 1.0, 5.22, 1.1),
        Rect("sill", 0.95, 0.9, 2.3, 1.0),  # under the first window, 2.5 cm off its centre
    ]
    out = structured(LabelledLayout(10.0, 10.0, tuple(rects))).rects
    assert out[0].x1 - out[0].x0 == out[1].x1 - out[1].x0
    assert (out[0].x0 + out[0].x1) / 2 == pytest.approx((out[1].x0 + out[1].x1) / 2, abs=1e-9)
    assert (out[4].x0 + out[4].x1) / 2 == pytest.approx((out[0].x0 + out[0].x1) / 2, abs=1e-9)
    assert out[2].x1 <= out[3].x0  # the small neighbours stay apart
    for before, after in zip(rects, out, strict=True):
        for a, b in (
            (before.x0 + before.x1, after.x0 + after.x1),
            (before.y0 + before.y1, after.y0 + after.y1),
        ):
            assert abs(a - b) / 2 <= NEAR * 10.0 + 1e-9


def _overlapping(rects: list[Rect]) -> int:
    shown = [r for r in rects if r.label in ("window", "door")]
    return sum(
        min(a.x1, b.x1) - max(a.x0, b.x0) > 0.01 and min(a.y1, b.y1) - max(a.y0, b.y0) > 0.01
        for a, b in itertools.combinations(shown, 2)
    )


@pytest.mark.parametrize("seed", [2, 5, 9, 24])
@pytest.mark.parametrize("share", [1.5, 2.0])
def test_a_family_facade_solved_wider_gains_bays_with_no_opening_over_another(
    tmp_path: Path, seed: int, share: float
) -> None:
    """A floor's windows drawn a few centimetres apart (a sill or a blind holds an edge)
    are one row, and the door between the ground floor's windows shares their word: the
    layers of a floor gain bays together, never over one another."""
    path = tmp_path / f"family-{seed}.xml"
    path.write_text(cmp_xml(family(seed)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    layout = solve(retarget(spec, 15.0 * share, 15.0))
    rects = list(solved_layout(layout, spec, inference).rects)
    assert _overlapping(rects) == 0
    assert len(_of(rects, "door")) == 1
    known = family(seed)[1]
    assert len(_of(rects, "window")) / known.windows >= 0.85 * share  # bays gained


def test_the_ground_floor_stays_on_the_ground_as_a_taller_facade_gains_floors(
    tmp_path: Path,
) -> None:
    """A door between the ground floor's windows, the floors above at one pitch: 1.5 times
    as tall, the door and the ground floor keep their height and place, and whole floors
    are added above at the input's pitch, over nothing."""
    rng = random.Random(7)
    rects = []
    for f in range(4):
        for k in range(5):
            cx = 2.3 + k * 2.6 + rng.uniform(-0.01, 0.01)
            if f == 0 and k == 2:
                rects.append(
                    {"label": "door", "x0": cx - 0.7, "y0": 0.0, "x1": cx + 0.7, "y1": 2.6}
                )
                continue
            y0 = 1.5 + f * PITCH_Y + rng.uniform(-0.01, 0.01)
            rects.append(
                {"label": "window", "x0": cx - 0.6, "y0": y0, "x1": cx + 0.6, "y1": y0 + 1.5}
            )
    path = tmp_path / "door.json"
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": HEIGHT}, "rects": rects}))
    solved = _solved(path, WIDTH, HEIGHT * 1.5)
    (door,) = _of(solved, "door")
    assert door.y0 == pytest.approx(0.0, abs=1e-6)
    assert door.y1 == pytest.approx(2.6, abs=0.03)
    windows = _of(solved, "window")
    floors = sorted({round(r.y0, 2) for r in windows})
    assert floors[0] == pytest.approx(1.5, abs=0.03)
    assert len(floors) >= 6
    assert all(b - a == pytest.approx(PITCH_Y, abs=0.05) for a, b in itertools.pairwise(floors))
    assert _overlapping(solved) == 0


def test_a_door_between_windows_shares_their_word_and_so_do_grids_of_a_label_on_a_floor() -> None:
    window = Grid("window", ((1.0, 2.0), (5.0, 6.0)), ((1.5, 3.0),))
    door = Grid("door", ((3.0, 4.0),), ((0.0, 3.0),))
    upper = Grid("window", ((1.0, 2.0), (3.0, 4.0), (5.0, 6.0)), ((4.0, 5.5),))
    found = frames([window, door, upper])
    assert (
        found[0]
        == found[1]
        == (
            ((1.0, 2.0), "window"),
            ((3.0, 4.0), "door"),
            ((5.0, 6.0), "window"),
        )
    )
    assert found[2] is None  # above the door: not beside it
    # a ground-floor window drawn a few centimetres off the others' rows joins their word
    other = Grid("window", ((7.0, 8.0),), ((1.4, 3.0),))
    assert frames([window, door, other]) == [(*found[0], ((7.0, 8.0), "window"))] * 3
    # a grid on the window's columns (one drawn over it) is one unit with it: one word
    inner = Grid("window", ((1.0, 2.0), (5.0, 6.0)), ((1.8, 2.8),))
    assert frames([window, door, inner]) == [found[0]] * 3
    # a grid of two floors whose upper column stands over the door's keeps its own word
    # (one word cannot hold both): the ground floor's others still share theirs
    tall = Grid("window", ((3.2, 3.8),), ((1.4, 3.0), (4.0, 5.5)))
    assert frames([window, door, other, tall]) == [
        (*found[0], ((7.0, 8.0), "window")),
        (*found[0], ((7.0, 8.0), "window")),
        (*found[0], ((7.0, 8.0), "window")),
        None,
    ]


def _two_kinds(path: Path, seed: int) -> Path:
    """One floor of windows of random widths, every other one with its head and sill 20-30
    cm higher (as CMP draws the windows of one floor: two grids of one label on
    overlapping rows, some widths in both)."""
    rng = random.Random(seed)
    rects, x, k = [], rng.uniform(0.8, 1.5), 0
    while x + 1.6 < 14.2:
        w = rng.uniform(0.9, 1.6)
        y0, y1 = (3.0, 4.6) if k % 2 == 0 else (3.3, 4.8)
        rects.append({"label": "window", "x0": x, "y0": y0, "x1": x + w, "y1": y1})
        x, k = x + w + rng.uniform(0.4, 1.2), k + 1
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": 8.0}, "rects": rects}))
    return path


@pytest.mark.parametrize("seed", [1, 3, 6])
@pytest.mark.parametrize("share", [0.7, 1.5])
def test_a_floors_windows_drawn_in_two_grids_never_meet_at_other_widths(
    tmp_path: Path, seed: int, share: float
) -> None:
    """The two grids of the floor share one x word, each showing its own windows: solved
    narrower or wider, their windows never overlap (each grid in a word of its own
    narrowed its gaps on its own: 2 overlaps at 0.7x). The floor's bays are each drawn
    a little unlike, so each inner bay has a counter (bays drawn once): narrower, the
    floor drops windows, wider it gains them; at the input's width the counters are
    at their drawn counts, so the high and low windows alternate as drawn."""
    path = _two_kinds(tmp_path / f"two-kinds-{seed}.json", seed)
    drawn = json.loads(path.read_text())["rects"]
    inference = infer(path, path.stem)
    assert len(inference.grids) == 2
    solved = _solved(path, WIDTH * share, 8.0)
    windows = sorted(_of(solved, "window"), key=lambda r: r.x0)
    assert (len(windows) < len(drawn)) if share < 1 else (len(windows) > len(drawn))
    assert _overlapping(solved) == 0
    at_input = sorted(_of(_solved(path, WIDTH, 8.0), "window"), key=lambda r: r.x0)
    assert [r.y0 > 3.1 for r in at_input] == [k % 2 == 1 for k in range(len(drawn))]  # order


TWO_FLOORS = 7.0  # m: the height of a façade of two floors (and a roof's margin)


def _two_floors(path: Path, seed: int) -> Path:
    """A ground floor (a door between windows) under one upper floor, every window with its
    sill: no run of floors anywhere; the upper floor drawn 2 cm off the ground floor's
    rows and every edge jittered by up to 1 cm."""
    rng = random.Random(seed)
    rects = []
    for f in range(2):
        for k in range(5):
            cx = 2.3 + k * 2.6 + rng.uniform(-0.01, 0.01)
            if f == 0 and k == 2:
                rects.append(
                    {"label": "door", "x0": cx - 0.7, "y0": 0.0, "x1": cx + 0.7, "y1": 2.6}
                )
                continue
            y0 = 1.5 + f * (PITCH_Y + 0.02) + rng.uniform(-0.01, 0.01)
            rects.append(
                {"label": "window", "x0": cx - 0.6, "y0": y0, "x1": cx + 0.6, "y1": y0 + 1.5}
            )
            rects.append(
                {"label": "sill", "x0": cx - 0.7, "y0": y0 - 0.2, "x1": cx + 0.7, "y1": y0}
            )
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": TWO_FLOORS}, "rects": rects}))
    return path


def test_the_top_floor_is_its_labels_top_row_with_a_floor_like_it_below() -> None:
    ground = Grid("window", ((1.0, 2.0), (5.0, 6.0)), ((1.5, 3.0),))
    upper = Grid("window", ((1.0, 2.0), (3.0, 4.0), (5.0, 6.0)), ((4.1, 5.6),))
    sills = Grid("sill", ((0.9, 2.1), (2.9, 4.1)), ((1.3, 1.5), (3.9, 4.1)))
    attic = Grid("window", ((3.0, 4.0),), ((7.0, 7.5),))  # too short to be a floor's
    band = Grid("balcony", ((0.1, 9.9),), ((2.0, 2.5), (4.5, 5.0)))  # across the façade
    assert top_floors([ground, upper, sills, band], 10.0, 10.0) == {
        1: pytest.approx(2.6),  # from the ground floor's windows below its own
        2: pytest.approx(2.6),  # its own rows: two floors of sills
    }
    # an attic's windows over it are no floor like it: it still repeats (the attic moves
    # up with its copies), and so does no floor under a floor like it
    assert top_floors([ground, upper, attic], 10.0, 10.0) == {1: pytest.approx(2.6)}
    over = Grid("window", ((3.0, 4.0),), ((6.7, 8.2),))  # a floor like it over it
    assert top_floors([ground, upper, over], 10.0, 10.0) == {2: pytest.approx(2.6)}
    assert top_floors([ground, upper], 10.0, 5.0) == {}  # 2.6 m: more than a floor of 5 m


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("share", [1.0, 1.5, 2.0])
def test_a_facade_of_two_floors_gains_floors_with_their_sills_at_its_pitch(
    tmp_path: Path, seed: int, share: float
) -> None:
    path = _two_floors(tmp_path / "two.json", seed)
    solved = _solved(path, WIDTH, TWO_FLOORS * share)
    windows, sills = _of(solved, "window"), _of(solved, "sill")
    floors = sorted({round(r.y0, 2) for r in windows})
    assert floors[0] == pytest.approx(1.5, abs=0.03)  # the ground floor stays
    # whole floors over the top one: as many as fit in the height gained (the roof's
    # margin takes the rest, never less than drawn)
    pitch, gained = PITCH_Y + 0.02, TWO_FLOORS * (share - 1)
    assert len(floors) == 2 + int(gained / pitch)
    assert all(
        b - a == pytest.approx(PITCH_Y + 0.02, abs=0.05) for a, b in itertools.pairwise(floors)
    )
    assert len(windows) == 4 + 5 * (len(floors) - 1)  # every new floor has all its bays
    assert len(sills) == len(windows)  # and a sill under each window
    for window in windows:
        centre = (window.x0 + window.x1) / 2
        assert any(
            abs((s.x0 + s.x1) / 2 - centre) < 0.03 and abs(s.y1 - window.y0) < 0.03 for s in sills
        )
    assert _overlapping(solved) == 0
    (door,) = _of(solved, "door")
    assert (door.y0, door.y1) == (pytest.approx(0.0, abs=1e-6), pytest.approx(2.6, abs=0.03))


@pytest.mark.parametrize(
    "seed", [s for s in range(25, 80) if family(s)[1].floors == 2][:3]
)  # façades of the family the bench does not measure
def test_a_family_facade_of_two_floors_gains_floors_when_taller(tmp_path: Path, seed: int) -> None:
    path = tmp_path / f"family-{seed}.xml"
    path.write_text(cmp_xml(family(seed)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    layout = solve(retarget(spec, 15.0, 15.0 * 1.5))
    rects = list(solved_layout(layout, spec, inference).rects)
    known = family(seed)[1]
    assert len(_of(rects, "window")) >= known.windows + known.bays  # a floor more, at least
    assert _overlapping(rects) == 0
    assert len(_of(rects, "door")) == 1


def _behind_an_opening(rects: list[Rect]) -> list[Rect]:
    """The sills and blinds wholly inside a window or a door (drawn over them: hidden)."""
    openings = [r for r in rects if r.label in ("window", "door")]
    return [
        r
        for r in rects
        if r.label in ("sill", "blind")
        and any(
            o.x0 <= r.x0 + 1e-6
            and r.x1 <= o.x1 + 1e-6
            and o.y0 <= r.y0 + 1e-6
            and r.y1 <= o.y1 + 1e-6
            for o in openings
        )
    ]


def test_a_taller_family_facade_keeps_its_first_floor_over_the_ground_floor(
    tmp_path: Path,
) -> None:
    """Family seed 4 at 1.5 times its height: the floors it gains go over the top, so the
    first upper floor keeps the gap over the ground floor's windows it was drawn with
    (1.24 m; it slid 0.75 m down), and no sill or blind is left behind a window."""
    path = tmp_path / "family-4.xml"
    path.write_text(cmp_xml(family(4)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    rects = list(solved_layout(solve(retarget(spec, 15.0, 22.5)), spec, inference).rects)
    drawn = sorted({round(r.y0, 3) for r in _of(list(inference.layout.rects), "window")})
    rows = sorted({round(r.y0, 3) for r in _of(rects, "window")})
    assert len(rows) > len(drawn)  # floors gained
    assert rows[:2] == pytest.approx(drawn[:2], abs=0.01)
    assert _behind_an_opening(rects) == []


def _top_floor_sills(path: Path, seed: int) -> Path:
    """Five floors of windows (the ground floor's too) at one pitch, sills under the top
    floor's alone; every edge jittered by up to 1 cm."""
    rng = random.Random(seed)
    rects = []
    for f in range(5):
        for k in range(5):
            cx = 2.3 + k * 2.6 + rng.uniform(-0.01, 0.01)
            y0 = 1.2 + f * PITCH_Y + rng.uniform(-0.01, 0.01)
            rects.append(
                {"label": "window", "x0": cx - 0.6, "y0": y0, "x1": cx + 0.6, "y1": y0 + 1.5}
            )
            if f == 4:
                rects.append(
                    {"label": "sill", "x0": cx - 0.7, "y0": y0 - 0.2, "x1": cx + 0.7, "y1": y0}
                )
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": 15.0}, "rects": rects}))
    return path


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("share", [0.8, 1.3, 1.5])
def test_what_stands_on_the_top_floor_stays_on_it_as_floors_are_gained_or_dropped(
    tmp_path: Path, seed: int, share: float
) -> None:
    """The openings' floors are one sequence every layer on them follows, with their one
    counter: shorter or taller, the top floor's sills stay under the top floor's windows
    (they stood where a dropped floor was, or under a gained one)."""
    solved = _solved(_top_floor_sills(tmp_path / "top.json", seed), WIDTH, 15.0 * share)
    windows, sills = _of(solved, "window"), _of(solved, "sill")
    top = max(r.y0 for r in windows)
    assert len({round(r.y0, 2) for r in windows}) != 5  # floors gained or dropped
    assert len(sills) == 5
    for sill in sills:
        centre = (sill.x0 + sill.x1) / 2
        assert any(
            abs((w.x0 + w.x1) / 2 - centre) < 0.03 and abs(sill.y1 - w.y0) < 0.03
            for w in windows
            if w.y0 == top
        )


def test_a_labels_grids_are_cut_by_floor_so_that_they_follow_the_floors() -> None:
    """Five floors of windows with sills, the second upper floor lacking one column's
    sill (a hand left it out), each sill a millimetre or two off its floor's pitch: cut by
    column, the floors' sills stood in a grid of three columns and one of two, and
    neither is alike on every floor of the run, so no sill was gained with a floor;
    re-cut by floor, the columns every floor shows are one grid on all five floors that
    follows the floors, and the third column's sills are a grid of their own."""
    columns = [(1.0, 2.0), (4.0, 5.0), (7.0, 8.0)]
    rects = []
    for f in range(5):
        y0 = 1.5 + 3 * f
        for k, (x0, x1) in enumerate(columns):
            rects.append(Rect("window", x0, y0, x1, y0 + 1.5))
            if (f, k) != (2, 2):
                low = y0 - 0.2 + 0.001 * (f % 3)
                rects.append(Rect("sill", x0, low, x1, low + 0.2))
    found = grids(LabelledLayout(9.0, 16.0, tuple(rects)))
    floors = Floors(cut=12.65, pitch=3.0, copies=3)
    assert not any(g.label == "sill" and follows(g.rows, floors) for g in found)
    recut = by_floors(found, floors)
    sills = [g for g in recut if g.label == "sill"]
    following = [g for g in sills if follows(g.rows, floors)]
    assert [(g.columns, len(g.rows)) for g in following] == [(tuple(columns[:2]), 5)]
    assert sum(g.elements for g in sills) == 14
    assert [g for g in recut if g.label == "window"] == [g for g in found if g.label == "window"]


def test_a_taller_family_facade_gains_its_floors_with_their_sills(tmp_path: Path) -> None:
    """Family seed 4 at 1.5 times its height: every floor the run of floors gains has the
    sills of the bays whose sills stand alike on every floor of the run (three of four:
    the door's bay drew its first upper floor's sill taller). Cut by column, the sills of
    a floor stood in other layers than the floor over it's, none followed the floors, and
    the floors gained had none."""
    path = tmp_path / "family-4.xml"
    path.write_text(cmp_xml(family(4)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    rects = list(solved_layout(solve(retarget(spec, 15.0, 22.5)), spec, inference).rects)
    drawn = {round(r.y0, 2) for r in _of(list(inference.layout.rects), "window")}
    windows = _of(rects, "window")
    top = max(r.y0 for r in windows)
    gained = sorted({round(r.y0, 2) for r in windows} - drawn - {round(top, 2)})
    assert gained  # floors gained under the top one
    sills = [r for r in _of(rects, "sill") if r.y1 - r.y0 > 0.1]
    for row in gained:
        held = [
            w
            for w in windows
            if round(w.y0, 2) == row
            and any(abs(s.y1 - w.y0) < 0.03 and s.x0 < (w.x0 + w.x1) / 2 < s.x1 for s in sills)
        ]
        assert len(held) >= 3, row


def test_the_grids_re_cut_by_floor_keep_the_facades_1x_fidelity(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Family-with-defects seed 14: re-cut by floor, its spec's y words changed and its two
    bay counters of equal pitch solved 0 and 2 at 1x where drawn 1 and 1 (mean IoU 0.9035
    -> 0.8807). The re-cut is kept only within ``RECUT_KEEP`` of the cut's 1x fidelity."""
    path = tmp_path / "family-14.xml"
    path.write_text(cmp_xml(family(14, defects=True)[0]))

    def fidelity_at_1x() -> float:
        inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
        faithful = at_input_size(inference)
        assert faithful is not None
        return faithful.iou_mean

    gated = fidelity_at_1x()
    monkeypatch.setattr(run, "RECUT_KEEP", -1.0)  # never kept: the cut as before
    assert gated >= fidelity_at_1x() - RECUT_KEEP


def test_a_sill_drawn_on_its_windows_edges_keeps_them() -> None:
    """Sills snapped to their windows' edges, fewer sills than windows: each label's sizes
    clustered alone have medians 1.12 and 1.125 m, and the spec would write each window's
    and its sill's edges a few millimetres apart (family seed 10's spec did, and its bays
    no longer solved at 1x). Elements of two labels on one span keep one size."""
    widths = [1.10, 1.12, 1.13, 1.14]
    windows = [
        Rect("window", 1.0 + 2.0 * k, 3.0, 1.0 + 2.0 * k + w, 4.5) for k, w in enumerate(widths)
    ]
    sills = [Rect("sill", r.x0, 2.85, r.x1, 3.0) for r in windows[:3]]
    layout = LabelledLayout(10.0, 6.0, (*windows, *sills))
    placed = structured(layout)
    for window, sill in zip(placed.rects[:3], placed.rects[4:], strict=True):
        assert (sill.x0, sill.x1) == pytest.approx((window.x0, window.x1), abs=1e-6)


def test_a_door_on_its_windows_edges_keeps_its_own_width() -> None:
    """A door snapped to the edges of the windows over it keeps its own label's width:
    the windows' sizes clustered have a median of 1.125 m, the door was drawn 1.12 m
    wide (family-with-defects seed 2's door, drawn wider than its windows, took their
    width and lost 0.05 of IoU). Only a companion (a sill) takes its opening's size."""
    widths = [1.10, 1.12, 1.13, 1.14]
    windows = [
        Rect("window", 1.0 + 2.0 * k, 3.0, 1.0 + 2.0 * k + w, 4.5) for k, w in enumerate(widths)
    ]
    door = Rect("door", windows[1].x0, 0.0, windows[1].x1, 2.5)
    placed = structured(LabelledLayout(10.0, 6.0, (*windows, door)))
    assert placed.rects[4].x1 - placed.rects[4].x0 == pytest.approx(1.12, abs=1e-6)
    assert placed.rects[1].x1 - placed.rects[1].x0 == pytest.approx(1.125, abs=1e-6)


def _stack_under_a_top_floor(path: Path, seed: int) -> Path:
    """Five floors of windows in five bays (a counted stack of rows) and over them a top
    floor of three wider windows in the middle bays, drawn 0.5 m further up than the
    stack's pitch; every height jittered by up to 3% and every edge by up to 1 cm."""
    rng = random.Random(seed)
    rects = []
    floors = [(f, k, 1.2, 1.5) for f in range(5) for k in range(5)]
    floors += [(5, k, 1.8, 1.4) for k in range(1, 4)]
    for f, k, width, height in floors:
        cx = 2.3 + k * 2.6 + rng.uniform(-0.01, 0.01)
        y0 = 1.2 + f * PITCH_Y + (0.5 if f == 5 else 0.0) + rng.uniform(-0.01, 0.01)
        y1 = y0 + height * (1 + rng.uniform(-0.03, 0.03))
        rects.append(
            {"label": "window", "x0": cx - width / 2, "y0": y0, "x1": cx + width / 2, "y1": y1}
        )
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": 18.0}, "rects": rects}))
    return path


def _floors_apart(path: Path, seed: int) -> Path:
    """Five floors of four windows each, every floor's columns shifted from the others'
    (no floor's windows over another's: each floor a layer, no counted stack), so the
    top floor repeats upwards; every height jittered by up to 3%, every edge by 1 cm."""
    rng = random.Random(seed)
    rects = []
    for f, shift in enumerate((0.0, 0.4, 0.8, 0.2, 0.6)):
        for k in range(4):
            cx = 2.3 + shift + k * 2.6 + rng.uniform(-0.01, 0.01)
            y0 = 1.2 + f * PITCH_Y + rng.uniform(-0.01, 0.01)
            y1 = y0 + 1.5 * (1 + rng.uniform(-0.03, 0.03))
            rects.append({"label": "window", "x0": cx - 0.6, "y0": y0, "x1": cx + 0.6, "y1": y1})
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": 15.0}, "rects": rects}))
    return path


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("facade", [_stack_under_a_top_floor, _floors_apart])
def test_a_taller_facade_gains_its_floors_in_one_place_with_no_opening_over_another(
    tmp_path: Path, facade: Callable[[Path, int], Path], seed: int
) -> None:
    """1.5 times as tall, a façade gains floors either in its counted stack (the floors
    over it moving up with it) or as copies of its top floor (everything under it staying
    as drawn), never both: a top floor drawn over the stack was copied upwards from where
    it stood while the stack grew into it, and under a top floor copied upwards the floors
    drawn apart moved up with the roof over its copies (cmp_b0011, b0005, b0006)."""
    path = facade(tmp_path / "facade.json", seed)
    height = json.loads(path.read_text())["canvas"]["height"]
    drawn = len(json.loads(path.read_text())["rects"])
    windows = _of(_solved(path, WIDTH, height * 1.5), "window")
    assert _overlapping(windows) == 0
    assert len(windows) > drawn  # floors gained


def _floors_unlike(path: Path, seed: int) -> Path:
    """Five floors of five windows (1.2 x 1.5 m) with sills, each floor with one window
    drawn 20% narrower, in a bay of its own (no two floors alike: each floor a layer, no
    counted stack), the top floor's windows lower (1.1 m: no floor like the ones under
    it) and an attic's small windows (0.6 x 0.4 m) over it; every height jittered by up
    to 3% and every edge by up to 1 cm."""
    rng = random.Random(seed)
    rects = []
    narrow = rng.sample(range(5), 5)  # each floor's narrower window, by bay
    for f in range(5):
        for k in range(5):
            cx = 2.3 + k * 2.6 + rng.uniform(-0.01, 0.01)
            w = 1.2 * (0.8 if k == narrow[f] else 1.0)
            y0 = 1.2 + f * PITCH_Y + rng.uniform(-0.01, 0.01)
            y1 = y0 + (1.1 if f == 4 else 1.5) * (1 + rng.uniform(-0.03, 0.03))
            rects.append(
                {"label": "window", "x0": cx - w / 2, "y0": y0, "x1": cx + w / 2, "y1": y1}
            )
            rects.append(
                {
                    "label": "sill",
                    "x0": cx - w / 2 - 0.1,
                    "y0": y0 - 0.2,
                    "x1": cx + w / 2 + 0.1,
                    "y1": y0,
                }
            )
    for k in range(5):
        cx = 2.3 + k * 2.6 + rng.uniform(-0.01, 0.01)
        y0 = 1.2 + 4 * PITCH_Y + 2.0 + rng.uniform(-0.01, 0.01)
        rects.append({"label": "window", "x0": cx - 0.3, "y0": y0, "x1": cx + 0.3, "y1": y0 + 0.4})
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": 16.0}, "rects": rects}))
    return path


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_floors_drawn_unlike_gain_whole_floors_under_the_attic_within_the_density(
    tmp_path: Path, seed: int
) -> None:
    """1.5 times as tall, a façade whose floors are each a layer of their own gains the
    floors that fit in the height gained, copies of the last floor like the ones under it
    at its pitch, with the lower top floor and the attic moved up with the roof over
    them (the rest of the height gained, less than a pitch, under the lower top floor):
    the windows a square metre within 0.85-1.15 of the input's, none over another.
    Before, the floors over the ground floor moved up with the roof and none was gained
    (0.67)."""
    path = _floors_unlike(tmp_path / "unlike.json", seed)
    windows = _of(_solved(path, WIDTH, 16.0 * 1.5), "window")
    assert _overlapping(windows) == 0
    assert 0.85 <= len(windows) / 30 / 1.5 <= 1.15
    rows = sorted({round(r.y0, 2) for r in windows})
    assert len(rows) == 5 + int(8.0 / PITCH_Y) + 1  # the floors gained: those that fit
    assert rows[0] == pytest.approx(1.2, abs=0.03)  # the drawn floors stay
    gained = rows[:-2]  # the floors drawn under the lower top floor and their copies
    assert all(b - a == pytest.approx(PITCH_Y, abs=0.05) for a, b in itertools.pairwise(gained))
    assert PITCH_Y - 0.05 <= rows[-2] - gained[-1] < 2 * PITCH_Y  # the lower top floor
    assert rows[-2] == pytest.approx(1.2 + 4 * PITCH_Y + 8.0, abs=0.05)  # at the roof's
    assert all(sum(round(r.y0, 2) == row for r in windows) == 5 for row in rows)  # whole floors
    attic = [r for r in windows if r.y1 - r.y0 < 0.5]
    assert len(attic) == 5 and min(r.y0 for r in attic) > max(
        r.y1 for r in windows if r not in attic
    )


def _two_houses(path: Path, seed: int) -> Path:
    """Two houses side by side, each floor's windows a layer of its own (every floor's
    columns shifted from the others', as ``_floors_apart``): on the left three floors
    of taller windows (1.2 x 1.9 m) at a pitch of 3.3 m, on the right four floors of
    lower ones (1.0 x 1.4 m) at 2.5 m, each floor with its sills; every height jittered
    by up to 3% and every edge by up to 1 cm."""
    rng = random.Random(seed)
    rects = []
    houses = ((1.2, 1.9, 3.3, 3, 0.8), (1.0, 1.4, 2.5, 4, 8.8))  # w, h, pitch, floors, x
    for width, height, pitch, floors, left in houses:
        for f in range(floors):
            shift = (0.0, 0.3, 0.6, 0.15)[f]
            for k in range(3):
                cx = left + 0.9 + shift + k * 2.1 + rng.uniform(-0.01, 0.01)
                y0 = 1.5 + f * pitch + rng.uniform(-0.01, 0.01)
                y1 = y0 + height * (1 + rng.uniform(-0.03, 0.03))
                x0, x1 = cx - width / 2, cx + width / 2
                rects.append({"label": "window", "x0": x0, "y0": y0, "x1": x1, "y1": y1})
                rects.append(
                    {"label": "sill", "x0": x0 - 0.1, "y0": y0 - 0.2, "x1": x1 + 0.1, "y1": y0}
                )
    path.write_text(json.dumps({"canvas": {"width": 16.0, "height": 13.0}, "rects": rects}))
    return path


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_two_houses_of_unlike_floor_pitches_each_gain_floors_at_their_own_pitch(
    tmp_path: Path, seed: int
) -> None:
    """1.5 times as tall, each house of a façade whose parts have floors of unlike
    pitches gains the whole floors that fit at its own pitch, its windows with their
    sills, none over another. Before, every copy stood at one pitch, the middle of the
    openings' top floors': the house whose pitch is another (cmp_b0003's left part)
    gained none (density 0.75 of the input's)."""
    path = _two_houses(tmp_path / "houses.json", seed)
    rects = _solved(path, 16.0, 13.0 * 1.5)
    windows = _of(rects, "window")
    assert _overlapping(windows) == 0
    for lo, hi, pitch, drawn in ((0.0, 8.0, 3.3, 3), (8.0, 16.0, 2.5, 4)):
        house = [r for r in windows if lo <= (r.x0 + r.x1) / 2 < hi]
        rows = sorted({round(r.y0, 1) for r in house})
        assert len(rows) == drawn + int(6.5 / pitch)  # the floors that fit in 6.5 m
        assert all(b - a == pytest.approx(pitch, abs=0.06) for a, b in itertools.pairwise(rows))
        sills = [r for r in _of(rects, "sill") if lo <= (r.x0 + r.x1) / 2 < hi]
        assert all(
            any(abs(s.y1 - w.y0) < 0.03 and s.x0 < w.x0 < s.x1 for s in sills) for w in house
        )


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize(
    ("facade", "pitches"),
    [(_floors_apart, {(0.0, 15.0): 2.6}), (_two_houses, {(0.0, 8.0): 3.3, (8.0, 16.0): 2.5})],
)
def test_a_shorter_facade_drops_whole_floors_from_the_top_keeping_its_windows(
    tmp_path: Path,
    facade: Callable[[Path, int], Path],
    pitches: dict[tuple[float, float], float],
    seed: int,
) -> None:
    """0.7 times as tall, a façade whose top floor repeats upwards drops the whole floors
    it must from the top (as many as free the height lost: the roof's margin never
    shrinks), in every column of a pitch alike and with their sills; the floors kept
    stand where drawn, every window its size, none over another. Before, no layout
    existed ("make the canvas taller"): the top floor's copies could only be added."""
    path = facade(tmp_path / "facade.json", seed)
    canvas = json.loads(path.read_text())["canvas"]
    drawn = _of([Rect(**r) for r in json.loads(path.read_text())["rects"]], "window")
    lost = 0.3 * canvas["height"]
    rects = _solved(path, canvas["width"], 0.7 * canvas["height"])
    windows = _of(rects, "window")
    assert _overlapping(windows) == 0
    for (lo, hi), pitch in pitches.items():
        part = [r for r in drawn if lo <= (r.x0 + r.x1) / 2 < hi]
        rows = sorted({round(r.y0, 1) for r in part})
        kept = rows[: len(rows) - math.ceil(lost / pitch)]
        found = [r for r in windows if lo <= (r.x0 + r.x1) / 2 < hi]
        assert sorted({round(r.y0, 1) for r in found}) == kept
        assert len(found) == sum(round(r.y0, 1) in kept for r in part)  # whole floors
        for r in found:  # each where drawn, its size
            assert any(
                abs(r.y0 - d.y0) < 0.02 and abs(r.y1 - r.y0 - (d.y1 - d.y0)) < 0.03 for d in part
            )
        sills = [s for s in _of(rects, "sill") if lo <= (s.x0 + s.x1) / 2 < hi]
        assert len(sills) == (len(found) if facade is _two_houses else 0)


def test_a_facade_too_short_for_its_lowest_floor_says_so(tmp_path: Path) -> None:
    """Where even one floor of the stack does not fit, there is no layout, and the
    error says to make the canvas taller."""
    path = _floors_apart(tmp_path / "facade.json", 1)
    with pytest.raises(InfeasibleError, match="make the canvas larger"):
        _solved(path, WIDTH, 3.0)


def _blinds_upstairs(path: Path, seed: int) -> Path:
    """A ground floor of four windows and over it two floors of five (1.2 x 1.6 m, one
    grid of two rows), a blind beside each upper window only, every edge jittered by up
    to 1 cm: the windows' stack stands on the ground floor, the blinds' on the first."""
    rng = random.Random(seed)
    rects = []
    for f, bays in ((0, 4), (1, 5), (2, 5)):
        for k in range(bays):
            cx = 2.0 + k * (11.0 / (bays - 1)) + rng.uniform(-0.01, 0.01)
            y0 = 1.5 + f * 3.2 + rng.uniform(-0.01, 0.01)
            rects.append(
                {"label": "window", "x0": cx - 0.6, "y0": y0, "x1": cx + 0.6, "y1": y0 + 1.6}
            )
            if f:
                rects.append(
                    {"label": "blind", "x0": cx + 0.6, "y0": y0, "x1": cx + 1.0, "y1": y0 + 1.6}
                )
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": 11.0}, "rects": rects}))
    return path


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_windows_and_blinds_on_stacks_from_unlike_floors_solve_at_every_height(
    tmp_path: Path, seed: int
) -> None:
    """The upper windows and their blinds stand on the same rows, on stacks from unlike
    floors (the windows' from the ground floor, the blinds' from the first): each solves
    at the input's height, taller and shorter, every blind beside its window. When the
    two layers shared their roof's margin, the sizes written to a tenth of a millimetre
    left no layout even at the input's height."""
    path = _blinds_upstairs(tmp_path / "blinds.json", seed)
    for share, floors in ((1.0, 3), (1.5, 4), (0.75, 2)):
        rects = _solved(path, WIDTH, 11.0 * share)
        windows, blinds = _of(rects, "window"), _of(rects, "blind")
        assert len({round(r.y0, 1) for r in windows}) == floors
        assert _overlapping(windows) == 0
        assert len(blinds) == len(windows) - 4
        assert all(
            any(abs(b.x0 - w.x1) < 0.03 and abs(b.y0 - w.y0) < 0.03 for w in windows)
            for b in blinds
        )


SHIFTS = (0.0, 0.2, 0.4, 0.1, 0.3)  # m: each floor's columns off the others' (by floor)


def _attic_over_the_middle(path: Path, seed: int) -> Path:
    """An end column of windows (1.0 x 1.4 m) each side with five floors at a pitch of
    2.6 m, 0.3 m higher than the middle's floors; between them three columns of wider
    windows (1.2 x 1.4 m, with sills) with three floors at that pitch, and between
    those, narrow columns of small windows (0.6 x 0.7 m) on every floor; over the middle
    part, an attic row of small windows over every wide and narrow column, like the
    narrow ones. Every floor's columns are
    shifted from the others' (each floor a layer, no run of floors: ``_floors_apart``),
    every height jittered by up to 3% and every edge by up to 1 cm (cmp_b0008's shape)."""
    rng = random.Random(seed)
    rects = []

    def window(cx: float, y0: float, width: float, height: float, sill: bool = False) -> None:
        cx += SHIFTS[round((y0 - 1.5) / PITCH_Y)] + rng.uniform(-0.01, 0.01)
        y0 += rng.uniform(-0.01, 0.01)
        y1 = y0 + height * (1 + rng.uniform(-0.03, 0.03))
        x0, x1 = cx - width / 2, cx + width / 2
        rects.append({"label": "window", "x0": x0, "y0": y0, "x1": x1, "y1": y1})
        if sill:
            rects.append(
                {"label": "sill", "x0": x0 - 0.1, "y0": y0 - 0.2, "x1": x1 + 0.1, "y1": y0}
            )

    for f in range(5):
        for cx in (1.0, 14.0):
            window(cx, 1.8 + f * PITCH_Y, 1.0, 1.4)
    for f in range(3):
        for cx in (4.0, 7.5, 11.0):
            window(cx, 1.5 + f * PITCH_Y, 1.2, 1.4, sill=True)
        for cx in (5.75, 9.25):
            window(cx, 2.0 + f * PITCH_Y, 0.6, 0.7)
    for cx in (4.0, 5.75, 7.5, 9.25, 11.0):
        window(cx, 2.0 + 3 * PITCH_Y, 0.6, 0.7)
    path.write_text(json.dumps({"canvas": {"width": WIDTH, "height": 15.0}, "rects": rects}))
    return path


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_a_middle_part_under_an_attic_row_gains_floors_beside_taller_ends(
    tmp_path: Path, seed: int
) -> None:
    """1.5 times as tall, a façade whose end columns have more floors than its middle
    part, under whose top floor an attic row of small windows stands, gains the whole
    floors that fit in the middle too, at the pitch, with their sills; the attic row
    stays one row over them, none over another. Before, the middle's top floor was no
    top floor (the ends' windows like it stand higher), and the attic row repeated
    upwards instead, over the wide columns (cmp_b0008: density 0.81 of the input's)."""
    path = _attic_over_the_middle(tmp_path / "attic.json", seed)
    rects = _solved(path, WIDTH, 15.0 * 1.5)
    windows = _of(rects, "window")
    assert _overlapping(windows) == 0
    gained = int(7.5 / PITCH_Y)  # the floors that fit in 7.5 m
    for wide, drawn in ((1.2, 3), (1.0, 5)):
        column = [r for r in windows if abs(r.x1 - r.x0 - wide) < 0.05 and r.y1 - r.y0 > 1.2]
        rows = sorted({round(r.y0, 1) for r in column})
        assert len(rows) == drawn + gained
        gains = itertools.pairwise(rows[drawn - 1 :])  # from the top floor as drawn
        assert all(b - a == pytest.approx(PITCH_Y, abs=0.06) for a, b in gains)
    small = [r for r in windows if r.y1 - r.y0 < 0.9]
    top_wide = max(r.y1 for r in windows if abs(r.x1 - r.x0 - 1.2) < 0.05)
    assert len([r for r in small if r.y0 > top_wide]) == 5  # the attic row, once
    sills = _of(rects, "sill")
    assert len(sills) == 3 * (3 + gained)
