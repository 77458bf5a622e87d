"""Labelled layouts in JSON: a plain list of rectangles, and facadecli's own reports.

- plain: ``[{label, x0, y0, x1, y1, z?}, ...]`` (later entries drawn over earlier ones), or
  ``{"rects": [...], "canvas": {"width": W, "height": H}}``; without a canvas the façade
  reaches to the rectangles' largest x1 and y1.
- report: the ``<name>.layout.json`` that ``facade solve`` writes; its visible shapes,
  labelled ``<x symbol>.<y symbol>`` and drawn in the order of their layers.

A problem is reported with its JSON path (``rects[3].x0``) and the line and column of the
value, found again in the text (Python's json keeps no positions). NaN and Infinity (which
Python's json accepts), nesting deeper than ``DEPTH_MAX`` and numbers past ``EXTENT_MAX``
are refused.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any, NoReturn

from facadecli.errors import Problem, SpecError
from facadecli.grammar.inputs import (
    EXTENT_MAX,
    LABEL_HINT,
    PROBLEMS_MAX,
    LabelledLayout,
    Rect,
    extent_problem,
    label_problem,
    number_problem,
    outside,
    read_text,
    too_many,
)

DEPTH_MAX = 64  # nesting of arrays and objects
# strings (an unterminated one runs to the end: each character is scanned once), brackets,
# and the constants Python's json would accept
TOKENS = re.compile(r'"[^"\\]*(?:\\[\s\S][^"\\]*)*(?:"|\\?\Z)|[\[{]|[\]}]|-?Infinity|NaN')
SPACE = re.compile(r"[ \t\n\r]+")
CORNERS = ("x0", "y0", "x1", "y1")
PLAIN_KEYS = ("label", *CORNERS, "z")
NUMBER_HINT = f"write a number from {-EXTENT_MAX:g} to {EXTENT_MAX:g}"

Key = str | int
Where = tuple[Key, ...]


def _kind(value: object) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true or false"
    names = {float: "a number", str: "a string", list: "a list", dict: "an object"}
    return names.get(type(value), type(value).__name__)


def path_text(where: Where) -> str:
    """``rects[3].x0``; the document itself is ``the top level``."""
    text = "".join(f"[{key}]" if isinstance(key, int) else f".{key}" for key in where)
    return text.removeprefix(".") or "the top level"


def _refuse_constant(name: str) -> NoReturn:
    raise ValueError(f"{name} is not a number JSON allows")


class JsonFile:
    """A JSON file's data, and the place of any value in it for problems."""

    def __init__(self, path: Path):
        self.file = str(path)
        self.text = read_text(path)
        self.problems: list[Problem] = []
        self._check_tokens()
        try:  # every number a float: a 5,000-digit integer becomes inf, refused by its place
            self.data: Any = json.loads(self.text, parse_int=float, parse_constant=_refuse_constant)
        except json.JSONDecodeError as error:
            raise SpecError.at(
                self.file,
                error.lineno,
                error.colno,
                f"not JSON: {error.msg}",
                "fix the JSON syntax",
            ) from None
        except ValueError as error:  # a constant ``_check_tokens`` missed: never expected
            raise SpecError.at(self.file, None, None, f"not JSON: {error}", "fix it") from None

    def _check_tokens(self) -> None:
        """NaN, Infinity and deep nesting, refused with their place before ``json`` sees
        them (it would accept the first two and overflow the stack on the third)."""
        depth = 0
        for token in TOKENS.finditer(self.text):
            first = token.group()[0]
            if first in "[{":
                depth += 1
                if depth > DEPTH_MAX:
                    raise self._at(token.start(), f"nested deeper than {DEPTH_MAX}", "flatten it")
            elif first in "]}":
                depth -= 1
            elif first != '"':
                raise self._at(
                    token.start(),
                    f"{token.group()} is not a number JSON allows",
                    "write a finite number",
                )

    # -- places ---------------------------------------------------------------------------

    def _place(self, index: int) -> tuple[int, int]:
        line = self.text.count("\n", 0, index) + 1
        return line, index - (self.text.rfind("\n", 0, index) + 1) + 1

    def _at(self, index: int, message: str, hint: str) -> SpecError:
        return SpecError.at(self.file, *self._place(index), message, hint)

    def place(self, where: Where) -> tuple[int, int]:
        """The line and column where the value at ``where`` starts."""
        return self._place(self._locate(where))

    def _locate(self, where: Where) -> int:
        """The index where the value at ``where`` starts (the nearest enclosing value's if
        it is missing). The last of repeated keys counts, as in ``json``."""
        index = self._space(0)
        for key in where:
            found = self._child(index, key)
            if found is None:
                break
            index = found
        return index

    def _space(self, index: int) -> int:
        """The index of the next character that is not white space."""
        match = SPACE.match(self.text, index)
        return match.end() if match else index

    def _child(self, index: int, key: Key) -> int | None:
        """Where the member ``key`` of the object, or element ``key`` of the list, at
        ``index`` starts: members and elements before it are skipped by ``json`` itself."""
        text, opening = self.text, self.text[index : index + 1]
        if (opening, isinstance(key, str)) not in (("{", True), ("[", False)):
            return None
        skip = json.JSONDecoder(parse_int=float).raw_decode
        found, count = None, 0
        index = self._space(index + 1)
        while text[index : index + 1] not in ("}", "]", ""):
            if opening == "{":  # "name": value
                name, index = skip(text, index)
                index = self._space(self._space(index) + 1)
                if name == key:
                    found = index
            elif count == key:
                return index
            index = self._space(skip(text, index)[1])
            if text[index : index + 1] == ",":
                index = self._space(index + 1)
            count += 1
        return found

    # -- problems -------------------------------------------------------------------------

    def fail(self, where: Where, message: str, hint: str) -> SpecError:
        line, col = self.place(where)
        return SpecError([*self.problems, Problem(self.file, line, col, message, hint)])

    def note(self, where: Where, message: str, hint: str) -> None:
        """A problem with a value: reading goes on, to report every one at once."""
        line, col = self.place(where)
        self.problems.append(Problem(self.file, line, col, message, hint))
        if len(self.problems) >= PROBLEMS_MAX:
            raise SpecError(self.problems)

    def done(self) -> None:
        if self.problems:
            raise SpecError(self.problems)

    # -- values ---------------------------------------------------------------------------

    def expect(self, value: object, where: Where, kind: type, what: str) -> Any:
        if not isinstance(value, kind):
            raise self.fail(
                where, f"{path_text(where)} is {_kind(value)}, not {what}", f"give {what}"
            )
        return value

    def members(
        self, value: object, where: Where, required: tuple[str, ...], allowed: tuple[str, ...]
    ) -> dict[str, Any]:
        """An object with the required keys (and, unless ``allowed`` is empty, no others)."""
        data: dict[str, Any] = self.expect(value, where, dict, "an object")
        for key in required:
            if key not in data:
                raise self.fail(
                    where,
                    f"not a labelled layout: {path_text(where)} has no {key!r}",
                    f"give {', '.join(required)}",
                )
        for key in data:
            if allowed and key not in allowed:
                raise self.fail(
                    (*where, key),
                    f"not a labelled layout: {path_text(where)} has an unknown key {key!r}",
                    f"the keys are {', '.join(allowed)}",
                )
        return data

    def number(self, data: dict[str, Any], where: Where, key: str) -> float | None:
        """A finite number, not too large; None after noting a problem."""
        value, here = data[key], (*where, key)
        if type(value) is not float:
            self.note(here, f"{path_text(here)} is {_kind(value)}, not a number", "write a number")
            return None
        problem = number_problem(value)
        if problem is not None:
            self.note(here, f"{path_text(here)}: {problem}", NUMBER_HINT)
            return None
        return value

    def label(self, data: dict[str, Any], where: Where, key: str) -> str | None:
        value, here = data[key], (*where, key)
        if not isinstance(value, str):
            self.note(here, f"{path_text(here)} is {_kind(value)}, not a string", LABEL_HINT)
            return None
        problem = label_problem(value)
        if problem is not None:
            self.note(here, f"{path_text(here)}: {problem}", LABEL_HINT)
            return None
        return value

    def canvas(self, value: object, where: Where) -> tuple[float, float]:
        """The façade's size: two numbers above 0 (reading stops at a problem)."""
        data = self.members(value, where, ("width", "height"), ())
        sizes = []
        for key in ("width", "height"):
            size = self.number(data, where, key)
            problem = None if size is None else extent_problem(size)
            if problem is not None:
                here = (*where, key)
                self.note(here, f"{path_text(here)}: {problem}", "give the façade's size")
            sizes.append(size or 0.0)
        self.done()
        return sizes[0], sizes[1]

    def count(self, items: list[Any], where: Where) -> None:
        too_many(self.file, len(items), *self.place(where))

    def check_ranges(self, placed: list[tuple[Rect, Where]], width: float, height: float) -> None:
        """Every corner inside the façade (within the slack): nothing is clipped away."""
        for rect, where in placed:
            for key, extent in zip(CORNERS, (width, height, width, height), strict=True):
                value = getattr(rect, key)
                if outside(value, extent):
                    here = (*where, key)
                    self.note(
                        here,
                        f"{path_text(here)} is {value:g}, outside the façade (0 to {extent:g})",
                        "move the rectangle onto the façade, or give a larger canvas",
                    )


