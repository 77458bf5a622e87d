"""Split grammars (Wu et al. 2014, section 3): rules, their cost, their text, and derivation
back to terminal rectangles.

A rule rewrites a non-terminal region into parts along one axis:

- ``split``: the parts in order;
- ``repeat``: the parts ``count`` times;
- ``repeatABA`` (extension): ``A (B A)^count`` for parts ``(A, B)``;
- ``symsplit`` (extension): the parts, then the same parts mirrored; with ``centre`` the last
  part is the centre and is not repeated;
- ``gridsplit`` (extension): rows of heights ``parts[i].size`` by columns of widths
  ``across``, the parts in row-major order, bottom up.

Its cost is Eq. 2: 0.1 for a split (``split``, ``symsplit``, ``gridsplit``) or 0.5 for a
repeat (``repeat``, ``repeatABA``), plus the number of parts written. A grammar's cost is the
sum over its rules (Eq. 1).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

Axis = Literal["x", "y"]
# "run" is the derivation's own (grammar.derive): bays of one size and kind, A B A B A,
# that a wider façade may have more of; no extracted grammar holds one
Op = Literal["split", "repeat", "repeatABA", "symsplit", "gridsplit", "run"]
EXTENSIONS: tuple[Op, ...] = ("repeatABA", "symsplit", "gridsplit")


@dataclass(frozen=True)
class Costs:
    split: float = 0.1
    repeat: float = 0.5


DEFAULT_COSTS = Costs()


@dataclass(frozen=True)
class Part:
    size: float  # along the rule's axis, in the layout's units
    symbol: str


@dataclass(frozen=True)
class Rule:
    op: Op
    axis: Axis
    parts: tuple[Part, ...]
    count: int = 1
    centre: bool = False  # symsplit: the last part is the centre
    across: tuple[float, ...] = ()  # gridsplit: the column widths

    def cost(self, costs: Costs = Costs()) -> float:
        base = costs.repeat if self.op in ("repeat", "repeatABA") else costs.split
        return base + len(self.parts)

    def sequence(self) -> tuple[Part, ...]:
        """The parts in the order they are laid along the axis (not for gridsplit)."""
        if self.op == "repeat":
            return self.parts * self.count
        if self.op == "repeatABA":
            a, b = self.parts
            return (a, *((b, a) * self.count))
        if self.op == "symsplit":
            mirrored = self.parts[:-1] if self.centre else self.parts
            return self.parts + tuple(reversed(mirrored))
        return self.parts

    def text(self, name: str) -> str:
        if self.op == "gridsplit":
            rows = len(self.parts) // len(self.across)
            body = " ; ".join(
                " | ".join(
                    p.symbol for p in self.parts[i * len(self.across) : (i + 1) * len(self.across)]
                )
                for i in range(rows)
            )
            heights = ", ".join(f"{self.parts[i * len(self.across)].size:.4g}" for i in range(rows))
            widths = ", ".join(f"{w:.4g}" for w in self.across)
            return f"{name} --> gridsplit(y: {heights}; x: {widths}) {{ {body} }}"
        body = " | ".join(f"{p.size:.4g}: {p.symbol}" for p in self.parts)
        suffix = f"*{self.count}" if self.op in ("repeat", "repeatABA") else ""
        if self.op == "symsplit" and self.centre:
            suffix = " centre"
        return f"{name} --> {self.op}({self.axis}) {{ {body} }}{suffix}"


@dataclass
class Grammar:
    start: str
    rules: dict[str, Rule] = field(default_factory=dict)
    terminals: set[str] = field(default_factory=set)
    costs: Costs = Costs()

    @property
    def cost(self) -> float:
        return sum(rule.cost(self.costs) for rule in self.rules.values())

    def text(self) -> str:
        """One rule a line, CGA-like (the paper's section 4.6), the start symbol first, then
        in the order the rules were made."""
        if not self.rules:  # the whole façade is one terminal
            return f"{self.start}\n"
        names = [self.start, *(name for name in self.rules if name != self.start)]
        return "\n".join(self.rules[name].text(name) for name in names if name in self.rules) + "\n"


def inlined(grammar: Grammar) -> Grammar:
    """The grammar with every split rule that is used once, as a part of a split along the
    same axis, written into that split: the same derivation for less (Eq. 1 charges a rule
    its operation and its parts; the parent only gains the parts). Wu et al. 2014 leave
    this to the search, which rarely finds it: most grammars it makes have such rules.

    A rule used once has one parent, so these rules hang from their parents as trees: each
    rule's parts are found once, its children's first (linear in the rules)."""
    rules = grammar.rules
    uses: dict[str, int] = {grammar.start: 1}
    for rule in rules.values():
        for part in rule.parts:
            uses[part.symbol] = uses.get(part.symbol, 0) + 1

    def inlinable(parent: Rule, symbol: str) -> bool:
        child = rules.get(symbol)
        return (
            parent.op == "split"
            and uses[symbol] == 1
            and child is not None
            and child.op == "split"
            and child.axis == parent.axis
        )

    parts: dict[str, tuple[Part, ...]] = {}  # each rule's parts, its inlined children's in
    inside: set[str] = set()  # rules written into their parent
    for name in rules:
        stack = [name]
        while stack:
            top = stack[-1]
            rule = rules[top]
            if top in parts:
                stack.pop()
                continue
            waiting = [p.symbol for p in rule.parts if inlinable(rule, p.symbol)]
            waiting = [symbol for symbol in waiting if symbol not in parts]
            if waiting:
                stack.extend(waiting)
                continue
            written: list[Part] = []
            for part in rule.parts:
                if inlinable(rule, part.symbol):
                    inside.add(part.symbol)
                    written.extend(parts[part.symbol])
                else:
                    written.append(part)
            parts[top] = tuple(written)
            stack.pop()
    merged = {
        name: rule if parts[name] == rule.parts else replace(rule, parts=parts[name])
        for name, rule in rules.items()
        if name not in inside
    }
    return replace(grammar, rules=merged)


Box = tuple[str, float, float, float, float]


def derive(grammar: Grammar, width: float, height: float) -> list[Box]:
    """The terminal rectangles (label, x0, y0, x1, y1) the grammar derives, with the sizes
    it was extracted with."""
    return [box for _, terminal, box in derive_tree(grammar, width, height) if terminal]


def derive_tree(grammar: Grammar, width: float, height: float) -> list[tuple[int, bool, Box]]:
    """Every region of the derivation, parents before children, as ``(depth, terminal,
    box)``; the start symbol is at depth 0."""
    out: list[tuple[int, bool, Box]] = []

    def expand(symbol: str, x0: float, y0: float, x1: float, y1: float, depth: int) -> None:
        rule = grammar.rules.get(symbol)
        out.append((depth, rule is None, (symbol, x0, y0, x1, y1)))
        if rule is None:
            return
        if rule.op == "gridsplit":
            columns = len(rule.across)
            y = y0
            for i in range(len(rule.parts) // columns):
                row = rule.parts[i * columns : (i + 1) * columns]
                x = x0
                for part, w in zip(row, rule.across, strict=True):
                    expand(part.symbol, x, y, x + w, y + row[0].size, depth + 1)
                    x += w
                y += row[0].size
            return
        cursor = y0 if rule.axis == "y" else x0
        for part in rule.sequence():
            end = cursor + part.size
            if rule.axis == "y":
                expand(part.symbol, x0, cursor, x1, end, depth + 1)
            else:
                expand(part.symbol, cursor, y0, end, y1, depth + 1)
            cursor = end

    expand(grammar.start, 0.0, 0.0, width, height, 0)
    return out
