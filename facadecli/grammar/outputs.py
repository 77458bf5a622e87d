"""What ``facade grammar`` writes: the grammar as text and JSON, the tiling as SVG, and a
report (cost, rules, time)."""

from __future__ import annotations

import itertools
import json
import re
from collections.abc import Sequence
from dataclasses import asdict
from typing import Any
from xml.sax.saxutils import escape

from facadecli.grammar.cga import grammar_cga
from facadecli.grammar.model import DerivedSize, Extraction
from facadecli.grammar.palette import label_colour
from facadecli.grammar.split import Grammar, derive_tree
from facadecli.grammar.tiling import Tiling

SCALE = 600.0  # pixels for the longer side of the façade
NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def xml_text(text: str) -> str:
    """Text for an XML element: markup escaped, and characters XML cannot hold (control
    characters, lone surrogates, U+FFFE/U+FFFF) replaced by U+FFFD."""
    return escape(NOT_XML.sub("\ufffd", text))


def _runs(row: tuple[str, ...]) -> list[tuple[int, int, str]]:
    """Runs of equal labels in a row of cells: (first column, column after, label)."""
    runs, start = [], 0
    for label, cells in itertools.groupby(row):
        stop = start + sum(1 for _ in cells)
        runs.append((start, stop, label))
        start = stop
    return runs


def grammar_json(grammar: Grammar) -> str:
    data: dict[str, Any] = {
        "start": grammar.start,
        "terminals": sorted(grammar.terminals),
        "costs": asdict(grammar.costs),
        "rules": {name: asdict(rule) for name, rule in grammar.rules.items()},
        "cost": round(grammar.cost, 6),
    }
    return json.dumps(data, indent=2) + "\n"


def _mix(a: str, b: str) -> str:
    """Half one colour, half the other."""
    channels = [(int(a[i : i + 2], 16) + int(b[i : i + 2], 16)) // 2 for i in (1, 3, 5)]
    return "#{:02x}{:02x}{:02x}".format(*channels)


def tiling_svg(tiling: Tiling, grammar: Grammar, title: str) -> str:
    """Two panels, drawn bottom up like the façade: the tiling's cells filled by label, and
    the grammar's regions, each terminal filled with the colour of the non-terminal that
    holds it (regions made by one rule look alike) and every non-terminal region outlined,
    the outer ones wider and named. Legends of labels and of the outer rules below."""
    width, height = tiling.xs[-1], tiling.ys[-1]
    scale = SCALE / max(width, height)
    w, h = width * scale, height * scale
    gap = 30.0
    tree = derive_tree(grammar, width, height)
    labels = sorted({label for row in tiling.labels for label in row})
    legend = 18 * len(labels) + 34
    total_w, total_h = 2 * w + gap + 20, h + legend + 20

    def rect(x0: float, y0: float, x1: float, y1: float, left: float) -> str:
        return (
            f'x="{left + x0 * scale:.2f}" y="{10 + (height - y1) * scale:.2f}" '
            f'width="{(x1 - x0) * scale:.2f}" height="{(y1 - y0) * scale:.2f}"'
        )

    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{total_w:.0f}" height="{total_h:.0f}">',
        f"<title>{xml_text(title)}: tiling and grammar regions</title>",
        f'<rect width="{total_w:.0f}" height="{total_h:.0f}" fill="#ffffff"/>',
    ]
    for r, row in enumerate(tiling.labels):
        for c0, c1, label in _runs(row):  # a run of one label is one rectangle
            box = rect(tiling.xs[c0], tiling.ys[r], tiling.xs[c1], tiling.ys[r + 1], 10)
            lines.append(f'<rect {box} fill="{label_colour(label)}"/>')
    right = 10 + w + gap
    parents: list[str] = []
    outlines, names = [], []
    for depth, terminal, (symbol, x0, y0, x1, y1) in tree:
        del parents[depth:]
        if terminal:
            holder = parents[-1] if parents else symbol
            fill = _mix(label_colour(symbol), label_colour(f"rule {holder}"))
            lines.append(f'<rect {rect(x0, y0, x1, y1, right)} fill="{fill}"/>')
            continue
        parents.append(symbol)
        stroke = max(3.0 - depth, 0.6)
        outlines.append(
            f'<rect {rect(x0, y0, x1, y1, right)} fill="none" stroke="#202020" '
            f'stroke-width="{stroke:.1f}"/>'
        )
        if depth <= 2 and (x1 - x0) * scale > 30 and (y1 - y0) * scale > 14:
            names.append(
                f'<text x="{right + x0 * scale + 3:.1f}" y="{10 + (height - y1) * scale + 12:.1f}" '
                f'font-family="sans-serif" font-size="11" fill="#000000">{xml_text(symbol)}</text>'
            )
    lines += outlines + names
    for i, label in enumerate(labels):
        y = h + 24 + 18 * i
        lines.append(
            f'<rect x="10" y="{y:.0f}" width="12" height="12" fill="{label_colour(label)}"/>'
        )
        lines.append(
            f'<text x="28" y="{y + 11:.0f}" font-family="sans-serif" font-size="12">'
            f"{xml_text(label)}</text>"
        )
    lines.append(
        f'<text x="{right:.0f}" y="{h + 35:.0f}" font-family="sans-serif" font-size="12">'
        f"{len(grammar.rules)} rules, cost {grammar.cost:.1f}: terminals tinted by the rule "
        "that makes them</text>"
    )
    lines.append("</svg>")
    return "\n".join(lines) + "\n"