def _corners(file: JsonFile, data: dict[str, Any], where: Where) -> tuple[float, ...] | None:
    corners = [file.number(data, where, key) for key in CORNERS]
    if any(value is None for value in corners):
        return None
    return tuple(value for value in corners if value is not None)


def read_plain(path: Path) -> LabelledLayout:
    """A JSON list of ``{label, x0, y0, x1, y1}`` (later entries drawn over earlier), or an
    object with that list under ``rects`` and the façade size under ``canvas``."""
    file = JsonFile(path)
    data: Any = file.data
    base: Where = ()
    canvas: tuple[float, float] | None = None
    if isinstance(data, dict):
        data = file.members(data, (), ("rects",), ("rects", "canvas"))
        if "canvas" in data:
            canvas = file.canvas(data["canvas"], ("canvas",))
        data, base = data["rects"], ("rects",)
    entries: list[Any] = file.expect(data, base, list, "a list of rectangles")
    file.count(entries, base)
    placed: list[tuple[Rect, Where]] = []
    for i, entry in enumerate(entries):
        where = (*base, i)
        fields = file.members(entry, where, PLAIN_KEYS[:5], PLAIN_KEYS)
        label = file.label(fields, where, "label")
        corners = _corners(file, fields, where)
        z = file.number(fields, where, "z") if "z" in fields else float(i)
        if label is None or corners is None or z is None:
            continue
        x0, y0, x1, y1 = corners
        if not (x1 > x0 and y1 > y0):
            file.note(
                where,
                f"rectangle {i + 1} ({label}) has no area: x {x0:g}..{x1:g}, y {y0:g}..{y1:g}",
                "give x0 < x1 and y0 < y1",
            )
            continue
        placed.append((Rect(label, x0, y0, x1, y1, z), where))
    file.done()
    if canvas is not None:
        width, height = canvas
    else:  # the façade reaches to the rectangles; it starts at 0
        width = max((rect.x1 for rect, _ in placed), default=1.0)
        height = max((rect.y1 for rect, _ in placed), default=1.0)
        for size in (width, height):
            if extent_problem(size) is not None:
                raise file.fail(
                    base,
                    f"the rectangles reach only to {size:g}: too small a façade",
                    "give a canvas, or the coordinates in larger units",
                )
    file.check_ranges(placed, width, height)
    file.done()
    return LabelledLayout(width, height, tuple(rect for rect, _ in placed))


