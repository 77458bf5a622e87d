"""The grammar as CityEngine CGA (``<name>.cga``): a small CGA syntax checker and a small
CGA interpreter (splits, floating and absolute sizes, repeats), applied to the CGA written
for hand-made layouts; the interpreter must reproduce the grammar's own derivation."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from facadecli.grammar.cga import grammar_cga
from facadecli.grammar.derive import derive_at
from facadecli.grammar.extract import extract_grammar
from facadecli.grammar.model import Options
from facadecli.grammar.search import extract
from facadecli.grammar.split import Box, Grammar, Part, Rule, derive
from facadecli.grammar.tiling import LabelledLayout, Rect, tile
from tests.test_grammar import _floors, _house, _random_layout, _row, _write_plain

ROOT = Path(__file__).resolve().parent.parent
TOLERANCE = 0.01  # of the façade's larger side

# -- a CGA syntax checker ------------------------------------------------------------------

TOKEN = re.compile(
    r'\s+|#[^\n]*|(?P<string>"(?:[^"\\\n]|\\.)*")|(?P<arrow>-->)'
    r"|(?P<number>\d+(?:\.\d+)?)|(?P<name>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)"
    r"|(?P<punct>[{}()|:~*,=@])"
)
IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
OPERATIONS = {"split", "set", "color", "extrude", "comp"}


class CgaError(AssertionError):
    pass


def tokens(text: str) -> list[tuple[str, str]]:
    out, at = [], 0
    while at < len(text):
        match = TOKEN.match(text, at)
        if match is None:
            raise CgaError(f"cannot read {text[at : at + 20]!r}")
        if match.lastgroup:
            out.append((match.lastgroup, match.group()))
        at = match.end()
    return out


@dataclass
class Size:
    floating: bool
    attr: str | None  # an attr's name, or None for a number
    value: float


@dataclass
class Piece:
    size: Size
    rule: str


@dataclass
class Group:
    items: list[Piece | Group]


@dataclass
class Split:
    axis: str
    items: list[Piece | Group]


@dataclass
class Cga:
    attrs: dict[str, float]
    rules: dict[str, list[object]]  # the operations: Split, ("call", rule), ("color", hex), ...
    start_rules: list[str]

    def label(self, rule: str) -> str | None:
        """The label a terminal rule names with ``set(material.name, ...)``."""
        found = (op for op in self.rules[rule] if isinstance(op, tuple) and op[0] == "material")
        return next((str(op[1]) for op in found), None)


class Parser:
    """Reads the CGA that ``grammar_cga`` writes, strictly: ``version`` first, attrs before
    the rules that use them, each rule once, splits ``split(x|y) { size: Rule | ... }`` with
    ``{ ... }*`` groups, sizes ``~attr`` / ``attr`` / numbers."""

    def __init__(self, text: str) -> None:
        self.toks = tokens(text)
        self.at = 0
        self.cga = Cga({}, {}, [])
        self.called: list[str] = []

    def peek(self, offset: int = 0) -> tuple[str, str]:
        at = self.at + offset
        return self.toks[at] if at < len(self.toks) else ("end", "")

    def take(self, kind: str, value: str | None = None) -> str:
        got = self.peek()
        if got[0] != kind or (value is not None and got[1] != value):
            raise CgaError(f"expected {value or kind}, got {got[1]!r} at token {self.at}")
        self.at += 1
        return got[1]

    def parse(self) -> Cga:
        self.take("name", "version")
        version = self.take("string")
        assert re.fullmatch(r'"\d{4}\.\d"', version), version
        annotations: list[str] = []
        while self.peek()[0] != "end":
            kind, value = self.peek()
            if (kind, value) == ("punct", "@"):
                self.take("punct")
                annotations.append(self.take("name"))
            elif (kind, value) == ("name", "attr"):
                assert not self.cga.rules, "attrs come before the rules"
                self.take("name")
                name = self.ident()
                assert name[0].islower(), f"attr {name} starts with a capital"
                assert name not in self.cga.attrs, f"attr {name} declared twice"
                self.take("punct", "=")
                self.cga.attrs[name] = float(self.take("number"))
            else:
                name = self.ident()
                assert name[0].isupper(), f"rule {name} starts with a small letter"
                assert name not in self.cga.rules, f"rule {name} defined twice"
                self.take("arrow")
                if "StartRule" in annotations:
                    self.cga.start_rules.append(name)
                annotations = []
                self.cga.rules[name] = self.operations()
        assert not annotations, "an annotation without its rule"
        for name in self.called:
            assert name in self.cga.rules, f"rule {name} is used but not defined"
        return self.cga

    def ident(self) -> str:
        name = self.take("name")
        assert IDENT.fullmatch(name), f"{name!r} is not a CGA identifier"
        return name

    def operations(self) -> list[object]:
        ops: list[object] = []
        while True:
            kind, value = self.peek()
            after = self.peek(1)
            if kind != "name" or after[1] in ("-->", "=") or value == "attr":
                break
            if value == "split":
                ops.append(self.split())
            elif value == "set":
                self.take("name")
                self.take("punct", "(")
                self.take("name", "material.name")
                self.take("punct", ",")
                ops.append(("material", json.loads(self.take("string"))))
                self.take("punct", ")")
            elif value == "color":
                self.take("name")
                self.take("punct", "(")
                colour = self.take("string")
                assert re.fullmatch(r'"#[0-9a-f]{6}"', colour), colour
                ops.append(("color", colour))
                self.take("punct", ")")
            elif value == "extrude":
                self.take("name")
                self.take("punct", "(")
                self.size()
                self.take("punct", ")")
                ops.append(("extrude",))
            elif value == "comp":
                self.take("name")
                self.take("punct", "(")
                self.take("name", "f")
                self.take("punct", ")")
                self.take("punct", "{")
                self.take("name", "side")
                self.take("punct", ":")
                ops.append(("comp", self.call()))
                self.take("punct", "}")
            else:
                assert value[0].isupper(), f"unknown operation {value}"
                ops.append(("call", self.call()))
        assert ops, f"a rule without operations at token {self.at}"
        return ops

    def call(self) -> str:
        name = self.ident()
        assert name[0].isupper(), f"{name} is not a rule"
        self.called.append(name)
        return name

    def split(self) -> Split:
        self.take("name", "split")
        self.take("punct", "(")
        axis = self.take("name")
        assert axis in ("x", "y"), axis
        self.take("punct", ")")
        return Split(axis, self.items())

    def items(self) -> list[Piece | Group]:
        self.take("punct", "{")
        items: list[Piece | Group] = []
        while True:
            if self.peek() == ("punct", "{"):
                items.append(Group(self.items()))
                self.take("punct", "*")
            else:
                size = self.size()
                self.take("punct", ":")
                items.append(Piece(size, self.call()))
            if self.peek() == ("punct", "}"):
                self.take("punct")
                return items
            self.take("punct", "|")

    def size(self) -> Size:
        floating = self.peek() == ("punct", "~")
        if floating:
            self.take("punct")
        if self.peek()[0] == "number":
            return Size(floating, None, float(self.take("number")))
        name = self.ident()
        assert name in self.cga.attrs, f"attr {name} used before it is declared"
        return Size(floating, name, self.cga.attrs[name])


def check(text: str) -> Cga:
    """The CGA parsed and checked: braces balanced, every rule used and defined once, the
    start rules Facade and Lot."""
    depth = 0
    for kind, value in tokens(text):
        if kind == "punct" and value in "{}":
            depth += 1 if value == "{" else -1
            assert depth >= 0, "a } without its {"
    assert depth == 0, "a { without its }"
    parser = Parser(text)
    cga = parser.parse()
    assert cga.start_rules == ["Lot", "Facade"]
    unused = set(cga.rules) - set(parser.called) - {"Lot"}
    assert not unused, f"rules never used: {sorted(unused)}"
    return cga


# -- a CGA interpreter -----------------------------------------------------------------------


def lengths(items: list[Piece | Group], extent: float) -> list[tuple[str, float]]:
    """A split's parts laid along ``extent`` as CityEngine does: a ``{ ... }*`` group
    repeated as many times as make its written size closest to what the rest leaves (at
    least once), then absolute sizes kept and floating sizes scaled to fill the remainder."""
    group = next((item for item in items if isinstance(item, Group)), None)
    outside = sum(i.size.value for i in items if isinstance(i, Piece))
    flat: list[Piece] = []
    for item in items:
        if isinstance(item, Piece):
            flat.append(item)
            continue
        assert item is group and all(isinstance(i, Piece) for i in item.items)
        period = sum(i.size.value for i in item.items if isinstance(i, Piece))
        copies = max(1, round((extent - outside) / period))
        flat += [i for i in item.items if isinstance(i, Piece)] * copies
    fixed = sum(p.size.value for p in flat if not p.size.floating)
    weights = sum(p.size.value for p in flat if p.size.floating)
    assert weights > 0, "a split without a floating part"
    scale = (extent - fixed) / weights
    return [(p.rule, p.size.value * scale if p.size.floating else p.size.value) for p in flat]


def interpret(cga: Cga, width: float, height: float) -> list[Box]:
    """The terminal rectangles (label, x0, y0, x1, y1) of Facade on a width x height façade."""
    out: list[Box] = []

    def apply(rule: str, x0: float, y0: float, x1: float, y1: float) -> None:
        for op in cga.rules[rule]:
            if isinstance(op, Split):
                cursor = x0 if op.axis == "x" else y0
                for child, size in lengths(op.items, (x1 - x0) if op.axis == "x" else y1 - y0):
                    if op.axis == "x":
                        apply(child, cursor, y0, cursor + size, y1)
                    else:
                        apply(child, x0, cursor, x1, cursor + size)
                    cursor += size
                return
            if isinstance(op, tuple) and op[0] == "call":
                apply(op[1], x0, y0, x1, y1)
                return
        label = cga.label(rule)
        assert label is not None, f"terminal rule {rule} names no label"
        out.append((label, x0, y0, x1, y1))

    apply("Facade", 0.0, 0.0, width, height)
    return out


def assert_same_boxes(got: list[Box], want: list[Box], size: float) -> None:
    """The same labelled rectangles, one to one, each edge within ``TOLERANCE`` of size."""
    assert len(got) == len(want)
    left = list(got)
    for label, *edges in sorted(want):
        match = next(
            (
                box
                for box in left
                if box[0] == label
                and max(abs(a - b) for a, b in zip(box[1:], edges, strict=True)) <= TOLERANCE * size
            ),
            None,
        )
        assert match is not None, f"{label} at {edges} is not derived by the CGA"
        left.remove(match)


def test_the_interpreter_follows_cityengines_documented_examples() -> None:
    # CityEngine's help (Subdivision split): a repeat of ~2.1 over 10 lays 5 copies of 2,
    # the count whose size is closest to the written one (floor would give 4 of 2.5); a
    # floating size takes what the absolute sizes leave
    cga = Parser(
        'version "2023.1"\nattr a = 2.1\nA --> split(x) { { ~a: B }* }\nB --> color("#000000")\n'
        "C --> split(x) { 3: B | ~1: B }\n"
    ).parse()
    group = cga.rules["A"][0]
    assert isinstance(group, Split)
    assert lengths(group.items, 10.0) == [("B", pytest.approx(2.0))] * 5
    floating = cga.rules["C"][0]
    assert isinstance(floating, Split)
    assert lengths(floating.items, 5.0) == [("B", 3.0), ("B", pytest.approx(2.0))]


def _grammar(layout: LabelledLayout, extensions: tuple[str, ...] = ()) -> Grammar:
    return extract(tile(layout, 0), iterations=150, extensions=extensions).grammar


def _round_trip(grammar: Grammar, width: float, height: float) -> str:
    text = grammar_cga(grammar, width, height, "test")
    cga = check(text)
    got = interpret(cga, width, height)
    assert_same_boxes(got, derive(grammar, width, height), max(width, height))
    return text


# -- the tests -------------------------------------------------------------------------------


def _grid() -> LabelledLayout:
    rects = (
        Rect("window", 0, 0, 1, 1),
        Rect("door", 1, 1, 3, 2),
        Rect("sill", 3, 2, 4, 4),
        Rect("balcony", 1, 2, 3, 4),
    )
    return LabelledLayout(4.0, 4.0, rects)


LAYOUTS = {
    "floors": (_floors(), ()),
    "house": (_house(), ()),
    "house-extended": (_house(), ("repeatABA", "symsplit", "gridsplit")),
    "aba": (_row(".w.w.w.", 1.3), ("repeatABA",)),
    "symmetric": (_row("w..ww..w", 0.7), ("symsplit",)),
    "grid": (_grid(), ("gridsplit",)),
}


@pytest.mark.parametrize("name", LAYOUTS)
def test_the_cga_derives_the_layout_the_grammar_derives(name: str) -> None:
    layout, extensions = LAYOUTS[name]
    grammar = _grammar(layout, extensions)
    _round_trip(grammar, layout.width, layout.height)


@pytest.mark.parametrize("seed", range(12))
def test_random_layouts_round_trip_through_cga(seed: int) -> None:
    extensions = ("repeatABA", "symsplit", "gridsplit") if seed % 2 else ()
    grammar = _grammar(_random_layout(seed), extensions)
    _round_trip(grammar, 8.0, 6.0)


def test_rules_map_to_cga_constructs() -> None:
    text = _round_trip(_grammar(_floors()), 7.0, 9.5)
    assert text.startswith('version "2023.1"\n')
    assert re.search(r"split\(x\) \{ \{ [^{}]*\}\* \}", text) or re.search(
        r"split\(y\) \{ \{ [^{}]*\}\* \}", text
    ), "a repeat is a { ... }* group"
    assert "@StartRule\nFacade -->" in text and "@StartRule\nLot -->" in text
    assert 'set(material.name, "window")' in text and 'color("#e7f2fa")' in text
    assert "Wall -->" in text  # the background label
    # extensions: repeatABA is A { B A }*, a grid is rows of columns
    aba = _round_trip(_grammar(_row(".w.w.w."), ("repeatABA",)), 7.0, 1.0)
    assert "split(x) { ~wall_w: Wall | { ~window_w: Window | ~wall_w: Wall }* }" in aba
    grid = _round_trip(_grammar(_grid(), ("gridsplit",)), 4.0, 4.0)
    assert "Facade_row1 -->" in grid and "facade_col_w" in grid


def _storeys() -> Grammar:
    """A plinth, three storeys of four bays and a cornice on a 10 x 11 façade."""
    rules = {
        "S": Rule("split", "y", (Part(1.2, "plinth"), Part(9.0, "Storeys"), Part(0.8, "cornice"))),
        "Storeys": Rule("repeat", "y", (Part(3.0, "Storey"),), 3),
        "Storey": Rule("split", "y", (Part(0.2, "molding"), Part(2.8, "Bays"))),
        "Bays": Rule("split", "x", (Part(1.0, "facade"), Part(8.0, "Row"), Part(1.0, "facade"))),
        "Row": Rule("repeat", "x", (Part(2.0, "Bay"),), 4),
        "Bay": Rule("split", "x", (Part(0.2, "facade"), Part(1.25, "Win"), Part(0.55, "facade"))),
        "Win": Rule(
            "split",
            "y",
            (Part(0.65, "facade"), Part(0.15, "sill"), Part(1.8, "window"), Part(0.2, "facade")),
        ),
    }
    return Grammar("S", rules, {"plinth", "cornice", "molding", "facade", "sill", "window"})


def test_thin_parts_and_the_parts_beside_a_repeat_keep_their_size() -> None:
    text = _round_trip(_storeys(), 10.0, 11.0)
    # the storeys repeat, so they float and the plinth and cornice keep their height
    assert "split(y) { plinth_h: Plinth | ~storeys_h: Storeys | cornice_h: Cornice }" in text
    assert "split(y) { { ~storey_h: Storey }* }" in text
    # a moulding and a sill are thin (under 3 % of the façade): fixed
    assert "split(y) { molding_h: Molding | ~bays_h: Bays }" in text
    assert "| sill_h: Sill |" in text
    # the walls beside the row of bays keep their width; the bays repeat and stretch
    assert "split(x) { wall_w: Wall | ~row_w: Row | wall_w: Wall }" in text
    assert "split(x) { wall_w2: Wall | ~win_w: Win | ~wall_w3: Wall }" in text
    cga = check(text)
    assert cga.attrs["storeys_h"] == 9.0 and cga.attrs["sill_h"] == 0.15
    # a wider and taller façade: more bays and storeys, the fixed sizes kept
    boxes = interpret(cga, 14.5, 14.0)
    assert sum(box[0] == "window" for box in boxes) == 6 * 4
    plinth = next(box for box in boxes if box[0] == "plinth")
    assert plinth[4] - plinth[2] == pytest.approx(1.2)


@pytest.mark.parametrize(
    ("name", "width", "height"), [("house", 16.5, 17.0), ("floors", 11.0, 13.0), ("aba", 12.0, 2.0)]
)
def test_at_a_new_size_the_cga_lays_what_facade_grammar_derive_lays(
    name: str, width: float, height: float
) -> None:
    # the CGA's fixed and floating sizes and repeats are those of --derive before alignment
    layout, extensions = LAYOUTS[name]
    grammar = _grammar(layout, extensions)
    cga = check(grammar_cga(grammar, layout.width, layout.height, name))
    want = [
        (p.label, p.x0, p.y0, p.x1, p.y1)
        for p in derive_at(grammar, (layout.width, layout.height), width, height)
    ]
    assert_same_boxes(interpret(cga, width, height), want, max(width, height))


def test_names_are_cga_identifiers_and_distinct() -> None:
    labels = ["fenêtre", "2nd floor", "NIL", "Facade", "Wall", "wall", "a-b", "a_b", 'say "hi"']
    rects = tuple(
        Rect(label, 0.5 + 1.5 * i, 1.0, 1.5 + 1.5 * i, 2.0) for i, label in enumerate(labels)
    )
    layout = LabelledLayout(1.5 * len(labels) + 0.5, 3.0, rects)
    grammar = _grammar(layout)
    text = grammar_cga(grammar, layout.width, layout.height, 'odd "name"\nhere')
    cga = check(text)
    named = {cga.label(rule) for rule in cga.rules} - {None}
    assert named == {*labels[:-1], "say _hi_", "facade"}
    assert "NIL -->" not in text and text.count("Facade -->") == 1
    sane = LabelledLayout(layout.width, 3.0, rects[:-1])
    _round_trip(_grammar(sane), sane.width, sane.height)


def test_a_single_label_is_a_start_rule_calling_it() -> None:
    grammar = Grammar("wall", {}, {"wall"})
    text = _round_trip(grammar, 4.0, 3.0)
    assert "Facade -->\n    Wall\n" in text


def test_the_cga_is_the_same_bytes_for_the_same_input() -> None:
    first = grammar_cga(_grammar(_house()), 11.7, 13.0, "house")
    assert grammar_cga(_grammar(_house()), 11.7, 13.0, "house") == first
    assert not re.search(r"\d[eE][+-]?\d", first)  # plain decimals


def _facade(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "facadecli", *args], capture_output=True, text=True
    )


def test_facade_grammar_writes_the_cga_beside_the_grammar(tmp_path: Path) -> None:
    source = tmp_path / "house.json"
    _write_plain(source, _house())
    result = _facade("grammar", str(source), "-o", str(tmp_path / "out"), "-n", "100")
    assert result.returncode == 0, result.stderr
    text = (tmp_path / "out" / "house.cga").read_text()
    assert str(tmp_path / "out" / "house.cga") in result.stdout
    extraction = extract_grammar(source, Options(iterations=100))
    tiling = extraction.tiling
    assert text == grammar_cga(extraction.grammar, tiling.xs[-1], tiling.ys[-1], "house")
    got = interpret(check(text), tiling.xs[-1], tiling.ys[-1])
    assert_same_boxes(got, derive(extraction.grammar, tiling.xs[-1], tiling.ys[-1]), 13.0)
