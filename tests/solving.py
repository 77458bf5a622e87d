"""Helpers for solver tests: specs from text, letters and shapes by name."""

from __future__ import annotations

import textwrap

from facadecli import Layout, parse_spec, solve
from facadecli.solver.axis import PlacedLetter


def solve_text(text: str) -> Layout:
    """The layout of a spec's text, with its wall-clock safety net (``solver.time_limit``)
    out of reach unless the text sets it: the work budgets decide, so the answer does not
    depend on the machine's load (a search-heavy spec takes seconds where the searches
    run in pure Python, on a machine with no C compiler)."""
    spec = parse_spec(textwrap.dedent(text), "test.yaml")
    if "time_limit" not in text:
        spec = spec.model_copy(
            update={"solver": spec.solver.model_copy(update={"time_limit": 3600.0})}
        )
    return solve(spec)


def letters(layout: Layout, layer: str, axis: str) -> list[PlacedLetter]:
    index = [layer_.name for layer_ in layout.spec.layers].index(layer)
    return list(layout.letters(index, axis))


def spans(layout: Layout, layer: str, axis: str, symbol: str) -> list[tuple[float, float]]:
    return [
        (round(p.start, 6), round(p.end, 6))
        for p in letters(layout, layer, axis)
        if p.symbol == symbol
    ]
