"""The grammar as CityEngine CGA (``<name>.cga``): a rule file to paste into CityEngine and
run on a façade shape.

- ``version "2023.1"``, then one ``attr`` a size, so that sizes can be tweaked in the
  Inspector: one per distinct size of one symbol along one axis (``window_w``,
  ``window_w2`` for a second width; ``_h`` for heights), declared before every rule.
- ``Facade`` (``@StartRule``) is the grammar's start symbol; ``Lot`` (``@StartRule`` too)
  extrudes a lot to the façade's height and puts ``Facade`` on every side.
- One rule a non-terminal: ``split`` is ``split(x|y) { size: Rule | ... }``; ``repeat`` is
  ``split(x) { { ~a: A | ~b: B }* }`` (CityEngine lays as many copies as fit best and
  stretches them); ``repeatABA`` is ``{ ~a: A | { ~b: B | ~a: A }* }``; ``symsplit`` is its
  parts written out mirrored; ``gridsplit`` is a split into rows (``<Rule>_row<k>``), each
  split into the columns.
- Sizes follow ``facade grammar --derive`` (``derive.py``): a part thinner than ``THIN``
  of the façade keeps its absolute size (frames, sills); in a split with a part that holds a
  repeat along the split's axis, that part floats (``~``) and the others keep their size,
  so a wider façade gets more bays rather than wider windows; otherwise the parts float and
  share the change. A split always has a floating part: the rounding of the sizes is taken
  up there. Grid rows and columns float.
- One rule a label: ``set(material.name, "<label>")`` (exported models keep the label) and
  ``color`` from the palette of the SVG pictures. The background label is ``Wall``.

Names are CGA identifiers: ASCII letters, digits and ``_``, starting with a letter; rules
start with a capital, attrs with a small letter, so they never meet. The text depends only
on the grammar, its size and its name: the same input gives the same bytes.
"""

from __future__ import annotations

import re
import unicodedata
from dataclasses import dataclass, field
from decimal import Decimal

from facadecli.grammar.derive import THIN, elastic_parts
from facadecli.grammar.inputs import BACKGROUND
from facadecli.grammar.palette import label_colour
from facadecli.grammar.split import Axis, Grammar, Part, Rule

VERSION = "2023.1"
START = "Facade"
LOT = "Lot"
WALL = "Wall"  # the background label's rule
HEIGHT_ATTR = "facade_height"
RESERVED = {START, LOT, "NIL"}
LINE = 96  # characters: a longer split is written one part a line
USES_SHOWN = 4  # rules named in an attr's comment

Item = str | list["Item"]  # a part ("~window_w: Window") or a repeated group of items


def _ascii(text: str) -> str:
    plain = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode()
    return re.sub(r"[^A-Za-z0-9_]+", "_", plain).strip("_")


def _unique(name: str, taken: set[str]) -> str:
    base, n = name, 2
    while name in taken:
        name, n = f"{base}_{n}", n + 1
    taken.add(name)
    return name


def rule_name(symbol: str, taken: set[str]) -> str:
    """A new rule name for a symbol: a CGA identifier starting with a capital."""
    name = _ascii(symbol) or "Label"
    if not name[0].isalpha():
        name = "L" + name
    return _unique(name[0].upper() + name[1:], taken)


def rule_names(grammar: Grammar) -> dict[str, str]:
    """Every symbol of the grammar and its CGA rule: the start symbol is ``Facade``, then the
    non-terminals in the grammar's order, then the labels in sorted order (the background
    label ``Wall``)."""
    taken = set(RESERVED)
    names = {grammar.start: START} if grammar.rules else {}
    for symbol in grammar.rules:
        if symbol not in names:
            names[symbol] = rule_name(symbol, taken)
    for label in sorted(_labels(grammar), key=lambda label: (label != BACKGROUND, label)):
        if label not in names:
            names[label] = rule_name(WALL if label == BACKGROUND else label, taken)
    return names


