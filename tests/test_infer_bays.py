"""Shared bay kinds (``infer.bays``, issue 34): on generated façades with known structure
(``annotated_family``, seeds 1-24; the hold-out 101-110 is never used here), the inferred
spec's layers follow one sequence of bays, a counter a repeated kind, so that solved at
another width the façade gains or drops whole bays of the right kind, its door bay once;
a façade whose bays cannot do that keeps per-layer words and says so."""

from __future__ import annotations

import json
import random
import re
import subprocess
import sys
from collections import Counter
from itertools import pairwise
from pathlib import Path

import pytest

from facadecli import parse_spec, solve
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.fidelity import FAITHFUL, fidelity
from facadecli.grammar.inputs import BACKGROUND, LabelledLayout, Rect
from facadecli.grammar.model import Options
from facadecli.grammar.tidy import tidy_layout
from facadecli.grammar.tiling import MOVE_SHARE
from facadecli.infer import run
from facadecli.infer.bays import KEEP, LOOSE, ODD, Bays, _common, _strips, _units, find_bays
from facadecli.infer.run import infer, solved_layout
from facadecli.infer.spec_text import _bay_counter_note, layer_names, spec_text
from facadecli.infer.structure import structured
from facadecli.solve import retarget
from tests.benchmarks.annotated_family import cmp_xml, doorway_family, family, paired_family

NEAR = 0.15  # m: window centres this close are one column (1% of the façade)


