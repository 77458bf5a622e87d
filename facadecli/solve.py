"""``solve(spec) -> Layout``: both axes, then the shapes; and variations of a spec."""

from __future__ import annotations

import itertools
import random
import time
from dataclasses import replace

from facadecli import proportions
from facadecli.errors import InfeasibleError, SearchLimitError
from facadecli.layout import Layout, build_shapes, uncovered_area
from facadecli.solver.axis import AxisLayout, solve_axis_alternatives
from facadecli.solver.budgets import safety_clock
from facadecli.spec.model import Canvas, Solver, Spec

ALTERNATIVES_PER_AXIS = 8
HOLE = 1e-6  # m^2: less uncovered area than this is no hole


def retarget(
    spec: Spec,
    width: float | None = None,
    height: float | None = None,
    seed: int | None = None,
    name: str | None = None,
) -> Spec:
    """The spec with another canvas size, seed or name (``--width/--height/--seed``)."""
    canvas = Canvas(
        width=spec.canvas.width if width is None else width,
        height=spec.canvas.height if height is None else height,
    )
    solver = spec.solver if seed is None else Solver(**{**spec.solver.model_dump(), "seed": seed})
    return spec.model_copy(update={"canvas": canvas, "solver": solver, "name": name or spec.name})


def _axes(spec: Spec, alternatives: int) -> tuple[list[AxisLayout], list[AxisLayout], float]:
    """Both axes' best layouts. Each axis is bounded by work units; the time limit is a
    safety net per axis, which a normal solve never reaches."""
    started = time.perf_counter()
    limit = spec.solver.time_limit
    x = solve_axis_alternatives(spec, "x", spec.canvas.width, safety_clock() + limit, alternatives)
    y = solve_axis_alternatives(spec, "y", spec.canvas.height, safety_clock() + limit, alternatives)
    return x, y, started


def _layout(spec: Spec, x: AxisLayout, y: AxisLayout, started: float) -> Layout:
    shapes = build_shapes(spec, x, y)
    elapsed = (time.perf_counter() - started) * 1000
    return Layout(spec, spec.canvas.width, spec.canvas.height, x, y, shapes, elapsed)


def solve(spec: Spec) -> Layout:
    """Solve a spec into a layout; raises InfeasibleError when no layout exists.

    Every search is bounded by work units (the same answer on any machine);
    ``spec.solver.time_limit`` is a safety net per axis: when it fires, the layout carries
    a warning, or :class:`SearchLimitError` says that no layout was found in time.
    """
    x, y, started = _axes(spec, 1)
    layout = _layout(spec, x[0], y[0], started)
    if uncovered_area(layout) <= HOLE:
        return layout
    # the axes' best layouts leave a hole together: look among near-best pairs for one that
    # does not, else keep the best and say where the hole is
    x, y, _ = _axes(spec, ALTERNATIVES_PER_AXIS)
    pairs = sorted(itertools.product(x, y), key=lambda pair: pair[0].objective + pair[1].objective)
    for pair in pairs:
        candidate = _layout(spec, pair[0], pair[1], started)
        if uncovered_area(candidate) <= HOLE:
            return candidate
    hole = uncovered_area(layout)
    warning = f"the layers leave {hole:.3f} m2 of the canvas uncovered (a hole in the façade)"
    return replace(layout, x=replace(layout.x, warnings=(*layout.x.warnings, warning)))


def solve_variants(spec: Spec, count: int) -> list[Layout]:
    """Up to ``count`` different layouts of a spec: the best first, then others drawn with
    ``spec.solver.seed`` from the pairs of near-best horizontal and vertical layouts (where
    the spec leaves choices open: alternations, free counters, placeholders), then, while
    fewer than ``count``, the spec solved with its symbols' sizes drawn near their own
    (:func:`proportioned`)."""
    x, y, started = _axes(spec, ALTERNATIVES_PER_AXIS)
    pairs = list(itertools.product(range(len(x)), range(len(y))))
    rest = pairs[1:]
    rng = random.Random(spec.solver.seed)
    rng.shuffle(rest)
    layouts = [solve(spec)]
    for i, j in rest:
        if len(layouts) >= count:
            break
        layout = _layout(spec, x[i], y[j], started)
        if uncovered_area(layout) <= HOLE and layout.shapes != layouts[0].shapes:
            layouts.append(layout)
    for _ in range(proportions.DRAWS * (count - len(layouts))):
        if len(layouts) >= count:
            break
        try:
            layout = solve(proportioned(spec, rng))
        except (InfeasibleError, SearchLimitError):
            continue  # those sizes leave no layout: draw again
        if uncovered_area(layout) <= HOLE and all(layout.shapes != o.shapes for o in layouts):
            layouts.append(layout)
    return layouts


def proportioned(spec: Spec, rng: random.Random) -> Spec:
    """The spec with new preferred sizes near its own (:mod:`facadecli.proportions`, Bao et
    al. 2013): a factor per class of sizes (within ``proportions.CLASS_SHARE`` of each
    other), kept within the symbol's ``min`` and ``max``; the canvas, counters and every
    other setting as they were."""
    sizes = {name: s.size for name, s in spec.symbols.items() if s.size is not None}
    largest = max(sizes.values(), default=0.0)
    classes = proportions.size_classes(sizes.values(), proportions.CLASS_SHARE * largest)
    factors = {number: proportions.factor(rng) for number in sorted(set(classes.values()))}
    symbols = dict(spec.symbols)
    for name, size in sorted(sizes.items()):
        symbol = spec.symbols[name]
        drawn = size * factors[classes[size]]
        if symbol.min is not None:
            drawn = max(drawn, symbol.min)
        if symbol.max is not None:
            drawn = min(drawn, symbol.max)
        symbols[name] = symbol.model_copy(update={"size": round(drawn, 6)})
    return spec.model_copy(update={"symbols": symbols})
