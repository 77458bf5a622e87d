"""``facade vary``'s draws (issue 14): near-best layouts first, then the spec solved with
its sizes drawn near their own, as Bao et al. 2013 draw region sizes."""

from __future__ import annotations

import itertools
import random
from pathlib import Path

import pytest

from facadecli import load_spec
from facadecli.proportions import warp
from facadecli.solve import proportioned, retarget, solve, solve_variants

ROOT = Path(__file__).resolve().parent.parent


def test_drawn_proportions_stay_near_keep_bounds_and_keep_equal_sizes_equal() -> None:
    spec = load_spec(ROOT / "specs" / "terraced-house.yaml")
    drawn = proportioned(spec, random.Random(3))
    assert drawn.canvas == spec.canvas and drawn.counters == spec.counters
    changed = 0
    for name, symbol in spec.symbols.items():
        new = drawn.symbols[name]
        if symbol.size is None:
            assert new.size is None
            continue
        assert 0.9 * symbol.size - 1e-6 <= new.size <= 1.11 * symbol.size  # type: ignore[operator]
        if symbol.min is not None:
            assert symbol.min <= new.size <= symbol.max  # type: ignore[operator]
        changed += new.size != symbol.size
    assert changed
    # S and Z are both 3.0 m, on purpose: one factor for both
    assert drawn.symbols["S"].size == drawn.symbols["Z"].size
    assert proportioned(spec, random.Random(3)) == drawn  # the seed decides


def test_vary_gives_as_many_layouts_as_asked_where_the_spec_leaves_few_choices() -> None:
    """The townhouse's free counter has one word that fits each width: near-best layouts
    alone gave 1 of 4 at 10 m; drawn proportions give 4, distinct, the best first."""
    spec = retarget(load_spec(ROOT / "specs" / "townhouse.yaml"), 10.0, None, 5)
    layouts = solve_variants(spec, 4)
    assert len(layouts) == 4
    assert layouts[0].shapes == solve(spec).shapes
    shapes = [layout.shapes for layout in layouts]
    assert all(a != b for i, a in enumerate(shapes) for b in shapes[i + 1 :])
    assert [layout.shapes for layout in solve_variants(spec, 4)] == shapes  # same seed


def _axis() -> list[tuple[float, float, str]]:
    """An axis 20 m long, mirrored about 10: wall, windows 1 m wide at one pitch, a door
    2 m wide on the centre line."""
    spans = [(0.0, 20.0, "wall"), (9.0, 11.0, "door")]
    for lo in (1.0, 3.0, 5.0):
        spans += [(lo, lo + 1.0, "window"), (19.0 - lo, 20.0 - lo, "window")]
    return spans


def test_a_warp_keeps_edges_in_order_and_stretches_of_one_kind_alike() -> None:
    spans = _axis()
    moved, drawn = warp(spans, 20.0, 0.4, random.Random(5))
    edges = sorted(moved)
    assert moved[0.0] == 0.0 and moved[20.0] == 20.0
    assert all(moved[a] < moved[b] for a, b in itertools.pairwise(edges))
    assert drawn and all(0.9 - 1e-6 <= f <= 1.11 for _, f in drawn)
    windows = {round(moved[hi] - moved[lo], 9) for lo, hi, label in spans if label == "window"}
    assert len(windows) == 1  # one kind: one factor
    pitches = {round(moved[a + 2.0] - moved[a], 9) for a in (1.0, 3.0)}
    assert len(pitches) == 1  # evenly spaced still
    assert any(abs(moved[v] - v) > 1e-3 for v in edges)  # something moved
    assert warp(spans, 20.0, 0.4, random.Random(5)) == (moved, drawn)  # the seed decides


def test_a_mirrored_warp_is_its_own_mirror_image() -> None:
    """A drain pipe down the right-hand edge makes the two margins stretches of different
    kinds, so drawn factors move the door off the centre line; a mirrored warp (the mean
    of the warp and its reflection) keeps every mirrored pair of edges mirrored and the
    door centred."""
    spans = [*_axis(), (19.6, 20.0, "pipe")]
    for seed in range(5):
        moved, _ = warp(spans, 20.0, 0.4, random.Random(seed), mirrored=True)
        for v, new in moved.items():
            if 20.0 - v in moved:
                assert moved[20.0 - v] == pytest.approx(20.0 - new, abs=1e-9)
        assert moved[9.0] + moved[11.0] == pytest.approx(20.0, abs=1e-9)
    plain = [warp(spans, 20.0, 0.4, random.Random(seed))[0] for seed in range(5)]
    assert any(abs(moved[9.0] + moved[11.0] - 20.0) > 1e-3 for moved in plain)