def _inferred(tmp_path: Path, seed: int):  # type: ignore[no-untyped-def]
    path = tmp_path / f"family-{seed}.xml"
    path.write_text(cmp_xml(family(seed)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    return inference, parse_spec(inference.text, path.stem)


def _solved(inference, spec, share: float) -> list[Rect]:  # type: ignore[no-untyped-def]
    width = round(inference.layout.width * share, 4)
    layout = solve(retarget(spec, width, inference.layout.height))
    return list(solved_layout(layout, spec, inference).rects)


def _in_band_at(inference, spec, drawn: list[Rect], shares: tuple[float, ...]) -> None:  # type: ignore[no-untyped-def]
    """At each of ``shares`` of the width: the windows a square metre within 0.85-1.15
    of the ``drawn`` windows', each window at a drawn size (within 15% both ways), and
    one door."""
    sizes = [(r.x1 - r.x0, r.y1 - r.y0) for r in drawn]
    for share in shares:
        rects = _solved(inference, spec, share)
        windows = [r for r in rects if r.label == "window"]
        assert 0.85 <= len(windows) / len(drawn) / share <= 1.15, (share, len(windows))
        assert all(
            any(
                abs((r.x1 - r.x0) / w - 1) <= 0.15 and abs((r.y1 - r.y0) / h - 1) <= 0.15
                for w, h in sizes
            )
            for r in windows
        )
        assert sum(r.label == "door" for r in rects) == 1


def _columns(rects: list[Rect], label: str = "window") -> list[int]:
    """How many elements of ``label`` each column (centres within ``NEAR``) holds."""
    centres = sorted((r.x0 + r.x1) / 2 for r in rects if r.label == label)
    counts: list[int] = []
    last = None
    for c in centres:
        if last is None or c - last > NEAR:
            counts.append(0)
        counts[-1] += 1
        last = c
    return counts


def _top_and_second(boxes):  # type: ignore[no-untyped-def]
    """The top floor's windows, left to right, and the second floor's window bottom."""
    windows = sorted((b for b in boxes if b[0] == "window"), key=lambda b: (b[2], b[1]))
    top = sorted((b for b in windows if abs(b[2] - windows[-1][2]) < 0.02), key=lambda b: b[1])
    return top, sorted({round(b[2], 2) for b in windows})[1]


def _x_words(text: str) -> dict[str, str]:
    spec = parse_spec(text, "spec")
    return {layer.name: str(layer.x) for layer in spec.layers if layer.name != "wall"}


@pytest.mark.parametrize("seed", [1, 6, 13])
def test_a_family_facade_is_one_sequence_of_bays_a_counter_a_repeated_kind(
    tmp_path: Path, seed: int
) -> None:
    inference, spec = _inferred(tmp_path, seed)
    assert not inference.unshared and inference.bays.startswith(f"{family(seed)[1].bays} bays")
    words = _x_words(inference.text)
    openings = {n: w for n, w in words.items() if n.startswith(("window", "door"))}
    # every opening's layer follows the one sequence of bays, and so does every other
    # layer but those of elements kept where drawn, off their bays' shape
    assert openings and all("bays_m1" in w for w in openings.values())
    names = layer_names(inference.grids)
    apart = {n for n, g in zip(names, inference.grids, strict=True) if g.apart}
    bands = {n for n in words if n.startswith("cornice")}  # across the façade: in no bay
    assert all("bays_m1" in w for n, w in words.items() if n not in apart | bands)
    bay_counters = {n for n in spec.counters if n.startswith("bays")}
    assert 1 <= len(bay_counters) <= 3  # at most two runs, and the ends' one
    assert all(any(f"^{n}" in w for w in openings.values()) for n in bay_counters)
    # one window width: the kinds share the label's sizes
    assert [n for n in spec.symbols if n.startswith("window_w")] == ["window_w1"]


@pytest.mark.parametrize("seed", [7, 13, 23])
def test_other_widths_gain_or_drop_whole_bays_and_the_door_bay_never_repeats(
    tmp_path: Path, seed: int
) -> None:
    """Each column of windows solved at another width holds as many windows as a column
    of the input (whole bays, aligned between floors), there are more columns wider and
    fewer narrower, the windows keep their width, and there is one door."""
    inference, spec = _inferred(tmp_path, seed)
    raw = list((inference.raw or inference.layout).rects)
    drawn = _columns(raw)
    widths = [r.x1 - r.x0 for r in raw if r.label == "window"]
    for share in (0.7, 1.5, 2.0):
        rects = _solved(inference, spec, share)
        columns = _columns(rects)
        assert set(columns) <= set(drawn), (share, columns, drawn)
        assert (len(columns) < len(drawn)) if share < 1 else (len(columns) > len(drawn))
        assert sum(r.label == "door" for r in rects) == 1
        assert all(
            any(abs((r.x1 - r.x0) / w - 1) <= 0.15 for w in widths)
            for r in rects
            if r.label == "window"
        )


@pytest.mark.parametrize(
    "seed",
    [s for s in range(1, 25) if family(s)[1].mirrored and family(s)[1].bays % 2][:3],
)
def test_a_mirrored_family_facade_is_written_reflected_and_stays_mirrored(
    tmp_path: Path, seed: int
) -> None:
    """Mirrored halves, the door in the middle bay: the windows' word repeats one counter
    on both sides, as the left half reflected where the bays themselves are mirrored (a
    family's blinds are all on the windows' right: such bays are not), and solved at
    other widths the windows stay mirrored."""
    inference, spec = _inferred(tmp_path, seed)
    window = _x_words(inference.text)["window"]
    assert window.count("^bays1") == 2  # one counter, both sides
    assert (")^-1" in window) == (not family(seed)[1].blinds)  # the left half, reflected
    for share in (0.7, 1.5):
        assert _mirrored(_solved(inference, spec, share), inference.layout.width * share)


def _mirrored(rects: list[Rect], width: float) -> bool:
    """90% of the windows have a mirror image about the middle (centres within NEAR)."""
    windows = [r for r in rects if r.label == "window"]
    mirrored = sum(
        any(
            abs((q.x0 + q.x1) / 2 - (width - (r.x0 + r.x1) / 2)) < NEAR and abs(q.y0 - r.y0) < NEAR
            for q in windows
        )
        for r in windows
    )
    return mirrored >= 0.9 * len(windows)


@pytest.mark.parametrize(("seed", "share"), [(4, 0.7), (8, 0.7), (16, 2.0)])
def test_a_mirrored_facade_whose_bays_do_not_read_backwards_stays_mirrored(
    tmp_path: Path, seed: int, share: float
) -> None:
    """Windows mirrored about the middle in a sequence of bays that is no palindrome (an
    even number of bays, the door's off the middle; blinds all on the windows' right):
    the bays stand in the façade's middle, both margins one symbol, so dropping or
    gaining bays keeps the windows mirrored (with the margins apart, the slack went to
    one side)."""
    inference, spec = _inferred(tmp_path, seed)
    assert _mirrored(list(inference.layout.rects), inference.layout.width)
    assert _mirrored(_solved(inference, spec, share), inference.layout.width * share)


def test_a_facade_whose_bays_cannot_narrow_keeps_per_layer_words_and_says_so(
    tmp_path: Path,
) -> None:
    """Two doors under their columns of windows between two narrow window columns, the
    right one a little wider (0.5 m to 0.4: not mirrored): the end bays may drop (their
    counter, and a spare copy of the last, so one at a time) but the doors' bays are
    written once and span 0.71 of the façade, so the bays could not narrow to 0.7x; the
    spec keeps a word a layer, and the spec, the report and a warning say why. Drawn
    mirrored (both narrow columns 0.4 m), the end bays would not repeat at all (a
    mirrored façade keeps its mirror), and the warning says that."""
    for right, why in (
        ((8.8, 0.5), "its 4 bays of 3 kinds cannot narrow below 0.71"),
        ((8.9, 0.4), "none of its 4 bays of 2 kinds repeat but its end bays, and it is mirrored"),
    ):
        rects = [
            {"label": "window", "x0": x, "y0": y, "x1": x + w, "y1": y + 1.5}
            for x, w in ((0.3, 0.4), (2.0, 1.2), (6.4, 1.2), right)
            for y in (3.0, 5.5, 8.0)
        ]
        rects += [
            {"label": "door", "x0": x, "y0": 0.0, "x1": x + 1.2, "y1": 2.6} for x in (2.0, 6.4)
        ]
        layout = tmp_path / "unlike.json"
        layout.write_text(json.dumps({"canvas": {"width": 9.6, "height": 11.0}, "rects": rects}))
        out = tmp_path / "unlike.yaml"
        run = subprocess.run(
            [sys.executable, "-m", "facadecli", "infer", str(layout), "-o", str(out), "--no-check"],
            capture_output=True,
            text=True,
        )
        assert run.returncode == 0, run.stderr
        assert f"warning: bays not shared: {why}" in run.stderr
        assert "# Bays not shared:" in out.read_text()
        report = json.loads(out.with_name("unlike.infer.json").read_text())
        assert report["bays"].startswith("not shared")
        assert "bays_m" not in out.read_text()


def test_three_unlike_bays_with_a_door_in_the_middle_share_their_bays(tmp_path: Path) -> None:
    """Three window bays each unlike the others (widths 1.0-1.6 m), a door under the
    middle one's windows: the end bays are the only ones that may repeat, so they do,
    one at a time, and the bays are shared. At 0.7x one end column drops and the other
    stays beside the door's (with the ends' counter alone both dropped, and the door's
    bay stood alone); at 2x the ends gain columns; every window keeps a drawn width."""
    rects = [
        {"label": "window", "x0": x, "y0": y, "x1": x + w, "y1": y + 1.5}
        for x, w in ((1.0, 1.0), (4.0, 1.3), (7.0, 1.6))
        for y in (2.0, 5.0, 8.0)
    ]
    rects.append({"label": "door", "x0": 4.0, "y0": 0.0, "x1": 5.3, "y1": 1.8})
    path = tmp_path / "unlike.json"
    path.write_text(json.dumps({"canvas": {"width": 9.6, "height": 11.0}, "rects": rects}))
    inference = infer(path, "unlike")
    assert inference.bays == "3 bays of 3 kinds (ABC)", inference.bays
    spec = parse_spec(inference.text, "unlike.yaml")
    for share in (0.7, 2.0):
        rects_at = _solved(inference, spec, share)
        doors = [r for r in rects_at if r.label == "door"]
        widths = {round(r.x1 - r.x0, 2) for r in rects_at if r.label == "window"}
        assert len(doors) == 1 and widths <= {1.0, 1.3, 1.6}, share
        assert len(_columns(rects_at)) >= 2, share  # never the door's bay alone
    assert len(_columns(rects_at)) > 3


def test_a_two_floor_family_facade_gains_a_floor_when_taller(tmp_path: Path) -> None:
    """Seed 15 (four bays of two floors, blinds beside the windows, the door's bay
    without a blind under its top floor's): the top floor's windows repeat upwards, and
    a layer on the same rows that does not (the door bay's blind) keeps its own margins,
    so at 1.5x the height a floor is gained (sharing them, no floor could be)."""
    inference, spec = _inferred(tmp_path, 15)
    width, height = inference.layout.width, inference.layout.height
    counts = []
    for share in (1.0, 1.5):
        layout = solve(retarget(spec, width, height * share))
        rects = list(solved_layout(layout, spec, inference).rects)
        counts.append(sum(r.label == "window" for r in rects))
    assert counts[1] > counts[0]


@pytest.mark.parametrize("seed", [7, 8, 9])
def test_the_bays_stand_where_the_windows_were_drawn(tmp_path: Path, seed: int) -> None:
    """Seeds whose door bay is wider than the others: the bays side by side are fitted to
    the elements as drawn (not started from the bays' mean start with each kind's median
    width, which put a whole side of windows 4-7 cm off), so the windows' centres stay on
    average within 1/600 of the façade (2.5 cm) of the annotation's."""
    inference, _ = _inferred(tmp_path, seed)
    raw = [r for r in (inference.raw or inference.layout).rects if r.label == "window"]
    placed = [r for r in inference.layout.rects if r.label == "window"]

    def overlap(a: Rect, b: Rect) -> float:
        return max(0.0, min(a.x1, b.x1) - max(a.x0, b.x0)) * max(
            0.0, min(a.y1, b.y1) - max(a.y0, b.y0)
        )

    moves = [
        abs((r.x0 + r.x1) / 2 - (q.x0 + q.x1) / 2)
        for r in raw
        for q in [max(placed, key=lambda q: overlap(r, q))]
    ]
    assert sum(moves) / len(moves) <= inference.layout.width / 600


def test_a_shared_row_is_the_middle_of_the_rows_drawn_not_the_one_drawn_most() -> None:
    """Sills of one floor drawn a few centimetres apart, three of them on one value: the
    floor's row is their median (the least moved in all), not the value drawn most."""
    seen = Counter({4.371: 3, 4.294: 1, 4.331: 1, 4.312: 1, 4.293: 1, 7.31: 2})
    assert _common(seen, 4.35, 0.1) == 4.331
    assert _common(seen, 7.0, 0.1) == 7.0  # none that close: as it was


@pytest.mark.parametrize("seed", [3, 12, 14])
def test_a_floor_row_keeps_the_windows_one_height(tmp_path: Path, seed: int) -> None:
    """A row shared by the bays' elements is their bottom and their height (their top
    and bottom each on its own gave one floor's windows 0.1 mm less, a second height
    symbol, and at 1.5x the height windows stretched): one height symbol, and taller
    every window keeps its height within 15%."""
    inference, spec = _inferred(tmp_path, seed)
    assert [n for n in spec.symbols if n.startswith("window_h")] == ["window_h1"]
    height = spec.symbols["window_h1"].size
    layout = solve(retarget(spec, inference.layout.width, inference.layout.height * 1.5))
    rects = list(solved_layout(layout, spec, inference).rects)
    assert all(abs((r.y1 - r.y0) / height - 1) <= 0.15 for r in rects if r.label == "window")


def test_a_thin_element_drawn_off_its_kinds_row_stays_where_it_was_drawn() -> None:
    """Four bays alike (a window over a 0.2 m sill), one sill drawn 4 cm lower: the bays
    are one kind (within 5% of their width), but standing on the kind's row would move
    that sill a fifth of its height. The windows stand on the kind's shape; the kind's
    sills stay where drawn (kept apart, in layers of their own)."""
    rects = [Rect(BACKGROUND, 0.0, 0.0, 13.0, 6.0, 0)]
    for k in range(4):
        low = 1.76 if k == 2 else 1.8
        rects.append(Rect("window", 1.0 + 3 * k, 2.0, 2.2 + 3 * k + 0.01 * k, 3.5, 1))
        rects.append(Rect("sill", 0.9 + 3 * k, low, 2.3 + 3 * k, low + 0.2, 2))
    layout = LabelledLayout(13.0, 6.0, tuple(rects))
    bays = find_bays(layout)
    assert isinstance(bays, Bays) and bays.kinds == (0, 0, 0, 0)
    sills = {k for k, r in enumerate(rects) if r.label == "sill"}
    assert bays.apart == sills
    assert all(bays.layout.rects[k] == rects[k] for k in sills)
    windows = [r for r in bays.layout.rects if r.label == "window"]
    assert len({round(r.x1 - r.x0, 4) for r in windows}) == 1  # on the kind's shape


@pytest.mark.parametrize("seed", [5, 24])
def test_family_sills_at_1x_stay_where_drawn_or_where_the_structure_put_them(
    tmp_path: Path, seed: int
) -> None:
    """Seeds whose sills were drawn a few centimetres off their floor's row in some bays
    (one shared row a kind moved seed 24's sills: IoU 0.844 -> 0.681): the spec solved at
    1x puts every sill where the structure put it or within an eighth of its height (and
    width: the tidy-up's move limit, to which the bays hold it) of where it was drawn, or,
    at most ``ODD`` of a row, on the row of the others of its slot (a hand's outlier the
    companions' reach left off its window's offset, put on its row by ``bays._apart``)."""
    inference, spec = _inferred(tmp_path, seed)
    assert not inference.unshared
    layout = solve(spec)
    solved = [r for r in solved_layout(layout, spec, inference).rects if r.label == "sill"]
    options = Options(size=(15.0, 15.0))
    path = tmp_path / f"family-{seed}.xml"
    tidied = tidy_layout(path, options, Deadline(options.time_limit, str(path)))
    pairs = [
        (r, d)
        for r, d in zip(structured(tidied.layout, tidied.raw).rects, tidied.raw.rects, strict=True)
        if r.label == "sill"
    ]
    assert len(solved) == len(pairs)

    def near(a: Rect, b: Rect, share: float) -> bool:
        return (
            max(abs(a.x0 - b.x0), abs(a.x1 - b.x1)) <= share * (b.x1 - b.x0) + 1e-3
            and max(abs(a.y0 - b.y0), abs(a.y1 - b.y1))
            <= share * (b.y1 - b.y0) + 1e-3  # sizes written to 0.1 mm
        )

    rows = Counter((round(q.y0, 3), round(q.y1, 3)) for q in solved)
    outliers: Counter[tuple[float, float]] = Counter()
    for r, d in pairs:
        q = min(solved, key=lambda q: abs(q.x0 - r.x0) + abs(q.y0 - r.y0))
        if near(q, r, 0.0) or near(q, d, MOVE_SHARE):
            continue
        row = (round(q.y0, 3), round(q.y1, 3))  # the bays' one outlier a slot, on its row
        reach = MOVE_SHARE * (r.x1 - r.x0) + 1e-3  # along x, as the bays hold any
        assert rows[row] > 1 + ODD and max(abs(q.x0 - r.x0), abs(q.x1 - r.x1)) <= reach
        outliers[row] += 1
    assert all(count <= ODD for count in outliers.values())


def _touching(a: Rect, b: Rect, reach: float = 0.05) -> bool:
    """Overlapping along one axis and at most ``reach`` apart (or overlapping) along the other."""
    over_x = min(a.x1, b.x1) - max(a.x0, b.x0)
    over_y = min(a.y1, b.y1) - max(a.y0, b.y0)
    return (over_x > 0 and over_y >= -reach) or (over_y > 0 and over_x >= -reach)


def test_windows_keep_their_blinds_when_the_facade_drops_bays(tmp_path: Path) -> None:
    """Seed 7 (every window over a sill, a blind beside it) solved at 0.7x its width drops
    bays; the windows left keep their blind, at its drawn size (the blinds stood apart, as
    drawn, in layers of their own when a kind's shape moved one by more than half the
    tidy-up's limit, and at 0.7x every window lost it)."""
    inference, spec = _inferred(tmp_path, 7)
    known = family(7)[1]
    assert known.blinds
    drawn = [r for r in (inference.raw or inference.layout).rects if r.label == "blind"]
    rects = _solved(inference, spec, 0.7)
    windows = [r for r in rects if r.label == "window"]
    assert 0 < len(windows) < known.windows
    blinds = [
        r
        for r in rects
        if r.label == "blind"
        and any(
            abs((r.x1 - r.x0) / (d.x1 - d.x0) - 1) <= 0.15
            and abs((r.y1 - r.y0) / (d.y1 - d.y0) - 1) <= 0.15
            for d in drawn
        )
    ]
    kept = [w for w in windows if any(_touching(w, b) for b in blinds)]
    assert len(kept) >= 0.85 * len(windows), (len(kept), len(windows))


def test_windows_keep_their_sills_at_their_drawn_width_when_the_facade_drops_bays(
    tmp_path: Path,
) -> None:
    """Seed 7 solved at 0.7x its width: most of its sills stand apart (drawn a good share
    of their height off their row), in layers of their own that share one width symbol;
    the solver, which counts a symbol once however many layers share it, squeezed that
    one to a millimetre to spare every layer's margins (1 window of 8 kept a sill). Now
    no sill is narrower than the least drawn, and the windows left stand over one."""
    inference, spec = _inferred(tmp_path, 7)
    drawn = [r for r in (inference.raw or inference.layout).rects if r.label == "sill"]
    least = min(r.x1 - r.x0 for r in drawn)
    rects = _solved(inference, spec, 0.7)
    sills = [r for r in rects if r.label == "sill"]
    windows = [r for r in rects if r.label == "window"]
    assert sills
    assert all(r.x1 - r.x0 >= 0.85 * least for r in sills)
    under = [
        w
        for w in windows
        if any(
            min(s.x1, w.x1) - max(s.x0, w.x0) > 0 and -0.05 <= w.y0 - s.y1 <= 0.05 for s in sills
        )
    ]
    assert len(under) >= 0.85 * len(windows), (len(under), len(windows))


@pytest.mark.parametrize("share", [0.7, 2.0])
def test_sills_drawn_off_their_row_follow_their_bays(tmp_path: Path, share: float) -> None:
    """Seed 20 (eight bays of seven floors, a sill under every window): 29 of its 55 sills
    are drawn further off their kind's row than the tidy-up's limit lets a shape move
    them, but along x they stand on it; they stand in the bays along x, each slot on a
    row of its own, so solved narrower or wider every window left or gained stands over
    one sill of its drawn width, and no sill stands without its window (before, those 29
    stood apart at fixed places: at 0.7x 3 windows of 34 lost theirs, at 2x 29 of 118)."""
    inference, spec = _inferred(tmp_path, 20)
    assert not any(g.apart for g in inference.grids if g.label == "sill")
    drawn = [r for r in (inference.raw or inference.layout).rects if r.label == "sill"]
    least = min(r.x1 - r.x0 for r in drawn)
    rects = _solved(inference, spec, share)
    sills = [r for r in rects if r.label == "sill" and r.x1 - r.x0 >= 0.85 * least]
    windows = [r for r in rects if r.label == "window"]

    def under(s: Rect, w: Rect) -> bool:
        return min(s.x1, w.x1) - max(s.x0, w.x0) > 0 and -0.05 <= w.y0 - s.y1 <= 0.05

    assert all(any(under(s, w) for s in sills) for w in windows)
    assert all(any(under(s, w) for w in windows) for s in sills)


def test_elements_across_two_bays_stay_over_the_shared_bays(tmp_path: Path) -> None:
    """Seed 6 (nine bays of six floors, blinds) with a balcony under two bays' windows
    and a short cornice over two others: the bays are cut on the openings, so each
    element across a wall's middle stays where it was drawn, in a layer of its own,
    and the windows still share the nine bays (before, each merged its two bays into
    one strip, and no bay was like another); solved wider and narrower, every window
    column holds a window of every floor (but the door's, once) and the two elements
    are shown."""
    boxes, known = family(6)
    top, second = _top_and_second(boxes)
    a, b = top[1], top[2]
    boxes.append(("balcony", a[1] - 0.01, second - 0.03, b[3] + 0.01, second - 0.014))
    c, d = top[5], top[6]
    boxes.append(("cornice", c[1] - 0.01, c[4] + 0.01, d[3] + 0.01, c[4] + 0.02))
    path = tmp_path / "across.xml"
    path.write_text(cmp_xml(boxes))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    assert not inference.unshared, inference.bays
    assert inference.bays.startswith(f"{known.bays} bays")
    spec = parse_spec(inference.text, path.stem)
    for share in (0.7, 1.5):
        rects = _solved(inference, spec, share)
        columns = _columns(rects)
        # whole bays: every floor a window, but under the door's bay (once)
        assert sorted(set(columns)) == [known.floors - 1, known.floors], columns
        assert columns.count(known.floors - 1) == 1, columns
        assert {"balcony", "cornice"} <= {r.label for r in rects}


def test_elements_left_where_drawn_have_no_runs_of_their_own(tmp_path: Path) -> None:
    """Seed 6 keeps some sills and blinds where drawn, off their bays: their layers'
    x words are as drawn, with no counters of their own (before, each brought runs and
    counters beside the bays': ten counters on this façade, each a search for the
    solver); the bays' counters and the floors' remain."""
    inference, spec = _inferred(tmp_path, 6)
    words = _x_words(inference.text)
    names = layer_names(inference.grids)
    apart = [n for n, g in zip(names, inference.grids, strict=True) if g.apart]
    assert apart and all("^" not in words[n].replace("^-1", "") for n in apart)
    assert any(n.startswith("bays") for n in spec.counters)


@pytest.mark.parametrize("bay", [0, 2])
def test_a_band_within_one_bay_stands_apart_and_the_spec_parses(tmp_path: Path, bay: int) -> None:
    """Seed 14 (three bays, the door's last) with a balcony under one bay's second-floor
    window nearly as wide as the bay (more than a quarter of the façade: a band): it
    stands apart, in a layer of its own, and the bays are shared. Before, a band was in
    no bay but inside one, so the bays' word wrote it without placing it: in the door's
    bay the spec did not parse (its mask named a width the word did not hold), in
    another the bays fell back to per-layer words."""
    boxes, known = family(14)
    top, second = _top_and_second(boxes)
    pitch = top[1][1] - top[0][1]
    centre = (top[bay][1] + top[bay][3]) / 2
    boxes.append(
        ("balcony", centre - 0.44 * pitch, second - 0.03, centre + 0.44 * pitch, second - 0.014)
    )
    path = tmp_path / "band.xml"
    path.write_text(cmp_xml(boxes))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    assert not inference.unshared, inference.bays
    assert inference.bays.startswith(f"{known.bays} bays")
    spec = parse_spec(inference.text, path.stem)
    names = layer_names(inference.grids)
    assert any(g.label == "balcony" and g.apart for g in inference.grids), names
    rects = _solved(inference, spec, 1.5)
    assert "balcony" in {r.label for r in rects}


@pytest.mark.parametrize("seed", [6, 9, 10])
def test_a_facade_with_defects_shares_its_bays_and_keeps_its_columns_wider(
    tmp_path: Path, seed: int
) -> None:
    """The family with CMP's defects (``family(defects=True)``: end bays wider than the
    rest, a window missing or drawn wider or narrower in some bays): the bays are read
    about their openings (an end bay's wider wall does not make its neighbour unlike),
    a bay differing in one opening is a variant of its kind on the kind's shape, so the
    bays are shared, and at 1.5x the width the façade gains whole columns of windows
    (each holding as many as a column of the input), the windows keep their size and
    the door is not repeated. Before, seeds 9 and 10 kept per-layer words (no two of
    their bays alike); seed 6 (a bay without one window) shared them as it does now."""
    path = tmp_path / f"family-{seed}.xml"
    path.write_text(cmp_xml(family(seed, defects=True)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    assert not inference.unshared, inference.bays
    raw = list((inference.raw or inference.layout).rects)
    drawn = _columns(raw)
    widths = [r.x1 - r.x0 for r in raw if r.label == "window"]
    rects = _solved(inference, spec, 1.5)
    columns = _columns(rects)
    assert set(columns) <= set(drawn), (columns, drawn)
    assert len(columns) > len(drawn)
    assert sum(r.label == "door" for r in rects) == 1
    assert all(
        any(abs((r.x1 - r.x0) / w - 1) <= 0.15 for w in widths)
        for r in rects
        if r.label == "window"
    )


@pytest.mark.parametrize("seed", [15, 18, 19])
def test_bays_are_kept_only_as_faithful_to_the_drawing_as_the_structure(
    tmp_path: Path, seed: int
) -> None:
    """Putting the bays on their kinds' shapes snaps sizes and rows to the façade's
    common values; bays are kept only where that leaves the mean IoU per label against
    the drawing within ``KEEP`` of the structure's, or, where no way of finding them
    does, at ``FAITHFUL`` or more and within ``LOOSE`` of it; never an element more lost
    or fused (on the family with defects, seed 18's bays read about their openings lost
    0.004 and seed 19's as cut 0.002)."""
    path = tmp_path / f"family-{seed}.xml"
    path.write_text(cmp_xml(family(seed, defects=True)[0]))
    options = Options(size=(15.0, 15.0))
    tidied = tidy_layout(path, options, Deadline(options.time_limit, str(path)))
    regular = structured(tidied.layout)
    bays = find_bays(regular, tidied.raw)
    was = fidelity(tidied.raw, regular)
    if isinstance(bays, Bays):
        now = fidelity(tidied.raw, bays.layout)
        assert now.iou_mean >= min(was.iou_mean - KEEP, max(FAITHFUL, was.iou_mean - LOOSE))
        assert now.lost <= was.lost and now.fused <= was.fused
    else:
        assert "IoU" in bays, bays


def test_a_facade_of_unlike_bays_keeps_its_windows_sized_when_narrower(
    tmp_path: Path,
) -> None:
    """Five bays each unlike the others (window widths 0.9-1.7 m, a door, sills under the
    windows, the top floor's windows narrower), as real façades are drawn: no kind
    repeats side by side. The openings are never squeezed: every window and the door
    solved at 0.7x are within 15% of the width of one drawn (before the walls and
    margins took the slack, the windows were squeezed to slivers); the inner bays but
    the door's each have a counter (bays drawn once), so the façade drops bays there,
    keeping its one door."""
    bays = ((0.6, 1.2), (3.2, 0.9), (5.6, 1.7), (8.9, 1.1), (11.4, 1.4))
    rects = []
    for k, (x, w) in enumerate(bays):
        for f, y in enumerate((1.0, 4.0, 7.0, 10.0)):
            if k == 2 and f == 0:
                rects.append({"label": "door", "x0": x, "y0": 0.0, "x1": x + w, "y1": 2.6})
                continue
            width = w * (0.8 if f == 3 else 1.0)
            rects.append({"label": "window", "x0": x, "y0": y, "x1": x + width, "y1": y + 1.6})
            rects.append(
                {"label": "sill", "x0": x - 0.05, "y0": y - 0.2, "x1": x + width + 0.05, "y1": y}
            )
    path = tmp_path / "unlike.json"
    path.write_text(json.dumps({"canvas": {"width": 13.5, "height": 12.5}, "rects": rects}))
    inference = infer(path, path.stem, Options())
    assert inference.bays.startswith("5 bays of 5 kinds"), inference.bays
    spec = parse_spec(inference.text, path.stem)
    for label in ("window", "door"):
        drawn = [r["x1"] - r["x0"] for r in rects if r["label"] == label]
        found = [r.x1 - r.x0 for r in _solved(inference, spec, 0.7) if r.label == label]
        assert 0 < len(found) <= len(drawn) and (label == "window") == (len(found) < len(drawn))
        squeezed = [w for w in found if not any(abs(w / d - 1) <= 0.15 for d in drawn)]
        assert not squeezed, (label, squeezed)


def test_bays_the_gate_refused_are_kept_where_the_facade_keeps_the_bar(tmp_path: Path) -> None:
    """Family-with-defects seed 19: its bays on their kinds' shapes lose more than
    ``KEEP`` of IoU against the structure's, in every way of finding them, but keep a
    mean IoU over ``FAITHFUL`` within ``LOOSE``, nothing lost or fused: its bays are
    shared, and at 2x width it gains whole bays (density 1.14 of the drawing's) where
    its per-layer words gained none (0.82: the margins took the width)."""
    path = tmp_path / "family-19.xml"
    boxes, known = family(19, defects=True)
    path.write_text(cmp_xml(boxes))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    assert "bays of" in inference.bays, inference.bays
    spec = parse_spec(inference.text, path.stem)
    solved = solved_layout(solve(spec), spec, inference)
    faithful = fidelity(inference.raw or inference.layout, solved)
    assert faithful.iou_mean >= FAITHFUL and faithful.lost == 0 and faithful.fused == 0
    wider = [r for r in _solved(inference, spec, 2.0) if r.label == "window"]
    assert len(wider) >= 2 * 0.85 * known.windows, (len(wider), known.windows)


def test_every_layer_writes_its_bay_gaps_from_the_lines_the_bay_shares() -> None:
    """Five bays alike, a window over a sill of its width, each sill drawn on its window
    but the first, 3.5 mm to the right (as on hold-out seed 116): the kind's sill,
    fitted on its own, stood 0.7 mm off its window, the window layer's word wrote a
    0.7 mm gap before the kind's wall that the sill layer's did not, and with the
    elements' widths held the spec did not solve (the solver sizes no letter under a
    millimetre). On the kind's shared lines the sill stands on its window's edges, and
    the spec solves at the façade's width."""
    rects = [Rect(BACKGROUND, 0.0, 0.0, 11.0, 6.0, 0)]
    for k in range(5):
        shift = 0.0035 if k == 0 else 0.0
        rects.append(Rect("window", 1.0 + 2 * k, 2.0, 2.0 + 2 * k, 3.5, 1))
        rects.append(Rect("sill", 1.0 + 2 * k + shift, 1.8, 2.0 + 2 * k + shift, 2.0, 2))
    layout = LabelledLayout(11.0, 6.0, tuple(rects))
    bays = find_bays(layout)
    assert isinstance(bays, Bays) and bays.kinds == (0,) * 5 and not bays.apart
    placed = bays.layout.rects
    for window, sill in zip(placed[1::2], placed[2::2], strict=True):
        assert (sill.x0, sill.x1) == (window.x0, window.x1)
    regular, found, shared, alike = run._layered(layout, bays, by_floor=False)
    spread = run.size_spread(regular, layout)  # the elements' widths held, as infer's
    text = spec_text("lines", 11.0, 6.0, found, "lines.xml", spread, shared, alike)
    spec = parse_spec(text, "lines.xml")
    shapes = solve(spec).shapes
    assert sum(s.layer.startswith("sill") for s in shapes) == 5


def _window_columns(boxes: list[tuple[str, float, float, float, float]]) -> list[float]:
    """The centres of the columns of windows (centres within 2 cm are one column)."""
    centres = sorted({round((b[1] + b[3]) / 2, 2) for b in boxes if b[0] == "window"})
    columns: list[float] = []
    for c in centres:
        if not columns or c - columns[-1] > 0.02:
            columns.append(c)
    return columns


def _bays_drawn_unlike(seed: int) -> list[tuple[str, float, float, float, float]]:
    """Family seed ``seed`` (mirrored, no blinds) with each bay's windows and sills drawn
    a fifth wider a bay in from the ends (about their centres; the middle bay's as its
    neighbours'): mirrored partners stay nearly alike (the drawing's jitter), no two bays
    of the half are alike, as on CMP."""
    boxes, _ = family(seed)
    columns = _window_columns(boxes)
    out = []
    for label, x0, y0, x1, y1 in boxes:
        if label in ("window", "sill"):
            centre = (x0 + x1) / 2
            bay = min(range(len(columns)), key=lambda k: abs(columns[k] - centre))
            scale = 1 + 0.2 * min(bay, len(columns) - 1 - bay, 2)
            half = (x1 - x0) * scale / 2
            x0, x1 = centre - half, centre + half
        out.append((label, x0, y0, x1, y1))
    return out


def test_bays_drawn_once_drop_and_gain_in_mirrored_pairs(tmp_path: Path) -> None:
    """Seed 48 (seven bays of four floors, mirrored, the door's bay in the middle) with
    every pair of bays the same way in drawn a fifth wider than the pair outside it
    (``ABCDCBA``): no unit of bays repeats side by side, so before, the spec kept a word
    a layer and solved at 0.7x or 2x kept its seven columns. Now the inner bays each
    have a counter, at one where drawn, shared with their mirrored partner: the layout
    at 1x keeps its 7 columns, and solved narrower or wider the façade drops or gains
    whole columns of windows (density within 0.85-1.15), stays mirrored, and every
    window keeps its drawn width (within 15%)."""
    path = tmp_path / "unlike-48.xml"
    path.write_text(cmp_xml(_bays_drawn_unlike(48)))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    assert inference.bays.startswith("7 bays of 4 kinds (ABCDCBA)"), inference.bays
    spec = parse_spec(inference.text, path.stem)
    raw = list((inference.raw or inference.layout).rects)
    drawn = [r for r in raw if r.label == "window"]
    widths = [r.x1 - r.x0 for r in drawn]
    assert len(_columns(list(solved_layout(solve(spec), spec, inference).rects))) == 7
    for share in (0.7, 2.0):
        rects = _solved(inference, spec, share)
        windows = [r for r in rects if r.label == "window"]
        assert (len(_columns(rects)) < 7) if share < 1 else (len(_columns(rects)) > 7)
        assert 0.85 <= len(windows) / len(drawn) / share <= 1.15, (share, len(windows))
        assert _mirrored(rects, inference.layout.width * share)
        assert all(any(abs((r.x1 - r.x0) / w - 1) <= 0.15 for w in widths) for r in windows)
        assert sum(r.label == "door" for r in rects) == 1


def _bays_each_unlike(seed: int) -> list[tuple[str, float, float, float, float]]:
    """Family seed ``seed`` with each bay's windows and sills drawn wider or narrower
    about their centres, by a share of their own that no other bay shares (0.7-1.4):
    every bay a kind of its own, as on most CMP samples."""
    boxes, _ = family(seed)
    columns = _window_columns(boxes)
    scales = (1.0, 1.3, 0.85, 1.15, 0.7, 1.4, 0.95, 1.22, 0.78)
    out = []
    for label, x0, y0, x1, y1 in boxes:
        if label in ("window", "sill"):
            centre = (x0 + x1) / 2
            bay = min(range(len(columns)), key=lambda k: abs(columns[k] - centre))
            half = (x1 - x0) * scales[bay] / 2
            x0, x1 = centre - half, centre + half
        out.append((label, x0, y0, x1, y1))
    return out


def test_bays_drawn_once_solve_at_their_drawn_counts_at_1x(tmp_path: Path) -> None:
    """Seed 13 (five bays of four floors, the door under the second's windows) with
    every bay drawn unlike the others (``ABCDE``): the three inner bays are on counters
    at one where drawn. The structure leaves one sill a fifth of a millimetre in from
    its bay's edge; written as a gap, that sliver is under the solver's least letter (a
    millimetre), so the drawn counts had no layout and the solver took others at the
    input's size (before: no end bays, the narrowest bay four times, the door's column
    moved). Now the element meets the edge: solved at 1x every counter of bays is at
    its drawn count and the columns are the drawing's; narrower the façade drops bays,
    wider it gains them, every window at a drawn width (within 15%), one door."""
    path = tmp_path / "unlike-13.xml"
    boxes = _bays_each_unlike(13)
    path.write_text(cmp_xml(boxes))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    assert inference.bays.startswith("5 bays of 5 kinds (ABCDE)"), inference.bays
    spec = parse_spec(inference.text, path.stem)
    raw = list((inference.raw or inference.layout).rects)
    widths = [r.x1 - r.x0 for r in raw if r.label == "window"]
    layout = solve(spec)
    assert {n: v for n, v in layout.counters.items() if n.startswith("bays")} == {
        "bays1": 1,
        "bays2": 1,
        "bays3": 1,
        "bays4": 0,  # the copies gained at the façade's density (``bays._gains``): none
    }
    assert _columns(list(solved_layout(layout, spec, inference).rects)) == _columns(raw)
    for share in (0.7, 2.0):
        rects = _solved(inference, spec, share)
        columns = len(_columns(rects))
        assert columns < len(_columns(raw)) if share < 1 else columns > len(_columns(raw))
        windows = [r for r in rects if r.label == "window"]
        assert all(any(abs((r.x1 - r.x0) / w - 1) <= 0.15 for w in widths) for r in windows)
        assert sum(r.label == "door" for r in rects) == 1


@pytest.mark.parametrize("seed", [8, 14])
def test_a_mirrored_facade_of_bays_drawn_once_stays_mirrored(tmp_path: Path, seed: int) -> None:
    """Family seeds 8 and 14 with defects (wider end bays, odd windows): mirrored as
    drawn, every bay unlike the others. Put as the structure placed them (bays drawn
    once), their bays passed the gate on a sequence not written reflected, and solved
    at 0.7x and 2x the façade went lopsided; on shapes fitted about the middle it stays
    mirrored at every width."""
    path = tmp_path / f"family-{seed}.xml"
    path.write_text(cmp_xml(family(seed, defects=True)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    for share in (0.7, 1.0, 2.0):
        rects = _solved(inference, spec, share)
        assert _mirrored(rects, inference.layout.width * share), share


ABA_SEEDS = [s for s in range(1, 80) if family(s)[1].mirrored and family(s)[1].bays == 3]


MIRRORED_SEEDS = [s for s in range(1, 80) if family(s)[1].mirrored and family(s)[1].bays > 3]


@pytest.mark.parametrize("seed", ABA_SEEDS[:3] + ABA_SEEDS[-2:] + MIRRORED_SEEDS[:2])
def test_a_mirrored_facade_stays_mirrored_narrower_and_wider(tmp_path: Path, seed: int) -> None:
    """A façade drawn mirrored stays so at 0.7x and 2x, its door once. On ``ABA`` (the
    door's bay between two window columns) only the end bays could repeat: dropping
    both leaves the door's bay alone (density 0.36-0.43 at 0.7x), and a spare copy of
    the last bay let the end bays change one at a time, which lost the mirror (0.7x: 10
    of 10 generated ``ABA`` façades; 2x: 6 of 10). A mirrored façade now keeps a word a
    layer there, as before the end bays repeated: the mirror and the windows' density
    kept, its columns squeezed."""
    inference, spec = _inferred(tmp_path, seed)
    raw = list((inference.raw or inference.layout).rects)
    assert _mirrored(raw, inference.layout.width)
    for share in (0.7, 2.0):
        rects = _solved(inference, spec, share)
        assert _mirrored(rects, round(inference.layout.width * share, 4)), share
        assert sum(r.label == "door" for r in rects) == 1, share


def _doors_in_every_bay(seed: int) -> list[tuple[str, float, float, float, float]]:
    """Family seed ``seed`` with a door (the family's door's size) in every ground-floor
    bay where a window and its sill were: a row of shops."""
    boxes, _ = family(seed)
    door = next(b for b in boxes if b[0] == "door")
    low = min(b[2] for b in boxes if b[0] == "window")
    ground = [b for b in boxes if b[0] in ("window", "sill") and b[2] <= low + 0.02]
    out = [b for b in boxes if b not in ground]
    half = (door[3] - door[1]) / 2
    for _, x0, _, x1, _ in (b for b in ground if b[0] == "window"):
        out.append(("door", (x0 + x1) / 2 - half, 0.0, (x0 + x1) / 2 + half, door[4]))
    return out


@pytest.mark.parametrize("seed", [7, 12])
def test_a_door_in_every_bay_repeats_with_its_bays(tmp_path: Path, seed: int) -> None:
    """A door in every bay singles none out: the bays are one kind and repeat, doors and
    all. Before, every bay was unique, each layer kept a word of its own, and a wider
    façade gained windows over the doors' row but no door (seed 7 at 2x: five doors
    under ten columns). Now each column keeps its door under it at every width."""
    path = tmp_path / f"doors-{seed}.xml"
    path.write_text(cmp_xml(_doors_in_every_bay(seed)))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    raw = list((inference.raw or inference.layout).rects)
    doors = sum(r.label == "door" for r in raw)
    assert not inference.unshared, inference.bays
    for share in (0.7, 1.5, 2.0):
        rects = _solved(inference, spec, share)
        columns = len(_columns(rects))
        assert sum(r.label == "door" for r in rects) == columns, share
        assert (columns < doors) if share < 1 else (columns > doors), share
        assert 0.85 <= columns / doors / share <= 1.15, (share, columns)


def test_a_gap_in_a_bay_is_cut_only_at_the_lines_of_the_elements_beside_it(
    tmp_path: Path,
) -> None:
    """Four bays of a window over its sill, a small ornament up in each bay's left
    wall: the window's gap from its bay's edge is its sill's gap and the sill's inset
    (one symbol either side, as the sill's layer names them), not cut again at the
    ornament's edges, which stand beside neither; nor the ornament's gap after it at the
    window's and sill's. Cut at every line of the kind, the words held every line of
    every layer (CMP's b0001: 6,058 letters along x where 2,590 hold the same layout,
    its solves five times the CPU)."""
    rects: list[dict[str, object]] = []
    for k in range(4):
        x = 1.0 + 3.0 * k
        for y in (2.0, 5.0, 8.0):
            rects.append({"label": "window", "x0": x, "y0": y, "x1": x + 1.2, "y1": y + 1.5})
            rects.append({"label": "sill", "x0": x - 0.1, "y0": y - 0.15, "x1": x + 1.3, "y1": y})
        rects.append({"label": "deco", "x0": x - 0.7, "y0": 9.8, "x1": x - 0.5, "y1": 10.4})
    path = tmp_path / "deco.json"
    path.write_text(json.dumps({"canvas": {"width": 12.6, "height": 11.0}, "rects": rects}))
    inference = infer(path, "deco")
    assert inference.bays == "4 bays of 1 kinds (AAAA)", inference.bays
    spec = parse_spec(inference.text, "deco.yaml")
    words = {layer.name: layer.x for layer in spec.layers}
    sill = re.fullmatch(r"bays_m1 \((\w+) sill_w1 bay1_w\)\^bays1 bays_m2", words["sill"])
    assert sill, words["sill"]
    inset = r"(bay1_g\d+)"
    window = rf"bays_m1 \({sill[1]} {inset} window_w1 \1 bay1_w\)\^bays1 bays_m2"
    assert re.fullmatch(window, words["window"]), words["window"]
    deco = r"bays_m1 \(bay1_g\d+ deco_w1 bay1_g\d+ bay1_w\)\^bays1 bays_m2"
    assert re.fullmatch(deco, words["deco"]), words["deco"]


def _pilastered(seed: int) -> tuple[list[dict[str, object]], float]:
    """A generated façade of bays drawn once (``seed``: 4-6 window columns, each its own
    width, 1.0-2.0 m, on 3-4 floors, drawn with a hand's jitter), a door under one inner
    column and a pillar in every wall between two columns and in both margins (as CMP's
    b0001, b0004 and b0009-b0011, whose bays are each drawn once, draw them): its
    rectangles and its width."""
    rng = random.Random(seed)
    bays, floors = rng.randint(4, 6), rng.randint(3, 4)
    door = rng.randrange(1, bays - 1)
    pillar = rng.uniform(0.25, 0.35)
    widths = [1.0 + 0.2 * k for k in range(bays)]
    rng.shuffle(widths)
    x, rects = 0.5 + rng.uniform(0.0, 0.2), []
    rects.append({"label": "pillar", "x0": x, "y0": 1.0, "x1": x + pillar, "y1": 3.0 * floors})
    x += pillar
    for k in range(bays):
        wall, window = rng.uniform(0.6, 0.9), widths[k] + rng.uniform(-0.03, 0.03)
        x += wall
        for floor in range(1, floors):
            jitter = rng.uniform(-0.02, 0.02)
            rects.append(
                {"label": "window", "x0": x + jitter, "y0": 3.0 * floor + 0.5}
                | {"x1": x + window + jitter, "y1": 3.0 * floor + 2.0}
            )
        if k == door:
            rects.append({"label": "door", "x0": x, "y0": 0.0, "x1": x + window, "y1": 2.4})
        x += window + wall
        rects.append({"label": "pillar", "x0": x, "y0": 1.0, "x1": x + pillar, "y1": 3.0 * floors})
        x += pillar
    return rects, round(x + 0.5 + rng.uniform(0.0, 0.2), 4)


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_pillars_in_the_walls_between_bays_are_gained_and_dropped_with_them(
    tmp_path: Path, seed: int
) -> None:
    """A pillar in every wall between two window columns and in both margins: each wall
    is cut beside its pillar (the line the fewest elements stand across), and the end
    bays reach over the margins' pillars, so every pillar is a bay's and is gained and
    dropped with it. At 0.7x and 2x every wall between two columns still holds one
    pillar, and no pillar stands over a window. Cut at the walls' middles, the pillars
    stood in no bay and kept words of their own: at 2x they bunched over the windows."""
    rects, width = _pilastered(seed)
    path = tmp_path / f"pillars-{seed}.json"
    path.write_text(json.dumps({"canvas": {"width": width, "height": 13.0}, "rects": rects}))
    inference = infer(path, "pillars")
    assert not inference.unshared, inference.bays
    spec = parse_spec(inference.text, "pillars.yaml")
    for share in (0.7, 1.0, 2.0):
        solved = _solved(inference, spec, share)
        windows = [r for r in solved if r.label == "window"]
        pillars = sorted((r for r in solved if r.label == "pillar"), key=lambda r: r.x0)
        assert not [
            (p, w) for p in pillars for w in windows if min(p.x1, w.x1) - max(p.x0, w.x0) > 0.01
        ], share
        columns = sorted({round((w.x0 + w.x1) / 2, 1) for w in windows})
        for left, right in pairwise(columns):  # one pillar in each wall between columns
            assert sum(left < (p.x0 + p.x1) / 2 < right for p in pillars) == 1, (share, left)


def _ornamented(seed: int) -> tuple[LabelledLayout, list[Rect]]:
    """A generated façade (``seed``: 4-6 window columns, each its own width, on 3-4
    floors, walls 1.4-2.0 m between them) whose windows stand on balconies reaching from
    a little left of the window to just past the middle of the wall on its right, and
    with three ornaments in a row in every wall under the roof, the middle one across
    the wall's middle by a hand's jitter (as CMP's b0007 draws them): the layout and
    the ornaments across the walls' middles, left to right."""
    rng = random.Random(seed)
    columns, floors = rng.randint(4, 6), rng.randint(3, 4)
    x, rects, middles = 1.0, [], []
    for k in range(columns):
        window = rng.uniform(1.0, 1.6)
        wall = rng.uniform(1.4, 2.0)
        middle = x + window + wall / 2
        for floor in range(floors):
            y = 3.0 * floor + 0.8
            rects.append(Rect("window", x, y, x + window, y + 1.6))
            if k < columns - 1:
                rects.append(Rect("balcony", x - 0.1, y - 0.3, middle + 0.27, y))
        if k < columns - 1:
            jitter = rng.uniform(-0.1, 0.1)
            middles.append(Rect("deco", middle - 0.15 + jitter, 12.5, middle + 0.15 + jitter, 13.0))
            rects.append(middles[-1])
            rects.append(Rect("deco", middle - 0.6, 12.5, middle - 0.3, 13.0))
            rects.append(Rect("deco", middle + 0.3, 12.5, middle + 0.6, 13.0))
        x += window + wall
    return LabelledLayout(round(x + 0.5, 4), 14.0, tuple(rects)), middles


@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5, 6])
def test_a_wall_is_cut_no_further_than_the_ornament_across_its_middle(seed: int) -> None:
    """A wall is cut beside what of its own stands across its middle (an ornament, a
    pillar), never further: the balconies that reach into it from the window on its
    left, ending just past the middle, neither move the cut nor give it a line, so
    the bays either side keep their widths but for the ornament's share. Cut where the
    fewest elements stood across it, each wall was cut past the balconies' ends, at
    the next ornament (every bay the wider by the wall's balcony reach; CMP's b0007
    dropped two of its four window columns at 0.7x the width); cut at the middle, the
    ornament stood across the cut, in no bay."""
    layout, ornaments = _ornamented(seed)
    strips, spans, _ = _strips(layout)
    assert len(strips) == len(ornaments) + 1
    cuts = [high for _, high in spans[:-1]]
    for cut, ornament in zip(cuts, ornaments, strict=True):
        assert min(abs(cut - ornament.x0), abs(cut - ornament.x1)) < 1e-9, (cut, ornament)
    kept = {layout.rects.index(o) for o in ornaments}
    assert kept <= {k for _, held in strips for k in held}  # each in a bay


@pytest.mark.parametrize("seed", [12, 20])
def test_a_column_and_its_narrow_bay_drop_and_gain_together(tmp_path: Path, seed: int) -> None:
    """Generated façades whose columns of windows alternate with narrow bays of one
    small window on the top floor (``paired_family``: ``ABAB..``, every bay drawn
    unlike, a door in one column). Counted a bay at a time, a column and a narrow bay
    were on counters of their own, so a narrower or wider façade traded one for the
    other and kept its width but not its windows a metre (before: density 0.82 / 1.24 /
    1.36 on seed 12, 1.27 / 0.52 / 1.35 on seed 20 at 0.7x / 1.5x / 2x). Counted in
    pairs (a column with its narrow bay), it drops and gains whole pairs: the windows a
    square metre stay within 0.85-1.15 of the drawing's at every width, each window at
    a drawn size (within 15%), one door."""
    path = tmp_path / f"paired-{seed}.xml"
    boxes, known = paired_family(seed)
    path.write_text(cmp_xml(boxes))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    raw = list((inference.raw or inference.layout).rects)
    drawn = [r for r in raw if r.label == "window"]
    assert len(drawn) == known.windows
    _in_band_at(inference, spec, drawn, (0.7, 1.5, 2.0))


def test_bays_drawn_once_are_counted_in_the_smallest_unit_that_holds_alike_openings() -> None:
    """``_units``: single bays where they hold alike numbers of openings (CMP's b0012:
    two columns of five); pairs side by side, counted in from the nearer end, where a
    column alternates with a narrow bay of one window (CMP's b0008: 7 1 6 1 | 1 6 1 7,
    pairs of 8 7 | 7 8); a bay left over by the pairs (the middle one, one beside a
    unique bay) is in no unit; single bays where no pairs are alike either."""
    assert _units([1, 3], 5, [5, 5]) == [[(1, 0)], [(3, 0)]]
    assert _units(list(range(1, 9)), 10, [7, 1, 6, 1, 1, 6, 1, 7]) == [
        [(1, 0), (2, 0)],
        [(3, 1), (4, 1)],
        [(5, 1), (6, 1)],
        [(7, 0), (8, 0)],
    ]
    assert _units([1, 2, 3, 4, 5], 7, [1, 6, 1, 6, 1]) == [[(1, 0), (2, 0)], [(4, 0), (5, 0)]]
    assert _units([1, 2, 3, 4], 6, [9, 1, 1, 2]) == [[(1, 0)], [(2, 1)], [(3, 1)], [(4, 0)]]


def test_two_units_on_one_counter_drop_one_at_a_time_with_a_spare(tmp_path: Path) -> None:
    """Generated seed 3 of ``paired_family`` (``ABABCDE``: two pairs of a column and its
    narrow bay, one each side of the middle, then the door's column and an end bay): its
    one counter of pairs drops both (6.7 m, 45% of the façade) or none, so at 0.7x it
    kept both and squeezed its margins (before: density 1.26) or, counted in pairs with
    no spare, dropped both (0.66). The spare copy of the last pair (``max: 1``, none at
    1x) lets it drop one: at 0.7x one pair fewer, density within 0.85-1.15; at 1x the
    drawn layout (the pairs' counter at one, the spare at none)."""
    path = tmp_path / "paired-3.xml"
    path.write_text(cmp_xml(paired_family(3)[0]))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    words = _x_words(inference.text)
    units = [w for w in words.values() if re.search(r"\(bay\d+_\S+ bay\d+_w bay\d+_", w)]
    assert units, "no layer writes a unit of two bays"
    spares = re.findall(r"(bays\d+): \{min: 0, max: 1\}  # a copy of a unit", inference.text)
    assert len(spares) == 1
    assert solve(spec).counters[spares[0]] == 0
    drawn = [r for r in (inference.raw or inference.layout).rects if r.label == "window"]
    rects = _solved(inference, spec, 0.7)
    windows = [r for r in rects if r.label == "window"]
    assert 0.85 <= len(windows) / len(drawn) / 0.7 <= 1.15, len(windows)


@pytest.mark.parametrize(
    ("count", "most", "note"),
    [
        (1, 1, "1 end bay (it may drop)"),
        (2, 1, "2 end bays (they may drop)"),
        (1, None, "1 bay"),
        (3, None, "3 bays"),
        (0, 1, "a copy of a unit of 1 bay more (the units change one at a time)"),
    ],
)
def test_a_bay_counters_comment_counts_in_words(count: int, most: int | None, note: str) -> None:
    """The comment over a counter of bays reads as English: one end bay, not "1 end bays"."""
    assert _bay_counter_note("bays1", count, most, (None, None), None) == note


def test_the_counter_comment_names_which_end_bay_the_spare_copies() -> None:
    """Where only the end bays repeat, each end has a spare copy (``Bays.spare``: the
    last bay's, ``Bays.spare_first``: the first's); the spec's comment on each counter
    says which, and the ends' own counter stays the end bays'."""
    spares = ("bays3", "bays4")
    assert _bay_counter_note("bays3", 0, 1, spares, None).startswith("a copy of the last bay")
    assert _bay_counter_note("bays4", 0, 1, spares, None).startswith("a copy of the first bay")
    assert _bay_counter_note("bays1", 2, 1, spares, None) == "2 end bays (they may drop)"
    assert _bay_counter_note("bays2", 3, None, spares, None) == "3 bays"


@pytest.mark.parametrize("seed", [1, 11, 13])
def test_copies_gained_are_no_denser_than_the_facade(tmp_path: Path, seed: int) -> None:
    """Generated façades whose door stands in a bay of its own, no window over it
    (``doorway_family``, as CMP's b0012): each column holds more windows a metre than
    the façade, so a wider façade that gained columns at their drawn pitch grew denser
    than drawn (before, at 1.5x / 2x: 1.11 / 1.33 on seed 1, 1.20 / 1.20 on seed 11,
    1.00 / 1.25 on seed 13). The copies gained
    are a counter of their own, each with the wall before it that puts it at the
    façade's windows a metre (``bays._gains``): the windows a square metre stay within
    0.85-1.15 of the drawing's, each window at a drawn size, one door; at 1x no copy is
    gained and the drawn layout is kept."""
    path = tmp_path / f"doorway-{seed}.xml"
    boxes, known = doorway_family(seed)
    path.write_text(cmp_xml(boxes))
    inference = infer(path, path.stem, Options(size=(15.0, 15.0)))
    spec = parse_spec(inference.text, path.stem)
    gains = re.findall(r"(bays\d+): \{min: 0\}  # copies of the units of", inference.text)
    assert gains, "no counter of copies gained at the façade's density"
    assert all(solve(spec).counters[gain] == 0 for gain in gains)
    drawn = [r for r in (inference.raw or inference.layout).rects if r.label == "window"]
    assert len(drawn) == known.windows
    _in_band_at(inference, spec, drawn, (1.5, 2.0))