def read_report(path: Path) -> LabelledLayout:
    """The visible shapes of a facadecli layout report, labelled ``<x symbol>.<y symbol>``;
    shapes of no area are left out (they show nothing)."""
    file = JsonFile(path)
    report = file.members(file.data, (), ("canvas", "layers", "shapes"), ())
    canvas = file.canvas(report["canvas"], ("canvas",))
    order: dict[str, int] = {}
    for i, layer in enumerate(file.expect(report["layers"], ("layers",), list, "a list")):
        where = ("layers", i)
        name = file.label(file.members(layer, where, ("name",), ()), where, "name")
        if name is not None:
            order[name] = i
    shapes = file.expect(report["shapes"], ("shapes",), list, "a list of shapes")
    file.count(shapes, ("shapes",))
    placed: list[tuple[Rect, Where]] = []
    for i, entry in enumerate(shapes):
        where = ("shapes", i)
        shape = file.members(entry, where, ("x", "y", "layer", "visible", *CORNERS), ())
        if file.expect(shape["visible"], (*where, "visible"), bool, "true or false") is False:
            continue
        label = _shape_label(file, shape, where)
        corners = _corners(file, shape, where)
        layer = file.label(shape, where, "layer")
        if layer is not None and layer not in order:
            here = (*where, "layer")
            file.note(here, f"{path_text(here)}: no layer {layer!r}", "name one of the layers")
        if corners is not None and (corners[2] < corners[0] or corners[3] < corners[1]):
            x0, y0, x1, y1 = corners
            message = f"shape {i + 1} is inverted: x {x0:g}..{x1:g}, y {y0:g}..{y1:g}"
            file.note(where, message, "give x0 <= x1 and y0 <= y1")
        elif label is not None and corners is not None and layer in order:
            x0, y0, x1, y1 = corners
            if x1 > x0 and y1 > y0:
                placed.append((Rect(label, x0, y0, x1, y1, order[layer]), where))
    file.done()
    file.check_ranges(placed, *canvas)
    file.done()
    return LabelledLayout(*canvas, tuple(rect for rect, _ in placed))


def _shape_label(file: JsonFile, shape: dict[str, Any], where: Where) -> str | None:
    symbols = [file.label(shape, where, axis) for axis in ("x", "y")]
    if symbols[0] is None or symbols[1] is None:
        return None
    label = f"{symbols[0]}.{symbols[1]}"
    problem = label_problem(label)
    if problem is not None:
        file.note(where, f"{path_text(where)}: {problem}", LABEL_HINT)
        return None
    return label