def _labels(grammar: Grammar) -> set[str]:
    """The terminal symbols: every part that has no rule (the start, when none has)."""
    if not grammar.rules:
        return {grammar.start}
    return {p.symbol for rule in grammar.rules.values() for p in rule.parts} - set(grammar.rules)


def _num(value: float) -> str:
    """Six significant digits, never in exponent form (CGA reads plain decimals)."""
    text = f"{value:.6g}"
    return format(Decimal(text), "f") if "e" in text else text


@dataclass
class _Attrs:
    """The attrs in the order they are first used: one a (base, axis, written size)."""

    taken: set[str] = field(default_factory=lambda: {HEIGHT_ATTR})
    names: dict[tuple[str, Axis, str], str] = field(default_factory=dict)
    next: dict[str, int] = field(default_factory=dict)  # the next number to try for a stem
    uses: dict[str, dict[str, None]] = field(default_factory=dict)  # attr: its rules, in order

    def get(self, base: str, axis: Axis, size: float, rule: str) -> str:
        key = (base, axis, _num(size))
        if key not in self.names:
            stem = f"{base}_{'w' if axis == 'x' else 'h'}"
            name, n = stem, self.next.get(stem, 2)
            while name in self.taken:
                name, n = f"{stem}{n}", n + 1
            self.next[stem] = n
            self.taken.add(name)
            self.names[key] = name
            self.uses[name] = {}
        name = self.names[key]
        self.uses[name][rule] = None
        return name

    def lines(self) -> list[str]:
        out = []
        for (_, axis, value), name in self.names.items():
            uses = list(self.uses[name])
            shown = ", ".join(uses[:USES_SHOWN]) + (", ..." if len(uses) > USES_SHOWN else "")
            out.append(f"attr {name} = {value}  # {axis} in {shown}")
        return out


def _attr_base(rule: str) -> str:
    return rule[0].lower() + rule[1:]


def _render(head: str, items: list[Item]) -> str:
    """``head { items }``, on one line when short, else one item a line."""

    def flat(items: list[Item]) -> str:
        return " | ".join(i if isinstance(i, str) else "{ " + flat(i) + " }*" for i in items)

    one = f"{head} {{ {flat(items)} }}"
    if len(one) <= LINE:
        return "    " + one

    def block(items: list[Item], indent: str) -> list[str]:
        lines = []
        for k, item in enumerate(items):
            bar = "  " if k == 0 else "| "
            if isinstance(item, str):
                lines.append(f"{indent}{bar}{item}")
            elif len(f"{indent}{bar}{{ {flat(item)} }}*") <= LINE:
                lines.append(f"{indent}{bar}{{ {flat(item)} }}*")
            else:
                lines.append(f"{indent}{bar}{{")
                lines += block(item, indent + "    ")
                lines.append(f"{indent}  }}*")
        return lines

    return "\n".join([f"    {head} {{", *block(items, "        "), "    }"])


