"""Reading a labelled layout, the first stage of ``facade grammar``: the reader of its
kind (CMP XML, a facadecli report, a JSON list of rectangles), and the layout stretched to
the façade's real size."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from facadecli.errors import SpecError
from facadecli.grammar.cmp_xml import read_cmp
from facadecli.grammar.inputs import LabelledLayout
from facadecli.grammar.json_layouts import read_plain, read_report


def read_layout(path: Path) -> tuple[LabelledLayout, str]:
    """The labelled layout in a file, and its kind: cmp, report or plain."""
    if not path.is_file():
        raise SpecError.at(str(path), None, None, "no such file", "check the path")
    name = path.name
    if name.endswith(".xml"):
        return read_cmp(path), "cmp"
    if name.endswith(".layout.json"):
        return read_report(path), "report"
    return read_plain(path), "plain"


def resize(layout: LabelledLayout, width: float, height: float) -> LabelledLayout:
    """The layout stretched to a new size (CMP annotations are on a unit square)."""
    sx, sy = width / layout.width, height / layout.height
    rects = tuple(
        replace(r, x0=r.x0 * sx, x1=r.x1 * sx, y0=r.y0 * sy, y1=r.y1 * sy) for r in layout.rects
    )
    return LabelledLayout(width, height, rects)


def stem(path: Path) -> str:
    name = path.name.removesuffix(".layout.json")
    return name.rsplit(".", 1)[0] if "." in name else name
