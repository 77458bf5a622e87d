"""CMP Facade Database annotations: a sequence of ``<object>`` elements without a root.

Each object is ``<points>`` with two ``<x>`` (the normalised *row* bounds, from the top)
and two ``<y>`` (the normalised *column* bounds, from the left), a ``<labelname>`` and
optionally ``<label>`` (the label's number) and ``<flag>``. Read with expat, one pass,
refusing DTDs and entity declarations (so neither entity expansion nor external entities
can happen); every problem is reported at its line and column.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from facadecli.errors import Problem, SpecError
from facadecli.grammar.inputs import (
    CMP_Z_ORDER,
    EDGE_SLACK,
    PROBLEMS_MAX,
    LabelledLayout,
    Rect,
    label_problem,
    read_text,
    too_many,
)

ROOT = "cmp-annotation"  # the root the file lacks; given on a line of its own before it
CHILDREN = {  # element -> the elements it may hold; the others hold text only
    ROOT: ("object",),
    "object": ("points", "label", "labelname", "flag"),
    "points": ("x", "y"),
}
COUNTS = {  # child -> how often an element holds it, at least and at most
    "points": (1, 1),
    "labelname": (1, 1),
    "label": (0, 1),
    "flag": (0, 1),
    "x": (2, 2),
    "y": (2, 2),
}
FORMAT = (
    "each <object> holds <points> with two <x> (rows from the top) and two <y> (columns "
    "from the left), a <labelname>, and optionally <label> and <flag>"
)
NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")  # unambiguous: linear
DECLARATION = re.compile(r"<\?xml[^>]*\?>")
DTD = re.compile(r"<!(?:DOCTYPE|ENTITY|ELEMENT|ATTLIST)")
XML_CHAR = re.compile("[\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


@dataclass
class _Element:
    name: str
    line: int
    col: int
    text: list[str] = field(default_factory=list)
    children: dict[str, list[_Element]] = field(default_factory=dict)

    @property
    def value(self) -> str:
        return "".join(self.text).strip()


class _Reader:
    """Builds the objects as expat reports elements; refuses what is not CMP at once."""

    def __init__(self, file: str):
        self.file = file
        self.parser = expat.ParserCreate()
        self.parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
        self.parser.StartElementHandler = self._start
        self.parser.EndElementHandler = self._end
        self.parser.CharacterDataHandler = self._text
        self.parser.StartDoctypeDeclHandler = self._doctype
        self.parser.EntityDeclHandler = self._entity
        self.open: list[_Element] = []
        self.objects = 0
        self.rects: list[Rect] = []
        self.problems: list[Problem] = []

    # -- positions and problems ------------------------------------------------------------

    def here(self) -> tuple[int, int]:
        """The parser's place in the file (1-based; the added root line not counted)."""
        return self.parser.CurrentLineNumber - 1, self.parser.CurrentColumnNumber + 1

    def fail(self, message: str, hint: str = FORMAT) -> SpecError:
        return SpecError.at(self.file, *self.here(), message, hint)

    def note(self, element: _Element, message: str, hint: str) -> None:
        """A problem with a value: reading goes on, to report every one at once."""
        self.problems.append(Problem(self.file, element.line, element.col, message, hint))
        if len(self.problems) >= PROBLEMS_MAX:
            raise SpecError(self.problems)

    def _doctype(self, *_: object) -> None:  # refused twice: our root comes first anyway
        raise self.fail("a DTD is not read", "remove the <!...>")

    def _entity(self, *_: object) -> None:
        raise self.fail("a DTD is not read", "remove the <!...>")

    # -- elements -------------------------------------------------------------------------

    def _start(self, name: str, _: dict[str, str]) -> None:
        line, col = self.here()
        parent = self.open[-1] if self.open else None
        if parent is not None and name not in CHILDREN.get(parent.name, ()):
            where = "at the top" if parent.name == ROOT else f"inside <{parent.name}>"
            hint = f"close <{parent.name}> first; {FORMAT}" if name == parent.name else FORMAT
            raise self.fail(f"<{name}> {where} is not CMP", hint)
        element = _Element(name, line, col)
        if parent is not None and parent.name != ROOT:  # objects are not kept: their rects are
            parent.children.setdefault(name, []).append(element)
        self.open.append(element)
        if name == "object":
            self.objects += 1
            too_many(self.file, self.objects, line, col)

    def _text(self, data: str) -> None:
        element = self.open[-1]
        if element.name not in CHILDREN:
            element.text.append(data)
        elif data.strip():
            where = "between objects" if element.name == ROOT else f"in <{element.name}>"
            raise self.fail(f"text {data.strip()[:20]!r} {where}")

    def _end(self, name: str) -> None:
        element = self.open.pop()
        if name in ("object", "points"):
            self._check_counts(element)
        if name == "object":
            self._object(element)

    def _check_counts(self, element: _Element) -> None:
        """Each child as often as CMP has it; else reading stops here."""
        for child in CHILDREN[element.name]:
            found = len(element.children.get(child, []))
            low, high = COUNTS[child]
            if not low <= found <= high:
                wanted = f"{low}" if low == high else f"at most {high}"
                self.problems.append(
                    Problem(
                        self.file,
                        element.line,
                        element.col,
                        f"<{element.name}> has {found} <{child}>, not {wanted}",
                        FORMAT,
                    )
                )
                raise SpecError(self.problems)

    def _object(self, element: _Element) -> None:
        named = element.children["labelname"][0]
        label = named.value
        problem = label_problem(label)
        if problem is None and label not in CMP_Z_ORDER:
            problem = f"unknown label {label!r}"
        if problem is not None:
            self.note(named, problem, f"use one of {', '.join(sorted(CMP_Z_ORDER))}")
        points = element.children["points"][0]
        rows = self._span(points.children["x"], "<x>", "rows")
        columns = self._span(points.children["y"], "<y>", "columns")
        if problem is None and rows is not None and columns is not None:
            (top, bottom), (left, right) = rows, columns
            z = CMP_Z_ORDER[label] + len(self.rects) * 1e-6  # later objects over earlier ones
            self.rects.append(Rect(label, left, 1.0 - bottom, right, 1.0 - top, z))

    def _span(self, ends: list[_Element], tag: str, what: str) -> tuple[float, float] | None:
        """The two bounds of one axis, clipped to 0..1, or None after noting a problem."""
        values = []
        for end in ends:
            if not NUMBER.fullmatch(end.value):
                self.note(end, f"{tag} {end.value[:20]!r} is not a number", "write e.g. 0.25")
                return None
            value = float(end.value)
            if not -EDGE_SLACK <= value <= 1 + EDGE_SLACK:
                self.note(
                    end,
                    f"{tag} {end.value[:20]} is outside the image",
                    "CMP coordinates are fractions of the image, from 0 to 1",
                )
                return None
            values.append(min(max(value, 0.0), 1.0))
        first, second = values
        if second <= first:
            self.note(
                ends[1],
                f"the object has no area: its second {tag} ({second:g}) is not past its first "
                f"({first:g})",
                f"give the {what} in increasing order",
            )
            return None
        return first, second

    # -- the file -------------------------------------------------------------------------

    def read(self, text: str) -> list[Rect]:
        declaration = DECLARATION.match(text)
        if declaration is not None:  # blanked: it may only open a document, and ours is wrapped
            text = re.sub(r"[^\r\n]", " ", declaration.group()) + text[declaration.end() :]
        body_read = False
        try:
            self.parser.Parse(f"<{ROOT}>\n", False)
            self.parser.Parse(text, False)
            body_read = True
            self.parser.Parse(f"</{ROOT}>", True)
        except expat.ExpatError as error:
            raise self._syntax(error, text, body_read) from None
        if self.problems:
            raise SpecError(self.problems)
        return self.rects

    def _syntax(self, error: expat.ExpatError, text: str, body_read: bool) -> SpecError:
        """The syntax error, said in CMP's terms where it can be."""
        unclosed = [e for e in self.open if e.name != ROOT]
        if body_read and unclosed:  # the file ends inside an element
            first = unclosed[-1]
            return SpecError.at(
                self.file,
                first.line,
                first.col,
                f"<{first.name}> is not closed before the file ends",
                f"add </{first.name}>, or remove the cut-off object",
            )
        lines = _Lines(text)
        dtd = DTD.search(text)
        if dtd is not None:  # inside our root a DTD is only a syntax error: say what it is
            return SpecError.at(
                self.file, *lines.place(dtd.start()), "a DTD is not read", "remove the <!...>"
            )
        line, col = error.lineno - 1, error.offset + 1
        message = expat.errors.messages[error.code]
        char = lines.char(line, col)
        if char and not XML_CHAR.match(char):
            message = f"the character U+{ord(char):04X} cannot be in XML"
        return SpecError.at(self.file, line, col, f"not XML: {message}", "fix the XML")


class _Lines:
    """Places in a text as XML counts them (CR LF, CR and LF each end a line)."""

    def __init__(self, text: str):
        self.text = text
        self.starts = [0, *(m.end() for m in re.finditer(r"\r\n|\r|\n", text))]

    def place(self, index: int) -> tuple[int, int]:
        line = bisect.bisect_right(self.starts, index)
        return line, index - self.starts[line - 1] + 1

    def char(self, line: int, col: int) -> str:
        """The character at a place, or "" past the text."""
        if not 1 <= line <= len(self.starts):
            return ""
        index = self.starts[line - 1] + col - 1
        return self.text[index : index + 1]


def read_cmp(path: Path) -> LabelledLayout:
    """A CMP annotation, on a unit façade (the images' pixel size is not in the XML)."""
    rects = _Reader(str(path)).read(read_text(path))
    return LabelledLayout(1.0, 1.0, tuple(rects))
