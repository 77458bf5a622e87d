"""The contact sheet of ``facade vary``: a grid of elevations, one row per size, each
labelled with its size, seed and variant number."""

from __future__ import annotations

import re
from dataclasses import dataclass
from xml.sax.saxutils import escape

from facadecli.export.svg import svg_text
from facadecli.layout import Layout

CELL = 260.0  # pixels given to each elevation's longer side
GAP = 24.0
LABEL = 18.0


@dataclass(frozen=True)
class Variant:
    layout: Layout | None  # None when no layout exists at this size
    size: tuple[float, float]
    seed: int
    index: int
    note: str = ""


def contact_sheet(rows: list[list[Variant]], title: str) -> str:
    columns = max((len(row) for row in rows), default=1)
    width = GAP + columns * (CELL + GAP)
    height = GAP + LABEL + len(rows) * (CELL + LABEL + GAP)
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
        f'viewBox="0 0 {width:.0f} {height:.0f}">',
        f"<title>{escape(title)}: variations</title>",
        f'<rect width="{width:.0f}" height="{height:.0f}" fill="#ffffff"/>',
        f'<text x="{GAP:.0f}" y="{GAP:.0f}" font-family="sans-serif" font-size="14">'
        f"{escape(title)}</text>",
    ]
    for r, row in enumerate(rows):
        top = GAP + LABEL + r * (CELL + LABEL + GAP)
        for c, variant in enumerate(row):
            left = GAP + c * (CELL + GAP)
            w, h = variant.size
            label = f"{w:g} x {h:g} m, seed {variant.seed}, #{variant.index}"
            drawn = 0.0
            if variant.layout is None:
                label += f": {variant.note}"
            else:
                nested, drawn = _nested(variant.layout, left, top)
                parts.append(nested)
            parts.append(
                f'<text x="{left:.0f}" y="{top + drawn + 14:.0f}" font-family="sans-serif" '
                f'font-size="11">{escape(label)}</text>'
            )
    parts.append("</svg>")
    return "\n".join(parts) + "\n"


def _nested(layout: Layout, left: float, top: float) -> tuple[str, float]:
    """The elevation as a nested <svg> fitted into a cell, and its drawn height."""
    text = svg_text(layout).split("\n", 1)[1]  # without the XML declaration
    match = re.match(r'<svg xmlns="[^"]+" width="([\d.]+)" height="([\d.]+)"', text)
    assert match is not None
    w, h = float(match[1]), float(match[2])
    scale = CELL / max(w, h)
    nested = re.sub(
        r'^<svg xmlns="[^"]+" width="[\d.]+" height="[\d.]+"',
        f'<svg x="{left:.1f}" y="{top:.1f}" width="{w * scale:.1f}" height="{h * scale:.1f}"',
        text,
        count=1,
    )
    return nested, h * scale
