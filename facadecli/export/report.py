"""The layout report ``<name>.layout.json`` (SPEC section 3), and more keys: the chosen
words, the alignment matrices, warnings and timings per stage."""

from __future__ import annotations

import json
from typing import Any

from facadecli.layout import Layout
from facadecli.solver.axis import AxisLayout

REPORT_VERSION = 1


def _axis_symbols(axis: AxisLayout) -> dict[str, Any]:
    return {
        name: {"preferred": preferred, "size": size}
        for name, (preferred, size) in sorted(axis.symbols.items())
    }


def _letters(layout: Layout, index: int, axis: str) -> list[dict[str, Any]]:
    return [
        {
            "symbol": letter.symbol,
            "start": letter.start,
            "end": letter.end,
            "reflected": letter.reflected,
            "transparent": letter.transparent,
        }
        for letter in layout.letters(index, axis)
    ]


def _alignment(axis: AxisLayout, layout: Layout) -> dict[str, Any]:
    names = [layer.name for layer in layout.spec.layers]
    return {
        group: {
            "columns": list(columns.boundaries),
            "error": columns.error,
            "rows": [
                {"layers": [names[i] for i in layers], "entries": list(entries)}
                for layers, entries in zip(columns.layers, columns.matrix, strict=True)
            ],
        }
        for group, columns in sorted(axis.groups.items())
    }


def report(layout: Layout) -> dict[str, Any]:
    """The report as plain data (the keys of SPEC section 3 first)."""
    spec = layout.spec
    return {
        "version": REPORT_VERSION,
        "name": spec.name,
        "canvas": {"width": layout.width, "height": layout.height},
        "counters": dict(sorted(layout.counters.items())),
        "symbols": {"x": _axis_symbols(layout.x), "y": _axis_symbols(layout.y)},
        "layers": [
            {"name": layer.name, "x": _letters(layout, i, "x"), "y": _letters(layout, i, "y")}
            for i, layer in enumerate(spec.layers)
            if layer.enabled
        ],
        "shapes": [
            {
                "layer": shape.layer,
                "x": shape.x,
                "y": shape.y,
                "x0": shape.x0,
                "x1": shape.x1,
                "y0": shape.y0,
                "y1": shape.y1,
                "z0": shape.z0,
                "z1": shape.z1,
                "material": shape.material,
                "mesh": shape.mesh,
                "visible": shape.visible,
                "reflected": {"x": shape.reflected_x, "y": shape.reflected_y},
            }
            for shape in layout.shapes
        ],
        "alignment": {"x": _alignment(layout.x, layout), "y": _alignment(layout.y, layout)},
        "objective": {"x": layout.x.objective, "y": layout.y.objective},
        "proof": {
            axis.axis: {"proven": axis.proven, "bound": axis.bound} for axis in (layout.x, layout.y)
        },
        "candidate": {
            axis.axis: {
                "words": dict(sorted(axis.words.items())),
                "tolerance": axis.mu,
                "candidates_tried": axis.candidates_tried,
            }
            for axis in (layout.x, layout.y)
        },
        "warnings": list(layout.warnings),
        "stats": {
            "time_ms": round(layout.time_ms, 3),
            "stages_ms": {
                f"{axis.axis}_{stage}": round(ms, 3)
                for axis in (layout.x, layout.y)
                for stage, ms in axis.timings.items()
            },
        },
    }


def report_text(layout: Layout, timings: bool = True) -> str:
    """The report as JSON text. Timings vary from run to run: with ``timings=False`` they
    are null, so that the same spec and seed give byte-identical files."""
    data = report(layout)
    if not timings:
        data["stats"] = {"time_ms": None}
    return json.dumps(data, indent=2, ensure_ascii=False) + "\n"
