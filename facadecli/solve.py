"""``solve(spec) -> Layout``: both axes, then the shapes."""

from __future__ import annotations

import time

from facadecli.layout import Layout, build_shapes
from facadecli.solver.axis import solve_axis
from facadecli.spec.model import Canvas, Solver, Spec


def retarget(
    spec: Spec, width: float | None = None, height: float | None = None, seed: int | None = None
) -> Spec:
    """The spec with another canvas size or seed (``--width/--height/--seed``)."""
    canvas = Canvas(
        width=spec.canvas.width if width is None else width,
        height=spec.canvas.height if height is None else height,
    )
    solver = spec.solver if seed is None else Solver(**{**spec.solver.model_dump(), "seed": seed})
    return spec.model_copy(update={"canvas": canvas, "solver": solver})


def solve(spec: Spec) -> Layout:
    """Solve a spec into a layout; raises InfeasibleError when no layout exists.

    The whole solve is bounded by ``spec.solver.time_limit``: the horizontal axis may use
    half of it, the vertical the rest; a search that runs out returns its best layout.
    """
    started = time.perf_counter()
    limit = spec.solver.time_limit
    x = solve_axis(spec, "x", spec.canvas.width, started + limit / 2)
    y = solve_axis(spec, "y", spec.canvas.height, started + limit)
    shapes = build_shapes(spec, x, y)
    elapsed = (time.perf_counter() - started) * 1000
    return Layout(spec, spec.canvas.width, spec.canvas.height, x, y, shapes, elapsed)
