"""Helpers for solver tests: specs from text, letters and shapes by name."""

from __future__ import annotations

import textwrap

from facadecli import Layout, parse_spec, solve
from facadecli.solver.axis import PlacedLetter


def solve_text(text: str) -> Layout:
    return solve(parse_spec(textwrap.dedent(text), "test.yaml"))


def letters(layout: Layout, layer: str, axis: str) -> list[PlacedLetter]:
    index = [layer_.name for layer_ in layout.spec.layers].index(layer)
    return list(layout.letters(index, axis))


def spans(layout: Layout, layer: str, axis: str, symbol: str) -> list[tuple[float, float]]:
    return [
        (round(p.start, 6), round(p.end, 6))
        for p in letters(layout, layer, axis)
        if p.symbol == symbol
    ]
