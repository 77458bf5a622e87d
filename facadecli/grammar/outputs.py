"""What ``facade grammar`` writes: the grammar as text and JSON, the tiling as SVG, and a
report (cost, rules, time)."""

from __future__ import annotations

import json
from dataclasses import asdict
from typing import Any
from xml.sax.saxutils import escape

from facadecli.grammar.palette import label_colour
from facadecli.grammar.run import Extraction
from facadecli.grammar.split import Grammar
from facadecli.grammar.tiling import Tiling

SCALE = 600.0  # pixels for the longer side of the façade


def grammar_json(grammar: Grammar) -> str:
    data: dict[str, Any] = {
        "start": grammar.start,
        "terminals": sorted(grammar.terminals),
        "costs": asdict(grammar.costs),
        "rules": {name: asdict(rule) for name, rule in grammar.rules.items()},
        "cost": round(grammar.cost, 6),
    }
    return json.dumps(data, indent=2) + "\n"


def tiling_svg(tiling: Tiling, title: str) -> str:
    """Cells filled by label (a legend below), drawn bottom up like the façade."""
    width, height = tiling.xs[-1], tiling.ys[-1]
    scale = SCALE / max(width, height)
    labels = sorted({label for row in tiling.labels for label in row})
    legend = 18 * len(labels) + 10
    w, h = width * scale, height * scale
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w + 20:.0f}" '
        f'height="{h + 20 + legend:.0f}">',
        f"<title>{escape(title)}: tiling</title>",
        f'<rect width="{w + 20:.0f}" height="{h + 20 + legend:.0f}" fill="#ffffff"/>',
    ]
    for r, row in enumerate(tiling.labels):
        y = 10 + (height - tiling.ys[r + 1]) * scale
        cell_h = (tiling.ys[r + 1] - tiling.ys[r]) * scale
        for c, label in enumerate(row):
            x = 10 + tiling.xs[c] * scale
            cell_w = (tiling.xs[c + 1] - tiling.xs[c]) * scale
            lines.append(
                f'<rect x="{x:.2f}" y="{y:.2f}" width="{cell_w:.2f}" height="{cell_h:.2f}" '
                f'fill="{label_colour(label)}"/>'
            )
    for i, label in enumerate(labels):
        y = h + 24 + 18 * i
        lines.append(
            f'<rect x="10" y="{y:.0f}" width="12" height="12" fill="{label_colour(label)}"/>'
        )
        lines.append(
            f'<text x="28" y="{y + 11:.0f}" font-family="sans-serif" font-size="12">'
            f"{escape(label)}</text>"
        )
    lines.append("</svg>")
    return "\n".join(lines) + "\n"


def grammar_report(extraction: Extraction, timings: bool = False) -> str:
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
        "regularization": extraction.regularization.summary(),
        "time_ms": round(extraction.time_ms, 3) if timings else None,
    }
    return json.dumps(data, indent=2) + "\n"
