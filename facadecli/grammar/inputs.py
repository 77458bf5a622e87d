"""Labelled layouts, and the rules every reader of one checks at the reading boundary.

A labelled layout is a set of rectangles with labels and a z-order, on a façade of a given
size: x left to right, y bottom to top (SPEC 2.1). The readers (``cmp_xml`` for CMP
annotations, ``json_layouts`` for JSON lists and facadecli reports) turn a file into one and
refuse, with the place, anything that would be lost or would not be a finite number later:
every coordinate is finite, inside the façade (within ``EDGE_SLACK``), and every rectangle
has an area; labels are printable text. The limits below keep one file from taking the
machine down; the README lists them.
"""

from __future__ import annotations

import math
import unicodedata
from dataclasses import dataclass
from pathlib import Path

from facadecli.errors import SpecError
from facadecli.files import decode_utf8, read_at_most
from facadecli.limits import (
    LABEL_CHARS_MAX,
    LAYOUT_BYTES_MAX,
    LAYOUT_EXTENT_MAX,
    LAYOUT_RECTS_MAX,
)

BACKGROUND = "facade"

# CMP labels and their z-order (label_names.txt of the database: higher is drawn over lower)
CMP_Z_ORDER = {
    "background": 1,
    "facade": 2,
    "molding": 7,
    "cornice": 11,
    "pillar": 12,
    "window": 10,
    "door": 5,
    "sill": 3,
    "blind": 6,
    "balcony": 4,
    "shop": 9,
    "deco": 8,
}

FILE_BYTES_MAX = LAYOUT_BYTES_MAX  # bytes of one layout file
RECTS_MAX = LAYOUT_RECTS_MAX  # rectangles of one layout
EXTENT_MAX = LAYOUT_EXTENT_MAX  # a façade's size and any coordinate, in the file's own units
EXTENT_MIN = 1e-6  # a façade's size, in the file's own units
LABEL_MAX = LABEL_CHARS_MAX  # characters of a label
EDGE_SLACK = 0.01  # x the façade's extent: edges this far outside it are clipped, not refused
PROBLEMS_MAX = 20  # problems reported at once; reading stops at the next one


@dataclass(frozen=True)
class Rect:
    label: str
    x0: float
    y0: float
    x1: float
    y1: float
    z: float = 0.0


@dataclass(frozen=True)
class LabelledLayout:
    width: float
    height: float
    rects: tuple[Rect, ...]


def read_text(path: Path) -> str:
    """The file's text: UTF-8, at most ``FILE_BYTES_MAX`` bytes, a leading BOM dropped."""
    file = str(path)
    try:
        data = read_at_most(path, FILE_BYTES_MAX)
    except OSError as error:
        message = f"cannot read: {error.strerror}"
        raise SpecError.at(file, None, None, message, "check the path") from None
    if data is None:
        raise SpecError.at(
            file,
            None,
            None,
            f"the file is longer than {FILE_BYTES_MAX:,} bytes, the most that is read",
            "split the layout, or give fewer rectangles",
        )
    return decode_utf8(data, file, "save the file as UTF-8")


def label_problem(label: str) -> str | None:
    """Why a label cannot be used (empty, too long, or a character XML and the outputs
    cannot hold: a control character, a lone surrogate, U+FFFE/U+FFFF), or None."""
    if not label.strip():
        return "the label is empty"
    if len(label) > LABEL_MAX:
        return f"the label has {len(label)} characters; at most {LABEL_MAX}"
    for char in label:
        if unicodedata.category(char) in ("Cc", "Cs") or char in "\ufffe\uffff":
            return f"the label holds the character U+{ord(char):04X}, which is not text"
    return None


LABEL_HINT = f"give printable text of 1 to {LABEL_MAX} characters"


def number_problem(value: float) -> str | None:
    """Why a coordinate or size cannot be used (not finite, too large), or None."""
    if math.isnan(value):
        return "NaN is not a number"
    if not abs(value) <= EXTENT_MAX:
        return f"{value:g} is too large: at most {EXTENT_MAX:g}"
    return None


def extent_problem(value: float) -> str | None:
    """Why a façade's width or height cannot be used, or None."""
    if not EXTENT_MIN <= value <= EXTENT_MAX:
        return f"{value:g} is not a façade size from {EXTENT_MIN:g} to {EXTENT_MAX:g}"
    return None


def outside(value: float, extent: float) -> bool:
    """Whether a coordinate lies outside ``0..extent`` by more than the slack."""
    slack = EDGE_SLACK * extent
    return value < -slack or value > extent + slack


def too_many(file: str, count: int, line: int | None = None, col: int | None = None) -> None:
    if count > RECTS_MAX:
        raise SpecError.at(
            file,
            line,
            col,
            f"more than {RECTS_MAX:,} rectangles",
            "split the façade into parts, or leave out small elements",
        )