def grammar_report(
    extraction: Extraction, timings: bool = False, derived: Sequence[DerivedSize] = ()
) -> str:
    grammar, found, tiling = extraction.grammar, extraction.found, extraction.tiling
    options = extraction.options
    ops: dict[str, int] = {}
    for rule in grammar.rules.values():
        ops[rule.op] = ops.get(rule.op, 0) + 1
    data = {
        "source": extraction.source,
        "method": found.method,
        "iterations": found.iterations,
        "seed": options.seed,
        "best_iteration": found.best_iteration,
        "extensions": list(options.extensions),
        "costs": {"split": grammar.costs.split, "repeat": grammar.costs.repeat},
        "cost": round(grammar.cost, 6),
        "greedy_cost": round(found.greedy_cost, 6),
        "rules": len(grammar.rules),
        "rules_by_op": dict(sorted(ops.items())),
        "terminals": len(grammar.terminals),
        "canvas": {"width": tiling.xs[-1], "height": tiling.ys[-1]},
        "cells": (len(tiling.xs) - 1) * (len(tiling.ys) - 1),
        "regions_explored": found.regions,
        "repeated_regions": found.repeats,
        "rederives_exactly": not extraction.problems,
        "fidelity": extraction.fidelity.summary() if extraction.fidelity else None,
        "snapping": extraction.snapping.summary(),
        "regularization": extraction.regularization.summary(),
        "warnings": extraction.warnings,
        "style": [constraint.summary() for constraint in extraction.style],
        "derived": [
            {
                "size": {"width": size.width, "height": size.height},
                "variation": k,
                "made": made,
                "style_kept": keeps.summary(),
            }
            for size in derived
            for k, (keeps, made) in enumerate(zip(size.kept, size.made, strict=True))
        ],
        "time_ms": round(extraction.time_ms, 3) if timings else None,
    }
    return json.dumps(data, indent=2) + "\n"


def grammar_files(
    extraction: Extraction,
    name: str,
    timings: bool = False,
    derived: Sequence[DerivedSize] = (),
) -> dict[str, str]:
    """The grammar's own files by name: text, JSON, CityEngine CGA, the tiling as SVG and
    the report (with the style each derived layout keeps)."""
    found = extraction.grammar
    tiling = extraction.tiling
    return {
        f"{name}.grammar.txt": found.text(),
        f"{name}.grammar.json": grammar_json(found),
        f"{name}.cga": grammar_cga(found, tiling.xs[-1], tiling.ys[-1], name),
        f"{name}.tiling.svg": tiling_svg(tiling, found, name),
        f"{name}.grammar-report.json": grammar_report(extraction, timings, derived),
    }


def variations_sheet(derived: list[DerivedSize], name: str, seed: int) -> str:
    """A contact sheet of every size's layouts, a row a size (``<name>.variations.svg``)."""
    from facadecli.export.contact import Variant, contact_sheet

    rows = [
        [
            Variant(layout, (size.width, size.height), seed, k)
            for k, layout in enumerate(size.layouts)
        ]
        for size in derived
    ]
    return contact_sheet(rows, f"{name} (grammar variations)")