def grammar_cga(grammar: Grammar, width: float, height: float, name: str = "facade") -> str:
    """The grammar as a CityEngine CGA rule file (see the module); ``width`` x ``height`` is
    the size it was extracted at."""
    names = rule_names(grammar)
    elastic = elastic_parts(grammar)
    thin = {"x": THIN * width, "y": THIN * height}
    attrs = _Attrs()
    taken = set(RESERVED) | set(names.values())
    rules: list[str] = []

    def part(p: Part, axis: Axis, floating: bool, rule: str) -> str:
        attr = attrs.get(_attr_base(names[p.symbol]), axis, p.size, rule)
        return f"{'~' if floating else ''}{attr}: {names[p.symbol]}"

    def floats(rule: Rule) -> dict[Part, bool]:
        """Which parts float (see the module): as ``derive.distribute`` sizes them."""
        free = {p: p.size >= thin[rule.axis] for p in rule.parts}
        stretch = {p: f and elastic.get((p.symbol, rule.axis), False) for p, f in free.items()}
        chosen = stretch if any(stretch.values()) else free
        return chosen if any(chosen.values()) else dict.fromkeys(rule.parts, True)

    order = [grammar.start, *(symbol for symbol in grammar.rules if symbol != grammar.start)]
    for symbol in order if grammar.rules else []:
        rule, cga = grammar.rules[symbol], names[symbol]
        head = f"split({rule.axis})"
        notes = []
        start = "@StartRule\n" if symbol == grammar.start else ""
        if rule.op == "gridsplit":
            columns = len(rule.across)
            col = f"{_attr_base(cga)}_col"
            rows: dict[tuple[str, ...], str] = {}
            items: list[Item] = []
            row_rules = []
            for i in range(len(rule.parts) // columns):
                cells = rule.parts[i * columns : (i + 1) * columns]
                key = tuple(c.symbol for c in cells)
                if key not in rows:
                    rows[key] = row = _unique(f"{cga}_row{len(rows) + 1}", taken)
                    row_items: list[Item] = [
                        f"~{attrs.get(col, 'x', w, row)}: {names[c.symbol]}"
                        for c, w in zip(cells, rule.across, strict=True)
                    ]
                    row_rules.append(f"{row} -->\n{_render('split(x)', row_items)}")
                height_attr = attrs.get(_attr_base(rows[key]), "y", cells[0].size, cga)
                items.append(f"~{height_attr}: {rows[key]}")
            rules.append(f"{start}{cga} -->\n{_render('split(y)', items)}")
            rules += row_rules
            continue
        floating = floats(rule)
        if rule.op == "repeat":
            items = [[part(p, rule.axis, floating[p], cga) for p in rule.parts]]
            notes.append(f"# {rule.count} copies at the extracted size")
        elif rule.op == "repeatABA":
            a, b = (part(p, rule.axis, floating[p], cga) for p in rule.parts)
            items = [a, [b, a]]
            notes.append(f"# {rule.count} copies of the group at the extracted size")
        else:  # split, symsplit
            items = [part(p, rule.axis, floating[p], cga) for p in rule.sequence()]
        rules.append("\n".join([*notes, f"{start}{cga} -->", _render(head, items)]))
    if not grammar.rules:  # the whole façade is one label
        rules.append(f"@StartRule\n{START} -->\n    {names[grammar.start]}")
    for label in sorted(_labels(grammar), key=lambda label: names[label]):
        shown = _printable(label)
        what = ": the wall between the elements" if label == BACKGROUND else ""
        rules.append(
            f'# label "{shown}"{what}\n{names[label]} -->\n'
            f'    set(material.name, "{shown}")\n    color("{label_colour(label)}")'
        )
    unit = ""
    if width == 1.0 and height == 1.0:
        unit = "# The layout is 1 x 1 (CMP annotations): facade grammar --size WxH gives metres.\n"
    header = (
        f'version "{VERSION}"\n\n'
        f"# {_printable(name)}: the split grammar that facade grammar extracted from a layout of "
        f"{_num(width)} x {_num(height)},\n"
        "# as CityEngine CGA. Start rule Facade on a facade shape (scope x along it, y up),\n"
        "# or Lot on a lot (extruded, with Facade on every side). Sizes are in the layout's\n"
        "# units: ~size floats (stretches to fill what the fixed sizes leave), size is fixed,\n"
        "# and { ... }* repeats as many times as fit best.\n"
        f"{unit}\n"
        f"attr {HEIGHT_ATTR} = {_num(height)}  # Lot: the building's height\n"
    )
    lot = f"@StartRule\n{LOT} -->\n    extrude({HEIGHT_ATTR})\n    comp(f) {{ side: {START} }}"
    return header + "\n".join(attrs.lines()) + "\n\n" + "\n\n".join([lot, *rules]) + "\n"


def _printable(text: str) -> str:
    """Text for a CGA string or comment: no quotes, backslashes or line breaks."""
    return re.sub(r'["\\\x00-\x1f\x7f-\x9f\u2028\u2029]', "_", text)


__all__ = ["grammar_cga", "rule_names"]
