"""``facade vary``'s draws (issue 14): near-best layouts first, then the spec solved with
its sizes drawn near their own, as Bao et al. 2013 draw region sizes."""

from __future__ import annotations

import random
from pathlib import Path

from facadecli import load_spec
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
